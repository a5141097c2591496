"""The experiment behind the README's dropped "pivot in a rotating inertial field": the grasp axis
vertical (the pads carry no weight in their plane), the hand translating on a horizontal circle of
radius R at the rate that makes its centripetal field a [m/s²] (Ω = √(a / R)); the grip firm
while the hand spins up (one radian of circle), lowered to N [N] per pad while the field sweeps
past the object by the sweep, firm again while it spins down. The slip model
(`regrasp.dexterity.slip`) predicts the outcome in 8 worlds (nominal, then pad friction and grip
drawn within ±20 %); printed: the settings that bring at least 4 of 8 to the grasp half a turn
away. Usage: python scripts/swirl-pivot-scan.py [OBJECT GRASP ...] (default: prism g2, box g0, box g6)."""

import itertools
import sys

import numpy as np

from regrasp.dexterity import actions as A
from regrasp.dexterity.graph import _object
from regrasp.dexterity.slip import Body, simulate
from regrasp.dexterity.trial import tolerance
from regrasp.dexterity.world import ramps

SPIN_UP = 1.0  # rad of circle while the hand spins up (and down)


def outcome(obj, tax, g, R: float, a: float, N: float, sweep: float, friction: float = 1.0, grip: float = 1.0):
    """(nearest grasp, its distance [m]) after the swirl in the slip model."""
    b = A.body(obj, g)
    b = Body(b.mass, b.inertia, b.com, b.k, b.mu * friction)
    omega = np.sqrt(a / R)
    start = np.arctan2(b.com[1], b.com[0])  # the field points along the centre of mass as the grip drops
    s, t_up, t_sweep = np.sign(sweep), 2 * SPIN_UP / omega, abs(sweep) / omega
    hold = 2 * A.RAMP + t_sweep

    def theta(t: float) -> float:
        if t < t_up:
            return start - s * SPIN_UP + s * 0.5 * omega / t_up * t * t
        if t < t_up + hold:
            return start + s * omega * (t - t_up)
        u = min(t - t_up - hold, t_up)
        return start + s * omega * hold + s * (omega * u - 0.5 * omega / t_up * u * u)

    force = ramps((0.0, obj.grip), (t_up, obj.grip), (t_up + A.RAMP, N * grip), (t_up + A.RAMP + t_sweep, N * grip),
                  (t_up + hold, obj.grip))
    slip = simulate(b, 2 * t_up + hold + 0.1, lambda t: (R * np.array([np.cos(theta(t)), np.sin(theta(t))]), 0.0),
                    force, (0.0, 0.0))
    return tax.nearest(A.moved(obj, g, slip))


def main() -> None:
    args = sys.argv[1:] or ["prism", "g2", "box", "g0", "box", "g6"]
    rng = np.random.default_rng(0)
    worlds = [(1.0, 1.0)] + [tuple(rng.uniform(0.8, 1.2, 2)) for _ in range(7)]
    for name, grasp in zip(args[::2], args[1::2]):
        _, tax, obj = _object(name)
        g = tax.grasp(grasp)
        want, tol = A.turn_target(obj, g)[1], tolerance(tax)
        found = []
        for R, a, N in itertools.product((0.05, 0.1), (2.0, 4.0, 8.0, 12.0), (1.2, 2.0, 3.0)):
            for sweep in np.radians(np.arange(120, 300, 20)):
                hits = sum(n == want and d <= tol for n, d in (outcome(obj, tax, g, R, a, N, sweep, f, k) for f, k in worlds))
                if hits >= 4:
                    found.append((hits, R, a, N, round(float(np.degrees(sweep)))))
        print(f"{name} {grasp} -> {want}: {sorted(found, reverse=True)[:5] or 'no setting reaches 4 of 8'}", flush=True)


if __name__ == "__main__":
    main()
