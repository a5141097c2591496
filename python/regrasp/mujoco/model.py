"""MuJoCo models of a grasp, built with ``mujoco.MjSpec``: the pieces that the one world
builder (:mod:`.world`) assembles for every rig and that the runs share — the options and
contact settings, the two force-driven pads, driven bodies and their :class:`Driver`, and
:class:`Rig` (a compiled model with its data) — and the planar scene's own
pieces: the object extruded from its outline (a non-convex outline as a union of convex pieces)
and the pushers' features.

Planar frames: the MuJoCo world is the gripper frame at the start; the manipulation plane is X-Z,
the grasp axis Y. A planar angle θ (counter-clockwise in the X-Z drawing) is a rotation by −θ
about +Y.

Contact settings (why a grasp holds when it should): elliptic friction cones (MuJoCo's
pyramidal cones admit less than the Coulomb disc), ``impratio`` 20 (stiffer friction than
normal constraints) and the no-slip post-processing solver (soft contact alone lets a pinched
object creep under gravity, mujoco issue #3328); the pads' torsional friction coefficient is
``k μ_s`` (``k = 0.6 r``), so a pad contact's elliptic cone is the scene's ellipsoidal limit
surface. :func:`regrasp.mujoco.world.creep` measures what happens without them.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import _moved
from ..errors import ArgumentError
from ..extras import need
from ..polygon import cross, triangulate
from ..pose import planar_quat, twist_between
from ..scene.planar import Scene

THICKNESS = 0.012  # m, the object's thickness along the grasp axis
PAD_DEPTH = 0.004  # m
FEATURE_RADIUS = 0.002  # m, the cylinder of a point pusher's feature
PAD_SPHERE = 0.05  # m, radius of the sphere that stands for a pad's contact
MASS, INERTIA = 1000.0, 1000.0  # kg, kg m²: a driven body the contacts cannot move
# collision filtering (contype, conaffinity): pads touch only the object, features only the object
OBJECT_BITS = (1, 3)
PAD_BITS = (2, 0)
FEATURE_BITS = (4, 1)


@dataclass(frozen=True)
class Contact:
    """MuJoCo contact settings (``solref``/``solimp``: the geoms' default, as numbers or as the
    MJCF strings of the first version)."""

    timestep: float = 5e-4
    cone: str = "elliptic"
    impratio: float = 20.0
    noslip_iterations: int = 20
    solref: tuple = (0.002, 1.0)
    solimp: tuple = (0.95, 0.99, 0.0005)


SOFT = Contact(cone="pyramidal", impratio=1.0, noslip_iterations=0, solref=(0.02, 1.0), solimp=(0.9, 0.95, 0.001))


def plan_dict(plan) -> dict:
    """A plan as the plan-file dict (docs/plan-file.md): a ``regrasp.Plan`` (its ``to_json()``) or
    the dict itself."""
    return plan.to_json() if hasattr(plan, "to_json") else plan


# --- the object's planar pose in MuJoCo ---------------------------------------------------------

def planar_pose(model, data, body: str) -> np.ndarray:
    """Planar pose [x, z, theta] of a body's frame in the world."""
    bid = model.body(body).id
    R = data.xmat[bid].reshape(3, 3)
    return np.array([data.xpos[bid][0], data.xpos[bid][2], np.arctan2(R[2, 0], R[0, 0])])


def put_object(model, data, pose):
    """Puts the object (its free joint, the model's first joint) at planar world ``pose``, at rest."""
    q = np.asarray(pose, float)
    a, v = int(model.jnt_qposadr[0]), int(model.jnt_dofadr[0])
    data.qpos[a:a + 3] = [q[0], 0.0, q[1]]
    data.qpos[a + 3:a + 7] = planar_quat(q[2])
    data.qvel[v:v + 6] = 0.0


# --- outlines ----------------------------------------------------------------------------------

def _merge_once(poly: np.ndarray, pieces: list) -> bool:
    """Merges the first two neighbouring pieces whose union is convex; whether it found some."""
    def convex(ids):
        pts = poly[ids]
        n = len(pts)
        return all(cross(pts[i], pts[(i + 1) % n], pts[(i + 2) % n]) >= -1e-15 for i in range(n))

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
                            return True
    return False


def convex_pieces(poly: np.ndarray) -> list:
    """Convex pieces of a simple counter-clockwise polygon (ear clipping, then Hertel–Mehlhorn:
    merge neighbouring pieces while the union stays convex)."""
    poly = np.asarray(poly, float)
    pieces = [list(t) for t in triangulate(poly)]
    while _merge_once(poly, pieces):
        pass
    return [poly[p] for p in pieces]


def _is_rectangle(o: np.ndarray) -> bool:
    if len(o) != 4:
        return False
    lo, hi = o.min(axis=0), o.max(axis=0)
    return {tuple(p) for p in o} == {(lo[0], lo[1]), (hi[0], lo[1]), (hi[0], hi[1]), (lo[0], hi[1])}


# --- model pieces (MjSpec) -------------------------------------------------------------------

def _padded(v, n: int, fill: float = 0.0) -> list:
    v = list(np.ravel(np.asarray(v, float)))
    return v + [fill] * (n - len(v))


def new_spec(name: str, gravity, contact: Contact = Contact()):
    """An empty model with the options and the geoms' default contact parameters of ``contact``."""
    mujoco = need("mujoco", "mujoco")

    spec = mujoco.MjSpec()
    spec.modelname = name
    o = spec.option
    o.timestep = contact.timestep
    o.gravity = np.asarray(gravity, float)
    o.cone = {"elliptic": mujoco.mjtCone.mjCONE_ELLIPTIC, "pyramidal": mujoco.mjtCone.mjCONE_PYRAMIDAL}[contact.cone]
    o.impratio = contact.impratio
    o.noslip_iterations = contact.noslip_iterations
    set_geom_defaults(spec, contact)
    return spec


def set_geom_defaults(spec, contact: Contact) -> None:
    """Sets the default ``solref``/``solimp`` of the geoms ``spec`` creates (not those of specs
    attached to it, which keep their own defaults) to ``contact``'s."""
    g = spec.default.geom
    for attr in ("solref", "solimp"):
        given = getattr(contact, attr)
        given = [float(x) for x in given.split()] if isinstance(given, str) else list(given)
        value = np.array(getattr(g, attr), float)
        value[:len(given)] = given  # what is not given keeps MuJoCo's default (as MJCF reads it)
        setattr(g, attr, value)


def add_geom(body, kind: str, size, bits=(0, 0), friction=None, **kw):
    """A geom of MuJoCo type ``kind`` ("box", "sphere", ...) with collision ``bits`` (contype,
    conaffinity) and ``friction`` (sliding, torsional, rolling; what is not given is 0, None:
    MuJoCo's default); other attributes as keywords."""
    mujoco = need("mujoco", "mujoco")

    if friction is not None:
        kw["friction"] = _padded(friction, 3)
    return body.add_geom(type=getattr(mujoco.mjtGeom, f"mjGEOM_{kind.upper()}"), size=_padded(size, 3),
                         contype=bits[0], conaffinity=bits[1], **kw)


def set_inertial(body, pos, mass: float, diag=None, full=None):
    """The body's explicit inertia: diagonal ``diag`` or ``full`` [Ixx, Iyy, Izz, Ixy, Ixz, Iyz]."""
    body.explicitinertial = True
    body.ipos = np.asarray(pos, float)
    body.mass = float(mass)
    if full is not None:
        body.fullinertia = np.asarray(full, float)
    else:
        body.inertia = np.asarray(diag, float)


# euler="90 0 0" (a cylinder along Y), as MuJoCo converts it: angle = degrees · π / 180
_EULER_X90 = np.array([np.cos(90 * np.pi / 180 / 2), np.sin(90 * np.pi / 180 / 2), 0.0, 0.0])


def add_driven_body(parent, name: str, spatial: bool = False):
    """A body moved along a prescribed trajectory by :class:`Driver`, which sets its joint
    positions and velocities every step: planar (slide joints along X and Z and a hinge about
    −Y, so its angle is the planar θ) or ``spatial`` (slides along X, Y, Z and a ball joint).
    Unlike a mocap body, its contacts see its velocity, so friction drags what it touches. It is
    heavy (1 t, 1000 kg m²) so that contact forces do not change its velocity within a step: a
    light driven body is kicked back by its contacts every step, which they see as slip."""
    mujoco = need("mujoco", "mujoco")

    body = parent.add_body(name=name, gravcomp=1.0)
    slide, hinge, ball = mujoco.mjtJoint.mjJNT_SLIDE, mujoco.mjtJoint.mjJNT_HINGE, mujoco.mjtJoint.mjJNT_BALL
    joints = ([("x", slide, [1, 0, 0]), ("y", slide, [0, 1, 0]), ("z", slide, [0, 0, 1]), ("r", ball, [0, 0, 1])]
              if spatial else [("x", slide, [1, 0, 0]), ("z", slide, [0, 0, 1]), ("th", hinge, [0, -1, 0])])
    for suffix, kind, axis in joints:
        body.add_joint(name=f"{name}_{suffix}", type=kind, axis=axis)
    set_inertial(body, [0, 0, 0], MASS, diag=[INERTIA] * 3)
    return body


def add_pads(parent, ys, geoms, gravcomp: float = 1.0):
    """The two pads, bodies ``pad_left`` (+Y side) and ``pad_right`` at Y = ``ys``, each on a
    slide joint along Y (damping 20) squeezed by the motors of :func:`add_grip_motors`;
    ``geoms(body, sign)`` adds a pad's geoms (sign +1 left, −1 right)."""
    mujoco = need("mujoco", "mujoco")

    for (name, sign), y in zip((("pad_left", 1), ("pad_right", -1)), ys):
        body = parent.add_body(name=name, pos=[0.0, y, 0.0], gravcomp=gravcomp)
        body.add_joint(name=name, type=mujoco.mjtJoint.mjJNT_SLIDE, axis=[0, 1, 0], damping=20)
        geoms(body, sign)


def add_pad_sphere(body, sign: int, mu: float, torsion: float):
    """A pad's contact: one point, the pad's centre, through a large sphere with sliding friction
    ``mu`` and torsional friction ``torsion · mu``, so MuJoCo's elliptic cone at that contact is the
    pad's ellipsoidal limit surface (a flat pad geom would give several rim contacts, each with
    torsional friction, a much stiffer pad than the pressure distribution it stands for)."""
    add_geom(body, "sphere", [PAD_SPHERE], PAD_BITS, [mu, torsion * mu], pos=[0.0, sign * PAD_SPHERE, 0.0],
             mass=0.05, condim=4)


def add_grip_motors(spec):
    """Force actuators squeezing the pads (control: the grip force [N])."""
    mujoco = need("mujoco", "mujoco")

    for side, gear in (("left", -1.0), ("right", 1.0)):
        spec.add_actuator(name=f"grip_{side}", target=f"pad_{side}", trntype=mujoco.mjtTrn.mjTRN_JOINT,
                          gear=[gear, 0, 0, 0, 0, 0], ctrllimited=mujoco.mjtLimited.mjLIMITED_FALSE)


# --- the planar scene's pieces -----------------------------------------------------------------

def planar_spec(scene: Scene, name: str, contact: Contact = Contact()):
    """An empty model for ``scene`` with its gravity in the X-Z plane."""
    gdir, g = scene.gravity
    return new_spec(name, [gdir[0] * g, 0.0, gdir[1] * g], contact)


def add_object(spec, scene: Scene, pose, friction: float = 0.0, mass_scale: float = 1.0):
    """The object at planar ``pose`` ``[x, z, theta]`` (m, m, rad) on a free joint; the body frame
    is the object frame."""
    o = scene.outline
    q = np.asarray(pose, float)
    body = spec.worldbody.add_body(name="object", pos=[q[0], 0.0, q[1]], quat=planar_quat(q[2]))
    body.add_freejoint()
    m = scene.mass * mass_scale
    L = scene.length
    # a lamina extruded along Y: I_yy = m L² about the COM; the others are not exercised in the plane
    side = m * (L**2 / 2 + THICKNESS**2 / 12)
    set_inertial(body, [scene.com[0], 0.0, scene.com[1]], m, diag=[side, m * L**2, side])
    if _is_rectangle(o):
        lo, hi = o.min(axis=0), o.max(axis=0)
        c, h = (lo + hi) / 2, (hi - lo) / 2
        add_geom(body, "box", [h[0], THICKNESS / 2, h[1]], OBJECT_BITS, [friction], name="object",
                 pos=[c[0], 0.0, c[1]], condim=4)
        return body
    for k, piece in enumerate(convex_pieces(o)):
        verts = [(p[0], y, p[1]) for p in piece for y in (-THICKNESS / 2, THICKNESS / 2)]
        spec.add_mesh(name=f"piece{k}", uservert=np.ravel(verts).tolist())
        add_geom(body, "mesh", [], OBJECT_BITS, [friction], name=f"object{k}", meshname=f"piece{k}", condim=4)
    return body


def add_planar_pads(parent, scene: Scene, friction_scale: float = 1.0, gravcomp: float = 1.0):
    """The pads at Y = ±THICKNESS/2 with the scene's friction (:func:`add_pad_sphere`; the
    torsional coefficient ``k`` of the scene's limit surface) and the pad's shape drawn by a geom
    that does not collide."""
    if scene.kind != "grasp":
        raise ArgumentError("invalid `scene`: the MuJoCo model needs a grasp (not an object on a surface)", "grasp")
    mu_s = scene.pad_friction * friction_scale
    pad = scene.pad
    k = scene.pad_limit_surface_k
    if pad[0] == "circle":
        shape = dict(kind="cylinder", size=[pad[1], PAD_DEPTH / 2], quat=_EULER_X90)
    else:
        shape = dict(kind="box", size=[pad[1] / 2, PAD_DEPTH / 2, pad[2] / 2])

    def geoms(body, sign):
        add_pad_sphere(body, sign, mu_s, k)
        add_geom(body, pos=[0.0, sign * PAD_DEPTH / 2, 0.0], group=1, mass=0.0, **shape)  # drawn only

    add_pads(parent, [THICKNESS / 2, -THICKNESS / 2], geoms, gravcomp)


def add_feature_geom(body, scene: Scene, pusher: str, friction_scale: float = 1.0):
    """The pusher's environment feature, in the pusher frame (= the object frame where the pusher
    meets it): a plate behind a line pusher's points (an edge or a face) or a thin cylinder along
    Y for a point pusher (an edge of the environment, a corner in the plane)."""
    p = scene.pusher(pusher)
    n = p.normal / np.linalg.norm(p.normal)
    mu = p.friction * friction_scale
    depth = 0.02
    if len(p.points) == 2:
        mid = p.points.mean(axis=0) - n * 0.003
        half = np.linalg.norm(p.points[1] - p.points[0]) / 2
        return add_geom(body, "box", [0.003, depth, half], FEATURE_BITS, [mu], pos=[mid[0], 0.0, mid[1]],
                        quat=planar_quat(np.arctan2(n[1], n[0])), condim=3)
    c = p.points[0] - n * FEATURE_RADIUS
    return add_geom(body, "cylinder", [FEATURE_RADIUS, depth], FEATURE_BITS, [mu], pos=[c[0], 0.0, c[1]],
                    quat=_EULER_X90, condim=3)


def add_feature(spec, scene: Scene, pusher: str, name: str, friction_scale: float = 1.0, park=(0.0, 5.0, 0.0)):
    """A mocap body holding the pusher's feature (:func:`add_feature_geom`), parked at ``park``
    until needed."""
    body = spec.worldbody.add_body(name=name, mocap=True, pos=np.asarray(park, float))
    add_feature_geom(body, scene, pusher, friction_scale)
    return body


# --- running -----------------------------------------------------------------------------------

class Driver:
    """Sets a driven body's pose and velocity every step (see :func:`add_driven_body`): a planar
    pose [x, z, θ] or a spatial one [x, y, z, qw, qx, qy, qz] — the body's joint positions in
    their order."""

    def __init__(self, model, name: str):
        body = model.body(name).id
        qadr, dadr = [], []
        for j in range(int(model.body_jntadr[body]), int(model.body_jntadr[body] + model.body_jntnum[body])):
            nq, nv = (4, 3) if model.jnt_type[j] == 1 else (1, 1)  # mjJNT_BALL
            qadr += range(int(model.jnt_qposadr[j]), int(model.jnt_qposadr[j]) + nq)
            dadr += range(int(model.jnt_dofadr[j]), int(model.jnt_dofadr[j]) + nv)
        self.qadr, self.dadr = qadr, dadr
        self.spatial = len(qadr) == 7
        self.pose = np.r_[0.0, 0, 0, 1, 0, 0, 0] if self.spatial else np.zeros(3)

    def set(self, data, pose, velocity=None):
        """Puts the body at ``pose`` (m, rad) with ``velocity`` (m/s, rad/s; default zero) in
        ``data``."""
        pose = np.asarray(pose, float)
        data.qpos[self.qadr] = pose
        data.qvel[self.dadr] = 0.0 if velocity is None else velocity
        self.pose = pose

    def velocity(self, pose, dt: float) -> np.ndarray:
        """The constant velocity (m/s, rad/s) from the current pose to ``pose`` over ``dt`` [s] (the spatial
        angular velocity: the SO(3) log of the relative rotation, in the body frame, as the ball
        joint's qvel)."""
        if not self.spatial:
            return (pose - self.pose) / dt
        w = np.array(twist_between([0, 0, 0, *self.pose[3:]], [0, 0, 0, *pose[3:]]))[3:] / dt
        return np.r_[(pose[:3] - self.pose[:3]) / dt, w]

    def move(self, data, pose, dt: float):
        """Moves to ``pose`` (m, rad) over the next step of length ``dt`` [s]."""
        pose = np.asarray(pose, float)
        self.set(data, self.pose, self.velocity(pose, dt))
        self.pose = pose


class Rig:
    """A compiled model with its data, the pads squeezed with ``grip_force`` [N] each."""

    def __init__(self, spec, contact: Contact, grip_force: float):
        mujoco = need("mujoco", "mujoco")

        self.contact, self.dt = contact, contact.timestep
        self.model = spec.compile()
        self.data = mujoco.MjData(self.model)
        self.grip_force = grip_force
        self.data.ctrl[:] = grip_force

    def step(self):
        """One MuJoCo time step (``mj_step``)."""
        mujoco = need("mujoco", "mujoco")

        mujoco.mj_step(self.model, self.data)

    def forward(self):
        """Recomputes the derived quantities without stepping (``mj_forward``)."""
        mujoco = need("mujoco", "mujoco")

        mujoco.mj_forward(self.model, self.data)

    def mocap(self, body: str) -> int:
        """The mocap index of body ``body``."""
        return int(self.model.body_mocapid[self.model.body(body).id])

    def geoms(self, body: str) -> set:
        """The ids of the geoms of body ``body``."""
        bid = self.model.body(body).id
        return {i for i in range(self.model.ngeom) if self.model.geom_bodyid[i] == bid}

    def touching(self, geoms: set) -> bool:
        """Whether any of ``geoms`` is in contact."""
        c = self.data.contact
        return any(c[i].geom1 in geoms or c[i].geom2 in geoms for i in range(self.data.ncon))


#: ``regrasp.mujoco.model.creep`` (before 0.2): now :func:`regrasp.mujoco.world.creep`.
__getattr__ = _moved.attribute_aliases(__name__, {"creep": "mujoco.world"})
