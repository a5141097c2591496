"""Time parametrisation of an arm's joint path within its joint velocity and acceleration
limits, never faster than the world motion planned it (TOPP-RA: Pham & Pham, "A New Approach to
Time-Optimal Path Parameterization based on Reachability Analysis", T-RO 2018; the ``toppra``
package).

The joint path (the IK's waypoints, one per world-motion sample) is cut where the arm must stop:
at a hold (the waypoint does not move while time goes on: a dwell, the fingers closing) and at a
sharp turn of the joint-space direction (:data:`CORNER`). Each piece is a cubic spline through its
waypoints over joint-space arc length ``s`` [rad], which a constant-speed stretch keeps straight;
TOPP-RA finds its fastest speed profile from rest to rest with

- ``|q_s ṡ| ≤ v_max`` and ``|q_ss ṡ² + q_s s̈| ≤ a_max`` per joint (the robot's limits), and
- ``ṡ ≤ Δs_i / Δt_i`` on waypoint interval ``i``: the world motion's own speed there (pushes
  are slow for the quasi-static mechanics and the grip's hold; retiming only slows them).

The constraints hold at the waypoints and at each interval's midpoint (TOPP-RA's grid); the
profile is then checked every :data:`CHECK_POINTS` per interval, and solved again with limits
scaled down until that check passes too. Holds keep their planned duration at rest.

With a ``hold`` test (the pads' share of friction the held object's load takes at each
waypoint over the share allowed, :mod:`.holding`), a piece whose load exceeds it is solved
again with its joint limits halved (:data:`HOLD_STEP`, at most :data:`MAX_HOLD_SOLVES` times):
slower, so the arm's accelerations load the grasp less; :class:`HoldError` names the waypoint
when even that does not hold."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ArgumentError, ExecutionError
from ..extras import need

#: Joint-space step [rad] at or below which a waypoint holds (no motion between two samples).
HOLD = 1e-9
#: Turn [rad] of the joint-space direction between two waypoint steps at which the arm stops.
CORNER = 0.35
#: Points per waypoint interval where the solved profile is checked against the limits.
CHECK_POINTS = 8
#: How far [−] over a limit the solved profile may be (the solver's own tolerance).
SLACK = 1e-6
#: Solves with scaled-down limits before giving up.
MAX_SOLVES = 6
#: The factor [−] a piece's joint limits are scaled by when the pads cannot hold its load, and
#: how many times at most.
HOLD_STEP = 0.5
MAX_HOLD_SOLVES = 10


class HoldError(ExecutionError):
    """The pads cannot hold the object's load at waypoint ``sample`` however slowly the piece is
    timed (within :data:`MAX_HOLD_SOLVES`): ``excess`` is its load over the allowed share."""

    def __init__(self, message: str, sample: int, excess: float):
        super().__init__(message, "robot")
        self.sample, self.excess = sample, excess


@dataclass(frozen=True)
class Retimed:
    """The timed joint trajectory through the waypoints: ``times`` (n,) [s] from 0, strictly
    increasing; ``q`` (n, dof) [rad] the waypoints themselves; ``qd`` (n, dof) [rad/s] and
    ``qdd`` (n, dof) [rad/s²] the joint velocities and accelerations there; ``stops``: the
    waypoint indices where the arm comes to rest (holds, sharp turns, the ends)."""

    times: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    stops: tuple


def retime(times, q, velocity_limit, acceleration_limit, hold=None) -> Retimed:
    """The :class:`Retimed` trajectory through waypoints ``q`` (n, dof) [rad], planned at
    ``times`` (n,) [s] (the speed cap), within ``velocity_limit`` (dof,) [rad/s] and
    ``acceleration_limit`` (dof,) [rad/s²] (see the module's doc); ``hold(idx, q, qd, qdd)``:
    the load over the allowed share at waypoints ``idx`` (NaN: not held; ``qdd`` (2, len(idx),
    dof): the accelerations after and before each waypoint, the larger load counts), slowing a
    piece until it is ≤ 1. ArgumentError naming the field for bad input; ExecutionError when TOPP-RA finds no
    profile; :class:`HoldError` when no timing holds."""
    t, q = np.asarray(times, float), np.asarray(q, float)
    if t.ndim != 1 or len(t) < 2 or not np.all(np.isfinite(t)) or np.any(np.diff(t) <= 0):
        raise ArgumentError("invalid `times`: at least 2 finite, strictly increasing times [s]", "times")
    if q.ndim != 2 or len(q) != len(t) or not np.all(np.isfinite(q)):
        raise ArgumentError(f"invalid `q`: finite joint positions, shape ({len(t)}, dof) [rad] (got {q.shape})", "q")
    vmax = _limit(velocity_limit, q.shape[1], "velocity_limit")
    amax = _limit(acceleration_limit, q.shape[1], "acceleration_limit")
    step = np.linalg.norm(np.diff(q, axis=0), axis=1)
    stops = _stops(q, step)
    out_t, qd, qdd = np.zeros(len(t)), np.zeros_like(q), np.zeros_like(q)
    clock = 0.0
    for a, b in zip(stops[:-1], stops[1:]):
        if step[a] <= HOLD:  # a hold: at rest for its planned time
            out_t[a + 1:b + 1] = clock + (t[a + 1:b + 1] - t[a])
        else:
            test = None if hold is None else \
                (lambda qd_, qdd_, a=a, b=b: hold(np.arange(a, b + 1), q[a:b + 1], qd_, qdd_))
            dt, qd[a:b + 1], qdd[a:b + 1] = _piece(t[a:b + 1], q[a:b + 1], vmax, amax, test, a)
            out_t[a + 1:b + 1] = clock + dt[1:]
        clock = out_t[b]
    return Retimed(out_t, q.copy(), qd, qdd, tuple(int(i) for i in stops))


def _limit(x, dof: int, name: str) -> np.ndarray:
    try:
        v = np.broadcast_to(np.asarray(x, float), (dof,)).copy()
    except (TypeError, ValueError):
        v = np.full(dof, np.nan)
    if not np.all(np.isfinite(v)) or np.any(v <= 0):
        raise ArgumentError(f"invalid `{name}`: {dof} positive finite limits (got {x!r:.80})", name)
    return v


def _stops(q: np.ndarray, step: np.ndarray) -> list:
    """Waypoint indices where a piece ends: the ends, both ends of every hold interval, sharp turns."""
    stops = {0, len(q) - 1}
    held = step <= HOLD
    for i in range(len(step)):
        if held[i] or (i and held[i - 1]):
            stops.add(i)
        if held[i]:
            stops.add(i + 1)
    d = np.diff(q, axis=0)
    for i in range(1, len(step)):
        if not held[i] and not held[i - 1]:
            c = float(d[i] @ d[i - 1]) / (step[i] * step[i - 1])
            if np.arccos(np.clip(c, -1.0, 1.0)) > CORNER:
                stops.add(i)
    return sorted(stops)


def _piece(t: np.ndarray, q: np.ndarray, vmax: np.ndarray, amax: np.ndarray, hold=None, first: int = 0):
    """One moving piece from rest to rest: (times from its start (m,), qd (m, dof), qdd (m, dof));
    ``hold(qd, qdd)``: the load over the allowed share at its waypoints (``first`` its first)."""
    need("toppra", "robot")
    from scipy.interpolate import CubicSpline

    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(q, axis=0), axis=1))])
    cap = np.diff(s) / np.diff(t)  # rad/s of arc length: the planned speed per interval
    spline = CubicSpline(s, q) if len(s) > 2 else CubicSpline(s, q, bc_type="natural")
    grid = np.sort(np.concatenate([s, 0.5 * (s[1:] + s[:-1])]))
    scale, solves, holds = 1.0, 0, 0
    while True:
        sd = _solve(spline, s, grid, cap, vmax * scale, amax * scale)
        times, ratio = _check(spline, grid, sd, vmax, amax)
        if ratio > 1.0 + SLACK:
            solves += 1
            if solves >= MAX_SOLVES:
                raise ExecutionError(f"the arm's trajectory exceeds its joint limits by {ratio - 1:.1%} after "
                                     f"{MAX_SOLVES} time parametrisations", "robot")
            scale *= 0.995 / ratio
            continue
        out, before = _at_waypoints(spline, s, grid, sd, times)
        # the hold at each waypoint with the acceleration of the half-interval after it and before it
        excess = None if hold is None else np.asarray(hold(out[1], np.stack([out[2], before])), float)
        if excess is None or not np.nanmax(excess, initial=0.0) > 1.0:
            return out
        holds, solves = holds + 1, 0
        if holds > MAX_HOLD_SOLVES:
            i = int(np.nanargmax(excess))
            raise HoldError(f"the pads cannot hold the object at waypoint {first + i} even with the arm's joint "
                            f"limits scaled by {scale:.2g}: its load is {excess[i]:.2f} of what they may take",
                            first + i, float(excess[i]))
        scale *= HOLD_STEP


def _at_waypoints(spline, s, grid, sd, times):
    """((times, qd, qdd) at the waypoints ``s`` among the grid points of a solved profile ``sd``,
    qdd with the half-interval before each instead of after): s̈ is constant per grid interval,
    so a waypoint's acceleration jumps there (TOPP-RA's switches)."""
    at = np.searchsorted(grid, s)
    u = np.diff(sd ** 2) / (2 * np.diff(grid))  # s̈ per grid interval (constant)
    u_at, u_before = np.append(u, u[-1])[at], np.insert(u, 0, u[0])[at]
    qs, qss = spline(s, 1), spline(s, 2)
    qd, base = qs * sd[at, None], qss * sd[at, None] ** 2
    return (times[at], qd, base + qs * u_at[:, None]), base + qs * u_before[:, None]


def _solve(spline, s, grid, cap, vmax, amax) -> np.ndarray:
    """TOPP-RA's ṡ at the grid points, from rest to rest."""
    from toppra import algorithm, constraint

    dof = spline.c.shape[-1]

    def vlim(x):  # joints at their limits; the arc length (the path's last coordinate) at the planned speed
        i = min(max(int(np.searchsorted(s, x, side="right")) - 1, 0), len(cap) - 1)
        c = cap[i] if x != s[i] or i == 0 else min(cap[i], cap[i - 1])
        return np.array([[-v, v] for v in vmax] + [[-c, c]])

    path = _Path(spline, s)
    big = np.array([[-a, a] for a in amax] + [[-1e9, 1e9]])
    inst = algorithm.TOPPRA([constraint.JointVelocityConstraintVarying(vlim), constraint.JointAccelerationConstraint(big)],
                            path, gridpoints=grid, parametrizer="ParametrizeConstAccel")
    inst.compute_parameterization(0.0, 0.0)
    data = inst.problem_data
    sd = data.sd_vec
    if data.return_code != algorithm.ParameterizationReturnCode.Ok or sd is None or not np.all(np.isfinite(sd)):
        raise ExecutionError(f"no time parametrisation within the arm's joint limits ({dof} joints)", "robot")
    return np.maximum(np.asarray(sd, float), 0.0)


def _check(spline, grid, sd, vmax, amax) -> tuple:
    """(times at the grid points [s], the largest |qd|/v_max or |qdd|/a_max between them)."""
    ds = np.diff(grid)
    dt = 2 * ds / (sd[1:] + sd[:-1])
    times = np.concatenate([[0.0], np.cumsum(dt)])
    u = np.diff(sd ** 2) / (2 * ds)
    tau = np.linspace(0.0, 1.0, CHECK_POINTS + 1)[None, :] * dt[:, None]  # time into each interval
    x = grid[:-1, None] + sd[:-1, None] * tau + 0.5 * u[:, None] * tau ** 2
    v = sd[:-1, None] + u[:, None] * tau
    x, v, uu = x.ravel(), v.ravel(), np.repeat(u, CHECK_POINTS + 1)
    qs, qss = spline(x, 1), spline(x, 2)
    ratio = max(float(np.max(np.abs(qs * v[:, None]) / vmax)),
                float(np.max(np.abs(qss * v[:, None] ** 2 + qs * uu[:, None]) / amax)))
    return times, ratio


class _Path:
    """The spline through the waypoints with the arc length appended: TOPP-RA's geometric path."""

    def __init__(self, spline, s):
        self.spline, self.s = spline, s
        self.d = [spline, spline.derivative(1), spline.derivative(2)]

    def __call__(self, x, order=0):
        x = np.atleast_1d(np.asarray(x, float))
        last = x if order == 0 else np.full_like(x, 1.0 if order == 1 else 0.0)
        return np.column_stack([self.d[order](x), last])

    @property
    def dof(self) -> int:
        return self.spline.c.shape[-1] + 1

    @property
    def path_interval(self) -> np.ndarray:
        return np.array([self.s[0], self.s[-1]])
