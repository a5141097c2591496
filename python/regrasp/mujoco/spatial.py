"""3-D plans executed in MuJoCo (:func:`execute_plan3d`), in the world's view (``view="world"``,
the default and what `regrasp simulate SCENE_3D --engine mujoco` runs: features fixed where each
push needs them, the gripper — a driven 6-DoF body carrying the pads — moving with the inverse of
the virtual pusher's motion) or in the planner's view (``view="planner"``: the pads fixed, each
pusher's feature on a driven 6-DoF body that follows the plan's pusher motion).

Gravity: the scene's gravity is given in the gripper frame, and the world's view keeps it there
(MuJoCo's gravity is the scene's vector, the gripper starts at the identity): as the gripper
turns with the inverse pusher motion, gravity in MuJoCo does not turn with it, while the planner
assumed it fixed in the gripper frame. The bundled examples turn the gripper by at most their
regrasp angle and execute within tolerance in both views (`docs/execution3d.py` prints both); a
plan with large gripper rotations should be executed in the planner's view.

The object: a box or the scene's convex mesh, with its mass, centre of mass and inertia. The pads:
as in the planar model (``regrasp.mujoco.model``), one contact point each through a large sphere
on a slide joint along Y, squeezed by a force actuator, with sliding friction ``μ_s`` and
torsional friction ``(2/3) r μ_s`` (the pad's ring of points at 2/3 of its radius in the
quasi-static model). Features: a 1.5 mm sphere behind a point pusher, a capsule behind a line
pusher, a thin plate behind a patch. A push with a new pusher brings its feature 2 mm behind
where it meets the object (where the object is), approaches until it touches, then moves with
the plan's pusher twist of each step over unit time (the step's `pusher_twist`, else the twist
between the poses). Same contact settings as the planar model (elliptic cones, impratio, no-slip).
"""

from __future__ import annotations

import numpy as np

from .. import _core
from ..errors import ArgumentError
from .model import FEATURE_BITS as BITS_FEAT
from .model import OBJECT_BITS as BITS_OBJ
from .model import PAD_BITS as BITS_PAD
from .model import PAD_SPHERE, Contact
from .model import _fmt as _f
PARK = np.array([0.0, 0.0, 5.0])
R_FEATURE = 0.0015
GAP = 0.002


def compose(a, b) -> np.ndarray:
    """Pose a ∘ b ([x, y, z, qw, qx, qy, qz])."""
    return np.array(_core.se3_compose(list(map(float, a)), list(map(float, b))))


def inverse(a) -> np.ndarray:
    return np.array(_core.se3_inverse(list(map(float, a))))


def _exp(u, t) -> np.ndarray:
    """exp of body twist u over time t, as a pose."""
    return np.array(_core.se3_integrate([0, 0, 0, 1, 0, 0, 0], list(map(float, u)), float(t)))


PLANE_HALF = 0.15  # m, half the side of a plane feature (a floor or a wall)


def plane_frame(scene, name: str, pose) -> np.ndarray:
    """For a plane pusher brought against the object at ``pose``: the pose, in the pusher's frame
    (the object frame then), of the plane's own frame (origin at the contact, +Z its normal)."""
    from scipy.spatial.transform import Rotation

    pts, n, _ = scene._core.pusher_spec(name, list(map(float, pose)))
    n = np.asarray(n, float) / np.linalg.norm(n)
    a = np.array([1.0, 0, 0]) if abs(n[0]) < 0.9 else np.array([0, 1.0, 0])
    t1 = np.cross(a, n)
    t1 /= np.linalg.norm(t1)
    q = Rotation.from_matrix(np.c_[t1, np.cross(n, t1), n]).as_quat()
    return np.r_[np.asarray(pts, float).mean(axis=0), q[3], q[:3]]


def feature_geoms(scene, name: str, friction: float) -> str:
    if scene._core.is_plane(name):
        # a thick slab whose top face is the plane z = 0 of the feature's frame (see plane_frame)
        g = f'friction="{friction:.9g} 0 0" condim="3" {BITS_FEAT}'
        return f'<geom type="box" size="{PLANE_HALF} {PLANE_HALF} 0.005" pos="0 0 -0.005" {g}/>'
    pts, n, _ = scene._core.pusher_spec(name)
    pts, n = np.asarray(pts, float), np.asarray(n, float) / np.linalg.norm(n)
    g = f'friction="{friction:.9g} 0 0" condim="3" {BITS_FEAT}'
    if len(pts) == 1:
        return f'<geom type="sphere" size="{R_FEATURE}" pos="{_f(pts[0] - n * R_FEATURE)}" {g}/>'
    if len(pts) == 2:
        a, b = pts - n * R_FEATURE
        return f'<geom type="capsule" size="{R_FEATURE}" fromto="{_f(a)} {_f(b)}" {g}/>'
    # a plate behind the patch, in the frame (t1, t2, n)
    a = np.array([1.0, 0, 0]) if abs(n[0]) < 0.9 else np.array([0, 1.0, 0])
    t1 = np.cross(n, a)
    t1 /= np.linalg.norm(t1)
    t2 = np.cross(n, t1)
    c = pts.mean(axis=0)
    e1, e2 = np.abs((pts - c) @ t1).max(), np.abs((pts - c) @ t2).max()
    from scipy.spatial.transform import Rotation

    q = Rotation.from_matrix(np.c_[t1, t2, n]).as_quat()
    return (f'<geom type="box" size="{e1:.9g} {e2:.9g} 0.0015" pos="{_f(c - n * 0.0015)}" '
            f'quat="{q[3]:.9g} {q[0]:.9g} {q[1]:.9g} {q[2]:.9g}" {g}/>')


PAD_BALL = 0.001  # m, the small spheres of a ring pad


def _driven_joints(name: str) -> str:
    """Slides along X, Y, Z and a ball joint of a heavy body driven by :class:`Driver6`."""
    return (f'<joint name="{name}_x" type="slide" axis="1 0 0"/><joint name="{name}_y" type="slide" axis="0 1 0"/>'
            f'<joint name="{name}_z" type="slide" axis="0 0 1"/><joint name="{name}_r" type="ball"/>'
            f'<inertial pos="0 0 0" mass="1000" diaginertia="1000 1000 1000"/>')


def build(scene, start, friction_scale: float = 1.0, grip_scale: float = 1.0, mass_scale: float = 1.0,
          contact: Contact = Contact(), pad: str = "point", world: bool = False) -> str:
    """MJCF of a 3-D execution: planner's view (pads fixed, features on driven 6-DoF bodies) or,
    with ``world``, the world's view (the pads on a driven 6-DoF gripper, features fixed where
    they are put: mocap bodies)."""
    v, t = scene.mesh()
    v, t = np.asarray(v, float), np.asarray(t, int)
    m = scene.mass * mass_scale
    I = np.asarray(scene.inertia, float) * mass_scale
    com = np.asarray(scene._core.com, float)
    s0 = np.asarray(start, float)
    asset = f'<mesh name="obj" vertex="{_f(v)}" face="{_f(t)}"/>'
    obj = (f'<body name="object" pos="{_f(s0[:3])}" quat="{_f(s0[3:])}"><freejoint/>'
           f'<inertial pos="{_f(com)}" mass="{m:.9g}" fullinertia="{I[0,0]:.9g} {I[1,1]:.9g} {I[2,2]:.9g} {I[0,1]:.9g} {I[0,2]:.9g} {I[1,2]:.9g}"/>'
           + (f'<geom type="sphere" size="{scene._core.sphere:.9g}" friction="0 0 0" condim="4" {BITS_OBJ}/></body>'
              if scene._core.sphere else f'<geom type="mesh" mesh="obj" friction="0 0 0" condim="4" {BITS_OBJ}/></body>'))
    mu = scene._core.grip_friction * friction_scale
    k = 2.0 / 3.0 * scene._core.pad_radius
    # pads at the object's extreme points along ±Y at the start
    w = np.array([compose(s0, np.r_[x, 1, 0, 0, 0])[:3] for x in v])
    pads = []
    R = scene._core.sphere
    for name, sign in (("pad_left", 1), ("pad_right", -1)):
        y = s0[1] + sign * R if R else np.max(sign * w[:, 1]) * sign
        if pad == "ring":
            # 8 point contacts on a ring at 2/3 of the pad's radius: the quasi-static model's pad
            geoms = "".join(
                f'<geom type="sphere" size="{PAD_BALL}" pos="{k * np.cos(a):.9g} {sign * PAD_BALL:.9g} {k * np.sin(a):.9g}" '
                f'mass="0.01" friction="{mu:.9g} 0 0" condim="3" {BITS_PAD}/>'
                for a in 2 * np.pi * (np.arange(8) + 0.5) / 8)
        else:
            geoms = (f'<geom type="sphere" size="{PAD_SPHERE}" pos="0 {sign * PAD_SPHERE:.9g} 0" mass="0.05" '
                     f'friction="{mu:.9g} {k * mu:.9g} 0" condim="4" {BITS_PAD}/>')
        pads.append(f'<body name="{name}" pos="0 {y:.9g} 0" gravcomp="1"><joint name="{name}" type="slide" axis="0 1 0" damping="20"/>'
                    f'{geoms}</body>')
    feats = []
    for i, p in enumerate(scene.pusher_names):
        _, _, fr = scene._core.pusher_spec(p)
        if world:
            feats.append(f'<body name="feature_{p}" mocap="true" pos="{_f(PARK + [0.1 * i, 0, 0])}">'
                         f'{feature_geoms(scene, p, fr * friction_scale)}</body>')
        else:
            feats.append(f'<body name="feature_{p}" pos="0 0 0" gravcomp="1">{_driven_joints(f"feature_{p}")}'
                         f'{feature_geoms(scene, p, fr * friction_scale)}</body>')
    if world:
        pads = [f'<body name="gripper" pos="0 0 0" gravcomp="1">{_driven_joints("gripper")}{"".join(pads)}</body>']
    g = np.asarray(scene._core.gravity, float)
    acts = ('<motor joint="pad_left" gear="-1" ctrllimited="false"/><motor joint="pad_right" gear="1" ctrllimited="false"/>')
    return (f'<mujoco model="{scene.name}"><option timestep="{contact.timestep}" gravity="{_f(g)}" cone="{contact.cone}" '
            f'impratio="{contact.impratio}" noslip_iterations="{contact.noslip_iterations}"/>'
            f'<default><geom solref="{contact.solref}" solimp="{contact.solimp}"/></default>'
            f'<asset>{asset}</asset><worldbody>{obj}{"".join(pads)}{"".join(feats)}</worldbody>'
            f'<actuator>{acts}</actuator></mujoco>')


class Driver6:
    """Sets a driven 6-DoF body's pose and velocity each step (slides + ball joint)."""

    def __init__(self, model, name: str):
        import mujoco

        j = lambda s: mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, f"{name}_{s}")  # noqa: E731
        self.qa = [int(model.jnt_qposadr[j(s)]) for s in "xyz"]
        self.da = [int(model.jnt_dofadr[j(s)]) for s in "xyz"]
        self.qr, self.dr = int(model.jnt_qposadr[j("r")]), int(model.jnt_dofadr[j("r")])
        self.pose = np.r_[PARK, 1, 0, 0, 0]

    def set(self, data, pose, vel=np.zeros(6)):
        for k in range(3):
            data.qpos[self.qa[k]] = pose[k]
            data.qvel[self.da[k]] = vel[k]
        data.qpos[self.qr:self.qr + 4] = pose[3:]
        data.qvel[self.dr:self.dr + 3] = vel[3:]
        self.pose = np.asarray(pose, float)

    def move(self, data, pose, dt):
        pose = np.asarray(pose, float)
        # body-frame angular velocity: the SO(3) log of the relative rotation (the ball joint's qvel)
        w = np.array(_core.se3_log([0, 0, 0, *map(float, self.pose[3:])], [0, 0, 0, *map(float, pose[3:])]))[3:] / dt
        self.set(data, self.pose, np.r_[(pose[:3] - self.pose[:3]) / dt, w])
        self.pose = pose


def execute_plan3d(scene, plan: dict, friction_scale: float = 1.0, grip_scale: float = 1.0, mass_scale: float = 1.0,
                   contact: Contact = Contact(), settle: float = 0.2, pad: str = "point", view: str = "world",
                   feedback: bool = False, max_replans: int = 10, seed: int = 0) -> dict:
    """Executes a 3-D plan in MuJoCo; returns the final pose, the error to the goal (position,
    angle), success, the object's pose in the grasp after each step and the re-plans made.

    ``feedback``: closed loop by re-planning — after each step the object's pose is measured; when
    it is off the plan by more than half the goal tolerance (position or angle), or the plan ends
    outside the tolerance, the T-RRT* plans again from the measured pose (at most
    ``max_replans`` times) and execution goes on with the new plan.

    ``view="world"``: each push's feature is fixed where the push needs it (2 mm back, then the
    gripper approaches until it touches), the gripper moves with the inverse of the virtual
    pusher's motion and backs off 2 mm before a switch-over. ``view="planner"``: the pads fixed,
    the feature (on a driven body) follows the virtual pusher's motion. Either way the feature's
    pose in the grasp, ``P``, follows the plan's pusher twists (each a body twist in the object's
    frame at the step's start, as the planner and the quasi-static replay apply it); only what
    moves differs."""
    import mujoco

    from ..scene.spatial import check_plan3d, goal_report, run_plan3d, twist_between

    if pad not in ("point", "ring"):
        raise ArgumentError(f"invalid `pad`: 'point' or 'ring' (got {pad!r})", "pad")
    if view not in ("world", "planner"):
        raise ArgumentError(f"invalid `view`: 'world' or 'planner' (got {view!r})", "view")
    world = view == "world"
    path = check_plan3d(scene, plan)
    model = mujoco.MjModel.from_xml_string(build(scene, path[0]["pose"], friction_scale, grip_scale, mass_scale, contact,
                                                 pad, world=world))
    data = mujoco.MjData(model)
    data.ctrl[:] = scene._core.grip_force * grip_scale
    dt = contact.timestep
    identity = np.r_[0.0, 0, 0, 1, 0, 0, 0]
    grip = Driver6(model, "gripper") if world else None
    drivers = {} if world else {p: Driver6(model, f"feature_{p}") for p in scene.pusher_names}
    if world:
        grip.set(data, identity)
    for i, d in enumerate(drivers.values()):
        d.set(data, np.r_[PARK + [0.1 * i, 0, 0], 1, 0, 0, 0])
    mujoco.mj_forward(model, data)
    bid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "object")
    G = lambda: grip.pose if world else identity  # noqa: E731 - the gripper in the world
    in_grasp = lambda: compose(inverse(G()), np.r_[data.xpos[bid], data.xquat[bid]])  # noqa: E731
    # the feature body's pose in the pusher's frame: identity for rigid pushers (built in the
    # object frame), the plane's frame for planes (set when the plane is brought)
    state = {"pusher": None, "F": None, "T": identity}

    def place(P):
        """One time step with the active feature at pose ``P`` in the grasp (None: nothing moves)."""
        if world:
            grip.move(data, grip.pose if P is None else compose(state["F"], inverse(P)), dt)
        for p, d in drivers.items():
            d.move(data, compose(P, state["T"]) if p == state["pusher"] and P is not None else d.pose, dt)
        mujoco.mj_step(model, data)

    def put(p, P):
        """Puts pusher ``p``'s feature at ``P`` in the grasp (where it stays, in the world's view)."""
        fid = model.body(f"feature_{p}").id
        state["T"] = plane_frame(scene, p, in_grasp()) if scene._core.is_plane(p) else identity
        if world:
            state["F"] = compose(G(), P)
            F = compose(state["F"], state["T"])
            fm = int(model.body_mocapid[fid])
            data.mocap_pos[fm], data.mocap_quat[fm] = F[:3], F[3:]
        else:
            drivers[p].set(data, compose(P, state["T"]))
        state["pusher"] = p
        mujoco.mj_forward(model, data)
        return {i for i in range(model.ngeom) if model.geom_bodyid[i] == fid}

    def park(p):
        if world:
            data.mocap_pos[int(model.body_mocapid[model.body(f"feature_{p}").id])] = PARK
        else:
            drivers[p].set(data, np.r_[PARK, 1, 0, 0, 0])

    for _ in range(int(settle / dt)):
        place(None)
    st = {"P": None, "n": None}
    creep = 0.005 * dt  # approach and back-off at 5 mm/s

    def step(a, b):
        """One step of the plan: bring the step's pusher if it is a new one, then move it."""
        P, n, p = st["P"], st["n"], b["pusher"]
        if state["pusher"] != p:
            if state["pusher"] is not None:  # back off, park the old feature (a switch-over)
                P0 = P.copy()
                for k in range(1, int(GAP / creep) + 1):
                    P = compose(P0, np.r_[-n * creep * k, 1, 0, 0, 0])
                    place(P)
                park(state["pusher"])
            _, n, _ = scene._core.pusher_spec(p, list(map(float, in_grasp())))
            n = np.asarray(n, float) / np.linalg.norm(n)
            P = compose(in_grasp(), np.r_[-GAP * n, 1, 0, 0, 0])  # where it meets the object, backed off
            ids = put(p, P)
            for _ in range(int(3 * GAP / creep)):  # approach until touching (at most 3 gaps)
                if any(data.contact[j].geom1 in ids or data.contact[j].geom2 in ids for j in range(data.ncon)):
                    break
                P = compose(P, np.r_[n * creep, 1, 0, 0, 0])
                place(P)
        u = b.get("pusher_twist")
        u = np.asarray(twist_between(a["pose"], b["pose"]) if u is None else u, float)
        # the step's twist is the pusher's body twist in the object's frame at the step's start
        # (where the planner and the quasi-static replay put the pusher); the feature, wherever
        # it is now (offset D from that frame), makes the same rigid motion: P(t) = A exp(ut) D
        # (a plane: the planned frame, so it makes its planned motion in the gripper frame and
        # stays level whatever the object's measured pose)
        A = np.asarray(a["pose"], float) if scene._core.is_plane(p) else in_grasp()
        D = compose(inverse(A), P)
        nsteps = int(round(1.0 / dt))
        for k in range(1, nsteps + 1):
            P = compose(A, compose(_exp(u, k / nsteps), D))
            place(P)
        st["P"], st["n"] = P, n
        return in_grasp()

    q, poses, replans = run_plan3d(scene, path, step, in_grasp(), feedback, max_replans, seed)
    return {"engine": "mujoco", "view": view, **goal_report(scene, q), "poses": np.array(poses), "replans": replans}
