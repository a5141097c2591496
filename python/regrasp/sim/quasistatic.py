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
from ..scene.settings import quasistatic_defaults
from ..fields import check_count, check_flag, check_name, check_number, check_vector

#: The simulator's defaults, stated once in the Rust core (``quasistatic::Options``).
DEFAULTS = quasistatic_defaults()
SPEED = DEFAULTS["speed"]  # m/s, the thesis' pushing speed
#: time step of simulated pushes and plan replays [s] (``regrasp push --dt``, ``regrasp simulate --dt``)
DT = 0.05


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


def push_dt(duration: float, dt: float | None = None) -> float:
    """The time step [s] of a push of ``duration`` [s]: ``dt`` when given, else min(:data:`DT`,
    ``duration``) (a short push is one step)."""
    return min(DT, duration) if dt is None else dt


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

def body_twist(a, b) -> np.ndarray:
    """Constant body twist taking pose ``a`` to pose ``b`` in unit time (planar log map)."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    c, s = np.cos(a[2]), np.sin(a[2])
    d = np.array([c * (b[0] - a[0]) + s * (b[1] - a[1]), -s * (b[0] - a[0]) + c * (b[1] - a[1])])
    w = b[2] - a[2]
    if abs(w) < 1e-9:
        return np.array([d[0], d[1], w])
    # inverse of V(w) = [[sin w / w, −(1−cos w)/w], [(1−cos w)/w, sin w / w]]
    A, B = np.sin(w) / w, (1 - np.cos(w)) / w
    det = A * A + B * B
    lin = np.array([A * d[0] + B * d[1], -B * d[0] + A * d[1]]) / det
    return np.array([lin[0], lin[1], w])


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


def integrate_pose(q, u, t: float) -> np.ndarray:
    """Pose reached from ``q`` after moving for ``t`` s with constant body twist ``u``."""
    q, u = np.asarray(q, float), np.asarray(u, float)
    w = u[2] * t
    lin = u[:2] * t
    if abs(w) < 1e-9:
        a, b = 1 - w * w / 6, w / 2
    else:
        a, b = np.sin(w) / w, (1 - np.cos(w)) / w
    d = np.array([a * lin[0] - b * lin[1], b * lin[0] + a * lin[1]])
    c, s = np.cos(q[2]), np.sin(q[2])
    return np.array([q[0] + c * d[0] - s * d[1], q[1] + s * d[0] + c * d[1], q[2] + w])
