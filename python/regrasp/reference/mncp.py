"""Reference solver of the quasi-static complementarity problem, faithful to the thesis (§3.2.2):
the mixed NCP written as a nonlinear program and solved with an interior-point method (IPOPT,
through casadi). The objective is the sum of the complementarity products, which are all
non-negative at feasible points, so a solution has objective ≈ 0; the constraints are the
rest of §3.2:

* Newton–Euler (eq 3.13): Σ J_nᵀ f_n + J_tᵀ f_t + w_ext − (M/h) V = 0
* unilateral contact (eq 3.16): u_n ≥ 0, f_n ≥ 0, objective term f_n u_n
* Coulomb cone (eq 3.1, 3.2): (μ f_n)² − |f_t|² ≥ 0, objective term ((μ f_n)² − |f_t|²) s
* maximum dissipation (eq 3.3): μ f_n u_t + f_t s = 0 with s = |u_t| (s ≥ 0, s² = |u_t|²)
* limit-surface patches: 1 − fᵀAf ≥ 0, objective term (1 − fᵀAf) s, f s + A⁻¹u = 0 with
  s² = uᵀA⁻¹u.

The objective alone has local minima with positive products (IPOPT then stops at a point that
is not a solution); as is standard for such programs with complementarity constraints, each
product is also bounded by a relaxation ε (Scholtes) driven from 1 to 1e-10 (scaled units),
each solve warm-starting the next.

The problem data come from :meth:`regrasp._core.MncpProblem.data`; the solution is checked with
the same residuals as the fast solver (:meth:`MncpProblem.residuals`).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from ..errors import RegraspError


class ReferenceSolverError(RegraspError):
    """IPOPT did not find a solution that satisfies the constraints."""


@dataclass
class ReferenceSolution:
    twist: np.ndarray
    pusher_twist: np.ndarray
    normal_forces: np.ndarray
    friction_forces: list
    objective: float
    residuals: dict
    max_residual: float
    status: str
    iterations: int
    solve_time_s: float


def solve(problem, pusher_twist=None, twist=None, tol: float = 1e-10, accept: float = 1e-6,
          x0: dict | None = None, max_iter: int = 500) -> ReferenceSolution:
    """Forward problem (give ``pusher_twist``) or inverse problem (give ``twist``) with IPOPT.

    ``problem`` is a :class:`regrasp._core.MncpProblem`. Raises :class:`ReferenceSolverError`
    when IPOPT fails or the solution's largest scaled constraint residual exceeds ``accept``.
    """
    import casadi as ca

    if (pusher_twist is None) == (twist is None):
        raise ValueError("give exactly one of pusher_twist (forward) or twist (inverse)")
    d = problem.data()
    dim = d["dim"]
    fs, vs = d["force_scale"], d["velocity_scale"]
    M, w, h = np.asarray(d["mass"]), np.asarray(d["wrench"]), d["h"]
    contacts = d["contacts"]

    # unknowns, scaled: V/vs, U/vs, f/fs, s/vs
    V = ca.SX.sym("V", dim) if twist is None else ca.DM(np.asarray(twist) / vs)
    U = ca.SX.sym("U", dim) if pusher_twist is None else ca.DM(np.asarray(pusher_twist) / vs)
    xs, lbx, ubx, x_init = [], [], [], []

    def var(name, n, lb, ub, init):
        x = ca.SX.sym(name, n)
        xs.append(x)
        lbx.extend([lb] * n)
        ubx.extend([ub] * n)
        x_init.extend(list(np.broadcast_to(init, (n,))))
        return x

    if twist is None:
        xs.append(V)
        lbx.extend([-np.inf] * dim)
        ubx.extend([np.inf] * dim)
        x_init.extend(list(np.asarray(pusher_twist) / vs if x0 is None else np.asarray(x0["twist"]) / vs))
    if pusher_twist is None:
        xs.append(U)
        lbx.extend([-np.inf] * dim)
        ubx.extend([np.inf] * dim)
        x_init.extend(list(np.asarray(twist) / vs))

    g, lbg, ubg = [], [], []
    objective = 0
    eps = ca.SX.sym("eps")
    relaxed = []  # complementarity products, each ≤ eps
    ne = ca.DM(w / fs) - ca.mtimes(ca.DM(M * vs / fs), V)
    f_n_expr, f_t_expr, s_vars = [], [], []
    for i, c in enumerate(contacts):
        jn, jt = np.asarray(c["jn"]), np.asarray(c["jt"])
        jno, jto = np.asarray(c["jn_other"]), np.asarray(c["jt_other"])
        k = jt.shape[0]
        un = ca.mtimes(ca.DM(jn[None, :]), V) - ca.mtimes(ca.DM(jno[None, :]), U) + c["gap"] / h / vs
        ut = ca.mtimes(ca.DM(jt), V) - ca.mtimes(ca.DM(jto), U)
        if c["normal"] == "unilateral":
            fn = var(f"fn{i}", 1, 0.0, np.inf, 0.1)
            g.append(un)
            lbg.append(0.0)
            ubg.append(np.inf)
            objective += fn * un
            relaxed.append(fn * un)
        else:
            fn = ca.DM(c["normal_force"] / fs)
        ft = var(f"ft{i}", k, -np.inf, np.inf, 0.0)
        s = var(f"s{i}", 1, 0.0, np.inf, 1.0)
        ne += ca.DM(jn[:, None]) * fn + ca.mtimes(ca.DM(jt.T), ft)
        if c["friction"] == "coulomb":
            mu = c["mu"]
            cone = (mu * fn) ** 2 - ca.sumsqr(ft)
            g.append(cone)
            lbg.append(0.0)
            ubg.append(np.inf)
            # maximum dissipation: mu f_n u_t + f_t s = 0, s = |u_t|
            g.append(mu * fn * ut + ft * s)
            lbg.extend([0.0] * k)
            ubg.extend([0.0] * k)
            g.append(s**2 - ca.sumsqr(ut))
            lbg.append(0.0)
            ubg.append(0.0)
            objective += cone * s
            relaxed.append(cone * s)
        else:
            A = np.asarray(c["A"]) * fs**2
            Ainv = np.linalg.inv(A)
            cone = 1 - ca.mtimes([ft.T, ca.DM(A), ft])
            g.append(cone)
            lbg.append(0.0)
            ubg.append(np.inf)
            g.append(ft * s + ca.mtimes(ca.DM(Ainv), ut))
            lbg.extend([0.0] * k)
            ubg.extend([0.0] * k)
            g.append(s**2 - ca.mtimes([ut.T, ca.DM(Ainv), ut]))
            lbg.append(0.0)
            ubg.append(0.0)
            objective += cone * s
            relaxed.append(cone * s)
        f_n_expr.append(fn)
        f_t_expr.append(ft)
        s_vars.append(s)
    g.insert(0, ne)
    lbg = [0.0] * dim + lbg
    ubg = [0.0] * dim + ubg
    for r in relaxed:
        g.append(r - eps)
        lbg.append(-np.inf)
        ubg.append(0.0)

    x = ca.vertcat(*xs)
    nlp = {"x": x, "f": objective, "g": ca.vertcat(*g), "p": eps}
    opts = {"ipopt.print_level": 0, "print_time": 0, "ipopt.tol": tol, "ipopt.max_iter": max_iter,
            "ipopt.sb": "yes", "ipopt.mu_strategy": "adaptive"}
    solver = ca.nlpsol("mncp", "ipopt", nlp, opts)
    t0 = time.perf_counter()
    xv, iters = ca.DM(x_init), 0
    for e in (1.0, 1e-2, 1e-4, 1e-6, 1e-8, 1e-10):
        sol = solver(x0=xv, p=e, lbx=ca.DM(lbx), ubx=ca.DM(ubx), lbg=ca.DM(lbg), ubg=ca.DM(ubg))
        xv = sol["x"]
        iters += int(solver.stats()["iter_count"])
    elapsed = time.perf_counter() - t0
    stats = solver.stats()
    f = ca.Function("unpack", [x], [V, U, ca.vertcat(*[ca.DM(fn) if isinstance(fn, ca.DM) else fn for fn in f_n_expr]),
                                    ca.vertcat(*f_t_expr)])
    Vv, Uv, fnv, ftv = (np.asarray(a).ravel() for a in f(xv))
    Vv, Uv, fnv, ftv = Vv * vs, Uv * vs, fnv * fs, ftv * fs
    fts, k0 = [], 0
    for c in contacts:
        k = np.asarray(c["jt"]).shape[0]
        fts.append(ftv[k0:k0 + k])
        k0 += k
    res = problem.residuals(list(Vv), list(Uv), list(fnv), [list(a) for a in fts])
    out = ReferenceSolution(
        twist=Vv, pusher_twist=Uv, normal_forces=fnv, friction_forces=fts, objective=float(sol["f"]),
        residuals=res, max_residual=max(res.values()), status=stats["return_status"],
        iterations=iters, solve_time_s=elapsed,
    )
    if out.max_residual > accept:
        raise ReferenceSolverError(
            f"IPOPT ({out.status}, {out.iterations} iterations) did not meet the constraints: largest scaled "
            f"residual {out.max_residual:.2e} ({res})")
    return out
