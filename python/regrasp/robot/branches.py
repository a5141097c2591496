"""Another branch of the arm for a joint path that failed on the home's
(:func:`~regrasp.execution.arm.solve_arm`): the joint at its limit wound 2π the other way
(:func:`rewound`), else a path from up to :data:`MAX_BRANCHES` other IK solutions at the first
pose (:func:`other_branch`)."""

from __future__ import annotations

import numpy as np

#: How many other branches of the arm at the first pose :func:`other_branch` tries when the path
#: from the home's branch fails (each a whole :func:`~regrasp.robot.ik.ik_path`, ~2–6 s).
MAX_BRANCHES = 2


def other_branch(robot, targets, avoid, gaps, home_q, err):
    """The joint path [rad] through ``targets`` from another branch of the arm at the first pose
    (:data:`MAX_BRANCHES` at most), after the home branch's path (from ``home_q``; None: the home
    found none) failed with ``err``; None when none passes or ``err`` is not the branch's (the
    pose out of reach, the gripper's own body against an obstacle: its pose is the TCP's)."""
    from .ik import MAX_JUMP, IKError, branch_distance, ik_path, ik_solutions
    from .kinds import GRIPPER_PREFIX

    if err.reason not in ("collision", "joint limit", "jump") or err.part.startswith(GRIPPER_PREFIX):
        return None  # out of reach, or the gripper itself against an obstacle: the same on every branch
    if home_q is not None and err.reason == "joint limit":  # the same arm shape, a joint wound 2π the other way
        q = rewound(robot, targets, avoid, gaps, home_q, err)
        if q is not None:
            return q
    tried = 0
    for q0 in ik_solutions(robot, targets[0], avoid, min_distance=gaps[0]):
        if home_q is not None and branch_distance(q0, home_q) <= MAX_JUMP:
            continue
        try:
            return ik_path(robot, targets, q0, avoid=avoid, min_distance=gaps)
        except IKError:
            tried += 1
            if tried >= MAX_BRANCHES:
                return None
    return None


def rewound(robot, targets, avoid, gaps, home_q, err):
    """The home branch's path (from ``home_q``) that failed with ``err`` at a joint limit, with a
    joint at its limit (``err.joints``) wound 2π the other way: the same arm shape, so the
    solutions before the failing pose (``err.path``) shifted stay valid where they stay within the
    joint's range, and only the rest is solved again. None when no such joint's shifted path
    stays within its range or the rest fails too."""
    from .ik import IKError, ik_path

    lo, hi = robot.joint_limits().T
    i = int(err.field.split("[")[1].rstrip("]")) if "[" in (err.field or "") and err.path is not None else 0
    done = np.asarray(err.path, float)[:i] if i else np.empty((0, len(home_q)))
    for j in err.joints:
        before = done[-1] if len(done) else home_q
        shift = -2 * np.pi if hi[j] - before[j] < before[j] - lo[j] else 2 * np.pi  # away from the limit met
        wound = np.r_[done[:, j], before[j]] + shift
        if not hi[j] > lo[j] or np.any(wound < lo[j]) or np.any(wound > hi[j]):
            continue
        start = before.copy()
        start[j] += shift
        try:
            rest = ik_path(robot, targets[i:], start, avoid=avoid, min_distance=gaps[i:])
        except IKError:
            continue
        head = done.copy()
        head[:, j] += shift
        return np.vstack([head, rest])
    return None
