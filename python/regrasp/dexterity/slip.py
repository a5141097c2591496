"""The model that predicts a pinched object's slip in the plane of the pads (the hand frame's x-z
plane): a rigid body (mass m, moment of inertia I about the grasp axis through its centre of
mass) held by two pads whose friction is the ellipsoidal limit surface about the pads' contact
centre (force capacity 2 μ N, torsion capacity 2 k μ N; thesis §2.3, ICRA 2014 notes in
docs/dexterity.md), moved by the hand (its planar pose in time) under gravity. Sticking while
the wrench the pads must supply lies inside the limit surface; sliding otherwise, the friction
wrench opposing the slip twist along the limit surface's normal:
``F = −2μN (v, k²ω) / √(|v|² + k²ω²)`` (v the contact centre's slip velocity, ω the spin).
Integrated with semi-implicit Euler at :data:`DT`. Used to predict the outcome of the gravity
and inertial actions (:mod:`.actions`)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

DT = 2e-4  # s, the integration step
STICK = 1e-6  # m/s (and m·rad/s scaled by k): a relative twist below this may stick


@dataclass(frozen=True)
class Body:
    """The held object in the plane: ``mass`` [kg], ``inertia`` [kg·m²] about the grasp axis
    through its centre of mass, ``com`` (2,) [m] its centre of mass from the contact centre in
    the hand frame (x, z), ``k`` [m] the pads' torsion radius, ``mu`` the pads' friction."""

    mass: float
    inertia: float
    com: tuple
    k: float
    mu: float


@dataclass(frozen=True)
class Slip:
    """The relative motion at the end: ``shift`` (2,) [m] of the contact point fixed in the
    object (hand frame x, z), ``turn`` [rad] about the grasp axis (x towards z), and ``com``
    (2,) [m] where the centre of mass ended, in the hand frame from the contact centre."""

    shift: np.ndarray
    turn: float
    com: np.ndarray


def _rot(a: float) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s], [s, c]])


def _cross(a, b) -> float:
    return float(a[0] * b[1] - a[1] * b[0])


def _perp(w: float, r) -> np.ndarray:
    """ω × r in the plane."""
    return w * np.array([-r[1], r[0]])


def pad_wrench(body: Body, cap: float, slip, spin: float, need, need_tau: float) -> tuple:
    """The pads' (force (2,), couple) on the object [N, N·m] about the contact centre: the
    ``need``/``need_tau`` that brings it to the hand's motion within the step when that lies
    inside the limit surface of capacity ``cap`` = 2 μ N [N] (it sticks), else the friction
    opposing the relative ``slip`` velocity [m/s] and ``spin`` [rad/s] along the limit surface's
    normal (or the need scaled onto the surface while the relative twist is still zero)."""
    if cap <= 0:
        return np.zeros(2), 0.0
    k = body.k
    load = np.hypot(*need) ** 2 / cap ** 2 + (need_tau / (k * cap)) ** 2
    s = float(np.sqrt(slip @ slip + (k * spin) ** 2))
    if load <= 1.0:
        return need, need_tau
    if s >= STICK:
        return -cap * slip / s, -cap * k * k * spin / s
    n = np.sqrt(load)
    return need / n, need_tau / n


def simulate(body: Body, duration: float, hand: Callable[[float], tuple], grip: Callable[[float], float],
             gravity=(0.0, -9.81), observe: Callable[[float, np.ndarray], None] | None = None) -> Slip:
    """Integrates the slip for ``duration`` [s] from rest in the hand. ``hand(t)`` → (position
    (2,) [m] of the contact centre, angle [rad] of the hand's x axis) in a fixed vertical plane
    (its x, z; angles from x towards z), ``grip(t)`` → the per-pad normal force [N]; ``gravity``
    (2,) [m/s²] in that plane; ``observe(t, x)``: called every step with the time [s] and the
    centre of mass's position (2,) [m] in the plane. Returns the :class:`Slip` relative to the hand.
    The hand's motion should start smoothly: a jump in its speed asks the pads for an impulse."""
    m, I = body.mass, body.inertia
    g = np.asarray(gravity, float)
    p0, a0 = hand(0.0)
    c0 = np.asarray(body.com, float)
    x, th = np.asarray(p0, float) + _rot(a0) @ c0, float(a0)
    v, w = np.zeros(2), 0.0
    prev_p, prev_a = np.asarray(p0, float), float(a0)
    for i in range(int(np.ceil(duration / DT))):
        t = (i + 1) * DT
        ph, ah = hand(t)
        ph = np.asarray(ph, float)
        vh, wh = (ph - prev_p) / DT, (ah - prev_a) / DT
        prev_p, prev_a = ph, float(ah)
        rc = ph - x  # the contact centre from the centre of mass
        slip = v + _perp(w, rc) - vh
        need = m * (vh + _perp(wh, -rc) - v) / DT - m * g
        need_tau = I * (wh - w) / DT - _cross(rc, need)
        f, tau = pad_wrench(body, 2 * body.mu * grip(t), slip, w - wh, need, need_tau)
        v = v + DT * (g + f / m)
        w = w + DT * (tau + _cross(rc, f)) / I
        x, th = x + DT * v, th + DT * w
        if observe is not None:
            observe(t, x)
    ph, ah = hand(duration)
    com = _rot(-ah) @ (x - np.asarray(ph, float))
    turn = th - ah  # it started turned as the hand (th = a0)
    return Slip(com - _rot(turn) @ c0, float(turn), com)
