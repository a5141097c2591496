"""Regrasp actions with the inertia of the arm's motion (thesis §1.1.1, ``resource =
"inertia"``): ``inertial-slide`` (:class:`InertialSlide`: slide deeper into the hand by a
downward jab of the arm) and ``toss-catch`` (:class:`TossCatch`: toss the object up along the
fingers and catch it one step out; :data:`ARM_LAG`)."""

from __future__ import annotations

import numpy as np

from ... import pose as P
from ...errors import ArgumentError
from ..slip import simulate
from ..world import WORK_POINT, HandPath, hand_pose, ramps
from .base import RAMP, Action, Setup, _params
from .catch import _catch_applies, _released, release
from .geometry import _intended, _offset_step, _step, body, moved


ARM_LAG = 0.005  # s, toss-catch: how far the arm's hand lags its commanded braking (the joint servo, robot.tracking; measured: the box's toss brakes 5–6 ms late)


class InertialSlide(Action):
    """Fingers down, the grip lowered to ``jab_hold`` times the holding force, the hand jabs
    downwards at ``acceleration`` (> g): in the hand the object feels m (a − g) towards the
    palm, more than the pads' 2 μ N, and slides deeper; the hand coasts while the grip comes
    back, then stops at ``braking``. The jab's length from the slip model, for one offset step."""

    def __init__(self):
        super().__init__("inertial-slide", "inertia", "slide deeper into the hand by a downward jab of the arm")

    def applies(self, obj, grasp):
        return None if _offset_step(obj, grasp, +1) is not None else "no grasp further towards the palm"

    @staticmethod
    def _run(obj, p, jab: float):
        """(duration [s], hand(t), grip(t)) of a jab of ``jab`` [s]: the grip lowered (RAMP), the
        jab, a coast at the jab's speed while the grip comes back (RAMP), the braking."""
        a, b = p["acceleration"], p["braking"]
        v = a * jab
        stop = v / b
        T = RAMP + jab + RAMP + stop
        top = np.array([WORK_POINT[0], WORK_POINT[2] + 0.05])

        def down(t: float) -> float:  # the hand's descent [m] at time t
            t = t - RAMP
            if t <= 0:
                return 0.0
            if t <= jab:
                return 0.5 * a * t * t
            coast = min(t - jab, RAMP)
            u = min(max(t - jab - RAMP, 0.0), stop)
            return 0.5 * a * jab * jab + v * (coast + u) - 0.5 * b * u * u

        low = obj.holding(p["jab_hold"])
        grip = ramps((0.0, obj.grip), (RAMP, low), (RAMP + jab, low), (2 * RAMP + jab, obj.grip))
        return T, (lambda t: (top - np.array([0.0, down(t)]), 0.0)), grip

    def setup(self, obj, grasp, params=None):
        p = _params(params)
        step = _step(obj, grasp, +1, self.name)
        jab, slip = 0.0, None
        for jab in np.linspace(0.005, 0.1, 39):  # the shortest jab that slides the object one step
            T, hand, grip = self._run(obj, p, float(jab))
            slip = simulate(body(obj, grasp), T + RAMP, hand, grip, (0.0, -obj.g))
            if slip.shift[1] >= step:
                break
        T, hand, grip = self._run(obj, p, float(jab))
        times = np.linspace(0.0, T, int(np.ceil(T / 0.005)) + 1)
        poses = np.array([hand_pose(0.0, (hand(t)[0][0], WORK_POINT[1], hand(t)[0][1])) for t in times])
        pose = moved(obj, grasp, slip)
        return Setup(poses[0], HandPath(times, poses), grip, 0.3, pose, _intended(obj, pose),
                     {"jab": float(jab), "grip": obj.holding(p["jab_hold"]), "slide": float(slip.shift[1])})


class TossCatch(Action):
    """Toss and re-catch: fingers up, the hand accelerates upwards at ``toss`` (the grip firm),
    then stops at ``toss_stop`` > g while the fingers open for a moment: the object flies on,
    free, decelerated by gravity only — (``toss_stop`` − g) relative to the hand — and is caught
    one offset step further towards the fingertips as the hand comes to rest: the flight
    ½ (``toss_stop`` − g) t² of the free time t = a δ + b (:func:`release`; the fingers commanded open so
    that the pads let go, ``delay`` after the command, as the arm begins to brake, ARM_LAG
    behind its own command)."""

    def __init__(self):
        super().__init__("toss-catch", "inertia", "toss it up along the fingers and catch it one step out")

    def applies(self, obj, grasp):
        return _catch_applies(obj, grasp)

    def setup(self, obj, grasp, params=None):
        p = _params(params)
        step = _step(obj, grasp, -1, self.name)
        rel = p["toss_stop"] - obj.g  # m/s², the object's deceleration relative to the hand while free
        if rel <= 0:
            raise ArgumentError(f"invalid `params.toss_stop`: more than g = {obj.g:.2f} m/s² (got {p['toss_stop']})",
                                "params.toss_stop")
        r = release(obj, grasp)
        delta = r.opening(float(np.sqrt(2 * step / rel)))
        t_free = r.free(delta)
        fly = 0.5 * rel * t_free ** 2
        stop = t_free  # s, the hand brakes while the object is free and is at rest as the pads catch it
        v = p["toss_stop"] * stop  # m/s, the speed at which the stop begins
        rise = v / p["toss"]  # s, the acceleration
        opening = rise + ARM_LAG - r.delay  # s, the pads let go as the arm (ARM_LAG behind its command) begins to brake
        T = rise + stop + 0.05
        base = np.asarray(WORK_POINT, float)  # the toss starts at the work point (the wrist, under the hand, clear of the table)

        def up(t: float) -> float:  # the hand's rise [m] at time t
            if t <= rise:
                return 0.5 * p["toss"] * t * t
            u = min(t - rise, stop)
            return 0.5 * v * rise + v * u - 0.5 * p["toss_stop"] * u * u

        times = np.linspace(0.0, T, int(np.ceil(T / 0.005)) + 1)
        poses = np.array([hand_pose(np.pi, base + np.array([0.0, 0.0, up(t)])) for t in times])
        pose = P.compose(np.array([0.0, 0.0, -fly, 1.0, 0.0, 0.0, 0.0]), grasp.pose)
        return Setup(poses[0], HandPath(times, poses), _released(obj.grip, opening, delta), 0.3, pose,
                     _intended(obj, pose), {"opening": delta, "free_time": t_free, "speed": v, "fly": fly})
