"""Plans executed in MuJoCo, in the world's view (thesis Fig 1-7): the environment features are
fixed and the gripper moves.

For each push of a plan (consecutive steps with the same pusher), the pusher's feature is put
where the plan needs it — relative to where the gripper is, with the object where the plan says
it is in the grasp (open loop) — 2 mm away from the object; the gripper closes the gap, then
moves with the inverse of the virtual pusher's planned motion, so that the object, pressed
against the fixed feature, moves in the grasp; then it backs off 2 mm and the next feature is
brought (a switch-over). The object's pose in the grasp is recorded all along
(:class:`PlanarExecution`; :func:`execute_plan` runs one).

What the world's view needs — the model (``regrasp.mujoco.model``, built with ``mujoco.MjSpec``),
the driven gripper, placing a feature and backing off from it — is :class:`GripperRig`, shared by
:class:`PlanarExecution` and :class:`WorldRig`, which the closed loop (``regrasp.control.loop``)
drives push by push.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .. import progress
from ..errors import ArgumentError
from ..scene.perturbation import PlanarEnginePerturbation, Perturbation as _Perturbation
from ..scene.planar import Scene
from ..fields import check_number
from ..sim.quasistatic import Replay
from .push import MAX_DURATION
from ..pose import body_twist, integrate_pose, planar_compose, planar_inverse, planar_quat, planar_rotate
from .model import Contact, Driver, Rig, plan_dict, planar_pose, put_object
from .world import PARK, Layout, build as build_world

GAP = 0.002  # m between the object and a feature when it is brought


class Feature(NamedTuple):
    """A feature brought against the object: its pusher, its mocap body, its frame in the world
    (the pusher frame where it meets the object), its normal in the world and its geoms."""

    pusher: str
    mocap: int
    frame: np.ndarray
    normal: np.ndarray
    geoms: set


def _segments(path: list) -> list:
    """The pushes of a path: consecutive steps with the same pusher, as their knots."""
    segs = []
    for a, b in zip(path[:-1], path[1:]):
        if not segs or segs[-1]["pusher"] != b["pusher"]:
            segs.append({"pusher": b["pusher"], "knots": [np.asarray(a["pose"], float)]})
        segs[-1]["knots"].append(np.asarray(b["pose"], float))
    return segs


def _spec(scene: Scene, q0, pushers, perturb: _Perturbation, contact: Contact):
    """The world (:func:`~.world.build`): the object at ``q0`` held by pads on a planar driven
    gripper, the ``pushers``' features parked."""
    return build_world(Layout(scene, q0, "gripper", pushers=tuple(pushers), perturbation=perturb,
                              name=f"{scene.name}-execution"), contact)


def build(scene: Scene, plan, perturb: _Perturbation = _Perturbation(), contact: Contact = Contact()):
    """The execution's model, a ``mujoco.MjSpec`` (``.compile()`` it; ``.to_xml()`` is its MJCF):
    the object at the plan's start, the gripper (a driven body) with force-driven pads, one parked
    feature (a mocap body) per pusher the plan uses."""
    path = plan_dict(plan)["path"]
    return _spec(scene, path[0]["pose"], sorted({k["pusher"] for k in path[1:]}), perturb, contact)


class GripperRig(Rig):
    """MuJoCo in the world's view: the object held by force-driven pads on a driven gripper (its
    planar pose :attr:`g` in the world), the ``pushers``' features parked until one is brought
    against the object (:attr:`current`)."""

    def __init__(self, scene: Scene, q0, pushers, perturb: _Perturbation = _Perturbation(), contact: Contact = Contact()):
        super().__init__(_spec(scene, q0, pushers, perturb, contact), contact, scene.grip_force * perturb.grip)
        self.scene = scene
        self.gripper = Driver(self.model, "gripper")
        self.g = np.zeros(3)
        self.gripper.set(self.data, self.g)
        self.forward()
        self.current: Feature | None = None

    def step_to(self, g):
        """One time step with the gripper moving to ``g``."""
        self.gripper.move(self.data, g, self.dt)
        self.g = np.asarray(g, float)
        self.step()

    def move(self, path, duration: float):
        """Moves the gripper along ``path(u)``, u in (0, 1], over ``duration`` [s] (whole time steps)."""
        n = max(1, int(np.ceil(duration / self.dt)))
        for i in range(1, n + 1):
            self.step_to(path(i / n))

    def idle(self, duration: float):
        """Holds the gripper still for ``duration`` [s] (whole time steps)."""
        for _ in range(max(1, int(round(duration / self.dt)))):
            self.step_to(self.g)

    def pose(self) -> np.ndarray:
        """The object's pose in the grasp."""
        return planar_compose(planar_inverse(self.g), planar_pose(self.model, self.data, "object"))

    def place_feature(self, pusher: str, at, back: float) -> Feature:
        """Puts ``pusher``'s feature where it meets the object at pose ``at`` in the grasp, then
        ``back`` [m] further along its normal (away from the object)."""
        p = self.scene.pusher(pusher)
        F = planar_compose(self.g, np.asarray(at, float))
        n_w = planar_rotate(F[2], p.normal / np.linalg.norm(p.normal))
        F = F - np.array([back * n_w[0], back * n_w[1], 0.0])
        m = self.mocap(f"feature_{pusher}")
        self.data.mocap_pos[m] = [F[0], 0.0, F[1]]
        self.data.mocap_quat[m] = planar_quat(F[2])
        self.current = Feature(pusher, m, F, n_w, self.geoms(f"feature_{pusher}"))
        return self.current

    def back_off(self, speed: float = 0.01):
        """Moves the gripper the gap away from the current feature and parks it (a switch-over)."""
        if self.current is None:
            return
        g1, d = self.g.copy(), GAP * np.r_[self.current.normal, 0.0]
        self.move(lambda u: g1 + d * u, GAP / speed)
        self.data.mocap_pos[self.current.mocap] = PARK
        self.current = None


class PlanarExecution(GripperRig):
    """One open-loop execution of a plan in the world's view (see the module), recorded: the
    object's pose in the grasp and the planned one every ``record_dt`` [s], and per push its slip."""

    def __init__(self, scene: Scene, plan, perturb: _Perturbation = _Perturbation(), contact: Contact = Contact(),
                 speed: float = 0.01, record_dt: float = 0.02):
        path = plan_dict(plan)["path"]
        for i, k in enumerate(path[1:], 1):
            if k["pusher"] not in scene.pusher_names:
                raise ArgumentError(f"invalid `plan.path[{i}].pusher`: no pusher {k['pusher']!r} in the scene "
                                    f"(its pushers: {', '.join(scene.pusher_names)})",
                                    f"plan.path[{i}].pusher")
        super().__init__(scene, path[0]["pose"], sorted({k["pusher"] for k in path[1:]}), perturb, contact)
        self.path, self.speed = path, speed
        self.every = max(1, int(round(record_dt / self.dt)))
        self.t, self.k = 0.0, 0
        self.planned = np.asarray(path[0]["pose"], float)
        self.rec_t, self.rec_q, self.rec_plan = [], [], []
        self.steps = []  # per push: pusher, slip, end pose, planned end pose

    def step_to(self, g):
        super().step_to(g)
        self.t += self.dt
        self.k += 1
        if self.k % self.every == 0:
            self.rec_t.append(self.t)
            self.rec_q.append(self.pose())
            self.rec_plan.append(self.planned.copy())

    def approach(self):
        """Closes the gap to the feature just placed: the object meets it."""
        g0, d = self.g.copy(), GAP * np.r_[self.current.normal, 0.0]
        self.move(lambda u: g0 - d * u, GAP / self.speed)

    def push(self, a, b, P) -> np.ndarray:
        """One step of the plan, from knot ``a`` to ``b``, with the current feature at planned
        pose ``P`` in the grasp: the gripper moves with the inverse of the virtual pusher's
        motion (the step's body twist, at the execution's speed). Returns the feature's planned
        pose at the end."""
        xi = body_twist(a, b)
        length = float(np.linalg.norm(self.scene.metric_twist(xi)))
        if length == 0:
            return P
        F = self.current.frame

        def path(u):
            self.planned = a + (b - a) * u
            return planar_compose(F, planar_inverse(integrate_pose(P, xi, u)))

        self.move(path, length / self.speed)
        return integrate_pose(P, xi, 1.0)

    def contact_point(self) -> np.ndarray:
        """The current feature's reference point (the middle of its pusher's points) in the
        object's frame."""
        ref = self.scene.pusher(self.current.pusher).points.mean(axis=0)
        obj = planar_pose(self.model, self.data, "object")
        return planar_compose(planar_inverse(obj), planar_compose(self.current.frame, np.r_[ref, 0.0]))[:2]

    def segment(self, pusher: str, knots: list) -> float:
        """One push: the feature placed the gap away from where the plan needs it, the approach,
        the plan's steps, the back-off. Returns the pusher's slip: the largest slide of its
        reference point along the contact on the object."""
        self.place_feature(pusher, knots[0], GAP)
        self.approach()
        n = self.scene.pusher(pusher).normal
        n = n / np.linalg.norm(n)
        along = np.array([-n[1], n[0]])
        r0, slip, P = self.contact_point(), 0.0, knots[0]
        for a, b in zip(knots[:-1], knots[1:]):
            P = self.push(a, b, P)
            slip = max(slip, abs(float(along @ (self.contact_point() - r0))))
        self.steps.append({"pusher": pusher, "slip": slip, "end_pose": self.pose().tolist(),
                           "planned_end": knots[-1].tolist()})
        self.back_off(self.speed)
        return slip

    def run(self, settle: float = 0.2) -> Replay:
        """Holds the object for ``settle`` [s], then executes the plan push by push."""
        self.idle(settle)
        max_slip = 0.0
        for seg in progress.iterate(_segments(self.path), "MuJoCo execution", unit="push"):
            max_slip = max(max_slip, self.segment(seg["pusher"], seg["knots"]))
        q = self.pose()
        err, ok = self.scene.goal_error(q, None if self.scene.task is not None else self.path[-1]["pose"])
        return Replay("mujoco", q, err, ok, max_slip, np.array(self.rec_t),
                      np.array(self.rec_q), np.array(self.rec_plan), self.steps)


def execute_plan(scene: Scene, plan, perturb: _Perturbation = _Perturbation(), speed: float = 0.01,
                 record_dt: float = 0.02, contact: Contact = Contact(), settle: float = 0.2) -> Replay:
    """Executes ``plan`` (a ``regrasp.Plan`` or its dict) open loop in MuJoCo; returns the
    recorded object pose in the grasp (:class:`PlanarExecution`). ``speed`` [m/s] at most 100 m/s
    (the core's bound on a pusher's speed), ``record_dt`` and ``settle`` [s] at most 60 s."""
    speed = check_number(speed, "speed", high=100.0)
    record_dt, settle = check_number(record_dt, "record_dt", high=MAX_DURATION), check_number(settle, "settle", 0.0, False, MAX_DURATION)
    return PlanarExecution(scene, plan, perturb, contact, speed, record_dt).run(settle)


def animate_execution(scene: Scene, rep: Replay, path, fps: int = 20, every: int = 3):
    """A GIF (or MP4 when ffmpeg is available) of the object in the grasp during an execution,
    with the planned pose dashed."""
    from ..viz.plotting import _object_at, animation_axes, pyplot, save_animation

    plt = pyplot()
    from matplotlib.animation import FFMpegWriter, FuncAnimation, PillowWriter, writers
    from matplotlib.patches import Circle, Polygon

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
        if not writers.is_available("ffmpeg"):
            plt.close(fig)
            raise ArgumentError("invalid `--video`: MP4 needs ffmpeg, which is not installed; use a .gif", "--video")
        writer = FFMpegWriter(fps=fps)
    else:
        writer = PillowWriter(fps=fps)
    return save_animation(anim, fig, path, writer)


class WorldRig(GripperRig):
    """MuJoCo in the world's view, driven push by push (for closed-loop control): every pusher's
    feature is parked; a push with a new pusher brings its feature against the object where the
    controller believes it is (12 mm back along the push normal, then the gripper approaches
    until the feature touches the object), then moves the gripper with the inverse of the
    virtual pusher's motion; a poke displaces the object in the grasp (the feature backs off
    first)."""

    APPROACH = 0.012  # m

    def __init__(self, scene: Scene, q0, perturb: _Perturbation = _Perturbation(), contact: Contact = Contact(),
                 settle: float = 0.2):
        super().__init__(scene, q0, sorted(scene.pusher_names), perturb, contact)
        self.idle(settle)

    def bring(self, pusher: str, belief, speed: float = 0.01):
        """Brings ``pusher``'s feature against the object, placed where it would meet the object
        at the believed pose ``belief`` (in the grasp)."""
        self.back_off(speed)
        f = self.place_feature(pusher, belief, self.APPROACH)
        step = speed * self.dt
        d = np.array([step * f.normal[0], step * f.normal[1], 0.0])
        for _ in range(int(2 * self.APPROACH / step)):  # until touching, at most twice the approach distance
            if self.touching(f.geoms):
                break
            self.step_to(self.g - d)

    def push(self, pusher: str, twist, duration: float, belief=None):
        """The object (believed at ``belief``) pushed with body twist ``twist`` (m/s, m/s, rad/s) for ``duration`` [s]
        against ``pusher``'s feature: the gripper moves so that the feature, seen from the
        gripper, follows the object's intended motion."""
        belief = self.pose() if belief is None else np.asarray(belief, float)
        if self.current is None or self.current.pusher != pusher:
            self.bring(pusher, belief)
        F = self.current.frame
        # the feature seen from the object
        rel = planar_compose(planar_inverse(belief), planar_compose(planar_inverse(self.g), F))
        n = max(1, int(round(duration / self.dt)))
        tw = np.asarray(twist, float)
        for i in range(1, n + 1):
            P = planar_compose(integrate_pose(belief, tw, duration * i / n), rel)
            self.step_to(planar_compose(F, planar_inverse(P)))

    def poke(self, delta):
        """Displaces the object in the grasp by ``delta`` (the current feature backs off first)."""
        self.back_off()
        put_object(self.model, self.data, planar_compose(self.g, self.pose() + np.asarray(delta, float)))
        self.forward()
        self.idle(0.1)


#: The old name (deprecated): ``regrasp.Perturbation`` (this engine's features followed the fingers' friction).
Perturbation = PlanarEnginePerturbation
