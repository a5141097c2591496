"""Regrasp actions that set the object down on the table and pick it again (thesis §1.1.1,
``resource = "contact"``): ``place-repick`` (:class:`PlaceRepick`: place it on a stable face and
pick it with another grasp) and ``topple-repick`` (:class:`ToppleRepick`: let it fall over from
an edge, then pick it again), with the quasi-static prediction of the fall (:func:`_topple`)."""

from __future__ import annotations

from typing import Optional

import numpy as np

from ... import pose as P
from ...errors import ArgumentError
from ..taxonomy import grasp_distance
from ..world import WORK_POINT, HandPath, hand_pose
from .base import Action, ObjectModel, Setup, _params
from .geometry import FINGER_ROOM, _corners, _fingers_clear


MAX_PLACE_TILT = np.radians(90.0) + 1e-9  # rad, place-repick: the hand placing at most this far from fingers-down (level)
MAX_PICK_TILT = np.radians(45.0)  # rad, place-repick: the hand picking at most this far from fingers-down
TARGETS = 4  # place-repick: at most this many new grasps per grasp (other faces first)


class PlaceRepick(Action):
    """Place the object on the table and pick it again with another grasp: the hand turns about
    the grasp axis (at most until its fingers are level) so that a face of the object's hull on
    which it rests stably (its centre of mass over the face) looks straight down, lowers it to
    ``drop`` above the table, opens, retreats ``clear`` along its fingers, comes down over the
    object at the new grasp's pose (the object where it was let go; the TCP corrected for where
    the linkage holds the pads at the new width) and closes on it for ``close_time``, then
    lifts. The new grasp (``params["target"]``): one of :meth:`targets`."""

    def __init__(self, name: str = "place-repick", summary: str = "place on the table and pick again with another grasp"):
        super().__init__(name, "contact", summary)

    def release(self, obj, grasp) -> Optional[tuple]:
        """(hand angle α [rad], the TCP's height above the table [m] when the object touches it,
        the object's resting pose (7,) with the table at z = 0 under the TCP) of the stable face
        nearest to straight down, or None."""
        V = P.transform(grasp.pose, obj.taxonomy.vertices)
        com = P.transform(grasp.pose, obj.com)
        best = None
        for f in obj.taxonomy.faces:
            n = P.quat_rotate(grasp.pose[3:], f.normal)
            if abs(n[1]) > 1e-6:
                continue  # not parallel to the grasp axis: the hand's turn cannot put it level
            alpha = float(np.angle(np.exp(1j * (-np.pi / 2 - np.arctan2(n[2], n[0])))))
            h = float(np.max(V @ n))  # the face's plane: p · n = h
            if abs(alpha) > MAX_PLACE_TILT or not _over(com, P.transform(grasp.pose, f.polygon), n) \
                    or not _fingers_clear(obj, alpha, h):
                continue  # too far turned, it would topple, or the fingers would reach the table first
            if best is None or abs(alpha) < abs(best[0]):
                best = (alpha, h)
        if best is None:
            return None
        return (*best, P.compose(hand_pose(best[0], (0.0, 0.0, best[1])), grasp.pose))

    def targets(self, obj, grasp, usable=None) -> list:
        """The new grasps (names) reachable from above once the object rests where
        :meth:`release` leaves it (the fingers within 45° of down, the pads above the table), other
        faces first, at most :data:`TARGETS`; ``usable``: the names allowed (default all)."""
        from ..world import finger_reach

        rest = self.release(obj, grasp)
        if rest is None:
            return []
        out = []
        for g in obj.taxonomy.grasps:
            if g.name == grasp.name or (usable is not None and g.name not in usable):
                continue
            tcp = P.compose(rest[2], P.inverse(g.pose))
            R = P.quat_matrix(tcp[3:])
            if R[2, 2] < np.cos(MAX_PICK_TILT) or \
                    tcp[2] + float(np.min((_corners(finger_reach(obj.scene), g.width) @ R.T)[:, 2])) < FINGER_ROOM:
                continue
            out.append((g.faces == grasp.faces, -R[2, 2], g.name))
        return [name for *_, name in sorted(out)[:TARGETS]]

    def applies(self, obj, grasp):
        if self.release(obj, grasp) is None:
            return "no way to set it down with the fingers at most level and clear of the table"
        return None if self.targets(obj, grasp) else "no other grasp to pick it with from above"

    def setup(self, obj, grasp, params=None):
        p = _params(params)
        target = p.get("target") or (self.targets(obj, grasp) or [None])[0]
        if target is None:
            raise ArgumentError(f"invalid `grasp`: {self.name} does not apply to {grasp.name}", "grasp")
        new = obj.taxonomy.grasp(str(target))
        alpha, h, rest = self.release(obj, grasp)
        x, y = WORK_POINT[0], WORK_POINT[1]
        above = hand_pose(alpha, (x, y, h + p["drop"] + p["clear"]))
        place = hand_pose(alpha, (x, y, h + p["drop"]))
        resting = P.compose(np.array([x, y, 0.0, 1.0, 0.0, 0.0, 0.0]), rest)  # let go, it settles
        # the robot's TCP sits between the pads closed at the first grasp's width; at the new width
        # the linkage holds them elsewhere along the fingers (up to ≈ 7 mm): the TCP goes where the
        # pads' centres meet the new grasp
        lower = pad_height(obj, new.width) - pad_height(obj, grasp.width)
        pick = P.compose(P.compose(resting, P.inverse(new.pose)), np.array([0.0, 0.0, lower, 1.0, 0.0, 0.0, 0.0]))
        over = P.compose(pick, np.array([0.0, 0.0, p["clear"], 1.0, 0.0, 0.0, 0.0]))  # back along its fingers
        down = HandPath.line(above, place, 1.0)
        t_open = down.times[-1]
        path = down.then(HandPath.line(place, place, 0.4)).then(HandPath.line(place, above, 0.8))
        path = path.then(HandPath.line(above, over, 1.2)).then(HandPath.line(over, pick, 1.0))
        t_close = path.times[-1]
        path = path.then(HandPath.line(pick, pick, p["close_time"]))
        t_lift = path.times[-1]
        path = path.then(HandPath.line(pick, over, 1.0))
        grip = _place_grip(obj.grip, t_open, t_close, t_lift)
        return Setup(above, path, grip, 0.3, new.pose, new.name, {"target": new.name, "alpha": alpha})


TOPPLE_TILTS = np.radians(np.arange(-90.0, 91.0, 15.0))  # rad, the hand angles topple-repick tries


class ToppleRepick(PlaceRepick):
    """Topple on the table and pick again: the hand (at most level) sets the object down on an
    edge with its centre of mass beyond it, lets go, and the object falls over onto a face
    (quasi-static prediction: it rolls on the table about its lowest edge towards its centre of
    mass, edge after edge, until the centre of mass is over the face it lies on); then the hand
    picks it from above as :class:`PlaceRepick` does. It reaches resting faces that a placing
    hand cannot put down (its fingers would touch the table first)."""

    def __init__(self):
        super().__init__("topple-repick", "let it fall over on the table from an edge, then pick it again")

    def release(self, obj, grasp) -> Optional[tuple]:
        """(hand angle α [rad], the TCP's height above the table [m] when the object's lowest edge
        touches it, the resting pose after the fall) of the turn nearest to fingers-down at which it
        falls over by more than 10°, or None."""
        V = P.transform(grasp.pose, obj.taxonomy.vertices)
        com = P.transform(grasp.pose, obj.com)
        placed = PlaceRepick.release(self, obj, grasp)
        for alpha in sorted(TOPPLE_TILTS, key=abs):
            H = hand_pose(float(alpha), (0.0, 0.0, 0.0))
            W, c = P.transform(H, V), P.transform(H, com)
            h = -float(W[:, 2].min())
            if not _fingers_clear(obj, float(alpha), h):
                continue
            fall = _topple(W[:, [0, 2]], c[[0, 2]])
            if fall is None or abs(fall[0]) < np.radians(10.0):
                continue
            turn, pivot = fall
            held = P.compose(np.array([0.0, 0.0, h, 1.0, 0.0, 0.0, 0.0]), P.compose(H, grasp.pose))
            about = np.array([pivot[0], 0.0, pivot[1] + h])
            spin = np.array([np.cos(-turn / 2), 0.0, np.sin(-turn / 2), 0.0])  # x towards z by `turn`: −turn about y
            rest = P.compose(np.array([*about, 1.0, 0.0, 0.0, 0.0]), P.compose(np.array([0.0, 0.0, 0.0, *spin]),
                             P.compose(np.array([*-about, 1.0, 0.0, 0.0, 0.0]), held)))
            rest[2] -= float(P.transform(rest, obj.taxonomy.vertices)[:, 2].min())
            if placed is not None and _same_rest(obj, rest, placed[2]):
                continue  # it would fall onto the face the hand can set it down on
            return float(alpha), h, rest
        return None


def _same_rest(obj, a, b) -> bool:
    """Whether resting poses ``a`` and ``b`` place the object alike: its hull within 1 mm, up to
    its symmetry, once both are centred (a slide on the table does not count)."""
    V = obj.taxonomy.vertices
    centred = [np.array([*(q[:3] - P.transform(q, V).mean(axis=0)), *q[3:]]) for q in (a, b)]
    return grasp_distance(V, *centred) < 1e-3


def _topple(points, com, steps: int = 8) -> Optional[tuple]:
    """(turn [rad], pivot (x, z) [m]) of the outline ``points`` (k, 2) (x, z, its lowest point
    on the table) rolling on the table towards its centre of mass ``com`` (2,), edge after edge,
    until the centre of mass is over its contact edge: the roll is the turn about ``pivot`` (for
    a roll over several edges, the point that turn leaves where the roll does); None if it stands
    on a single point right over it or rolls on past ``steps`` edges."""
    Q0 = np.asarray(points, float)
    Q, c = Q0.copy(), np.asarray(com, float)
    total = 0.0
    for _ in range(steps):
        low = Q[:, 1].min()
        touching = Q[Q[:, 1] < low + 1e-9]
        lo, hi = touching[:, 0].min(), touching[:, 0].max()
        if lo - 1e-9 <= c[0] <= hi + 1e-9:
            return total, _fixed_point(Q0, Q, total)
        side = 1.0 if c[0] > hi else -1.0
        p = touching[np.argmax(side * touching[:, 0])]
        d = Q - p
        ahead = side * d[:, 0] > 1e-9
        # the angle each point ahead must turn through (towards the table) to touch it
        turn = -side * float(np.arctan2(d[ahead, 1], side * d[ahead, 0]).min())  # x towards z: towards +x is clockwise
        R = np.array([[np.cos(turn), -np.sin(turn)], [np.sin(turn), np.cos(turn)]])
        Q, c = (Q - p) @ R.T + p, R @ (c - p) + p
        total += turn
    return None


def pad_height(obj: ObjectModel, width: float) -> float:
    """The pads' centres' distance [m] from the gripper's base along its fingers when closed on an
    object ``width`` [m] wide (:func:`regrasp.robot.model.tcp_height`, with the scene's pads)."""
    from ...robot.model import tcp_height
    from ...robot.pads import Pads

    return float(tcp_height(float(width), "", Pads.of_scene(obj.scene), float(obj.mu)))


def _place_grip(force: float, t_open: float, t_close: float, t_lift: float):
    def grip(t: float):
        if t_open <= t < t_close:
            return None  # open
        if t >= t_close:
            return force * min(1.0, 0.3 + 0.7 * (t - t_close) / max(t_lift - t_close, 1e-9))
        return force
    return grip


def _over(point, polygon, normal) -> bool:
    """Whether ``point`` projects inside the convex ``polygon`` (k, 3) along ``normal``."""
    c = polygon.mean(axis=0)
    for a, b in zip(polygon, np.roll(polygon, -1, axis=0)):
        if np.dot(np.cross(b - a, point - a), normal) * np.dot(np.cross(b - a, c - a), normal) < 0:
            return False
    return True


def _fixed_point(before, after, turn: float) -> np.ndarray:
    """The point about which turning ``before`` (k, 2) by ``turn`` [rad] gives ``after`` (a rigid
    motion in the plane: x' = R x + t; its fixed point solves (I − R) p = t); the first point of
    ``before`` on the table when it does not turn."""
    if abs(turn) < 1e-12:
        return before[np.argmin(before[:, 1])]
    R = np.array([[np.cos(turn), -np.sin(turn)], [np.sin(turn), np.cos(turn)]])
    t = after[0] - R @ before[0]
    return np.linalg.solve(np.eye(2) - R, t)
