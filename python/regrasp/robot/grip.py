"""Force-controlled fingers. The 2F-85's position actuator is replaced by a force actuator on
its driver tendon (:func:`regrasp.robot.model.gripper_spec`); the map from the actuator's force
to each pad's normal force through the linkage is measured on the bare gripper closing on a
fixed box (:func:`pad_state`: affine, ≈ 9 N of pad force per N of actuator force at a 40 mm
grasp plus the linkage spring's ≈ 0.7 N), and
:func:`set_grip_force` commands a per-finger grip force through it (feed-forward; no force
sensor is needed). :func:`pad_forces` measures the pads' normal forces in MuJoCo."""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from ..errors import ArgumentError
from ..extras import need

GRIP_RANGE = 20.0  # N, the grip actuator's force range (≈ 180 N per pad at a 40 mm grasp)
CALIBRATION_FORCES = (1.0, 5.0)  # N, the actuator forces at which pad_state measures the (affine) map
CORRECTION = 0.3  # the grip controller's correction bound: a share of the requested force,
MIN_CORRECTION = 1.0  # N, or this much when more
CALIBRATION_TIME = 1.0  # s, simulated to let the gripper settle on the box


def pad_forces(robot, data=None) -> np.ndarray:
    """The total normal contact force [N] on the (left, right) pad now (``data``: the robot's by
    default)."""
    mujoco = need("mujoco", "robot")
    m, d = robot.model, data if data is not None else robot.data
    return contact_normal_forces(m, d, robot.pad_geoms)


def contact_normal_forces(model, data, groups) -> np.ndarray:
    """The total normal contact force [N] on each group of geom ids in ``groups``."""
    mujoco = need("mujoco", "robot")
    out = np.zeros(len(groups))
    f6 = np.zeros(6)
    sets = [set(g) for g in groups]
    for i in range(data.ncon):
        c = data.contact[i]
        for k, s in enumerate(sets):
            if c.geom1 in s or c.geom2 in s:
                mujoco.mj_contactForce(model, data, i, f6)
                out[k] += f6[0]
    return out


def pad_state(grasp_width: float, robot_name: str = "") -> tuple:
    """(gain, bias, height) of the gripper closed on a fixed box ``grasp_width`` [m] wide, gravity
    off: a pad's normal force is ``gain · u + bias`` [N] at grip actuator force ``u`` [N]
    (``gain`` [N/N] the linkage's force ratio, ``bias`` [N] the linkage spring's share, both
    measured at two actuator forces), ``height`` [m] the pads' centres along the 2F-85 base's z
    (where the TCP goes). ``robot_name``: the robot's gripper (the default robot's by default).
    Measured once per width and robot."""
    from .model import DEFAULT_ROBOT

    return _pad_state(float(grasp_width), robot_name or DEFAULT_ROBOT)


@lru_cache(maxsize=32)
def _pad_state(grasp_width: float, robot_name: str) -> tuple:
    mujoco = need("mujoco", "robot")
    from .model import ROBOTS, gripper_spec
    from .pads import LENGTH, Pads

    kind = ROBOTS[robot_name]
    g = gripper_spec(kind, Pads(), 0.5)
    g.option.timestep, g.option.gravity, g.option.impratio, g.option.noslip_iterations = 5e-4, [0, 0, 0], 20, 20
    # a tall box: the pads meet it wherever the linkage puts them
    g.worldbody.add_geom(name="calibration_box", type=mujoco.mjtGeom.mjGEOM_BOX, size=[grasp_width / 2, 0.03, 0.035],
                         pos=[0, 0, 0.16])
    m = g.compile()
    d = mujoco.MjData(m)
    pads = tuple(tuple(i for i in range(m.ngeom) if m.geom_bodyid[i] == m.body(b).id and m.geom_contype[i])
                 for b in kind.pad_bodies)
    f = []
    for u in CALIBRATION_FORCES:
        d.ctrl[m.actuator("grip").id] = u
        for _ in range(int(CALIBRATION_TIME / m.opt.timestep)):
            mujoco.mj_step(m, d)
        f.append(contact_normal_forces(m, d, pads))
        if not np.all(f[-1] > 0):
            raise ArgumentError(f"invalid `grasp_width`: the pads do not reach a {grasp_width * 1e3:.1f} mm box",
                                "grasp_width")
    (u1, u2), (f1, f2) = CALIBRATION_FORCES, (f[0].mean(), f[1].mean())
    gain = (f2 - f1) / (u2 - u1)
    base = m.body(kind.gripper_base).id
    pad = m.body(kind.pad_bodies[1]).id
    centre = d.xpos[pad] + d.xmat[pad].reshape(3, 3) @ [0, 0, LENGTH / 2]
    local = d.xmat[base].reshape(3, 3).T @ (centre - d.xpos[base])
    return float(gain), float(f1 - gain * u1), float(local[2])


def grip_command(robot, grip_force: float) -> float:
    """The grip actuator's force [N] that makes each pad press with ``grip_force`` [N] on an
    object as wide as the robot's grasp width (through the measured linkage map
    :func:`pad_state`; below the linkage spring's share the actuator pulls the fingers back)."""
    if not (np.isfinite(grip_force) and grip_force >= 0):
        raise ArgumentError(f"invalid `grip_force`: >= 0 N (got {grip_force!r})", "grip_force")
    gain, bias, _ = pad_state(robot.grasp_width, robot.name)
    u = (grip_force - bias) / gain
    if u > GRIP_RANGE:
        raise ArgumentError(f"invalid `grip_force`: {grip_force} N is more than the gripper's "
                            f"{GRIP_RANGE * pad_state(robot.grasp_width, robot.name)[0]:.0f} N", "grip_force")
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
    """Holds a per-finger grip force ``grip_force`` [N]: the feed-forward :func:`grip_command`
    plus an integral correction on the pads' measured normal force (their mean), with time
    constant ``tau`` [s], updated every ``period`` [s] while both pads touch, bounded to
    ``CORRECTION`` of the requested force (at least ``MIN_CORRECTION``: an impact's spike must
    not open the hand). Why a loop: a load along the pads moves them through the linkage — under
    a 0.1 kg box the normal force sags ≈ 20 % as the load comes on and settles ≈ 0.5 N high
    without it; with τ = 0.1 s the box slipped up to 1.35 times the holding limit, with the
    default (a 2 kHz loop, τ = 5 ms) up to ≈ 1.05 times. Call :meth:`update` before each
    ``mj_step``."""

    def __init__(self, robot, grip_force: float, tau: float = 0.005, period: float = 0.0005, data=None):
        self.robot, self.data = robot, data if data is not None else robot.data
        self.grip_force, self.tau, self.period = float(grip_force), float(tau), float(period)
        self.u = self.feedforward = grip_command(robot, grip_force)
        self.gain = pad_state(robot.grasp_width, robot.name)[0]
        self.next = self.data.time
        self.data.ctrl[robot.grip_actuator] = self.u

    def update(self) -> None:
        """Updates the grip actuator's command from the pads' forces now (at most every ``period``)."""
        d = self.data
        if d.time + 1e-12 < self.next:
            return
        self.next = d.time + self.period
        f = pad_forces(self.robot, d)
        if np.all(f > 0):
            self.u += self.period / self.tau * (self.grip_force - f.mean()) / self.gain
            bound = max(CORRECTION * self.grip_force, MIN_CORRECTION) / self.gain
            self.u = float(np.clip(self.u, self.feedforward - bound, self.feedforward + bound))
        d.ctrl[self.robot.grip_actuator] = self.u
