"""The creep of a held object: the robot holds a box between its distributed-contact pads at a
grip force, under gravity, with the arm still; how far the box slides [m] and turns [rad]
relative to the TCP in a given time, split into the settling as the load comes on (the first
``SETTLE_TIME``) and the creep rate afterwards (the drift's slope over the last ``RATE_WINDOW``).
A grip below the holding limit (regrasp's mechanics: ``Scene.hold_grip_force``) lets it slip;
above it, it should only settle and creep."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Optional

import numpy as np

from ..errors import ArgumentError
from ..extras import need
from ..pose import compose, inverse, quat_angle, transform
from .pads import PAD_FRICTION

OBJECT = "held_object"  # the name of the held box's body
CLOSE_TIME = (0.3, 1.5)  # s, the fingers close on the box (held in place) at least, at most, until
SETTLED = 0.05  # both pads press within this share of the grip force; then the box is let go
SETTLE_TIME = 0.1  # s, after the box is let go: its settling as the load comes on
RATE_WINDOW = 1.0  # s, the creep rate is the drift's slope over the run's last this long (after settling)
SAMPLE = 0.005  # s, the box's relative pose is sampled this often for the creep rate


@dataclass(frozen=True)
class Creep:
    """What a held box did in ``duration`` [s]: ``slip`` [m] the distance its centre moved and
    ``rotation`` [rad] the angle it turned, both relative to the TCP over the whole run;
    ``settle`` [m] the distance it moved in the first ``SETTLE_TIME``; ``creep_rate`` [m/s] the
    speed of its drift over the last ``RATE_WINDOW`` (after settling; the norm of the
    least-squares slope of its relative position; nan when the run is not longer than
    ``SETTLE_TIME``); ``grip_forces`` [N] the
    measured normal force of the (left, right) pad at the end, mean over the last 0.1 s;
    ``robot`` the :class:`~regrasp.robot.model.Robot` at the end (its box: body ``OBJECT``)."""

    slip: float
    rotation: float
    settle: float
    creep_rate: float
    grip_forces: tuple
    duration: float
    robot: object = field(default=None, repr=False, compare=False)


def hold_box(grip_force: float, size=(0.04, 0.04, 0.04), mass: float = 0.1, friction: float = PAD_FRICTION,
             duration: float = 2.0, q=None, robot_name: Optional[str] = None, offset=(0.0, 0.0), sensing=None) -> Creep:
    """Holds a box of full ``size`` [m] (x, y along the grasp axis, z), ``mass`` [kg] and
    Coulomb friction ``friction`` between the pads (whose friction is the same) at per-finger
    ``grip_force`` [N] with the arm at joint positions ``q`` [rad] (home by default) for
    ``duration`` [s] under gravity, and returns its :class:`Creep`. ``offset`` [m]: the box's
    centre from the TCP along the TCP's (x, z) (a torque on the pads); ``sensing``: the grip
    loop's (:class:`~regrasp.robot.sensing.GripSensing`; None: ideal)."""
    mujoco = need("mujoco", "robot")
    from .grip import GripController, pad_forces
    from .model import DEFAULT_ROBOT, build, is_number

    try:
        size = np.asarray(size, float)
    except (TypeError, ValueError):
        size = np.zeros(0)
    if size.shape != (3,) or not np.all(np.isfinite(size) & (size > 0)):
        raise ArgumentError(f"invalid `size`: 3 lengths > 0 m (got {size!r})", "size")
    for name_, value in (("grip_force", grip_force), ("mass", mass), ("friction", friction), ("duration", duration)):
        if not (is_number(value) and value > 0):
            raise ArgumentError(f"invalid `{name_}`: a number > 0 (got {value!r})", name_)
    name = robot_name or DEFAULT_ROBOT
    probe = build(name, grasp_width=float(size[1]), pad_friction=friction)
    if q is not None:
        probe.set_q(q)
    tcp = probe.tcp_pose()
    centre = transform(tcp, [offset[0], 0.0, offset[1]])

    def add(spec):
        b = spec.worldbody.add_body(name=OBJECT, pos=centre, quat=tcp[3:])
        b.add_freejoint()
        b.add_geom(name=OBJECT, type=mujoco.mjtGeom.mjGEOM_BOX, size=size / 2, mass=mass, friction=[friction, 0, 0],
                   rgba=[0.2, 0.6, 0.9, 1])

    robot = build(name, grasp_width=float(size[1]), pad_friction=friction, add=add)
    robot.set_q(probe.q)
    m, d = robot.model, robot.data
    body = m.body(OBJECT).id
    jq = m.jnt_qposadr[m.body_jntadr[body]]
    hold = d.qpos[jq:jq + 7].copy()
    box = [m.geom(OBJECT).id]
    grip = GripController(robot, grip_force, box, sensing=sensing)
    t0 = d.time
    while d.time - t0 < CLOSE_TIME[1]:
        if d.time - t0 >= CLOSE_TIME[0] and np.all(np.abs(pad_forces(robot, box) - grip_force) <= SETTLED * grip_force):
            break
        d.qpos[jq:jq + 7], d.qvel[m.jnt_dofadr[m.body_jntadr[body]]:][:6] = hold, 0.0
        grip.update()
        mujoco.mj_step(m, d)
    start = relative(robot, body)
    n = int(round(duration / m.opt.timestep))
    last = min(n, max(1, int(0.1 / m.opt.timestep)))
    every = max(1, int(round(SAMPLE / m.opt.timestep)))
    forces, times, drift, settle = np.zeros(2), [], [], None
    for k in range(n):
        grip.update()
        mujoco.mj_step(m, d)
        if k >= n - last:
            forces += pad_forces(robot, box) / last
        t = (k + 1) * m.opt.timestep
        if settle is None and t >= SETTLE_TIME - 1e-12:
            settle = float(np.linalg.norm(relative(robot, body)[:3] - start[:3]))
        if (k + 1) % every == 0 and t > max(SETTLE_TIME, duration - RATE_WINDOW) + 1e-12:
            times.append(t)
            drift.append(relative(robot, body)[:3])
    end = relative(robot, body)
    slip = float(np.linalg.norm(end[:3] - start[:3]))
    rate = float(np.linalg.norm(np.polyfit(times, np.array(drift), 1)[0])) if len(times) >= 2 else float("nan")
    return Creep(slip, float(quat_angle(start[3:], end[3:])), slip if settle is None else settle, rate,
                 tuple(float(f) for f in forces), float(duration), robot)


def relative(robot, body: int) -> np.ndarray:
    """The pose ``[x, y, z, qw, qx, qy, qz]`` (m) of MuJoCo body ``body`` in the TCP's frame now."""
    from .grip import body_pose

    return compose(inverse(robot.tcp_pose()), body_pose(robot.data, body))
