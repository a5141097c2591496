"""Plans executed in MuJoCo, in the world's view (thesis Fig 1-7): the environment features are
fixed and the gripper moves.

For each push of a plan (consecutive steps with the same pusher), the pusher's feature is put
where the plan needs it — relative to where the gripper is, with the object where the plan says
it is in the grasp (open loop) — 2 mm away from the object; the gripper closes the gap, then
moves with the inverse of the virtual pusher's planned motion, so that the object, pressed
against the fixed feature, moves in the grasp; then it backs off 2 mm and the next feature is
brought (a switch-over). The object's pose in the grasp is recorded all along.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ArgumentError
from .model import (Contact, Driver, compose, driven_body_xml, feature_xml, header, inverse, object_xml,
                           pads_xml, planar_pose, quat_y)
from ..sim.quasistatic import Replay, body_twist, integrate_pose
from ..scene.planar import Scene

GAP = 0.002  # m between the object and a feature when it is brought
PARK = np.array([0.0, 5.0, 0.0])


@dataclass
class Perturbation:
    """Scale factors of the physical parameters (the executed world differs from the plan's)."""

    friction: float = 1.0
    grip: float = 1.0
    mass: float = 1.0
    #: factor on the features' (pushers') friction; None: ``friction``
    pusher_friction: float | None = None

    @property
    def pusher(self) -> float:
        return self.friction if self.pusher_friction is None else self.pusher_friction

    @classmethod
    def draw(cls, spread: float, rng, base: "Perturbation" = None) -> "Perturbation":
        """Each factor uniformly in [1 − spread, 1 + spread], times ``base``."""
        b = base or cls()
        u = rng.uniform(1 - spread, 1 + spread, 3)
        return cls(b.friction * u[0], b.grip * u[1], b.mass * u[2])


def _segments(plan: dict) -> list:
    path = plan["path"]
    segs = []
    for a, b in zip(path[:-1], path[1:]):
        if not segs or segs[-1]["pusher"] != b["pusher"]:
            segs.append({"pusher": b["pusher"], "knots": [np.asarray(a["pose"], float)]})
        segs[-1]["knots"].append(np.asarray(b["pose"], float))
    return segs


def build(scene: Scene, plan: dict, perturb: Perturbation = Perturbation(), contact: Contact = Contact()) -> str:
    """MJCF of the execution: object at the plan's start, gripper (mocap) with force-driven pads,
    one parked feature (mocap) per pusher the plan uses."""
    q0 = np.asarray(plan["path"][0]["pose"], float)
    assets, obj = object_xml(scene, q0, mass_scale=perturb.mass)
    pads, acts = pads_xml(scene, friction_scale=perturb.friction)
    used = sorted({k["pusher"] for k in plan["path"][1:]})
    feats = "\n".join(feature_xml(scene, p, f"feature_{p}", perturb.pusher, PARK) for p in used)
    return (f'<mujoco model="{scene.name}-execution">{header(scene, contact)}<asset>{assets}</asset>\n'
            f'<worldbody>\n{obj}\n{driven_body_xml("gripper", pads)}\n{feats}\n</worldbody>\n'
            f'<actuator>{acts}</actuator></mujoco>')


def execute_plan(scene: Scene, plan: dict, perturb: Perturbation = Perturbation(), speed: float = 0.01,
                 record_dt: float = 0.02, contact: Contact = Contact(), settle: float = 0.2) -> Replay:
    """Executes ``plan`` open loop in MuJoCo; returns the recorded object pose in the grasp."""
    import mujoco

    for i, k in enumerate(plan["path"][1:], 1):
        if k["pusher"] not in scene.pusher_names:
            raise ArgumentError(f"invalid `plan.path[{i}].pusher`: no pusher {k['pusher']!r} in the scene",
                                f"plan.path[{i}].pusher")
    model = mujoco.MjModel.from_xml_string(build(scene, plan, perturb, contact))
    data = mujoco.MjData(model)
    data.ctrl[:] = scene.grip_force * perturb.grip
    grip = Driver(model, "gripper")
    dt = contact.timestep
    every = max(1, int(round(record_dt / dt)))
    rec_t, rec_q, rec_plan = [], [], []
    state = {"t": 0.0, "k": 0, "gripper": np.zeros(3), "planned": np.asarray(plan["path"][0]["pose"], float)}

    def set_gripper(g):
        grip.move(data, g, dt)
        state["gripper"] = np.asarray(g, float)

    def grasp_pose():
        return compose(inverse(state["gripper"]), planar_pose(model, data, "object"))

    def step():
        mujoco.mj_step(model, data)
        state["t"] += dt
        state["k"] += 1
        if state["k"] % every == 0:
            rec_t.append(state["t"])
            rec_q.append(grasp_pose())
            rec_plan.append(state["planned"].copy())

    def move(path_fn, duration):
        n = max(1, int(np.ceil(duration / dt)))
        for i in range(1, n + 1):
            set_gripper(path_fn(i / n))
            step()

    grip.set(data, np.zeros(3))
    mujoco.mj_forward(model, data)
    for _ in range(int(settle / dt)):
        set_gripper(np.zeros(3))
        step()
    max_slip, steps = 0.0, []
    for seg in _segments(plan):
        pusher = seg["pusher"]
        fm = int(model.body_mocapid[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, f"feature_{pusher}")])
        p = scene.pusher(pusher)
        n_obj = p.normal / np.linalg.norm(p.normal)
        # the feature where the plan needs it, relative to the gripper: F = G ∘ P0
        F = compose(state["gripper"], seg["knots"][0])
        c, s = np.cos(F[2]), np.sin(F[2])
        n_w = np.array([c * n_obj[0] - s * n_obj[1], s * n_obj[0] + c * n_obj[1]])
        data.mocap_pos[fm] = [F[0] - GAP * n_w[0], 0.0, F[1] - GAP * n_w[1]]
        data.mocap_quat[fm] = quat_y(F[2])
        g0 = state["gripper"].copy()
        # approach: the object moves against the feature
        move(lambda u: g0 - np.array([GAP * n_w[0], GAP * n_w[1], 0.0]) * u, GAP / speed)
        F = F - np.array([GAP * n_w[0], GAP * n_w[1], 0.0])
        ref = p.points.mean(axis=0)  # the feature's reference point, in its frame
        r0 = compose(inverse(planar_pose(model, data, "object")), compose(F, np.r_[ref, 0.0]))[:2]
        seg_slip = 0.0
        Pa = seg["knots"][0]
        for a, b in zip(seg["knots"][:-1], seg["knots"][1:]):
            xi = body_twist(a, b)
            length = float(np.linalg.norm(scene.metric_twist(xi)))
            if length == 0:
                continue
            P_start = Pa
            state["planned"] = a

            def path(u, P_start=P_start, xi=xi, a=a, b=b):
                P = integrate_pose(P_start, xi, u)
                state["planned"] = a + (b - a) * u
                return compose(F, inverse(P))

            move(path, length / speed)
            Pa = integrate_pose(P_start, xi, 1.0)
            r = compose(inverse(planar_pose(model, data, "object")), compose(F, np.r_[ref, 0.0]))[:2]
            t_obj = np.array([-n_obj[1], n_obj[0]])
            seg_slip = max(seg_slip, abs(float(t_obj @ (r - r0))))
        max_slip = max(max_slip, seg_slip)
        steps.append({"pusher": pusher, "slip": seg_slip, "end_pose": grasp_pose().tolist(),
                      "planned_end": seg["knots"][-1].tolist()})
        # back off and park the feature (a switch-over)
        g1 = state["gripper"].copy()
        move(lambda u: g1 + np.array([GAP * n_w[0], GAP * n_w[1], 0.0]) * u, GAP / speed)
        data.mocap_pos[fm] = PARK
    q = grasp_pose()
    task = scene.task
    goal = task.goal if task is not None else np.asarray(plan["path"][-1]["pose"], float)
    tol = task.tolerance if task is not None else np.array([1e-3, 1e-3, 0.0175])
    err = q - goal
    return Replay("mujoco", q, err, bool(np.all(np.abs(err) <= tol)), max_slip, np.array(rec_t), np.array(rec_q),
                  np.array(rec_plan), steps)


def animate_execution(scene: Scene, rep: Replay, path, fps: int = 20, every: int = 3):
    """A GIF (or MP4 when ffmpeg is available) of the object in the grasp during an execution,
    with the planned pose dashed."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.animation import FFMpegWriter, FuncAnimation, PillowWriter
    from matplotlib.patches import Circle, Polygon

    from ..viz.plotting import _object_at, animation_axes

    idx = list(range(0, len(rep.t), every))
    fig, ax = animation_axes(scene, [rep.poses[i] for i in idx])
    planned = Polygon(_object_at(scene, rep.planned[0]), closed=True, fill=False, ls="--", edgecolor="0.5")
    obj = Polygon(_object_at(scene, rep.poses[0]), closed=True, facecolor="tab:blue", alpha=0.5, edgecolor="k")
    ax.add_patch(planned)
    ax.add_patch(obj)
    if scene.pad is not None:
        ax.add_patch(Circle((0, 0), scene.pad[1], color="0.2", zorder=5))
    title = ax.set_title("")

    def draw(k):
        i = idx[k]
        obj.set_xy(_object_at(scene, rep.poses[i]))
        planned.set_xy(_object_at(scene, rep.planned[i]))
        title.set_text(f"{scene.name} in MuJoCo, t = {rep.t[i]:.1f} s (dashed: plan)")
        return obj, planned, title

    anim = FuncAnimation(fig, draw, frames=len(idx), blit=False)
    path = str(path)
    if path.lower().endswith(".mp4"):
        if not matplotlib.animation.writers.is_available("ffmpeg"):
            plt.close(fig)
            raise ArgumentError("invalid `--video`: MP4 needs ffmpeg, which is not installed; use a .gif", "--video")
        anim.save(path, writer=FFMpegWriter(fps=fps))
    else:
        anim.save(path, writer=PillowWriter(fps=fps))
    plt.close(fig)
    return path


class WorldRig:
    """MuJoCo in the world's view, driven push by push (for closed-loop control): every pusher's
    feature is parked; a push with a new pusher brings its feature against the object where the
    controller believes it is (12 mm back along the push normal, then the gripper approaches
    until the feature touches the object), then moves the gripper with the inverse of the
    virtual pusher's motion; a poke displaces the object in the grasp (the feature backs off
    first)."""

    APPROACH = 0.012  # m

    def __init__(self, scene: Scene, q0, perturb: Perturbation = Perturbation(), contact: Contact = Contact(),
                 settle: float = 0.2):
        import mujoco

        self.scene, self.contact = scene, contact
        q0 = np.asarray(q0, float)
        fake = {"path": [{"pose": q0.tolist(), "pusher": None}] + [{"pose": q0.tolist(), "pusher": p} for p in scene.pusher_names]}
        self.model = mujoco.MjModel.from_xml_string(build(scene, fake, perturb, contact))
        self.data = mujoco.MjData(self.model)
        self.data.ctrl[:] = scene.grip_force * perturb.grip
        self.grip = Driver(self.model, "gripper")
        self.g = np.zeros(3)
        self.grip.set(self.data, self.g)
        mujoco.mj_forward(self.model, self.data)
        self.dt = contact.timestep
        self.current = None  # (pusher, mocap id, feature frame F, world normal)
        self.feature_geoms = {}
        for p in scene.pusher_names:
            bid = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_BODY, f"feature_{p}")
            self.feature_geoms[p] = {i for i in range(self.model.ngeom) if self.model.geom_bodyid[i] == bid}
        self.idle(settle)

    def _step(self, g):
        import mujoco

        self.grip.move(self.data, g, self.dt)
        self.g = np.asarray(g, float)
        mujoco.mj_step(self.model, self.data)

    def pose(self) -> np.ndarray:
        """The object's pose in the grasp."""
        return compose(inverse(self.g), planar_pose(self.model, self.data, "object"))

    def idle(self, duration: float):
        for _ in range(max(1, int(round(duration / self.dt)))):
            self._step(self.g)

    def _touching(self, pusher: str) -> bool:
        ids = self.feature_geoms[pusher]
        return any(self.data.contact[i].geom1 in ids or self.data.contact[i].geom2 in ids for i in range(self.data.ncon))

    def back_off(self, speed: float = 0.01):
        """Moves the gripper away from the current feature and parks it (a switch-over)."""
        if self.current is None:
            return
        _, fm, _, n_w = self.current
        g1 = self.g.copy()
        n = max(1, int(round(GAP / speed / self.dt)))
        for i in range(1, n + 1):
            self._step(g1 + np.array([GAP * n_w[0], GAP * n_w[1], 0.0]) * i / n)
        self.data.mocap_pos[fm] = PARK
        self.current = None

    def bring(self, pusher: str, belief, speed: float = 0.01):
        """Brings ``pusher``'s feature against the object, placed where it would meet the object
        at the believed pose ``belief`` (in the grasp)."""
        import mujoco

        self.back_off(speed)
        fm = int(self.model.body_mocapid[mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_BODY, f"feature_{pusher}")])
        p = self.scene.pusher(pusher)
        n_obj = p.normal / np.linalg.norm(p.normal)
        F = compose(self.g, np.asarray(belief, float))
        c, s = np.cos(F[2]), np.sin(F[2])
        n_w = np.array([c * n_obj[0] - s * n_obj[1], s * n_obj[0] + c * n_obj[1]])
        self.data.mocap_pos[fm] = [F[0] - self.APPROACH * n_w[0], 0.0, F[1] - self.APPROACH * n_w[1]]
        self.data.mocap_quat[fm] = quat_y(F[2])
        F = F - np.array([self.APPROACH * n_w[0], self.APPROACH * n_w[1], 0.0])
        # approach until touching (at most twice the approach distance)
        step = speed * self.dt
        for _ in range(int(2 * self.APPROACH / step)):
            if self._touching(pusher):
                break
            self._step(self.g - np.array([step * n_w[0], step * n_w[1], 0.0]))
        self.current = (pusher, fm, F, n_w)

    def push(self, pusher: str, twist, duration: float, belief=None):
        """The object (believed at ``belief``) pushed with body twist ``twist`` for ``duration``
        against ``pusher``'s feature: the gripper moves so that the feature, seen from the
        gripper, follows the object's intended motion."""
        belief = self.pose() if belief is None else np.asarray(belief, float)
        if self.current is None or self.current[0] != pusher:
            self.bring(pusher, belief)
        F = self.current[2]
        P0 = compose(inverse(self.g), F)  # the feature (virtual pusher) in the grasp
        b = belief
        rel = compose(inverse(b), P0)
        n = max(1, int(round(duration / self.dt)))
        tw = np.asarray(twist, float)
        for i in range(1, n + 1):
            P = compose(integrate_pose(b, tw, duration * i / n), rel)
            self._step(compose(F, inverse(P)))

    def poke(self, delta):
        """Displaces the object in the grasp by ``delta`` (the current feature backs off first)."""
        import mujoco

        self.back_off()
        q = self.pose() + np.asarray(delta, float)
        w = compose(self.g, q)
        a = int(self.model.jnt_qposadr[0])
        self.data.qpos[a:a + 3] = [w[0], 0.0, w[1]]
        self.data.qpos[a + 3:a + 7] = [np.cos(-w[2] / 2), 0.0, np.sin(-w[2] / 2), 0.0]
        self.data.qvel[int(self.model.jnt_dofadr[0]):int(self.model.jnt_dofadr[0]) + 6] = 0.0
        mujoco.mj_forward(self.model, self.data)
        self.idle(0.1)
