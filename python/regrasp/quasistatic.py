"""The quasi-static complementarity simulator through Python: single pushes, long pushes, plan
replay, and the validation of motion cones against it (thesis §3.2–3.3, Table 3.2).

A *push* is the pusher's motion: a twist ``[vx, vz, omega]`` in the object frame (the pusher
frame coincides with the object frame when the push starts). A line pusher that sticks moves the
object with exactly that twist; a point pusher only imposes its contact point's velocity.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .errors import ArgumentError
from .scene import Scene, _vec

SPEED = 0.01  # m/s, the thesis' pushing speed


def support_kwargs(support: str = "points", rings: int = 3, points: int = 0, merge_fingers: bool = True) -> dict:
    if support not in ("points", "limit_surface"):
        raise ArgumentError(f"invalid `support`: must be 'points' or 'limit_surface', got {support!r}", "support")
    return dict(support=support, rings=rings, points=points, merge_fingers=merge_fingers)


def problem(scene: Scene, pose, pusher: str | None = None, h: float = 1.0, **support):
    """The instantaneous complementarity problem (``regrasp._core.MncpProblem``)."""
    kw = support_kwargs(**support)
    return scene._core.quasistatic_problem(list(_vec(pose, 3, "pose")), pusher, kw["support"], kw["rings"],
                                           kw["points"], kw["merge_fingers"], h, SPEED)


def simulate_push(scene: Scene, pose, pusher: str, twist, duration: float, dt: float = 0.05, **support) -> dict:
    """Explicit time stepping of one push: the pusher moves with constant body ``twist``."""
    kw = support_kwargs(**support)
    if not (duration > 0 and dt > 0 and np.isfinite(duration) and np.isfinite(dt)):
        raise ArgumentError("invalid `duration`/`dt`: must be positive and finite", "duration")
    return scene._core.simulate_push(list(_vec(pose, 3, "pose")), pusher, list(_vec(twist, 3, "twist")),
                                     float(duration), float(dt), kw["support"], kw["rings"], kw["points"],
                                     kw["merge_fingers"])


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


def load_plan(path) -> dict:
    p = Path(path)
    try:
        plan = json.loads(p.read_text())
    except (OSError, ValueError) as e:
        raise ArgumentError(f"invalid `plan`: cannot read {p}: {e}", "plan") from e
    path_ = plan.get("path")
    if not isinstance(path_, list) or len(path_) < 1:
        raise ArgumentError("invalid `plan`: it needs a non-empty `path`", "plan.path")
    for i, k in enumerate(path_):
        q = k.get("pose") if isinstance(k, dict) else None
        if not (isinstance(q, list) and len(q) == 3 and all(isinstance(x, (int, float)) and np.isfinite(x) for x in q)):
            raise ArgumentError(f"invalid `plan.path[{i}].pose`: expected 3 finite numbers", f"plan.path[{i}].pose")
        if i > 0 and not isinstance(k.get("pusher"), str):
            raise ArgumentError(f"invalid `plan.path[{i}].pusher`: expected a pusher name", f"plan.path[{i}].pusher")
    return plan


@dataclass
class Replay:
    """Result of replaying a plan in a simulator."""

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
        return {
            "engine": self.engine,
            "final_pose": self.final_pose.tolist(),
            "goal_error": self.goal_error.tolist(),
            "success": bool(self.success),
            "max_pusher_slip": float(self.max_pusher_slip),
        }


def replay_plan(scene: Scene, plan: dict, speed: float = SPEED, dt: float = 0.05, **support) -> Replay:
    """Replays a plan in the quasi-static simulator: for each step the pusher is put in contact
    with the object where it is now, then follows the planned object motion of that step (its
    body twist, at ``speed``)."""
    path = plan["path"]
    for i, k in enumerate(path[1:], 1):
        if k["pusher"] not in scene.pusher_names:
            raise ArgumentError(f"invalid `plan.path[{i}].pusher`: no pusher {k['pusher']!r} in the scene",
                                f"plan.path[{i}].pusher")
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
    task = scene.task
    goal = task.goal if task is not None else np.asarray(path[-1]["pose"], float)
    tol = task.tolerance if task is not None else np.array([1e-3, 1e-3, 0.0175])
    err = q - goal
    return Replay("quasistatic", q, err, bool(np.all(np.abs(err) <= tol)), max_slip, np.array(ts),
                  np.array(qs), np.array(planned), steps)


# --- validation of motion cones against the simulator ------------------------------------------

def _random_pose(scene: Scene, rng, theta=np.pi / 6):
    out = scene.outline
    lo, hi = out.min(axis=0), out.max(axis=0)
    for _ in range(1000):
        c = rng.uniform(lo, hi)
        th = rng.uniform(-theta, theta)
        # pad centre at object point c: t = -R c
        R = np.array([[np.cos(th), -np.sin(th)], [np.sin(th), np.cos(th)]])
        q = np.r_[-(R @ c), th]
        if scene.admissible(q) and (scene.kind != "grasp" or scene.hold_ratio(q) < 0.95):
            return q
    raise ArgumentError("invalid `scene`: no admissible pose found where the grasp holds the object", "scene")


def _rotate_metric(v: np.ndarray, angle: float, rng) -> np.ndarray:
    """``v`` (unit) turned by ``angle`` towards a random perpendicular direction."""
    p = rng.normal(size=3)
    p -= (p @ v) * v
    p /= np.linalg.norm(p)
    return np.cos(angle) * v + np.sin(angle) * p


def sample_push(scene: Scene, pose, pusher: str, kind: str, rng):
    """A pusher motion of the given kind ('inside', 'near', 'random') for the validation."""
    cone = scene.motion_cone(pose, pusher)
    E = cone._core.pusher_edges
    if cone.is_line_pusher:
        if kind == "inside":
            # uniform over the twist directions inside the exact cone (rejection from a cap
            # around it)
            from .report import _cap

            G = scene.metric_twist(cone.generators)
            axis = G.sum(axis=0)
            axis = axis / np.linalg.norm(axis)
            radius = min(np.pi, 1.2 * max(np.arccos(np.clip(G @ axis, -1, 1))))
            u = None
            for _ in range(50):
                cand = scene.metric_twist_inv(_cap(axis, radius, 64, rng))
                inside = np.asarray(cone.contains(cand))
                if inside.any():
                    u = cand[np.flatnonzero(inside)[0]]
                    break
            if u is None:
                u = cone.ray(rng.dirichlet(np.ones(len(E))) @ E)
        elif kind == "near":
            i, j = cone._core.boundary_segments[rng.integers(len(cone._core.boundary_segments))]
            t = rng.uniform()
            u = cone.ray((1 - t) * E[i] + t * E[j])
            m = scene.metric_twist(u)
            u = scene.metric_twist_inv(_rotate_metric(m / np.linalg.norm(m), np.radians(rng.uniform(0, 5)), rng))
        else:
            m = rng.normal(size=3)
            u = scene.metric_twist_inv(m / np.linalg.norm(m))
        u = u / np.linalg.norm(scene.metric_twist(u)) * SPEED
        return u, bool(cone.contains(u))
    # point pusher: its contact point's velocity
    r = scene.pusher(pusher).points[0]
    pv = lambda g: g[:2] + g[2] * np.array([-r[1], r[0]])  # noqa: E731
    a, b = pv(cone.generators[0]), pv(cone.generators[1])
    a, b = a / np.linalg.norm(a), b / np.linalg.norm(b)
    if kind == "inside":
        s = rng.uniform()
        v = (1 - s) * a + s * b
    elif kind == "near":
        base = a if rng.uniform() < 0.5 else b
        ang = np.radians(rng.uniform(-5, 5))
        v = np.array([[np.cos(ang), -np.sin(ang)], [np.sin(ang), np.cos(ang)]]) @ base
    else:
        ang = rng.uniform(0, 2 * np.pi)
        v = np.array([np.cos(ang), np.sin(ang)])
    v = v / np.linalg.norm(v) * SPEED
    t = cone.point_pusher_twist(v)
    stick = t is not None and bool(cone.contains(t))
    return np.array([v[0], v[1], 0.0]), stick


def validate(scene: Scene, pushes: int = 2000, seed: int = 0, support: str = "points", rings: int = 3,
             progress: bool = False) -> dict:
    """Random pushes (a third drawn uniformly among the twist directions inside the motion cone,
    a third within 5° of its boundary, a third in random directions) at random poses; the exact motion-cone prediction of stick or slip at
    the pusher against the quasi-static simulator's outcome."""
    if pushes < 1:
        raise ArgumentError(f"invalid `pushes`: must be at least 1 (got {pushes})", "pushes")
    rng = np.random.default_rng(seed)
    kinds = ["inside", "near", "random"]
    rows = []  # (pusher, kind, pose, twist, predicted)
    for k in range(pushes):
        pusher = scene.pusher_names[rng.integers(len(scene.pusher_names))]
        pose = _random_pose(scene, rng)
        kind = kinds[k % 3]
        u, pred = sample_push(scene, pose, pusher, kind, rng)
        rows.append((pusher, kind, pose, u, pred))
    sim = np.zeros(pushes, bool)
    ok = np.zeros(pushes, bool)
    by_pusher = {}
    for i, r in enumerate(rows):
        by_pusher.setdefault(r[0], []).append(i)
    for p, idx in by_pusher.items():
        poses = np.array([rows[i][2] for i in idx])
        tw = np.array([rows[i][3] for i in idx])
        sticks, _, _, errors = scene._core.push_outcomes(poses, p, tw, support, rings, 0, True)
        sim[idx] = sticks
        ok[idx] = [e is None for e in errors]
    pred = np.array([r[4] for r in rows])
    kind = np.array([r[1] for r in rows])
    n = int(ok.sum())

    def table(mask):
        m = mask & ok
        return {
            "predicted_stick_simulated_stick": int((pred & sim & m).sum()),
            "predicted_stick_simulated_slip": int((pred & ~sim & m).sum()),
            "predicted_slip_simulated_stick": int((~pred & sim & m).sum()),
            "predicted_slip_simulated_slip": int((~pred & ~sim & m).sum()),
        }

    agree = float(((pred == sim) & ok).sum() / max(n, 1))
    return {
        "scene": scene.name,
        "pushes": pushes,
        "solved": n,
        "support_model": support,
        "agreement_quasistatic": agree,
        "confusion_quasistatic": table(np.ones(pushes, bool)),
        "by_sample_kind": {k: {"pushes": int((kind == k).sum()),
                               "agreement": float(((pred == sim) & ok & (kind == k)).sum() / max(((kind == k) & ok).sum(), 1))}
                           for k in kinds},
        "seed": seed,
    }


def format_confusion(res: dict) -> str:
    c = res["confusion_quasistatic"]
    return "\n".join([
        f"{res['scene']}: {res['pushes']} pushes ({res['solved']} solved), support model '{res['support_model']}'",
        f"  agreement of the motion-cone prediction with the quasi-static simulator: {100 * res['agreement_quasistatic']:.1f}%",
        "                         simulated stick   simulated slip",
        f"  predicted stick        {c['predicted_stick_simulated_stick']:15d}   {c['predicted_stick_simulated_slip']:14d}",
        f"  predicted slip         {c['predicted_slip_simulated_stick']:15d}   {c['predicted_slip_simulated_slip']:14d}",
        "  by kind of push: " + ", ".join(f"{k} {100 * v['agreement']:.1f}% of {v['pushes']}"
                                         for k, v in res["by_sample_kind"].items()),
    ])


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
