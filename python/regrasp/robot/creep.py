"""The creep of a held object: the robot holds a box between its distributed-contact pads at a
grip force, under gravity, with the arm still; how far the box slides [m] and turns [rad]
relative to the TCP in a given time. A grip below the holding limit (regrasp's mechanics:
``Scene.hold_grip_force``) lets it slip; above it, it should only creep."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Optional

import numpy as np

from ..errors import ArgumentError
from ..extras import need
from ..pose import quat_angle, quat_from_matrix

OBJECT = "held_object"  # the name of the held box's body
CLOSE_TIME = (0.3, 1.5)  # s, the fingers close on the box (held in place) at least, at most, until
SETTLED = 0.05  # both pads press within this share of the grip force; then the box is let go


@dataclass(frozen=True)
class Creep:
    """What a held box did in ``duration`` [s]: ``slip`` [m] the distance its centre moved and
    ``rotation`` [rad] the angle it turned, both relative to the TCP; ``grip_forces`` [N] the
    measured normal force of the (left, right) pad at the end, mean over the last 0.1 s;
    ``robot`` the :class:`~regrasp.robot.model.Robot` at the end (its box: body ``OBJECT``)."""

    slip: float
    rotation: float
    grip_forces: tuple
    duration: float
    robot: object = field(default=None, repr=False, compare=False)


def hold_box(grip_force: float, size=(0.04, 0.04, 0.04), mass: float = 0.1, friction: float = 0.5,
             duration: float = 2.0, q=None, robot_name: Optional[str] = None, offset=(0.0, 0.0)) -> Creep:
    """Holds a box of full ``size`` [m] (x, y along the grasp axis, z), ``mass`` [kg] and
    Coulomb friction ``friction`` between the pads (whose friction is the same) at per-finger
    ``grip_force`` [N] with the arm at joint positions ``q`` [rad] (home by default) for
    ``duration`` [s] under gravity, and returns its :class:`Creep`. ``offset`` [m]: the box's
    centre from the TCP along the TCP's (x, z) (a torque on the pads)."""
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
    R = quat_from_matrix(probe.data.site_xmat[probe.tcp].reshape(3, 3))
    centre = tcp[:3] + probe.data.site_xmat[probe.tcp].reshape(3, 3) @ [offset[0], 0.0, offset[1]]

    def add(spec):
        b = spec.worldbody.add_body(name=OBJECT, pos=centre, quat=R)
        b.add_freejoint()
        b.add_geom(name=OBJECT, type=mujoco.mjtGeom.mjGEOM_BOX, size=size / 2, mass=mass, friction=[friction, 0, 0],
                   rgba=[0.2, 0.6, 0.9, 1])

    robot = build(name, grasp_width=float(size[1]), pad_friction=friction, add=add)
    robot.set_q(probe.q)
    m, d = robot.model, robot.data
    body = m.body(OBJECT).id
    jq = m.jnt_qposadr[m.body_jntadr[body]]
    hold = d.qpos[jq:jq + 7].copy()
    grip = GripController(robot, grip_force)
    t0 = d.time
    while d.time - t0 < CLOSE_TIME[1]:
        if d.time - t0 >= CLOSE_TIME[0] and np.all(np.abs(pad_forces(robot) - grip_force) <= SETTLED * grip_force):
            break
        d.qpos[jq:jq + 7], d.qvel[m.jnt_dofadr[m.body_jntadr[body]]:][:6] = hold, 0.0
        grip.update()
        mujoco.mj_step(m, d)
    start = relative(robot, body)
    n = int(round(duration / m.opt.timestep))
    last = min(n, max(1, int(0.1 / m.opt.timestep)))
    forces = np.zeros(2)
    for k in range(n):
        grip.update()
        mujoco.mj_step(m, d)
        if k >= n - last:
            forces += pad_forces(robot) / last
    end = relative(robot, body)
    return Creep(float(np.linalg.norm(end[:3] - start[:3])), float(quat_angle(start[3:], end[3:])),
                 tuple(float(f) for f in forces), float(duration), robot)


def relative(robot, body: int) -> np.ndarray:
    """The pose ``[x, y, z, qw, qx, qy, qz]`` (m) of MuJoCo body ``body`` in the TCP's frame now."""
    d = robot.data
    Rt = d.site_xmat[robot.tcp].reshape(3, 3)
    Rb = d.xmat[body].reshape(3, 3)
    return np.concatenate([Rt.T @ (d.xpos[body] - d.site_xpos[robot.tcp]), quat_from_matrix(Rt.T @ Rb)])
