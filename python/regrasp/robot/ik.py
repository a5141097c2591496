"""Inverse kinematics of the arm with ``mink`` (differential IK on MuJoCo, solved as a QP with
DAQP): the TCP site brought to a world pose, the arm's joint limits respected (a configuration
limit) and the arm and gripper kept off the table (mink's collision-avoidance limit); every
other degree of freedom (the fingers, a held object) frozen. Each solve iterates to 1e-5 m /
1e-5 rad and accepts within 1 mm / 0.01 rad; the solution's clearance is then checked exactly
(mink's collision limit is linearised and can tunnel). :class:`IKSolver` is set up once and
reused; :func:`ik_path` chains solutions through a list of TCP poses with one solver, each
seeded by the previous one, and refuses a joint jump over ``MAX_JUMP`` (a branch flip)."""

from __future__ import annotations

import numpy as np

from ..errors import ArgumentError
from ..extras import need
from ..pose import quat_angle
from .model import check_pose

POSITION_TOLERANCE = 1e-3  # m, the accept/reject bound on a solution's TCP position error
ANGLE_TOLERANCE = 0.01  # rad, the accept/reject bound on a solution's TCP orientation error
CONVERGED_POSITION = 1e-5  # m, the differential IK iterates until the TCP is this close ...
CONVERGED_ANGLE = 1e-5  # rad, ... and this well turned (or MAX_ITERATIONS)
MIN_DISTANCE = 0.005  # m, the closest the arm and gripper may come to the table and obstacles
LIMIT_MARGIN_DISTANCE = 0.002  # m, mink's collision limit is this much more (it is linearised and can tunnel)
LIMIT_DISTANCE = MIN_DISTANCE + LIMIT_MARGIN_DISTANCE  # m, mink's collision limit at MIN_DISTANCE
MAX_ITERATIONS = 300  # of the differential IK
STALL_ITERATIONS = 3  # ... which stops early when this many steps in a row ...
STALL_STEP = 1e-9  # rad, ... turned no joint more than this (the limits hold it where it is)
POLISH_ITERATIONS = 50  # without the collision limit, when it held the TCP back from the target
POLISH_REACH = 0.005  # m, ... by at most this much (the margin's worth; a larger miss is not the margin's)
IK_DT = 0.05  # s, the differential IK's integration step
MAX_SPEED = np.pi  # rad/s, a joint's speed in the differential IK (a step turns it at most MAX_SPEED · IK_DT)
LIMIT_MARGIN = 1e-3  # rad, a joint this close to its range's end is at its limit
MAX_JUMP = 0.5  # rad, the largest joint change between consecutive poses of an ik_path (more: a branch flip)
BRANCH_SEEDS = 24  # random starts :func:`ik_solutions` tries (uniform within the joint limits, at most ±π)


class IKError(ArgumentError):
    """No arm configuration reaches a TCP pose: ``field`` names it (``pose``, or ``poses[i]``
    in a path), ``reason`` says why: ``"unreachable"``, ``"joint limit"`` or ``"collision"``;
    ``part``: for a collision, the robot's body nearest the obstacle (``arm/…`` or ``gripper/…``);
    ``joints``: for a joint limit, the indices of the arm joints at theirs; ``path``: in a path
    (:func:`ik_path`), the solutions [rad] of the poses before the failing one, shape (i, n)."""

    def __init__(self, message: str, field: str, reason: str, part: str = "", joints: tuple = ()):
        super().__init__(message, field)
        self.reason, self.part, self.joints = reason, part, tuple(joints)
        self.path = None


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


def fixed_geoms(robot) -> list:
    """The colliding geoms fixed in the world (on the world body: a workcell's table and
    features added through ``build(add=...)``), the obstacles of an execution's IK."""
    m = robot.model
    return [g for g in range(m.ngeom) if m.geom_bodyid[g] == 0 and (m.geom_contype[g] or m.geom_conaffinity[g])]


def table_distance(robot, q, avoid=()) -> float:
    """The smallest distance [m] between the arm's and gripper's collision geoms and the table
    (and the geoms ``avoid``) at arm joint positions ``q`` [rad] (inf when there are none;
    negative: penetration)."""
    return closest(robot, q, avoid)[0]


def closest(robot, q, avoid=(), scratch=None) -> tuple:
    """(distance [m], the robot's body, the obstacle's geom name) of the closest pair between the
    arm's and gripper's collision geoms and the table and ``avoid`` at arm joints ``q`` [rad]
    (inf, "", "" when there are no obstacles; a distance beyond 0.1 m reads 0.1 m). ``scratch``:
    an ``MjData`` of the robot's model to compute in (making a new one is most of a call's cost)."""
    mujoco = need("mujoco", "robot")
    obstacles = obstacle_geoms(robot, avoid)
    if not obstacles:
        return float("inf"), "", ""
    m = robot.model
    d = mujoco.MjData(m) if scratch is None else scratch
    d.qpos[:] = robot.data.qpos
    d.qpos[robot.arm_qpos] = q
    mujoco.mj_kinematics(m, d)
    gap, g, o = min((mujoco.mj_geomDistance(m, d, g, o, 0.1, None), g, o) for g in robot.clearance_geoms
                    for o in obstacles)
    return float(gap), m.body(m.geom_bodyid[g]).name, m.geom(o).name or f"geom {o}"


class IKSolver:
    """Differential IK (mink) of ``robot``'s arm, set up once and reused for many poses: one
    mink ``Configuration`` with a frame task on the TCP, the joint limits, a joint speed limit
    (``MAX_SPEED``) and a collision limit (``LIMIT_DISTANCE``) between the arm's and gripper's
    collision geoms and the table and the geoms ``avoid`` (ids or names); every other degree
    of freedom (the fingers, a held object) frozen at the robot's state when it is made;
    ``min_distance`` [m]: the clearance to keep (default ``MIN_DISTANCE``; less near a feature
    the gripper pushes against)."""

    def __init__(self, robot, avoid=(), min_distance: float = MIN_DISTANCE):
        mink = need("mink", "robot")
        mujoco = need("mujoco", "robot")
        from .model import ARM_PREFIX

        self.robot, self.mink = robot, mink
        m = robot.model
        full = robot.data.qpos.copy()
        # the frozen joints inside their ranges (a closed finger linkage may sit a hair outside,
        # which would make the joint-limit constraint infeasible); they do not move the TCP
        for j in range(m.njnt):
            bounded = (int(mujoco.mjtJoint.mjJNT_HINGE), int(mujoco.mjtJoint.mjJNT_SLIDE))
            if m.jnt_limited[j] and int(m.jnt_type[j]) in bounded:
                a = m.jnt_qposadr[j]
                full[a] = np.clip(full[a], m.jnt_range[j, 0] + 1e-6, m.jnt_range[j, 1] - 1e-6)
        self.full = full
        self.config = mink.Configuration(m, full)
        self.site = m.site(robot.tcp).name
        self.task = mink.FrameTask(frame_name=self.site, frame_type="site", position_cost=1.0,
                                   orientation_cost=1.0, lm_damping=1e-3)
        others = [i for i in range(m.nv) if i not in set(robot.arm_dof.tolist())]
        self.constraints = [mink.DofFreezingTask(m, dof_indices=others)] if others else None
        self.limits = [mink.ConfigurationLimit(m),
                       mink.VelocityLimit(m, {ARM_PREFIX + j: MAX_SPEED for j in robot.arm_joints})]
        self.free_limits = list(self.limits)  # without the collision limit (the polish)
        self.avoid, self.min_distance = tuple(avoid), float(min_distance)
        self.scratch = mujoco.MjData(m)  # the exact clearance check's
        self.obstacles = obstacle_geoms(robot, avoid)
        if self.obstacles:
            self.limits.append(mink.CollisionAvoidanceLimit(m, [(list(robot.clearance_geoms), self.obstacles)],
                                                            minimum_distance_from_collisions=self.min_distance + LIMIT_MARGIN_DISTANCE,
                                                            collision_detection_distance=0.05))

    def tcp_pose(self) -> np.ndarray:
        """The TCP's world pose ``[x, y, z, qw, qx, qy, qz]`` (m) at the configuration now."""
        T = self.config.get_transform_frame_to_world(self.site, "site").wxyz_xyz
        return np.concatenate([T[4:], T[:4]])

    def _iterate(self, target, limits, iterations: int) -> None:
        """Differential IK steps towards ``target`` under ``limits`` until converged
        (``CONVERGED_POSITION``/``CONVERGED_ANGLE``), stalled (no feasible step, or
        ``STALL_ITERATIONS`` steps in a row that turn no joint more than ``STALL_STEP``: the limits
        hold the arm where it is, and the same state gives the same step) or ``iterations``."""
        mink = self.mink
        still = 0
        for _ in range(iterations):
            reached = pose_error(self.tcp_pose(), target)
            if reached[0] <= CONVERGED_POSITION and reached[1] <= CONVERGED_ANGLE:
                return
            try:
                v = mink.solve_ik(self.config, [self.task], IK_DT, "daqp", damping=1e-3, limits=limits,
                                  constraints=self.constraints)
            except mink.NoSolutionFound:  # the limits admit no step from here: classified by solve
                return
            still = still + 1 if np.abs(v).max() * IK_DT <= STALL_STEP else 0
            if still >= STALL_ITERATIONS:
                return
            self.config.integrate_inplace(v, IK_DT)

    def solve(self, target_pose, q_init, field: str = "pose") -> np.ndarray:
        """Arm joint positions [rad] putting the TCP at world ``target_pose``
        ``[x, y, z, qw, qx, qy, qz]`` (m), from ``q_init`` [rad]: iterates to ``CONVERGED_POSITION``
        / ``CONVERGED_ANGLE``, accepts within ``POSITION_TOLERANCE`` / ``ANGLE_TOLERANCE`` when the
        solution is within the joint limits and ``MIN_DISTANCE`` off the obstacles
        (:func:`table_distance`, checked exactly); else raises :class:`IKError` naming ``field``."""
        mink, robot = self.mink, self.robot
        target = check_pose(target_pose, field)
        q0 = np.asarray(q_init, float)
        if q0.shape != robot.arm_qpos.shape:
            raise ArgumentError(f"invalid `q_init`: {len(robot.arm_qpos)} joint positions [rad] (got shape {q0.shape})",
                                "q_init")
        full = self.full.copy()
        full[robot.arm_qpos] = q0
        self.config.update(full)
        self.task.set_target(mink.SE3(np.concatenate([target[3:], target[:3]])))
        self._iterate(target, self.limits, MAX_ITERATIONS)
        if self.obstacles and POSITION_TOLERANCE < pose_error(self.tcp_pose(), target)[0] <= POLISH_REACH:
            # held back by the collision limit's margin (LIMIT_MARGIN_DISTANCE) within a few mm of the
            # target: the last steps without it; the exact clearance check below still decides
            self._iterate(target, self.free_limits, POLISH_ITERATIONS)
        q = self.config.q[robot.arm_qpos].copy()
        reached = pose_error(self.tcp_pose(), target)
        rng = robot.joint_limits()
        free = ~(rng[:, 1] > rng[:, 0])  # a joint without limits (MuJoCo's range [0, 0])
        inside = np.all(free | ((q >= rng[:, 0] - 1e-9) & (q <= rng[:, 1] + 1e-9)))
        gap, part, obstacle = closest(robot, q, self.avoid, self.scratch)
        if reached[0] <= POSITION_TOLERANCE and reached[1] <= ANGLE_TOLERANCE and inside and gap >= self.min_distance:
            return q
        limited = [i for i in range(len(q)) if not free[i] and min(q[i] - rng[i, 0], rng[i, 1] - q[i]) < LIMIT_MARGIN]
        at_limit = [robot.arm_joints[i] for i in limited]
        beyond = robot.reach(target)
        if beyond > 0:
            reason, why = "unreachable", f"{beyond * 1e3:.0f} mm beyond the arm's reach"
        elif gap < self.min_distance + LIMIT_MARGIN_DISTANCE + 1e-3:  # the collision limit held it back
            reason, why = "collision", (f"the arm or gripper {gap * 1e3:.1f} mm from the table or an obstacle "
                                        f"({part} and {obstacle}; it keeps {self.min_distance * 1e3:.0f} mm)")
        elif at_limit:
            reason, why = "joint limit", f"joint {', '.join(at_limit)} at its limit"
        else:
            reason, why = "unreachable", "no arm configuration found"
        raise IKError(f"invalid `{field}`: the TCP cannot reach {np.round(target, 4).tolist()} ({reason}: {why}; "
                      f"closest {reached[0] * 1e3:.1f} mm, {reached[1]:.3f} rad away)", field, reason,
                      part if reason == "collision" else "", limited if reason == "joint limit" else ())


def solve_ik(robot, target_pose, q_init=None, field: str = "pose", avoid=()) -> np.ndarray:
    """Arm joint positions [rad] that put the TCP at world ``target_pose``
    ``[x, y, z, qw, qx, qy, qz]`` (m) (converged to ``CONVERGED_POSITION`` / ``CONVERGED_ANGLE``,
    accepted within ``POSITION_TOLERANCE`` and ``ANGLE_TOLERANCE``), starting from ``q_init``
    [rad] (the arm's joint positions now by default), within the joint limits and
    ``MIN_DISTANCE`` off the table and the geoms ``avoid`` (ids or names). Raises
    :class:`IKError` (its ``field`` is ``field``) saying why when none is found."""
    return IKSolver(robot, avoid).solve(target_pose, robot.q if q_init is None else q_init, field)


def branch_distance(a, b) -> float:
    """The largest turn [rad] of one joint between configurations ``a`` and ``b``, each joint's
    difference wrapped to [−π, π] (a revolute joint 2π round is the same branch)."""
    d = np.asarray(a, float) - np.asarray(b, float)
    return float(np.abs((d + np.pi) % (2 * np.pi) - np.pi).max())


def ik_solutions(robot, target_pose, avoid=(), seeds=(), tries: int = BRANCH_SEEDS, min_distance=MIN_DISTANCE):
    """Distinct arm configurations [rad] (each more than ``MAX_JUMP`` in some joint from those
    before, :func:`branch_distance`: other branches of the arm — elbow, wrist, base turned) putting the TCP at
    ``target_pose``, clear of the table and ``avoid``, yielded lazily: from each of ``seeds``
    first, then from ``tries`` random starts (uniform within the joint limits, at most ±π; a fixed
    random stream, so the same arm and target give the same answers)."""
    solver = IKSolver(robot, avoid, min_distance)
    lo, hi = robot.joint_limits().T
    unlimited = ~(hi > lo)  # MuJoCo's range of a joint without limits is [0, 0]
    lo, hi = np.where(unlimited, -np.pi, lo), np.where(unlimited, np.pi, hi)
    a, b = np.maximum(lo, -np.pi), np.minimum(hi, np.pi)
    a, b = np.where(a < b, a, lo), np.where(a < b, b, hi)  # a range beyond ±π: all of it
    rng = np.random.default_rng(0)
    starts = [np.asarray(q, float) for q in seeds]
    starts += [rng.uniform(a, b) for _ in range(tries)]
    found: list = []
    for q0 in starts:
        try:
            q = solver.solve(target_pose, q0)
        except IKError:
            continue
        if all(branch_distance(q, f) > MAX_JUMP for f in found):
            found.append(q)
            yield q


def ik_path(robot, poses, q_init=None, avoid=(), max_jump: float = MAX_JUMP, min_distance=MIN_DISTANCE) -> np.ndarray:
    """Arm joint positions [rad], shape (n, 6), reaching each of the TCP world ``poses`` (n, 7)
    ``[x, y, z, qw, qx, qy, qz]`` (m) in turn with one :class:`IKSolver`, each solution seeding
    the next, clear of the table and ``avoid``. Raises :class:`IKError` naming ``poses[i]`` at
    the first pose that cannot be reached (its ``reason`` as :func:`solve_ik`'s) or whose
    solution moves a joint more than ``max_jump`` [rad] from the previous one's (``q_init``'s
    for ``poses[0]``; reason ``"jump"``: a branch flip, or poses sampled too far apart).
    ``min_distance`` [m]: the clearance, one for every pose or one per pose (a solver each)."""
    P = np.asarray(poses, float)
    if P.ndim != 2 or P.shape[1] != 7 or len(P) == 0:
        raise ArgumentError(f"invalid `poses`: shape (n >= 1, 7) (got {P.shape})", "poses")
    gaps = np.broadcast_to(np.asarray(min_distance, float), (len(P),))
    solvers = {g: IKSolver(robot, avoid, g) for g in np.unique(gaps)}
    q = robot.q if q_init is None else np.asarray(q_init, float)
    out = []
    for i, p in enumerate(P):
        try:
            nxt = solvers[gaps[i]].solve(p, q, field=f"poses[{i}]")
            jump = np.abs(nxt - q)
            if jump.max() > max_jump:
                j = int(np.argmax(jump))
                raise IKError(f"invalid `poses[{i}]`: joint {robot.arm_joints[j]} jumps {jump[j]:.3f} rad from the "
                              f"previous pose's solution (more than {max_jump} rad: a branch flip, or poses too far "
                              f"apart)", f"poses[{i}]", "jump")
        except IKError as e:
            e.path = np.array(out).reshape(len(out), len(q))
            raise
        q = nxt
        out.append(q)
    return np.array(out)
