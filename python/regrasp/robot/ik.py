"""Inverse kinematics of the arm with ``mink`` (differential IK on MuJoCo, solved as a QP with
DAQP): the TCP site brought to a world pose, the arm's joint limits respected (a configuration
limit) and the arm and gripper kept off the table (mink's collision-avoidance limit); every
other degree of freedom (the fingers, a held object) frozen. :func:`ik_path` chains solutions
through a list of TCP poses, each seeded by the previous one, and checks each."""

from __future__ import annotations

import numpy as np

from ..errors import ArgumentError
from ..extras import need
from ..pose import quat_angle
from .model import check_pose

POSITION_TOLERANCE = 1e-3  # m, a reached TCP position
ANGLE_TOLERANCE = 0.01  # rad, a reached TCP orientation
MIN_DISTANCE = 0.005  # m, the closest the arm and gripper may come to the table
MAX_ITERATIONS = 300  # of the differential IK
IK_DT = 0.05  # s, the differential IK's integration step
MAX_SPEED = np.pi  # rad/s, a joint's speed in the differential IK (a step turns it at most MAX_SPEED · IK_DT)
LIMIT_MARGIN = 1e-3  # rad, a joint this close to its range's end is at its limit


class IKError(ArgumentError):
    """No arm configuration reaches a TCP pose: ``field`` names it (``pose``, or ``poses[i]``
    in a path), ``reason`` says why: ``"unreachable"``, ``"joint limit"`` or ``"collision"``."""

    def __init__(self, message: str, field: str, reason: str):
        super().__init__(message, field)
        self.reason = reason


def pose_error(a, b) -> tuple:
    """(distance [m], angle [rad]) between poses ``a`` and ``b`` ``[x, y, z, qw, qx, qy, qz]`` (m)."""
    return float(np.linalg.norm(np.asarray(a)[:3] - np.asarray(b)[:3])), float(quat_angle(a[3:], b[3:]))


def obstacle_geoms(robot, avoid=()) -> list:
    """The geom ids the arm and gripper keep clear of: the table (when there is one) and
    ``avoid`` (geom ids or names, e.g. a workcell's features added through ``build(add=...)``)."""
    out = [robot.table] if robot.table >= 0 else []
    for g in avoid:
        out.append(robot.model.geom(g).id if isinstance(g, str) else int(g))
    return out


def table_distance(robot, q, avoid=()) -> float:
    """The smallest distance [m] between the arm's and gripper's collision geoms and the table
    (and the geoms ``avoid``) at arm joint positions ``q`` [rad] (inf when there are none;
    negative: penetration)."""
    mujoco = need("mujoco", "robot")
    obstacles = obstacle_geoms(robot, avoid)
    if not obstacles:
        return float("inf")
    d = mujoco.MjData(robot.model)
    d.qpos[:] = robot.data.qpos
    d.qpos[robot.arm_qpos] = q
    mujoco.mj_kinematics(robot.model, d)
    return min(mujoco.mj_geomDistance(robot.model, d, g, o, 0.1, None) for g in robot.robot_geoms for o in obstacles)


def solve_ik(robot, target_pose, q_init=None, field: str = "pose", avoid=()) -> np.ndarray:
    """Arm joint positions [rad] that put the TCP at world ``target_pose``
    ``[x, y, z, qw, qx, qy, qz]`` (m) within ``POSITION_TOLERANCE`` and ``ANGLE_TOLERANCE``,
    starting from ``q_init`` [rad] (the arm's joint positions now by default), within the joint
    limits and ``MIN_DISTANCE`` off the table and the geoms ``avoid`` (ids or names). Raises
    :class:`IKError` (its ``field`` is ``field``) saying why when none is found."""
    mink = need("mink", "robot")
    target = check_pose(target_pose, field)
    m = robot.model
    q0 = robot.q if q_init is None else np.asarray(q_init, float)
    if q0.shape != robot.arm_qpos.shape:
        raise ArgumentError(f"invalid `q_init`: {len(robot.arm_qpos)} joint positions [rad] (got shape {q0.shape})",
                            "q_init")
    full = robot.data.qpos.copy()
    # the frozen joints inside their ranges (a closed finger linkage may sit a hair outside,
    # which would make the joint-limit constraint infeasible); they do not move the TCP
    for j in range(m.njnt):
        if m.jnt_limited[j] and m.jnt_type[j] in (2, 3):  # hinge, slide
            a = m.jnt_qposadr[j]
            full[a] = np.clip(full[a], m.jnt_range[j, 0] + 1e-6, m.jnt_range[j, 1] - 1e-6)
    full[robot.arm_qpos] = q0
    config = mink.Configuration(m, full)
    task = mink.FrameTask(frame_name=m.site(robot.tcp).name, frame_type="site", position_cost=1.0,
                          orientation_cost=1.0, lm_damping=1e-3)
    task.set_target(mink.SE3(np.concatenate([target[3:], target[:3]])))
    posture = mink.PostureTask(m, cost=1e-3)
    posture.set_target(full)
    others = [i for i in range(m.nv) if i not in set(robot.arm_dof.tolist())]
    constraints = [mink.DofFreezingTask(m, dof_indices=others)] if others else None
    limits = [mink.ConfigurationLimit(m), mink.VelocityLimit(m, {"arm/" + j: MAX_SPEED for j in robot.arm_joints})]
    obstacles = obstacle_geoms(robot, avoid)
    if obstacles:
        limits.append(mink.CollisionAvoidanceLimit(m, [(list(robot.robot_geoms), obstacles)],
                                                   minimum_distance_from_collisions=MIN_DISTANCE,
                                                   collision_detection_distance=0.05))
    for _ in range(MAX_ITERATIONS):
        q = config.q[robot.arm_qpos]
        reached = pose_error(robot.tcp_pose(q), target)
        if reached[0] <= POSITION_TOLERANCE and reached[1] <= ANGLE_TOLERANCE:
            break
        try:
            v = mink.solve_ik(config, [task, posture], IK_DT, "daqp", damping=1e-3, limits=limits, constraints=constraints)
        except mink.NoSolutionFound:  # the limits admit no step from here: classified below
            break
        config.integrate_inplace(v, IK_DT)
    q = config.q[robot.arm_qpos].copy()
    reached = pose_error(robot.tcp_pose(q), target)
    if reached[0] <= POSITION_TOLERANCE and reached[1] <= ANGLE_TOLERANCE:
        return q
    rng = robot.joint_limits()
    at_limit = [robot.arm_joints[i] for i in range(len(q)) if min(q[i] - rng[i, 0], rng[i, 1] - q[i]) < LIMIT_MARGIN]
    gap = table_distance(robot, q, avoid)
    beyond = robot.reach(target)
    if beyond > 0:
        reason, why = "unreachable", f"{beyond * 1e3:.0f} mm beyond the arm's reach"
    elif at_limit:
        reason, why = "joint limit", f"joint {', '.join(at_limit)} at its limit"
    elif gap < MIN_DISTANCE + 1e-3:
        reason, why = "collision", f"the arm or gripper {gap * 1e3:.1f} mm from the table or an obstacle"
    else:
        reason, why = "unreachable", "no arm configuration found"
    raise IKError(f"invalid `{field}`: the TCP cannot reach {np.round(target, 4).tolist()} ({reason}: {why}; "
                  f"closest {reached[0] * 1e3:.1f} mm, {reached[1]:.3f} rad away)", field, reason)


def ik_path(robot, poses, q_init=None, avoid=()) -> np.ndarray:
    """Arm joint positions [rad], shape (n, 6), reaching each of the TCP world ``poses`` (n, 7)
    ``[x, y, z, qw, qx, qy, qz]`` (m) in turn, each solution seeding the next (so the path stays
    on one IK branch), clear of the table and ``avoid`` (:func:`solve_ik`). Raises
    :class:`IKError` naming ``poses[i]`` and why at the first pose that cannot be reached."""
    P = np.asarray(poses, float)
    if P.ndim != 2 or P.shape[1] != 7 or len(P) == 0:
        raise ArgumentError(f"invalid `poses`: shape (n >= 1, 7) (got {P.shape})", "poses")
    q = robot.q if q_init is None else np.asarray(q_init, float)
    out = []
    for i, p in enumerate(P):
        q = solve_ik(robot, p, q, field=f"poses[{i}]", avoid=avoid)
        out.append(q)
    return np.array(out)
