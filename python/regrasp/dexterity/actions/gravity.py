"""Regrasp actions with gravity (thesis §1.1.1, ``resource = "gravity"``): ``gravity-pivot``
(:class:`GravityPivot`: swing about the grasp axis with a lowered grip), ``gravity-slide``
(:class:`GravitySlide`: slide along the fingers with a lowered grip), ``grip-pivot``
(:class:`GripPivot`: pivot to a target angle by turning the hand with the grip set for a lag)
and ``drop-catch`` (:class:`DropCatch`: let go for a moment, fall one step and catch it)."""

from __future__ import annotations

import numpy as np

from ... import pose as P
from ..slip import simulate
from ..world import HandPath, hand_pose, ramps
from .base import DEFAULTS, RAMP, Action, Setup, _params
from .catch import _catch_applies, _released, release
from .geometry import (_angle, _intended, _offset_step, _step, _still, _turning, body, com_in_hand, moved,
                       turn_target)


class GravityPivot(Action):
    """The hand turns (grip firm) so that the centre of mass would hang under the grasp axis once
    the object has turned to the nearest other orientation of its faces (:func:`turn_target`),
    then lowers the grip until the gravity moment m g d sin φ at the start is ``overdrive``
    times the pads' torsion capacity (the limit surface: (m g / 2μN)² + (m g d sin φ / 2kμN)²
    = 1 at the capacity): the object swings about the grasp axis towards hanging; the grip comes
    back after ``pivot_time``."""

    def __init__(self):
        super().__init__("gravity-pivot", "gravity", "swing about the grasp axis under gravity with a lowered grip")

    def applies(self, obj, grasp):
        t = turn_target(obj, grasp)
        if t is None:
            return "no other orientation on these faces"
        d = float(np.hypot(*com_in_hand(obj, grasp)))
        moment = d * abs(np.sin(self._tilt(t[0], DEFAULTS)))
        return None if moment > 0.5 * grasp.torsion_k else \
            f"the gravity moment arm at the start is {moment * 1e3:.1f} mm (a pivot needs > k / 2 = " \
            f"{0.5e3 * grasp.torsion_k:.1f} mm)"

    @staticmethod
    def _tilt(turn: float, p: dict) -> float:
        """The centre of mass's angle from hanging at the start [rad] (signed as ``turn``)."""
        return float(np.sign(turn) * min(abs(turn), p["max_tilt"]))

    def grip(self, obj, grasp, tilt: float, overdrive: float) -> float:
        """The per-pad force [N] at which the start moment is ``overdrive`` times the torsion capacity."""
        d = float(np.hypot(*com_in_hand(obj, grasp)))
        ratio = np.sqrt(1.0 + (d * abs(np.sin(tilt)) / (overdrive * grasp.torsion_k)) ** 2)
        return obj.holding(float(ratio))

    def setup(self, obj, grasp, params=None):
        p = _params(params)
        turn = turn_target(obj, grasp)[0]
        tilt = self._tilt(turn, p)
        c = com_in_hand(obj, grasp)
        # the hand starts with the centre of mass `tilt` from hanging and, while the grip is low, turns
        # so that it hangs once the object has turned by `turn` (a turn beyond max_tilt: the hand adds the rest)
        end = float(np.angle(np.exp(1j * (-np.pi / 2 - _angle(c) - turn))))
        start_angle = end + (turn - tilt)
        low, T = self.grip(obj, grasp, tilt, p["overdrive"]), p["pivot_time"]
        grip = ramps((0.0, obj.grip), (RAMP, low), (RAMP + T, low), (2 * RAMP + T, obj.grip))

        def angle(t: float) -> float:
            s = min(max((t - RAMP) / (T / 2), 0.0), 1.0)
            return start_angle + (end - start_angle) * s * s * (3 - 2 * s)

        hand = _turning(obj, grasp, angle)
        slip = simulate(body(obj, grasp), 2 * RAMP + T, hand, grip, (0.0, -obj.g))
        pose = moved(obj, grasp, slip)
        times = np.linspace(0.0, 2 * RAMP + T, int(np.ceil((2 * RAMP + T) / 0.01)) + 1)
        poses = np.array([hand_pose(angle(t)) for t in times])
        return Setup(poses[0], HandPath(times, poses), grip, 0.3, pose, _intended(obj, pose),
                     {"alpha": start_angle, "tilt": tilt, "turn": slip.turn, "target_turn": turn, "grip": low})


class GravitySlide(Action):
    """Fingers down, the grip lowered until the pads carry ``slide_ratio`` of the weight: the
    object slides towards the fingertips at (1 − ratio) g for the time that makes it slide one
    offset step of the taxonomy (½ a t²), then the grip comes back."""

    def __init__(self):
        super().__init__("gravity-slide", "gravity", "slide along the fingers under gravity with a lowered grip")

    def applies(self, obj, grasp):
        return None if _offset_step(obj, grasp, -1) is not None else "no grasp further towards the fingertips"

    def setup(self, obj, grasp, params=None):
        p = _params(params)
        step = _step(obj, grasp, -1, self.name)
        a = (1 - min(p["slide_ratio"], 0.99)) * obj.g
        T = float(np.sqrt(2 * step / a))
        low = obj.holding(p["slide_ratio"])
        grip = ramps((0.0, obj.grip), (RAMP, low), (RAMP + T, low), (2 * RAMP + T, obj.grip))
        slip = simulate(body(obj, grasp), 2 * RAMP + T, _still(0.0), grip, (0.0, -obj.g))
        pose = moved(obj, grasp, slip)
        start = hand_pose(0.0)
        return Setup(start, HandPath(np.array([0.0, 2 * RAMP + T]), np.array([start, start])), grip, 0.3, pose,
                     _intended(obj, pose), {"slide_time": T, "grip": low, "slide": float(-slip.shift[1])})


class GripPivot(Action):
    """A controlled pivot to a target angle by grip modulation: the object hanging (centre of
    mass under the grasp axis), the grip is set so that the object lags the turning hand at
    ``lag`` from the vertical ((m g / 2μN)² + (m g d sin φ / 2kμN)² = 1, the limit surface), and
    the hand turns about the grasp axis by the target in-hand turn plus the lag over
    ``turn_time``; the grip comes back. The target: the turn to the nearest other orientation
    of the grasp's faces."""

    def __init__(self):
        super().__init__("grip-pivot", "gravity", "pivot to a target angle: turn the hand with the grip set for a lag")

    def applies(self, obj, grasp):
        if turn_target(obj, grasp) is None:
            return "no other orientation on these faces"
        d = float(np.hypot(*com_in_hand(obj, grasp)))
        return None if d * np.sin(DEFAULTS["lag"]) > 0.5 * grasp.torsion_k else \
            f"the centre of mass is {d * 1e3:.1f} mm from the grasp axis (a lag of {np.degrees(DEFAULTS['lag']):.0f}° " \
            f"needs > {0.5e3 * grasp.torsion_k / np.sin(DEFAULTS['lag']):.1f} mm)"

    def grip_for_lag(self, obj, grasp, lag: float) -> float:
        """The per-pad force [N] at which a hanging object stays at ``lag`` [rad] from the vertical."""
        d = float(np.hypot(*com_in_hand(obj, grasp)))
        cap = obj.weight * np.sqrt(1.0 + (d * np.sin(lag) / grasp.torsion_k) ** 2)
        return float(cap / (2 * obj.mu))

    def setup(self, obj, grasp, params=None):
        p = _params(params)
        c = com_in_hand(obj, grasp)
        alpha0 = float(np.angle(np.exp(1j * (-np.pi / 2 - _angle(c)))))  # hanging
        target = turn_target(obj, grasp)[0]
        # the object turns by −(hand turn − lag) relative to the hand (it lags): turn the hand the other way
        sweep = -np.sign(target) * (abs(target) + p["lag"])
        low, T = self.grip_for_lag(obj, grasp, p["lag"]), p["turn_time"]
        grip = ramps((0.0, obj.grip), (RAMP, low), (RAMP + T, low), (2 * RAMP + T, obj.grip))

        def angle(t: float) -> float:
            s = min(max((t - RAMP) / T, 0.0), 1.0)
            return alpha0 + sweep * s * s * (3 - 2 * s)

        slip = simulate(body(obj, grasp), 2 * RAMP + T, _turning(obj, grasp, angle), grip, (0.0, -obj.g))
        pose = moved(obj, grasp, slip)
        times = np.linspace(0.0, 2 * RAMP + T, int(np.ceil((2 * RAMP + T) / 0.01)) + 1)
        poses = np.array([hand_pose(angle(t)) for t in times])
        return Setup(poses[0], HandPath(times, poses), grip, 0.3, pose, _intended(obj, pose),
                     {"alpha": alpha0, "sweep": float(sweep), "grip": low, "turn": slip.turn, "target_turn": target})


class DropCatch(Action):
    """Fingers down, the fingers open for a moment and close again: the object falls freely
    while the pads are apart and is caught one offset step further towards the fingertips: the
    fall ½ g t² of the free time t = a δ + b, the opening δ from the gripper's measured release
    (:func:`release`; the closing pads' impact stops it)."""

    def __init__(self):
        super().__init__("drop-catch", "gravity", "let go for a moment: fall one step and catch it")

    def applies(self, obj, grasp):
        return _catch_applies(obj, grasp)

    def setup(self, obj, grasp, params=None):
        _params(params)
        step = _step(obj, grasp, -1, self.name)
        rel = release(obj, grasp)
        delta = rel.opening(float(np.sqrt(2 * step / obj.g)))
        t = rel.free(delta)
        fall = 0.5 * obj.g * t * t
        t0 = 0.1
        start = hand_pose(0.0)
        pose = P.compose(np.array([0.0, 0.0, -fall, 1.0, 0.0, 0.0, 0.0]), grasp.pose)
        return Setup(start, HandPath(np.array([0.0, t0 + 3 * delta + 0.1]), np.array([start, start])),
                     _released(obj.grip, t0, delta), 0.3, pose, _intended(obj, pose),
                     {"opening": delta, "free_time": t, "fall": fall})
