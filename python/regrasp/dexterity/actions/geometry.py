"""The geometry of a grasp in the hand that the regrasp actions share (thesis §1.1.1): the pads'
contact centre and the centre of mass in the hand frame (x, z: the plane of the pads, y the
grasp axis), the slip model's :class:`~regrasp.dexterity.slip.Body` and the in-hand pose a slip
leaves, the grasps one offset step away and the turn to the next orientation of the grasp's
faces (:func:`turn_target`), and whether the fingers clear the table (:data:`FINGER_ROOM`)."""

from __future__ import annotations

import weakref
from typing import Callable, Optional

import numpy as np

from ... import pose as P
from ...errors import ArgumentError
from ..slip import Body, Slip
from ..taxonomy import classification_tolerance as tolerance
from ..world import WORK_POINT, hand_pose
from .base import ObjectModel


def contact_centre(obj: ObjectModel, grasp) -> np.ndarray:
    """The pads' contact centre (x, z) [m] in the hand frame: the centroid of the pad's patch
    (the object's face against the left pad, clipped to the pad's face)."""
    return np.asarray(obj.taxonomy.patch_centre(grasp), float)


def com_in_hand(obj: ObjectModel, grasp) -> np.ndarray:
    """The centre of mass (x, z) [m] in the hand frame from the contact centre."""
    c = P.transform(grasp.pose, obj.com)
    return np.array([c[0], c[2]]) - contact_centre(obj, grasp)


def plane_inertia(obj: ObjectModel, grasp) -> float:
    """The moment of inertia [kg·m²] about the grasp axis through the centre of mass."""
    R = P.quat_matrix(grasp.pose[3:])
    return float((R @ obj.inertia @ R.T)[1, 1])


def body(obj: ObjectModel, grasp) -> Body:
    """The slip model's :class:`~regrasp.dexterity.slip.Body` of ``obj`` at ``grasp``."""
    return Body(obj.mass, plane_inertia(obj, grasp), tuple(com_in_hand(obj, grasp)), float(grasp.torsion_k), obj.mu)


def moved(obj: ObjectModel, grasp, slip: Slip) -> np.ndarray:
    """The in-hand pose after ``slip`` of ``grasp``: turned by ``slip.turn`` (x towards z: −turn
    about y) about the grasp axis through the contact centre, then shifted by ``slip.shift``."""
    cx, cz = contact_centre(obj, grasp)
    turn = np.array([np.cos(-slip.turn / 2), 0.0, np.sin(-slip.turn / 2), 0.0])
    to_centre = np.array([-cx, 0.0, -cz, 1.0, 0.0, 0.0, 0.0])
    back = np.array([cx + slip.shift[0], 0.0, cz + slip.shift[1], 1.0, 0.0, 0.0, 0.0])
    return P.compose(back, P.compose(np.array([0.0, 0.0, 0.0, *turn]), P.compose(to_centre, grasp.pose)))


def lowest(grasp, vertices) -> np.ndarray:
    """The object's vertex (hand frame, (3,)) farthest towards the fingertips (least z)."""
    v = P.transform(grasp.pose, vertices)
    return v[int(np.argmin(v[:, 2]))]


def _angle(v) -> float:
    return float(np.arctan2(v[1], v[0]))


def _turning(obj: ObjectModel, grasp, angle: Callable[[float], float]):
    """The slip model's hand (its contact centre, angle) for a TCP fixed at the work point turning
    by ``angle(t)`` [rad]: the contact centre, off the TCP, goes round it."""
    centre = contact_centre(obj, grasp)
    tcp = np.array([WORK_POINT[0], WORK_POINT[2]])

    def hand(t: float) -> tuple:
        a = angle(t)
        return tcp + np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]]) @ centre, a
    return hand


def _still(alpha: float, point=WORK_POINT):
    return lambda t: (np.array([point[0], point[2]]), alpha)


def _intended(obj: ObjectModel, pose) -> Optional[str]:
    return None if pose is None else obj.taxonomy.nearest(pose)[0]


def _siblings(obj: ObjectModel, grasp) -> list:
    """The grasps on the same faces as ``grasp``."""
    return [g for g in obj.taxonomy.grasps if g.faces == grasp.faces and g.name != grasp.name]


def _offset_step(obj: ObjectModel, grasp, sign: int) -> Optional[float]:
    """The distance [m] to the nearest grasp on the same faces at the same turn and lateral
    offset with an offset further in ``sign`` (+1 towards the palm), or None."""
    steps = [sign * (g.offset - grasp.offset) for g in _siblings(obj, grasp)
             if abs(np.angle(np.exp(1j * (g.angle - grasp.angle)))) < 1e-6 and abs(g.lateral - grasp.lateral) < 1e-9
             and sign * (g.offset - grasp.offset) > 1e-6]
    return min(steps) if steps else None


def _step(obj: ObjectModel, grasp, sign: int, action: str) -> float:
    """:func:`_offset_step`, or an ArgumentError naming ``grasp`` when there is no such grasp."""
    step = _offset_step(obj, grasp, sign)
    if step is None:
        where = "palm" if sign > 0 else "fingertips"
        raise ArgumentError(f"invalid `grasp`: {action} does not apply to {grasp.name}: no grasp further towards "
                            f"the {where}", "grasp")
    return step


TURNS = np.radians(np.arange(-180, 180, 1.0))  # the turns that turn_target tries


_TURNS: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()  # taxonomy -> {grasp name: turn_target}


def turn_target(obj: ObjectModel, grasp) -> Optional[tuple]:
    """(turn [rad] about the grasp axis through the contact centre, x towards z; the grasp it
    reaches; its distance [m]): the least turn (of more than 0.2 rad, to the degree) that brings
    ``grasp`` (the pads staying where they are on the object's faces) nearest to another grasp
    on the same faces — the object's symmetry included (a triangle's next orientation is 60°
    away) — within the classification tolerance; None if no turn does."""
    cache = _TURNS.setdefault(obj.taxonomy, {})
    if grasp.name in cache:
        return cache[grasp.name]
    best, tol = None, tolerance(obj.taxonomy)
    siblings = {g.name for g in _siblings(obj, grasp)}
    for turn in TURNS:
        if abs(turn) < 0.2:
            continue
        name, dist = obj.taxonomy.nearest(moved(obj, grasp, Slip(np.zeros(2), float(turn), np.zeros(2))))
        if name in siblings and dist <= tol and (best is None or (round(dist, 4), abs(turn)) < (round(best[2], 4), abs(best[0]))):
            best = (float(turn), name, float(dist))
    cache[grasp.name] = best
    return best


FINGER_ROOM = 0.008  # m, the pads' lowest corner at least this far above the table (the IK keeps 5 mm)


def _corners(reach: float, width: float = 0.0) -> np.ndarray:
    """The corners (hand frame) [m] of a box about the fingers' tips: across the pads' face, at
    y = ±``width``/2, from ``reach`` [m] below the TCP
    (:func:`~regrasp.dexterity.world.finger_reach`) to the pads' top."""
    from ...robot.pads import HALF_WIDTH, LENGTH

    return np.array([[x, y, z] for x in (-HALF_WIDTH, HALF_WIDTH) for y in {-width / 2, width / 2}
                     for z in (-reach, LENGTH / 2)])


def _fingers_clear(obj: ObjectModel, alpha: float, height: float, room: float = FINGER_ROOM) -> bool:
    """Whether the fingers' tips stay ``room`` [m] above the table with the TCP at ``height`` [m]
    and the hand at angle ``alpha`` [rad]."""
    from ..world import finger_reach

    R = P.quat_matrix(hand_pose(alpha)[3:])
    return height + float(np.min((_corners(finger_reach(obj.scene)) @ R.T)[:, 2])) >= room
