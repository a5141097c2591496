"""Regrasp actions with contacts against the table (thesis §1.1.1, ``resource = "contact"``):
``push-down`` (:class:`PushDown`: press the object on the table to slide it deeper into the
hand), ``table-slide`` (:class:`TableSlide`: stand it on the table at a light grip and raise the
hand) and ``table-pivot`` (:class:`TablePivot`: pivot about an edge on the table by moving the
hand on an arc). The post push is in :mod:`.post`, placing and picking again in :mod:`.repick`."""

from __future__ import annotations

from typing import Optional

import numpy as np

from ... import pose as P
from ...errors import ArgumentError
from ..slip import Slip
from ..world import WORK_POINT, HandPath, hand_pose, ramps
from .base import DEFAULTS, RAMP, Action, Setup, _params
from .geometry import _fingers_clear, _intended, _offset_step, _step, contact_centre, lowest, moved, turn_target


class PushDown(Action):
    """Fingers down, the object below the fingertips: the hand descends at ``speed`` with the
    grip at ``press_hold`` times the holding force until the table has pushed the object one
    offset step deeper into the hand (the object sticks on the table, the pads slide: a
    prehensile push against the table), then the grip comes back and the hand lifts."""

    def __init__(self):
        super().__init__("push-down", "contact", "press the object on the table to slide it deeper into the hand")

    def applies(self, obj, grasp):
        if _offset_step(obj, grasp, +1) is None:
            return "no grasp further towards the palm"
        reach = -lowest(grasp, obj.taxonomy.vertices)[2]
        step = _offset_step(obj, grasp, +1)
        from ...robot.pads import LENGTH

        return None if reach - LENGTH / 2 > step + 0.005 else \
            f"the object reaches {(reach - LENGTH / 2) * 1e3:.1f} mm below the pads (a {step * 1e3:.1f} mm push needs more)"

    def setup(self, obj, grasp, params=None):
        p = _params(params)
        step = _step(obj, grasp, +1, self.name)
        reach = -lowest(grasp, obj.taxonomy.vertices)[2]
        top = reach + p["approach"]  # the TCP's height above the table at the start
        low = obj.holding(p["press_hold"])
        start = hand_pose(0.0, (WORK_POINT[0], WORK_POINT[1], top))
        bottom = hand_pose(0.0, (WORK_POINT[0], WORK_POINT[1], reach - step))
        down = HandPath.line(start, bottom, (p["approach"] + step) / p["speed"] * 1.5)
        up = HandPath.line(bottom, start, 1.0)
        t1 = down.times[-1]
        grip = ramps((0.0, obj.grip), (RAMP, low), (t1, low), (t1 + RAMP, obj.grip))
        pose = P.compose(np.array([0.0, 0.0, step, 1.0, 0.0, 0.0, 0.0]), grasp.pose)
        return Setup(start, down.then(up), grip, 0.3, pose,
                     _intended(obj, pose), {"push": step, "grip": low})


class TableSlide(Action):
    """Fingers down, the object standing on the table on a face below the fingertips: the grip
    lowered until the pads' friction 2 μ N carries ``rest_ratio`` (< 1) of the weight, the hand
    rises by one offset step at ``speed`` — the object, its weight more than the pads' friction,
    stays on the table while the pads slide up it (the object slides towards the fingertips by
    exactly the rise) — then the grip comes back and the hand lifts it. The mirror of
    ``push-down``; unlike ``gravity-slide``, the table, not a timed fall, sets the distance."""

    def __init__(self):
        super().__init__("table-slide", "contact", "stand the object on the table at a light grip and raise the hand: "
                                                   "the pads slide up it")

    @staticmethod
    def _support(obj, grasp) -> tuple:
        """(reach [m]: the object's lowest point below the TCP, the face it stands on: its x-range
        (2,) in the hand frame) — the hull's vertices within 0.1 mm of the lowest."""
        V = P.transform(grasp.pose, obj.taxonomy.vertices)
        low = V[V[:, 2] < V[:, 2].min() + 1e-4]
        return float(-V[:, 2].min()), np.array([low[:, 0].min(), low[:, 0].max()])

    @staticmethod
    def least_grip(obj, grasp) -> float:
        """The least per-pad force [N] the gripper presses the object with at ``grasp``'s width
        (:func:`~regrasp.robot.grip.least_force`, with the scene's pads)."""
        from ...execution.arm import grasp_of
        from ...robot.grip import least_force
        from ...robot.pads import Pads

        width, _ = grasp_of(obj.scene, grasp.pose)
        return least_force(width, "", Pads.of_scene(obj.scene), obj.mu)

    def applies(self, obj, grasp):
        return self._why_not(obj, grasp, DEFAULTS["rest_ratio"])

    def _why_not(self, obj, grasp, r: float) -> Optional[str]:
        """Why the slide cannot be done at the grip ``r`` (2 μ N / m g), or None."""
        from ...robot.ik import MIN_DISTANCE

        if _offset_step(obj, grasp, -1) is None:
            return "no grasp further towards the fingertips"
        reach, (x0, x1) = self._support(obj, grasp)
        if not _fingers_clear(obj, 0.0, reach, MIN_DISTANCE):
            return f"standing on the table, the pads come within the arm's {MIN_DISTANCE * 1e3:.0f} mm of it"
        least = self.least_grip(obj, grasp)
        if least > 0.8 * obj.holding(r):  # the gripper must come down to the grip, with room for the force loop
            return f"the gripper presses at least {least:.2f} N per pad at this width (the slide's grip, " \
                   f"{obj.holding(r):.2f} N, needs it below {0.8 * obj.holding(r):.2f} N)"
        # the weight less the pads' pull (at the contact centre) must press inside the face it stands on
        x = (P.transform(grasp.pose, obj.com)[0] - r * contact_centre(obj, grasp)[0]) / (1 - r)
        margin = 0.002  # m
        return None if x0 + margin <= x <= x1 - margin else \
            f"it would not stand on the table: the load lies {x * 1e3:.1f} mm across the fingers, its face spans " \
            f"{x0 * 1e3:.1f} to {x1 * 1e3:.1f} mm"

    def setup(self, obj, grasp, params=None):
        p = _params(params)
        if p["rest_ratio"] >= 1.0:
            raise ArgumentError(f"invalid `params.rest_ratio`: below 1 (the table must keep part of the weight; got "
                                f"{p['rest_ratio']!r})", "params.rest_ratio")
        why = self._why_not(obj, grasp, p["rest_ratio"])
        if why is not None:
            raise ArgumentError(f"invalid `grasp`: table-slide does not apply to {grasp.name}: {why}", "grasp")
        step = _offset_step(obj, grasp, -1)
        reach, _ = self._support(obj, grasp)
        press = 0.0005  # m, the object pressed this far into the table (soft contact) while it stands on it

        def at(height: float) -> np.ndarray:
            return hand_pose(0.0, (WORK_POINT[0], WORK_POINT[1], height))

        start, touch, top = at(reach + p["approach"]), at(reach - press), at(reach - press + step)
        down = HandPath.line(start, touch, 1.5 * p["approach"] / p["speed"])
        rest = HandPath.line(touch, touch, 2 * RAMP)
        rise = HandPath.line(touch, top, 1.5 * step / p["speed"])
        hold = HandPath.line(top, top, 2 * RAMP)
        lift = HandPath.line(top, at(reach + step + p["approach"]), 1.0)
        path = down.then(rest).then(rise).then(hold).then(lift)
        t0 = down.times[-1]
        t1 = t0 + rest.times[-1] + rise.times[-1]
        low = obj.holding(p["rest_ratio"])
        grip = ramps((0.0, obj.grip), (t0, obj.grip), (t0 + RAMP, low), (t1, low), (t1 + RAMP, obj.grip))
        pose = P.compose(np.array([0.0, 0.0, -step, 1.0, 0.0, 0.0, 0.0]), grasp.pose)
        stand = [float(t0), float(path.times[-1] - lift.times[-1])]  # s, from the touch to the lift
        return Setup(start, path, grip, 0.3, pose, _intended(obj, pose), {"slide": step, "grip": low, "stand": stand})


class TablePivot(Action):
    """Fingers down, the object's lowest vertex on the table: the hand moves on an arc about that
    vertex, keeping its orientation, so that the object (held on the table by friction) turns in
    the hand about the grasp axis by the turn to the nearest other orientation of its faces
    (a pivot on an edge against the table: Hou, Jia & Mason's pivot-on-support); the grip at
    ``press_hold`` times the holding force meanwhile."""

    def __init__(self):
        super().__init__("table-pivot", "contact", "pivot about an edge on the table by moving the hand on an arc")

    @staticmethod
    def _plan(obj, grasp):
        """(turn [rad], the pivot vertex (3,) and the contact centre (2,) in the hand frame), or
        why the pivot cannot be done: the pivot is the lowest vertex on the side the object turns
        away from (the rest of it rises), and along the arc neither the object goes into the table
        nor the pads come within the arm's clearance (the IK's ``MIN_DISTANCE``) of it."""
        from ...robot.ik import MIN_DISTANCE

        t = turn_target(obj, grasp)
        if t is None:
            return "no other orientation on these faces"
        target = t[0]
        V = P.transform(grasp.pose, obj.taxonomy.vertices)
        low = V[V[:, 2] < V[:, 2].min() + 1e-9]
        v = low[np.argmax(low[:, 0])] if target < 0 else low[np.argmin(low[:, 0])]
        c = contact_centre(obj, grasp)
        for a in np.linspace(0.0, target, 25):
            R = np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])
            q = (V[:, [0, 2]] - v[[0, 2]]) @ R.T
            if q[:, 1].min() < -1e-4:
                return f"turning {np.degrees(target):.0f}° about its lowest edge takes the object into the table"
            tcp = (R @ (c - v[[0, 2]]))[1] - c[1]  # the TCP's height above the table (the hand does not turn)
            if not _fingers_clear(obj, 0.0, float(tcp), MIN_DISTANCE):
                return f"the pads would come within the arm's {MIN_DISTANCE * 1e3:.0f} mm of the table along the arc"
        return target, v, c

    def applies(self, obj, grasp):
        plan = self._plan(obj, grasp)
        return plan if isinstance(plan, str) else None

    def setup(self, obj, grasp, params=None):
        p = _params(params)
        plan = self._plan(obj, grasp)
        if isinstance(plan, str):
            raise ArgumentError(f"invalid `grasp`: table-pivot does not apply to {grasp.name}: {plan}", "grasp")
        target, v, c = plan
        r0 = np.array([c[0] - v[0], c[1] - v[2]])  # the contact centre from the vertex, in the plane (x, z)
        pivot = np.array([WORK_POINT[0], 0.0])  # the vertex on the table (world x, z)
        T = p["turn_time"]
        low = obj.holding(p["press_hold"])
        # the object turns by `target` (x towards z) in the world about the vertex; the hand only translates
        press = 0.0005  # m, the vertex pressed this far into the table (soft contact)

        def tcp(t: float, above: float = 0.0) -> np.ndarray:
            s = min(max(t / T, 0.0), 1.0)
            a = target * s * s * (3 - 2 * s)
            ca, sa = np.cos(a), np.sin(a)
            centre = pivot + np.array([ca * r0[0] - sa * r0[1], sa * r0[0] + ca * r0[1]])
            return hand_pose(0.0, (centre[0] - c[0], WORK_POINT[1], centre[1] - c[1] - press + above))

        times = np.linspace(0.0, T, int(np.ceil(T / 0.01)) + 1)
        lift = HandPath.line(tcp(0.0, p["approach"]), tcp(0.0), 0.6)
        arc = HandPath(times, np.array([tcp(t) for t in times]))
        path = lift.then(arc).then(HandPath.line(tcp(T), tcp(T, p["approach"]), 0.6))
        t0, t1 = lift.times[-1], lift.times[-1] + T
        grip = ramps((0.0, obj.grip), (t0 - RAMP, obj.grip), (t0, low), (t1, low), (t1 + RAMP, obj.grip))
        pose = moved(obj, grasp, Slip(np.zeros(2), float(target), np.zeros(2)))
        return Setup(path.poses[0], path, grip, 0.3, pose, _intended(obj, pose), {"turn": float(target), "grip": low})
