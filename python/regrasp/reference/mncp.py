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
from ..extras import need


class ReferenceSolverError(RegraspError):
    """IPOPT did not find a solution that satisfies the constraints."""


@dataclass
class ReferenceSolution:
    """The IPOPT solution of a quasi-static problem: object and pusher twists (m/s, rad/s), normal
    and friction forces [N], the objective and the residuals."""
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


class _Program:
    """The nonlinear program as it is built: unknowns (scaled) with bounds and start values,
    constraints with bounds, the objective and the complementarity products each relaxed by ε."""

    def __init__(self):
        self.xs, self.lbx, self.ubx, self.x_init = [], [], [], []
        self.g, self.lbg, self.ubg = [], [], []
        self.objective = 0
        self.relaxed = []

    def unknown(self, x, n: int, lb: float, ub: float, init) -> object:
        self.xs.append(x)
        self.lbx.extend([lb] * n)
        self.ubx.extend([ub] * n)
        self.x_init.extend(list(np.broadcast_to(init, (n,))))
        return x

    def var(self, name: str, n: int, lb: float, ub: float, init):
        ca = need("casadi", "reference")

        return self.unknown(ca.SX.sym(name, n), n, lb, ub, init)

    def constrain(self, expr, lb: float, ub: float, n: int = 1) -> None:
        self.g.append(expr)
        self.lbg.extend([lb] * n)
        self.ubg.extend([ub] * n)

    def complementarity(self, a, b) -> None:
        """The product ``a b``, ≥ 0 at feasible points: minimized, and bounded by ε."""
        self.objective += a * b
        self.relaxed.append(a * b)


def _twists(prog: _Program, dim: int, vs: float, pusher_twist, twist, x0):
    """The object's twist V and the pusher's U (scaled): the given one a constant, the other an
    unknown started at the given one (or at ``x0["twist"]``)."""
    ca = need("casadi", "reference")

    if twist is None:
        init = np.asarray(pusher_twist) / vs if x0 is None else np.asarray(x0["twist"]) / vs
        V = prog.unknown(ca.SX.sym("V", dim), dim, -np.inf, np.inf, init)
    else:
        V = ca.DM(np.asarray(twist) / vs)
    if pusher_twist is None:
        U = prog.unknown(ca.SX.sym("U", dim), dim, -np.inf, np.inf, np.asarray(twist) / vs)
    else:
        U = ca.DM(np.asarray(pusher_twist) / vs)
    return V, U


def _friction(prog: _Program, c: dict, fn, ft, s, ut, k: int, fs: float) -> None:
    """The friction law of one contact: Coulomb's cone with maximum dissipation, or a
    limit-surface patch."""
    ca = need("casadi", "reference")

    if c["friction"] == "coulomb":
        mu = c["mu"]
        cone = (mu * fn) ** 2 - ca.sumsqr(ft)
        prog.constrain(cone, 0.0, np.inf)
        # maximum dissipation: mu f_n u_t + f_t s = 0, s = |u_t|
        prog.constrain(mu * fn * ut + ft * s, 0.0, 0.0, k)
        prog.constrain(s**2 - ca.sumsqr(ut), 0.0, 0.0)
    else:
        A = np.asarray(c["A"]) * fs**2
        Ainv = np.linalg.inv(A)
        cone = 1 - ca.mtimes([ft.T, ca.DM(A), ft])
        prog.constrain(cone, 0.0, np.inf)
        prog.constrain(ft * s + ca.mtimes(ca.DM(Ainv), ut), 0.0, 0.0, k)
        prog.constrain(s**2 - ca.mtimes([ut.T, ca.DM(Ainv), ut]), 0.0, 0.0)
    prog.complementarity(cone, s)


def _contact(prog: _Program, i: int, c: dict, V, U, h: float, vs: float, fs: float):
    """One contact's unknowns and constraints; returns its normal force, friction force and its
    term of the Newton–Euler equations."""
    ca = need("casadi", "reference")

    jn, jt = np.asarray(c["jn"]), np.asarray(c["jt"])
    jno, jto = np.asarray(c["jn_other"]), np.asarray(c["jt_other"])
    k = jt.shape[0]
    un = ca.mtimes(ca.DM(jn[None, :]), V) - ca.mtimes(ca.DM(jno[None, :]), U) + c["gap"] / h / vs
    ut = ca.mtimes(ca.DM(jt), V) - ca.mtimes(ca.DM(jto), U)
    if c["normal"] == "unilateral":
        fn = prog.var(f"fn{i}", 1, 0.0, np.inf, 0.1)
        prog.constrain(un, 0.0, np.inf)
        prog.complementarity(fn, un)
    else:
        fn = ca.DM(c["normal_force"] / fs)
    ft = prog.var(f"ft{i}", k, -np.inf, np.inf, 0.0)
    s = prog.var(f"s{i}", 1, 0.0, np.inf, 1.0)
    _friction(prog, c, fn, ft, s, ut, k, fs)
    return fn, ft, ca.DM(jn[:, None]) * fn + ca.mtimes(ca.DM(jt.T), ft)


def _solve_relaxed(prog: _Program, newton_euler, dim: int, tol: float, max_iter: int):
    """IPOPT on the program, the relaxation ε driven from 1 to 1e-10, each solve warm-starting
    the next. Returns (x, the last solution, solver stats, iterations, seconds)."""
    ca = need("casadi", "reference")

    eps = ca.SX.sym("eps")
    g = [newton_euler] + prog.g + [r - eps for r in prog.relaxed]
    lbg = [0.0] * dim + prog.lbg + [-np.inf] * len(prog.relaxed)
    ubg = [0.0] * dim + prog.ubg + [0.0] * len(prog.relaxed)
    x = ca.vertcat(*prog.xs)
    nlp = {"x": x, "f": prog.objective, "g": ca.vertcat(*g), "p": eps}
    opts = {"ipopt.print_level": 0, "print_time": 0, "ipopt.tol": tol, "ipopt.max_iter": max_iter,
            "ipopt.sb": "yes", "ipopt.mu_strategy": "adaptive"}
    solver = ca.nlpsol("mncp", "ipopt", nlp, opts)
    t0 = time.perf_counter()
    xv, iters, sol = ca.DM(prog.x_init), 0, None
    for e in (1.0, 1e-2, 1e-4, 1e-6, 1e-8, 1e-10):
        sol = solver(x0=xv, p=e, lbx=ca.DM(prog.lbx), ubx=ca.DM(prog.ubx), lbg=ca.DM(lbg), ubg=ca.DM(ubg))
        xv = sol["x"]
        iters += int(solver.stats()["iter_count"])
    return x, sol, solver.stats(), iters, time.perf_counter() - t0


def solve(problem, pusher_twist=None, twist=None, tol: float = 1e-10, accept: float = 1e-6,
          x0: dict | None = None, max_iter: int = 500) -> ReferenceSolution:
    """Forward problem (give ``pusher_twist``) or inverse problem (give ``twist``), twists in
    (m/s, rad/s), with IPOPT.

    ``problem`` is a :class:`regrasp._core.MncpProblem`. Raises :class:`ReferenceSolverError`
    when IPOPT fails or the solution's largest scaled constraint residual exceeds ``accept``.
    """
    ca = need("casadi", "reference")

    if (pusher_twist is None) == (twist is None):
        raise ValueError("give exactly one of pusher_twist (forward) or twist (inverse)")
    d = problem.data()
    dim = d["dim"]
    fs, vs = d["force_scale"], d["velocity_scale"]
    M, w, h = np.asarray(d["mass"]), np.asarray(d["wrench"]), d["h"]
    contacts = d["contacts"]

    # unknowns, scaled: V/vs, U/vs, f/fs, s/vs
    prog = _Program()
    V, U = _twists(prog, dim, vs, pusher_twist, twist, x0)
    ne = ca.DM(w / fs) - ca.mtimes(ca.DM(M * vs / fs), V)
    f_n_expr, f_t_expr = [], []
    for i, c in enumerate(contacts):
        fn, ft, term = _contact(prog, i, c, V, U, h, vs, fs)
        ne += term
        f_n_expr.append(fn)
        f_t_expr.append(ft)
    x, sol, stats, iters, elapsed = _solve_relaxed(prog, ne, dim, tol, max_iter)
    f = ca.Function("unpack", [x], [V, U, ca.vertcat(*f_n_expr), ca.vertcat(*f_t_expr)])
    Vv, Uv, fnv, ftv = (np.asarray(a).ravel() for a in f(sol["x"]))
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
