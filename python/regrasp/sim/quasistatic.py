"""The quasi-static complementarity simulator through Python: single pushes, long pushes and
plan replay (thesis §3.2; the validation of motion cones against it is in ``validation``).

A *push* is the pusher's motion: a twist ``[vx, vz, omega]`` in the object frame (the pusher
frame coincides with the object frame when the push starts). A line pusher that sticks moves the
object with exactly that twist; a point pusher only imposes its contact point's velocity.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import ArgumentError
from ..planning.plan import as_plan
from ..scene.planar import Scene
from ..scene.settings import DT, push_dt, quasistatic_defaults  # noqa: F401 (DT: its home until 0.2)
from ..pose import body_twist, integrate_pose  # noqa: F401 (their home until 0.2)
from ..fields import check_count, check_flag, check_name, check_number, check_vector

#: The simulator's defaults, stated once in the Rust core (``quasistatic::Options``).
DEFAULTS = quasistatic_defaults()
SPEED = DEFAULTS["speed"]  # m/s, the thesis' pushing speed


def support_kwargs(support: str | None = None, rings: int | None = None, points: int | None = None,
                   merge_fingers: bool | None = None) -> dict:
    """The finger support model (defaults: the core's): ``support`` "points" (pads as rings of
    contact points) or "limit_surface" (each pad one patch on the ellipsoidal limit surface, eq 3.7); ``rings`` in [1, 64] and
    ``points`` in [0, 4096] (bounds against runaway model sizes)."""
    given = dict(support=support, rings=rings, points=points, merge_fingers=merge_fingers)
    kw = {k: DEFAULTS[k] if v is None else v for k, v in given.items()}
    if not isinstance(kw["support"], str) or kw["support"] not in ("points", "limit_surface"):
        raise ArgumentError(f"invalid `support`: must be 'points' or 'limit_surface', got {kw['support']!r:.60}", "support")
    kw["rings"] = check_count(kw["rings"], "rings", 1, 64)
    kw["points"] = check_count(kw["points"], "points", 0, 4096)
    kw["merge_fingers"] = check_flag(kw["merge_fingers"], "merge_fingers")
    return kw


def problem(scene: Scene, pose, pusher: str | None = None, h: float | None = None, **support):
    """The instantaneous complementarity problem (``regrasp._core.MncpProblem``); ``h`` the time
    step [s] (default: the core's)."""
    kw = support_kwargs(**support)
    h = None if h is None else check_number(h, "h")
    pusher = None if pusher is None else check_name(pusher, "pusher")
    return scene.quasistatic_problem(check_vector(pose, 3, "pose"), pusher, kw["support"], kw["rings"],
                                           kw["points"], kw["merge_fingers"], h, SPEED)


def simulate_push(scene: Scene, pose, pusher: str, twist, duration: float, dt: float | None = None, **support) -> dict:
    """Explicit time stepping of one push from ``pose`` (m, m, rad): the pusher moves with
    constant body ``twist`` (m/s, m/s, rad/s) for ``duration`` [s] in steps of ``dt`` [s]
    (dt: time step [s], default min(0.05, duration))."""
    kw = support_kwargs(**support)
    duration = check_number(duration, "duration")
    dt = check_number(push_dt(duration, dt), "dt")
    return scene.simulate_push(check_vector(pose, 3, "pose"), check_name(pusher, "pusher"), check_vector(twist, 3, "twist"),
                                     duration, dt, kw["support"], kw["rings"], kw["points"], kw["merge_fingers"])


# --- plans -------------------------------------------------------------------------------------

@dataclass
class Replay:
    """Result of replaying a plan in a simulator: the final pose and the poses along the way
    ``[x, z, theta]`` (m, m, rad)."""

    engine: str
    final_pose: np.ndarray
    goal_error: np.ndarray
    success: bool
    max_pusher_slip: float  # largest slip distance of the pusher over one step [m]
    t: np.ndarray = field(repr=False, default=None)
    poses: np.ndarray = field(repr=False, default=None)
    planned: np.ndarray = field(repr=False, default=None)
    steps: list = field(repr=False, default_factory=list)

    def to_json(self) -> dict:
        """The replay as a JSON-ready dict (lists, not arrays)."""
        return {
            "engine": self.engine,
            "final_pose": self.final_pose.tolist(),
            "goal_error": self.goal_error.tolist(),
            "success": bool(self.success),
            "max_pusher_slip": float(self.max_pusher_slip),
        }


def replay_plan(scene: Scene, plan, speed: float = SPEED, dt: float = DT, **support) -> Replay:
    """Replays a plan (a :class:`~regrasp.Plan` or a plan dict) in the quasi-static simulator:
    for each step the pusher is put in contact with the object where it is now, then follows the
    planned object motion of that step (its body twist, at ``speed`` [m/s]) in steps of ``dt`` [s]."""
    speed, dt = check_number(speed, "speed"), check_number(dt, "dt")
    path = as_plan(plan, scene).path
    q = np.asarray(path[0]["pose"], float)
    ts, qs, planned = [0.0], [q.copy()], [q.copy()]
    t_now, max_slip, steps = 0.0, 0.0, []
    for k0, k1 in zip(path[:-1], path[1:]):
        xi = body_twist(k0["pose"], k1["pose"])
        length = np.linalg.norm(scene.metric_twist(xi))
        if length == 0:
            continue
        T = length / speed
        n = max(1, int(np.ceil(T / dt)))
        tr = simulate_push(scene, q, k1["pusher"], xi / T, T, T / n, **support)
        slip = float(np.sum(tr["pusher_slip"][:-1]) * T / n)
        max_slip = max(max_slip, slip)
        steps.append({"pusher": k1["pusher"], "duration": T, "slip": slip,
                      "end_pose": tr["pose"][-1].tolist(), "planned_end": list(k1["pose"])})
        ts.extend((t_now + tr["t"][1:]).tolist())
        qs.extend(tr["pose"][1:])
        planned.extend([np.asarray(k0["pose"]) + (np.asarray(k1["pose"]) - np.asarray(k0["pose"])) * s
                        for s in tr["t"][1:] / T])
        t_now += T
        q = tr["pose"][-1]
    err, ok = scene.goal_error(q, None if scene.task is not None else path[-1]["pose"])
    return Replay("quasistatic", q, err, ok, max_slip, np.array(ts),
                  np.array(qs), np.array(planned), steps)
