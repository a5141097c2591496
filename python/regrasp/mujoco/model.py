"""A planar scene as a MuJoCo model (MJCF): the object extruded from its outline (a non-convex
outline as a union of convex pieces), a parallel-jaw gripper whose two pads squeeze it with the
scene's grip force (force actuators on slide joints, not a position clamp), gravity in the
scene's direction, and pushers as kinematic (mocap) features.

Frames: the MuJoCo world is the gripper frame at the start; the manipulation plane is X-Z, the
grasp axis Y. A planar angle θ (counter-clockwise in the X-Z drawing) is a rotation by −θ about
+Y.

Contact settings (why a grasp holds when it should): elliptic friction cones (MuJoCo's
pyramidal cones admit less than the Coulomb disc), ``impratio`` 20 (stiffer friction than
normal constraints) and the no-slip post-processing solver (soft contact alone lets a pinched
object creep under gravity, mujoco issue #3328); the pads' torsional friction coefficient is
``k μ_s`` (``k = 0.6 r``), so a pad contact's elliptic cone is the scene's ellipsoidal limit
surface. ``creep()`` measures what happens without them.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ArgumentError
from ..scene.planar import Scene

THICKNESS = 0.012  # m, the object's thickness along the grasp axis
PAD_DEPTH = 0.004  # m
FEATURE_RADIUS = 0.002  # m, the cylinder of a point pusher's feature


@dataclass(frozen=True)
class Contact:
    """MuJoCo contact settings."""

    timestep: float = 5e-4
    cone: str = "elliptic"
    impratio: float = 20.0
    noslip_iterations: int = 20
    solref: str = "0.002 1"
    solimp: str = "0.95 0.99 0.0005"


SOFT = Contact(cone="pyramidal", impratio=1.0, noslip_iterations=0, solref="0.02 1", solimp="0.9 0.95 0.001")


def quat_y(theta: float) -> np.ndarray:
    """Quaternion of the planar angle theta (a rotation by −theta about +Y)."""
    return np.array([np.cos(-theta / 2), 0.0, np.sin(-theta / 2), 0.0])


def _fmt(a) -> str:
    return " ".join(f"{x:.9g}" for x in np.ravel(a))


def _cross(o, a, b):
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])


def triangulate(poly: np.ndarray) -> list:
    """Ear clipping of a simple counter-clockwise polygon: triangles as index triples."""
    idx = list(range(len(poly)))
    tris = []
    guard = 0
    while len(idx) > 3 and guard < 10000:
        guard += 1
        for k in range(len(idx)):
            i0, i1, i2 = idx[k - 1], idx[k], idx[(k + 1) % len(idx)]
            a, b, c = poly[i0], poly[i1], poly[i2]
            if _cross(a, b, c) <= 1e-15:
                continue  # reflex or flat corner
            inside = False
            for j in idx:
                if j in (i0, i1, i2):
                    continue
                p = poly[j]
                if _cross(a, b, p) >= 0 and _cross(b, c, p) >= 0 and _cross(c, a, p) >= 0:
                    inside = True
                    break
            if not inside:
                tris.append((i0, i1, i2))
                idx.pop(k)
                break
    if len(idx) == 3:
        tris.append(tuple(idx))
    return tris


def convex_pieces(poly: np.ndarray) -> list:
    """Convex pieces of a simple counter-clockwise polygon (ear clipping, then Hertel–Mehlhorn:
    merge neighbouring pieces while the union stays convex)."""
    poly = np.asarray(poly, float)
    pieces = [list(t) for t in triangulate(poly)]

    def convex(ids):
        pts = poly[ids]
        n = len(pts)
        return all(_cross(pts[i], pts[(i + 1) % n], pts[(i + 2) % n]) >= -1e-15 for i in range(n))

    merged = True
    while merged:
        merged = False
        for i in range(len(pieces)):
            for j in range(i + 1, len(pieces)):
                a, b = pieces[i], pieces[j]
                # a shared edge (u, v) in a appears as (v, u) in b
                for ka in range(len(a)):
                    u, v = a[ka], a[(ka + 1) % len(a)]
                    for kb in range(len(b)):
                        if b[kb] == v and b[(kb + 1) % len(b)] == u:
                            # walk: a from v .. u (excluding the shared edge), then b from u .. v
                            ra = a[(ka + 1) % len(a):] + a[: (ka + 1) % len(a)]  # starts at v, ends at u
                            rb = b[(kb + 1) % len(b):] + b[: (kb + 1) % len(b)]  # starts at u, ends at v
                            cand = ra[:-1] + rb[:-1]
                            if convex(cand):
                                pieces[i] = cand
                                pieces.pop(j)
                                merged = True
                                break
                    if merged:
                        break
                if merged:
                    break
            if merged:
                break
    return [poly[p] for p in pieces]


def _is_rectangle(o: np.ndarray) -> bool:
    if len(o) != 4:
        return False
    lo, hi = o.min(axis=0), o.max(axis=0)
    return {tuple(p) for p in o} == {(lo[0], lo[1]), (hi[0], lo[1]), (hi[0], hi[1]), (lo[0], hi[1])}


def object_xml(scene: Scene, pose, friction: float = 0.0, mass_scale: float = 1.0) -> tuple[str, str]:
    """(assets, body) MJCF of the object at planar ``pose``; the body frame is the object frame."""
    o = scene.outline
    q = np.asarray(pose, float)
    assets, geoms = [], []
    if _is_rectangle(o):
        lo, hi = o.min(axis=0), o.max(axis=0)
        c, h = (lo + hi) / 2, (hi - lo) / 2
        geoms.append(f'<geom name="object" type="box" size="{h[0]:.9g} {THICKNESS / 2} {h[1]:.9g}" '
                     f'pos="{c[0]:.9g} 0 {c[1]:.9g}" friction="{friction} 0 0" condim="4" {OBJECT_BITS}/>')
    else:
        for k, piece in enumerate(convex_pieces(o)):
            verts = [(p[0], y, p[1]) for p in piece for y in (-THICKNESS / 2, THICKNESS / 2)]
            assets.append(f'<mesh name="piece{k}" vertex="{_fmt(verts)}"/>')
            geoms.append(f'<geom name="object{k}" type="mesh" mesh="piece{k}" friction="{friction} 0 0" condim="4" {OBJECT_BITS}/>')
    m = scene.mass * mass_scale
    L = scene.length
    # a lamina extruded along Y: I_yy = m L² about the COM; the others are not exercised in the plane
    inertia = f"{m * (L**2 / 2 + THICKNESS**2 / 12):.9g} {m * L**2:.9g} {m * (L**2 / 2 + THICKNESS**2 / 12):.9g}"
    body = (f'<body name="object" pos="{q[0]:.9g} 0 {q[1]:.9g}" quat="{_fmt(quat_y(q[2]))}">\n'
            f'  <freejoint/>\n'
            f'  <inertial pos="{scene.com[0]:.9g} 0 {scene.com[1]:.9g}" mass="{m:.9g}" diaginertia="{inertia}"/>\n'
            + "\n".join("  " + g for g in geoms) + "\n</body>")
    return "\n".join(assets), body


PAD_SPHERE = 0.05  # m, radius of the sphere that stands for a pad's contact
# collision filtering: pads touch only the object, features only the object
OBJECT_BITS = 'contype="1" conaffinity="3"'
PAD_BITS = 'contype="2" conaffinity="0"'
FEATURE_BITS = 'contype="4" conaffinity="1"'


def pads_xml(scene: Scene, friction_scale: float = 1.0, gravcomp: float = 1.0) -> tuple[str, str]:
    """(bodies, actuators) of the two pads: slide joints along Y squeezed by motors.

    Each pad touches the object at one point — the pad's centre — through a large sphere, with
    the sliding friction ``μ_s`` and the torsional friction ``k μ_s`` of the scene's limit
    surface, so MuJoCo's elliptic cone at that contact is the pad's ellipsoidal limit surface
    (a flat pad geom would give several rim contacts, each with torsional friction, a much
    stiffer pad than the pressure distribution it stands for). The pad's shape is drawn by a
    geom that does not collide."""
    if scene.kind != "grasp":
        raise ArgumentError("invalid `scene`: the MuJoCo model needs a grasp (not an object on a surface)", "grasp")
    mu_s = scene._core.friction_scale / (2 * scene.grip_force) * friction_scale
    pad = scene.pad
    k = scene._core.pad_limit_surface_k
    if pad[0] == "circle":
        visual = f'<geom type="cylinder" size="{pad[1]:.9g} {PAD_DEPTH / 2}" euler="90 0 0" contype="0" conaffinity="0" group="1" mass="0"/>'
    else:
        visual = f'<geom type="box" size="{pad[1] / 2:.9g} {PAD_DEPTH / 2} {pad[2] / 2:.9g}" contype="0" conaffinity="0" group="1" mass="0"/>'
    body = []
    for name, sign in (("pad_left", 1), ("pad_right", -1)):
        y = sign * THICKNESS / 2
        body.append(f'<body name="{name}" pos="0 {y:.9g} 0" gravcomp="{gravcomp}">'
                    f'<joint name="{name}" type="slide" axis="0 1 0" damping="20"/>'
                    f'<geom type="sphere" size="{PAD_SPHERE}" pos="0 {sign * PAD_SPHERE:.9g} 0" mass="0.05" '
                    f'friction="{mu_s:.9g} {k * mu_s:.9g} 0" condim="4" {PAD_BITS}/>'
                    f'<geom pos="0 {sign * PAD_DEPTH / 2:.9g} 0" {visual[6:]}'
                    f'</body>')
    actuators = ('<motor name="grip_left" joint="pad_left" gear="-1" ctrllimited="false"/>\n'
                 '<motor name="grip_right" joint="pad_right" gear="1" ctrllimited="false"/>')
    return "\n".join(body), actuators


def feature_xml(scene: Scene, pusher: str, name: str, friction_scale: float = 1.0, park=(0.0, 5.0, 0.0)) -> str:
    """A mocap body holding the pusher's environment feature, in the pusher frame (= the object
    frame where the pusher meets it): a plate behind a line pusher's points (an edge or a face)
    or a thin cylinder along Y for a point pusher (an edge of the environment, a corner in the
    plane). Parked far away until needed."""
    p = scene.pusher(pusher)
    n = p.normal / np.linalg.norm(p.normal)
    mu = p.friction * friction_scale
    depth = 0.02
    if len(p.points) == 2:
        mid = p.points.mean(axis=0) - n * 0.003
        half = np.linalg.norm(p.points[1] - p.points[0]) / 2
        ang = np.arctan2(n[1], n[0])
        g = (f'<geom type="box" size="0.003 {depth} {half:.9g}" pos="{mid[0]:.9g} 0 {mid[1]:.9g}" '
             f'quat="{_fmt(quat_y(ang))}" friction="{mu:.9g} 0 0" condim="3" {FEATURE_BITS}/>')
    else:
        c = p.points[0] - n * FEATURE_RADIUS
        g = (f'<geom type="cylinder" size="{FEATURE_RADIUS} {depth}" pos="{c[0]:.9g} 0 {c[1]:.9g}" euler="90 0 0" '
             f'friction="{mu:.9g} 0 0" condim="3" {FEATURE_BITS}/>')
    return f'<body name="{name}" mocap="true" pos="{_fmt(park)}">{g}</body>'


def header(scene: Scene, contact: Contact) -> str:
    gdir, g = scene.gravity
    return (f'<option timestep="{contact.timestep}" gravity="{gdir[0] * g:.9g} 0 {gdir[1] * g:.9g}" '
            f'cone="{contact.cone}" impratio="{contact.impratio}" noslip_iterations="{contact.noslip_iterations}"/>\n'
            f'<default><geom solref="{contact.solref}" solimp="{contact.solimp}"/></default>')


def planar_pose(model, data, body: str) -> np.ndarray:
    """Planar pose [x, z, theta] of a body's frame in the world."""
    import mujoco

    bid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, body)
    R = data.xmat[bid].reshape(3, 3)
    return np.array([data.xpos[bid][0], data.xpos[bid][2], np.arctan2(R[2, 0], R[0, 0])])


def compose(a, b) -> np.ndarray:
    """Planar pose composition a ∘ b."""
    c, s = np.cos(a[2]), np.sin(a[2])
    return np.array([a[0] + c * b[0] - s * b[1], a[1] + s * b[0] + c * b[1], a[2] + b[2]])


def inverse(a) -> np.ndarray:
    c, s = np.cos(a[2]), np.sin(a[2])
    return np.array([-(c * a[0] + s * a[1]), -(-s * a[0] + c * a[1]), -a[2]])


def creep(scene: Scene, pose=None, duration: float = 2.0, contact: Contact = Contact()) -> float:
    """How far [m] the object slides in the grasp while simply held for ``duration`` (no pusher):
    rigid Coulomb friction holds it still; soft contact lets it creep."""
    import mujoco

    q = scene.task.start if pose is None else np.asarray(pose, float)
    assets, obj = object_xml(scene, q)
    pads, acts = pads_xml(scene)
    xml = (f'<mujoco>{header(scene, contact)}<asset>{assets}</asset><worldbody>{obj}{pads}</worldbody>'
           f'<actuator>{acts}</actuator></mujoco>')
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    data.ctrl[:] = scene.grip_force
    for _ in range(int(0.1 / contact.timestep)):
        mujoco.mj_step(model, data)
    start = planar_pose(model, data, "object")
    for _ in range(int(duration / contact.timestep)):
        mujoco.mj_step(model, data)
    return float(np.linalg.norm(planar_pose(model, data, "object")[:2] - start[:2]))


MASS, INERTIA = 1000.0, 1000.0  # kg, kg m²: a driven body the contacts cannot move


def driven_body_xml(name: str, inner: str, pose=(0.0, 0.0, 0.0), mass: float = MASS, inertia: float = INERTIA) -> str:
    """A body moved along a prescribed planar trajectory: slide joints along X and Z and a hinge
    about −Y (so its angle is the planar θ). Driven by :class:`Driver`, which sets its joint
    positions and velocities every step: unlike a mocap body, its contacts see its velocity, so
    friction drags what it touches. It is heavy (1 t, 1000 kg m²) so that contact forces do not
    change its velocity within a step: a light driven body is kicked back by its contacts every
    step, which they see as slip."""
    q = np.asarray(pose, float)
    return (f'<body name="{name}" pos="0 0 0" gravcomp="1">\n'
            f'  <joint name="{name}_x" type="slide" axis="1 0 0" ref="0"/>\n'
            f'  <joint name="{name}_z" type="slide" axis="0 0 1" ref="0"/>\n'
            f'  <joint name="{name}_th" type="hinge" axis="0 -1 0" ref="0"/>\n'
            f'  <inertial pos="0 0 0" mass="{mass}" diaginertia="{inertia} {inertia} {inertia}"/>\n'
            f'  {inner}\n</body>') + f"<!-- {name} starts at {_fmt(q)} -->"


class Driver:
    """Sets a driven body's planar pose and velocity (see :func:`driven_body_xml`)."""

    def __init__(self, model, name: str):
        import mujoco

        ids = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, f"{name}_{s}") for s in ("x", "z", "th")]
        self.qadr = [int(model.jnt_qposadr[i]) for i in ids]
        self.dadr = [int(model.jnt_dofadr[i]) for i in ids]
        self.pose = np.zeros(3)

    def set(self, data, pose, velocity=(0.0, 0.0, 0.0)):
        for a, v in zip(self.qadr, pose):
            data.qpos[a] = v
        for a, v in zip(self.dadr, velocity):
            data.qvel[a] = v
        self.pose = np.asarray(pose, float)

    def move(self, data, pose, dt: float):
        """Moves to ``pose`` over the next step of length ``dt``."""
        pose = np.asarray(pose, float)
        self.set(data, self.pose, (pose - self.pose) / dt)
        self.pose = pose
