"""The solvers: the MNCP solver against IPOPT (one problem, and its scaling with support points) and one MPC step against the same QP in SciPy."""

from __future__ import annotations

import time

import numpy as np

from .. import examples as bundled
from ..extras import need
from ..scene.planar import Scene
from .timing import _median_time


def run_mncp(reps: int = 11, ref_reps: int = 3) -> dict:
    """One instantaneous quasi-static solve (two finger patches of 4 points, a line pusher):
    the Rust solver against the IPOPT reference on the same problem, for a push that sticks, one
    that slides and one that separates."""
    from ..reference import mncp as mncp_reference

    scene = Scene.load(bundled.path("block-low-friction"))
    p = scene.quasistatic_problem([0.0, 0.0, 0.0], "left", "points", 0, 4, False, None, None)
    out = {}
    for name, u in (("stick", [0.01, 0.0, 0.0]), ("slide", [0.002, 0.01, 0.0]), ("separate", [-0.01, 0.0, 0.2])):
        fast = p.solve_forward(u)
        ref = mncp_reference.solve(p, pusher_twist=u)
        m = 200
        t_fast = _median_time(lambda: [p.solve_forward(u) for _ in range(m)], reps) / m
        # IPOPT's own solve time (the casadi model is built outside it)
        t_ref = float(np.median([mncp_reference.solve(p, pusher_twist=u).solve_time_s for _ in range(ref_reps)]))
        out[f"mncp_forward_{name}"] = {
            "median_s": t_fast,
            "baseline_median_s": t_ref,
            "ratio": t_ref / t_fast,
            "baseline": "IPOPT solve (casadi), the thesis' NLP",
            "n": 1,
            "max_abs_twist_diff": float(np.abs(fast["twist"] - ref.twist).max()),
            "residual_fast": fast["max_residual"],
            "residual_reference": ref.max_residual,
        }
    return out


#: Finger contact points (both fingers together) of :func:`run_mncp_scaling`.
SCALING_POINTS = (8, 32, 128, 512, 1024)


#: The pusher twists of :func:`run_mncp_scaling` (the block's left line pusher): a push that
#: sticks, one that slides, one that separates.
SCALING_PUSHES = (("stick", [0.01, 0.0, 0.0]), ("slide", [0.002, 0.01, 0.0]), ("separate", [-0.01, 0.0, 0.2]))


def run_mncp_scaling(points=SCALING_POINTS, reps: int = 5) -> dict:
    """The forward complementarity solve as the finger pads get more contact points (the block of
    ``block-low-friction`` in two pads of ``points / 2`` points each, pushed by its left line
    pusher): the median time of a push that sticks, slides and separates, against IPOPT's own
    solve time (casadi's model build excluded) on the sliding one, in the same run; each row also
    gives the largest twist difference between the two. The entry's time is the sliding solve at
    512 points (or the largest size given)."""
    from ..reference import mncp as mncp_reference

    scene = Scene.load(bundled.path("block-low-friction"))
    rows = []
    for n in points:
        p = scene.quasistatic_problem([0.0, 0.0, 0.0], "left", "points", 0, max(1, n // 2), False, None, None)
        row = {"points": int(n)}
        for name, u in SCALING_PUSHES:
            m = max(1, 200 // n)
            row[f"{name}_s"] = _median_time(lambda: [p.solve_forward(u) for _ in range(m)], reps) / m
        u = dict(SCALING_PUSHES)["slide"]
        ref = mncp_reference.solve(p, pusher_twist=u)
        row["ipopt_s"] = float(ref.solve_time_s)
        row["ratio_ipopt"] = row["ipopt_s"] / row["slide_s"]
        row["max_abs_twist_diff"] = float(np.abs(p.solve_forward(u)["twist"] - ref.twist).max())
        rows.append(row)
    at = next((r for r in rows if r["points"] == 512), rows[-1])
    return {"mncp_scaling": {
        "median_s": at["slide_s"], "baseline_median_s": at["ipopt_s"], "ratio": at["ratio_ipopt"],
        "baseline": f"IPOPT (casadi) on the sliding push at {at['points']} finger points; rows: "
                    + ", ".join(f"{r['points']}: {r['slide_s'] * 1e3:.3g} ms vs {r['ipopt_s'] * 1e3:.3g} ms" for r in rows),
        "rows": rows,
    }}


def mpc_qp_condensed(scene: Scene, q, steps, targets, settings: dict):
    """The MPC's QP (crates/regrasp-core/src/control/step_qp.rs) in its condensed form, written
    independently with the poses eliminated: ``(P, c, speed_rows, offs, sizes)`` with the cost
    ``½αᵀPα + cᵀα`` over the weights α (units of v_max) and step i's speed bound
    ``‖α[offs[i]:offs[i] + sizes[i]] @ speed_rows[i]‖ ≤ 1`` (and ``α ≥ 0``, each step's weights summing to
    at most 10); ``settings`` the MPC's
    (``mpc_defaults()``), ``targets`` the reference knots."""
    speed, dt = settings["speed"], settings["dt"]
    stage, terminal, effort = settings["stage_weight"], settings["terminal_weight"], settings["effort_weight"]
    L = scene.length
    ds = speed * dt
    gens = [np.asarray(st["generators"]) for st in steps]
    sizes = [len(g) for g in gens]
    n = sum(sizes)
    offs = np.cumsum([0] + sizes[:-1])
    B = np.zeros((3, n))
    T = []
    for i, g in enumerate(gens):
        th = q[2] if i == 0 else targets[i - 1][2]
        c, s_ = np.cos(th), np.sin(th)
        for k, v in enumerate(g):
            B[:, offs[i] + k] = [c * v[0] - s_ * v[1], s_ * v[0] + c * v[1], L * v[2]]
        T.append(scene.metric_twist(g) if len(g) else np.zeros((0, 3)))
    q0 = np.array([q[0], q[1], L * q[2]]) / ds
    P = 2 * effort * np.eye(n)
    c = np.zeros(n)
    for i, t in enumerate(targets[:len(gens)]):
        w = terminal if i + 1 == len(gens) else stage
        up = offs[i] + sizes[i]
        M = np.zeros((3, n))
        M[:, :up] = B[:, :up]
        e0 = q0 - np.array([t[0], t[1], L * t[2]]) / ds
        P += 2 * w * M.T @ M
        c += 2 * w * M.T @ e0
    return P, c, T, offs, sizes


def _mpc_qp_scipy(scene: Scene, q, steps, targets, settings: dict):
    """The MPC's QP (:func:`mpc_qp_condensed`) solved by scipy's SLSQP: the baseline."""
    minimize = need("scipy.optimize", "reference").minimize
    P, c, T, offs, sizes = mpc_qp_condensed(scene, q, steps, targets, settings)
    n = len(c)
    cons = []
    for i in range(len(sizes)):
        if not sizes[i]:
            continue
        blk = slice(offs[i], offs[i] + sizes[i])

        def norm_jac(a, blk=blk, Ti=T[i]):  # d/da (1 - |a_i T_i|^2) = -2 T_i (a_i T_i)
            g = np.zeros(n)
            g[blk] = -2.0 * (Ti @ (a[blk] @ Ti))
            return g

        def sum_jac(a, blk=blk):
            g = np.zeros(n)
            g[blk] = -1.0
            return g

        cons.append({"type": "ineq", "fun": (lambda a, blk=blk, Ti=T[i]: 1.0 - np.sum((a[blk] @ Ti) ** 2)),
                     "jac": norm_jac})
        # the weights of a step sum to at most 10
        cons.append({"type": "ineq", "fun": (lambda a, blk=blk: 10.0 - np.sum(a[blk])), "jac": sum_jac})
    r = minimize(lambda a: 0.5 * a @ P @ a + c @ a, np.zeros(n), jac=lambda a: P @ a + c, bounds=[(0, 10)] * n,
                 constraints=cons, method="SLSQP", options={"ftol": 1e-10, "maxiter": 200})
    return r.x * settings["speed"]


def run_mpc(reps: int = 200) -> dict:
    """One MPC step called from Python (Rust: closest knot, cones of the horizon, the QP with
    clarabel, the exact check; wall time of the call) against the same QP solved by scipy's SLSQP (the QP alone, generators given)."""
    from ..planning.plan import plan
    from ..scene.settings import mpc_defaults

    out = {}
    for name in ("block-high-friction", "t-shape"):
        scene = Scene.load(bundled.path(name))
        p = plan(scene, seed=0)
        poses = p.poses.tolist()
        q = (np.asarray(poses[0]) + [0.0005, -0.0005, 0.01]).tolist()
        times = []
        for _ in range(reps):
            m = scene.mpc(poses, p.pushers)
            t0 = time.perf_counter()  # wall time of the call from Python (bindings included)
            m.step(q)
            times.append(time.perf_counter() - t0)
        m = scene.mpc(poses, p.pushers)
        steps, _ = m.solve_qp(q, 0)
        knots = np.asarray(m.knots)
        targets = [knots[min(1 + i, len(knots) - 1)] for i in range(len(steps))]
        t_base = _median_time(lambda: _mpc_qp_scipy(scene, q, steps, targets, mpc_defaults()), 5)
        t = float(np.median(times))
        out[f"mpc_step_{name}"] = {
            "median_s": t, "baseline_median_s": t_base, "ratio": t_base / t,
            "baseline": "the same QP alone (generators given) with scipy SLSQP",
        }
    return out


#: the horizons of :func:`run_mpc_horizons` and issue 45's targets: H = 20 within 1 ms, the
#: step's cost growing at most as H^1.3 from the shortest to the longest
MPC_HORIZONS, MPC_TARGETS = (5, 10, 20, 40, 80), (1e-3, 1.3)


def run_mpc_horizons(reps: int = 15, horizons=MPC_HORIZONS) -> dict:
    """The MPC tracking the T-shape's seed-0 plan at each horizon: one controller, ``reps`` steps
    from poses 0.5 mm and 10 mrad off successive knots (as in a control loop: each step's horizon
    shares all but one knot's cone with the last); the median CPU time of a step [s] and the
    growth exponent between the first and the last horizon. No baseline solver (the targets,
    :data:`MPC_TARGETS`)."""
    from ..planning.plan import plan

    scene = Scene.load(bundled.path("t-shape"))
    p = plan(scene, seed=0)
    poses = p.poses.tolist()
    out, times = {}, {}
    for h in horizons:
        m = scene.mpc(poses, p.pushers, horizon=h)
        knots = np.asarray(m.knots)
        runs = []
        for k in range(reps):
            q = (knots[min(k, len(knots) - 1)] + [0.0005, -0.0005, 0.01]).tolist()
            t0 = time.process_time()
            m.step(q)
            runs.append(time.process_time() - t0)
        times[h] = float(np.median(runs))
    growth = float(np.log(times[horizons[-1]] / times[horizons[0]]) / np.log(horizons[-1] / horizons[0]))
    for h in horizons:
        out[f"mpc_horizon_{h}"] = {"median_s": times[h], "baseline_median_s": None, "ratio": None,
                                 "baseline": f"none: CPU time; target H=20 <= {MPC_TARGETS[0] * 1e3:g} ms, growth "
                                             f"H^{growth:.2f} from H={horizons[0]} to {horizons[-1]} (target <= "
                                             f"H^{MPC_TARGETS[1]})", "growth": growth}
    return out
