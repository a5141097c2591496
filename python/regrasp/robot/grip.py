"""Force-controlled fingers. The 2F-85's position actuator is replaced by a force actuator on
its driver tendon (:func:`regrasp.robot.model.gripper_spec`); the map from the actuator's force
to each pad's normal force through the linkage is measured on the bare gripper closing on a
fixed box (:func:`pad_state`: affine, ≈ 9 N of pad force per N of actuator force at a 40 mm
grasp plus the linkage spring's ≈ 0.02 N), with the robot's own pads, pad friction and contact
settings (timestep included), and :func:`set_grip_force` commands a per-finger grip force through
it (feed-forward). The feed-forward map alone gives ≈ +0.5 N under a held 0.1 kg box (2.53 N for
2 N, 5.53 N for 5 N, 20.49 N for 20 N: the load moves the pads through the linkage), so
:class:`GripController` closes a loop on the pads' normal force **as MuJoCo reports it** — an
ideal tactile sensor that a real 2F-85 lacks (it has none; its current is a coarse proxy);
:mod:`.sensing` gives the loop a force sensor's readings (delay, bandwidth, noise) or none.
:func:`pad_forces` measures the pads' normal forces on the held object only.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from ..errors import ArgumentError
from ..extras import need
from ..pose import inverse, transform
from .kinds import DEFAULT_ROBOT, GRIP_RANGE, GRIPPER_PREFIX, ROBOTS, gripper_spec, set_options

CALIBRATION_FORCES = (1.0, 5.0)  # N, the actuator forces at which pad_state measures the (affine) map
CORRECTION = 0.3  # the grip controller's correction bound: a share of the requested force,
MIN_CORRECTION = 1.0  # N, or this much when more
CALIBRATION_TIME = 1.0  # s, simulated to let the gripper settle on the box


def geom_ids(model, geoms, field: str = "objects") -> np.ndarray:
    """The geom ids of ``geoms`` (ids or names) in ``model``, or an ArgumentError naming ``field``."""
    out = []
    for g in geoms if not isinstance(geoms, (str, int, np.integer)) else [geoms]:
        try:
            i = model.geom(g).id if isinstance(g, str) else int(g)
        except (KeyError, TypeError, ValueError):
            i = -1
        if not 0 <= i < model.ngeom:
            raise ArgumentError(f"invalid `{field}`: geom ids or names of the model (got {g!r})", field)
        out.append(i)
    return np.array(out, int)


def pad_forces(robot, objects, data=None) -> np.ndarray:
    """The total normal contact force [N] of the (left, right) pad on the geoms ``objects``
    (ids or names: the held object's) now (``data``: the robot's by default); a pad's contacts
    with anything else (a feature, the table) do not count."""
    m, d = robot.model, data if data is not None else robot.data
    return contact_normal_forces(m, d, robot.pad_geoms, geom_ids(m, objects))


def contact_normal_forces(model, data, groups, others=None) -> np.ndarray:
    """The total normal contact force [N] on each group of geom ids in ``groups`` from its
    contacts with the geoms ``others`` (ids; None: any geom) (:class:`ContactForces`)."""
    return ContactForces(model, groups, others)(data)


class ContactForces:
    """Sums normal contact forces [N] per group of geom ids ``groups`` of ``model`` over the
    group's contacts with the geoms ``others`` (ids; None: any geom), vectorised: the geoms'
    labels looked up once, the forces read from the constraint forces (``efc_force`` at each
    contact's ``efc_address``: an elliptic cone's normal row, the sum of a pyramidal cone's
    edges, as ``mj_contactForce``). Call it with a ``mujoco.MjData``."""

    def __init__(self, model, groups, others=None):
        mujoco = need("mujoco", "robot")
        self.count = len(groups)
        self.label = np.full(model.ngeom, -1)
        for j, group in enumerate(groups):
            self.label[np.asarray(group, int)] = j
        self.other = np.ones(model.ngeom, bool) if others is None else np.zeros(model.ngeom, bool)
        if others is not None:
            self.other[np.asarray(others, int)] = True
        self.elliptic = int(model.opt.cone) == int(mujoco.mjtCone.mjCONE_ELLIPTIC)

    def __call__(self, data) -> np.ndarray:
        """The total normal force [N] on each group now, shape (len(groups),)."""
        n = data.ncon
        if n == 0:
            return np.zeros(self.count)
        c = data.contact
        g1, g2, adr = c.geom1, c.geom2, c.efc_address
        live = adr >= 0
        if self.elliptic:
            f = np.where(live, data.efc_force[np.maximum(adr, 0)], 0.0)
        else:  # pyramidal: the normal force is the sum of the 2 (dim - 1) edges' forces
            dim = c.dim
            rows = np.where(dim > 1, 2 * (dim - 1), 1)
            k = np.arange(rows.max())
            idx = np.minimum(np.maximum(adr, 0)[:, None] + k, data.nefc - 1)
            f = np.where(live, np.where(k < rows[:, None], data.efc_force[idx], 0.0).sum(axis=1), 0.0)
        a, b = self.label[g1], self.label[g2]
        s1, s2 = (a >= 0) & self.other[g2], (b >= 0) & self.other[g1]
        return (np.bincount(a[s1], f[s1], self.count) + np.bincount(b[s2], f[s2], self.count)).astype(float)


def pad_state(grasp_width: float, robot_name: str = "", pads=None, pad_friction: float = None,
              contact=None) -> tuple:
    """(gain, bias, height) of the gripper closed on a fixed box ``grasp_width`` [m] wide, gravity
    off: a pad's normal force is ``gain · u + bias`` [N] at grip actuator force ``u`` [N]
    (``gain`` [N/N] the linkage's force ratio, ``bias`` [N] the linkage spring's share, both
    measured at two actuator forces), ``height`` [m] the pads' centres along the 2F-85 base's z
    (where the TCP goes). Measured with robot ``robot_name``'s gripper (the default robot's by
    default), its ``pads`` (a :class:`~regrasp.robot.pads.Pads`), ``pad_friction`` and MuJoCo
    ``contact`` settings (``regrasp.mujoco.model.Contact``: timestep, cone, impratio, no-slip);
    the defaults: :func:`~regrasp.robot.model.build`'s. Measured once per distinct set of these."""
    from ..mujoco.model import Contact
    from .pads import PAD_FRICTION, Pads

    return _pad_state(float(grasp_width), robot_name or DEFAULT_ROBOT, pads or Pads(),
                      float(PAD_FRICTION if pad_friction is None else pad_friction), contact or Contact())[:3]


def robot_pad_state(robot) -> tuple:
    """:func:`pad_state` (gain [N/N], bias [N], height [m]) for ``robot``'s own grasp width,
    gripper, pads, pad friction and contact settings."""
    return pad_state(robot.grasp_width, robot.name, robot.pads, robot.pad_friction, robot.contact)


def _calibration_rig(grasp_width: float, robot_name: str, pads, pad_friction: float, contact) -> tuple:
    """(model, data, pad geoms (left, right), [box geom]): the bare gripper of ``robot_name``,
    gravity off, around a fixed tall box ``grasp_width`` [m] wide (the pads meet it wherever the
    linkage puts them)."""
    mujoco = need("mujoco", "robot")

    kind = ROBOTS[robot_name]
    g = gripper_spec(kind, pads, pad_friction)
    set_options(g, contact)
    g.option.gravity = [0, 0, 0]
    g.worldbody.add_geom(name="calibration_box", type=mujoco.mjtGeom.mjGEOM_BOX, size=[grasp_width / 2, 0.03, 0.035],
                         pos=[0, 0, kind.calibration_height])
    m = g.compile()
    pad_geoms = tuple(tuple(i for i in range(m.ngeom) if m.geom_bodyid[i] == m.body(b).id and m.geom_contype[i])
                      for b in kind.pad_bodies)
    return m, mujoco.MjData(m), pad_geoms, [m.geom("calibration_box").id]


@lru_cache(maxsize=32)
def _pad_state(grasp_width: float, robot_name: str, pads, pad_friction: float, contact) -> tuple:
    mujoco = need("mujoco", "robot")
    from .pads import LENGTH

    kind = ROBOTS[robot_name]
    m, d, pad_geoms, box = _calibration_rig(grasp_width, robot_name, pads, pad_friction, contact)
    f = []
    for u in CALIBRATION_FORCES:
        d.ctrl[m.actuator("grip").id] = u
        for _ in range(int(CALIBRATION_TIME / m.opt.timestep)):
            mujoco.mj_step(m, d)
        f.append(contact_normal_forces(m, d, pad_geoms, box))
        if not np.all(f[-1] > 0):
            raise ArgumentError(f"invalid `grasp_width`: the pads do not reach a {grasp_width * 1e3:.1f} mm box",
                                "grasp_width")
    (u1, u2), (f1, f2) = CALIBRATION_FORCES, (f[0].mean(), f[1].mean())
    gain = (f2 - f1) / (u2 - u1)
    base = m.body(kind.gripper_base).id
    pad = m.body(kind.pad_bodies[1]).id
    centre = transform(body_pose(d, pad), [0.0, 0.0, LENGTH / 2])
    local = transform(inverse(body_pose(d, base)), centre)
    joints = tuple((m.joint(j).name, float(d.qpos[m.jnt_qposadr[j]])) for j in range(m.njnt))
    return float(gain), float(f1 - gain * u1), float(local[2]), joints


LOW_FORCES = (0.0, 0.02, 0.05, 0.1, 0.2, 0.4, 0.7, 1.0)  # N, the actuator forces of low_force_curve (up to CALIBRATION_FORCES[0])


def low_force_curve(robot) -> tuple:
    """(u [N], f [N]): the pads' mean normal force ``f`` at grip actuator forces ``u``
    (:data:`LOW_FORCES`) on a fixed box as wide as ``robot``'s grasp, gravity off — the low end of
    the linkage's map, where the affine :func:`pad_state` (measured at 1 and 5 N) is off by up to
    0.5 N (its spring is not linear: at a 30 mm grasp the affine map reads 0.58 N at u = 0.115 N,
    the gripper presses 0.95 N there). Measured once per grasp width, gripper, pads and settings."""
    return _low_force_curve(robot.grasp_width, robot.name, robot.pads, robot.pad_friction, robot.contact)


def least_force(grasp_width: float, robot_name: str = "", pads=None, pad_friction: float | None = None,
                contact=None) -> float:
    """The least per-pad force [N] the gripper presses an object ``grasp_width`` [m] wide with: its
    pads' force at a zero actuator force (:func:`low_force_curve`; the linkage's springs alone —
    2.6 N at 70 mm with the bundled objects' pads, about 0 at 30 mm). The arguments and their
    defaults: :func:`pad_state`'s."""
    from ..mujoco.model import Contact
    from .pads import PAD_FRICTION, Pads

    return float(_low_force_curve(float(grasp_width), robot_name or DEFAULT_ROBOT, pads or Pads(),
                                  float(PAD_FRICTION if pad_friction is None else pad_friction),
                                  contact or Contact())[1][0])


@lru_cache(maxsize=32)
def _low_force_curve(grasp_width: float, robot_name: str, pads, pad_friction: float, contact) -> tuple:
    mujoco = need("mujoco", "robot")
    m, d, pad_geoms, box = _calibration_rig(grasp_width, robot_name, pads, pad_friction, contact)
    forces = []
    for u in reversed((*LOW_FORCES, CALIBRATION_FORCES[0])):  # from closed down: the pads stay on the box
        d.ctrl[m.actuator("grip").id] = u
        for _ in range(int(CALIBRATION_TIME / 2 / m.opt.timestep)):
            mujoco.mj_step(m, d)
        forces.append(float(contact_normal_forces(m, d, pad_geoms, box).mean()))
    return np.array((*LOW_FORCES, CALIBRATION_FORCES[0])), np.array(forces[::-1])


def close_fingers(robot) -> None:
    """Puts ``robot``'s finger linkage where it closes on an object as wide as its grasp width
    (measured by :func:`pad_state`), at rest: the state its IK freezes the fingers in (the
    linkage moves in and down as it closes: from open, its spring links come 10 mm nearer
    to a feature beside the pads)."""
    mujoco = need("mujoco", "robot")

    m, d = robot.model, robot.data
    for name, q in _pad_state(robot.grasp_width, robot.name, robot.pads, robot.pad_friction, robot.contact)[3]:
        j = m.joint(GRIPPER_PREFIX + name).id
        if m.jnt_limited[j]:  # a linkage joint settles a hair outside its range
            q = min(max(q, m.jnt_range[j, 0]), m.jnt_range[j, 1])
        d.qpos[m.jnt_qposadr[j]], d.qvel[m.jnt_dofadr[j]] = q, 0.0
    mujoco.mj_forward(m, d)


def body_pose(data, body: int) -> np.ndarray:
    """The world pose ``[x, y, z, qw, qx, qy, qz]`` (m) of MuJoCo body ``body`` now."""
    return np.concatenate([data.xpos[body], data.xquat[body]])


def grip_command(robot, grip_force: float) -> float:
    """The grip actuator's force [N] that makes each pad press with ``grip_force`` [N] on an
    object as wide as the robot's grasp width (through the measured linkage map
    :func:`pad_state`; below the linkage spring's share the actuator pulls the fingers back)."""
    if not (np.isfinite(grip_force) and grip_force >= 0):
        raise ArgumentError(f"invalid `grip_force`: >= 0 N (got {grip_force!r})", "grip_force")
    gain, bias, _ = robot_pad_state(robot)
    u = (grip_force - bias) / gain
    if u > GRIP_RANGE:
        raise ArgumentError(f"invalid `grip_force`: {grip_force} N is more than the gripper's "
                            f"{GRIP_RANGE * gain:.0f} N", "grip_force")
    return u


def set_grip_force(robot, grip_force: float, data=None) -> None:
    """Commands a per-finger grip force ``grip_force`` [N] (0 opens nothing: it only relaxes;
    a negative actuator force opens, see :func:`open_gripper`)."""
    d = data if data is not None else robot.data
    d.ctrl[robot.grip_actuator] = grip_command(robot, grip_force)


def open_gripper(robot, data=None) -> None:
    """Commands the fingers open (the actuator's force −1 N: the driver runs to its stop)."""
    d = data if data is not None else robot.data
    d.ctrl[robot.grip_actuator] = -1.0


class GripController:
    """Holds a per-finger grip force ``grip_force`` [N] on the geoms ``objects`` (ids or names:
    the held object's): the feed-forward :func:`grip_command` plus an integral correction on the
    pads' normal force on ``objects`` (their mean; MuJoCo's contact force, an ideal sensor), with time
    constant ``tau`` [s], updated every ``period`` [s] while both pads touch, bounded to
    ``CORRECTION`` of the requested force (at least ``MIN_CORRECTION``: an impact's spike must
    not open the hand). Why a loop: a load along the pads moves them through the linkage — under
    a 0.1 kg box the normal force sags ≈ 20 % as the load comes on and settles ≈ 0.5 N high
    without it; with τ = 0.1 s the box slipped up to 1.35 times the holding limit, with the
    default (a 2 kHz loop, τ = 5 ms) up to ≈ 1.05 times. ``sensing``
    (:class:`~regrasp.robot.sensing.GripSensing`): what the loop measures — the ideal contact
    forces (default), a force sensor's delayed, filtered, noisy readings (τ at least
    ``SETTLE_DELAYS`` delays; a pad touches when its reading exceeds 3 noise deviations), or
    nothing (``"open-loop"``: the feed-forward alone). Call :meth:`update` before each
    ``mj_step``."""

    def __init__(self, robot, grip_force: float, objects, tau: float = 0.005, period: float = 0.0005, data=None,
                 sensing=None):
        from .sensing import SETTLE_DELAYS, GripSensing, SensedForces

        self.robot, self.data = robot, data if data is not None else robot.data
        self.objects = geom_ids(robot.model, objects)
        self.forces = ContactForces(robot.model, robot.pad_geoms, self.objects)
        self.sensing = GripSensing() if sensing is None else sensing
        if self.sensing.kind == "sensor":
            tau = max(float(tau), SETTLE_DELAYS * self.sensing.delay)
        self.sensed = SensedForces(self.sensing, period) if self.sensing.kind == "sensor" else None
        self.grip_force, self.tau, self.period = float(grip_force), float(tau), float(period)
        self.u = self.feedforward = grip_command(robot, grip_force)
        self.gain = robot_pad_state(robot)[0]
        self.next = self.data.time
        self.data.ctrl[robot.grip_actuator] = self.u

    def set_force(self, grip_force: float) -> None:
        """A new per-finger grip force [N] to hold: the feed-forward moves to it, the loop's
        correction stays."""
        feedforward = grip_command(self.robot, grip_force)
        self.u += feedforward - self.feedforward
        self.grip_force, self.feedforward = float(grip_force), feedforward
        self.data.ctrl[self.robot.grip_actuator] = self.u

    def update(self) -> None:
        """Updates the grip actuator's command from the pads' forces now (at most every ``period``)."""
        d = self.data
        if d.time + 1e-12 < self.next or self.sensing.kind == "open-loop":
            return
        self.next = d.time + self.period
        f = self.forces(d).tolist()
        if self.sensed is not None:
            f = self.sensed.read(f)
            f = f.tolist() if min(f) > 3 * self.sensing.noise else [0.0]
        if min(f) > 0:
            self.u += self.period / self.tau * (self.grip_force - sum(f) / len(f)) / self.gain
            bound = max(CORRECTION * self.grip_force, MIN_CORRECTION) / self.gain
            self.u = min(max(self.u, self.feedforward - bound), self.feedforward + bound)
        d.ctrl[self.robot.grip_actuator] = self.u
