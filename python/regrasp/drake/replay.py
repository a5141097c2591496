"""A planar plan replayed open loop in Drake (``regrasp simulate --engine drake``), in the
planner's view (:mod:`.push`): the gripper fixed, each push's feature brought to where the plan
needs it — relative to the gripper, with the object where the plan says it is in the grasp —
:data:`GAP` away, closing the gap, then following the planned motion of the object in the grasp
(the steps' body twists at ``speed``), then backing off and parked (a switch-over). As the MuJoCo
replay (:func:`regrasp.mujoco.planar.execute_plan`), but in an engine that shares none of our
contact model."""

from __future__ import annotations

import numpy as np

from ..errors import ArgumentError
from ..fields import check_number
from ..pose import body_twist, integrate_pose, planar_compose, planar_inverse, planar_rotate
from ..scene.planar import Scene
from ..sim.quasistatic import Replay
from .push import MAX_DURATION, PARK, DrakeRig

#: The gap [m] between the object and a feature when it is brought, as MuJoCo's replay's.
GAP = 0.002


def _segments(path: list) -> list:
    """The pushes of a path: consecutive steps with one pusher, as their knots."""
    segs: list = []
    for a, b in zip(path[:-1], path[1:]):
        if not segs or segs[-1]["pusher"] != b["pusher"]:
            segs.append({"pusher": b["pusher"], "knots": [np.asarray(a["pose"], float)]})
        segs[-1]["knots"].append(np.asarray(b["pose"], float))
    return segs


def replay_plan(scene: Scene, plan, perturb=None, speed: float = 0.01, record_dt: float = 0.02,
                settle: float = 0.2) -> Replay:
    """Replays ``plan`` (a :class:`~regrasp.Plan` or its dict) open loop in Drake (see the
    module's doc) in a world perturbed by ``perturb`` (a :class:`~regrasp.Perturbation`; None:
    nominal); the object's pose in the grasp every ``record_dt`` [s], and per push the pusher's
    slip (the largest slide of its reference point along the contact on the object)."""
    from ..mujoco.model import plan_dict

    speed = check_number(speed, "speed", high=100.0)
    record_dt = check_number(record_dt, "record_dt", high=MAX_DURATION)
    settle = check_number(settle, "settle", 0.0, False, MAX_DURATION)
    path = plan_dict(plan)["path"]
    for i, k in enumerate(path[1:], 1):
        if k["pusher"] not in scene.pusher_names:
            raise ArgumentError(f"invalid `plan.path[{i}].pusher`: no pusher {k['pusher']!r} in the scene "
                                f"(its pushers: {', '.join(scene.pusher_names)})", f"plan.path[{i}].pusher")
    rig = DrakeRig(scene, sorted({k["pusher"] for k in path[1:]}), perturb)
    rig.reset(np.asarray(path[0]["pose"], float))
    rec = {"t": [], "q": [], "plan": []}
    planned = [np.asarray(path[0]["pose"], float)]
    last = [-np.inf]

    def record(now):
        if now - last[0] >= record_dt - 1e-9:
            last[0] = now
            rec["t"].append(now)
            rec["q"].append(rig.object_pose())
            rec["plan"].append(planned[0].copy())

    rig.idle(settle)
    steps, max_slip = [], 0.0
    for seg in _segments(path):
        slip = _segment(rig, scene, seg["pusher"], seg["knots"], speed, planned, record)
        steps.append({"pusher": seg["pusher"], "slip": slip, "end_pose": rig.object_pose().tolist(),
                      "planned_end": seg["knots"][-1].tolist()})
        max_slip = max(max_slip, slip)
    q = rig.object_pose()
    err, ok = scene.goal_error(q, None if scene.task is not None else path[-1]["pose"])
    return Replay("drake", q, err, ok, max_slip, np.array(rec["t"]), np.array(rec["q"]), np.array(rec["plan"]), steps)


def _segment(rig: DrakeRig, scene: Scene, pusher: str, knots: list, speed: float, planned: list, record) -> float:
    """One push (see the module's doc); returns the pusher's slip [m]."""
    n = np.asarray(scene.pusher(pusher).normal, float)
    n = n / np.linalg.norm(n)
    ref = np.r_[scene.pusher(pusher).points.mean(axis=0), 0.0]

    def contact_point() -> np.ndarray:  # the feature's reference point in the object's frame
        return planar_compose(planar_inverse(rig.object_pose()), planar_compose(rig._targets[pusher], ref))[:2]

    back = lambda P: P - np.r_[GAP * planar_rotate(P[2], n), 0.0]  # noqa: E731
    P = knots[0]
    rig.place(pusher, back(P))
    start = back(P)
    rig.move(pusher, lambda u: start + (P - start) * u, GAP / speed, record)
    along = np.array([-n[1], n[0]])
    r0, slip = contact_point(), 0.0
    for a, b in zip(knots[:-1], knots[1:]):
        xi = body_twist(a, b)
        length = float(np.linalg.norm(scene.metric_twist(xi)))
        if length == 0:
            continue

        def path(u, a=a, b=b, xi=xi):
            planned[0] = a + (b - a) * u
            return integrate_pose(P, xi, u)

        rig.move(pusher, path, length / speed, record)
        P = integrate_pose(P, xi, 1.0)
        slip = max(slip, abs(float(along @ (contact_point() - r0))))
    end = P.copy()
    rig.move(pusher, lambda u: end + (back(end) - end) * u, GAP / speed, record)
    rig.place(pusher, PARK)
    return slip
