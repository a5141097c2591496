"""Regrasp actions (thesis §1.1.1, ICRA 2014 "Extrinsic dexterity"): open-loop, parameterised
motions of the arm and grip-force schedules that change the grasp on an object with resources
outside the hand — gravity, the inertia of the arm's motion, contacts with the table. Each
action (:class:`Action`) says which grasps it applies to (:meth:`Action.applies`), and
turns a grasp into a :class:`Setup`: the hand's start pose, its timed path, the grip schedule
and the model's prediction of the in-hand pose at the end (:mod:`.slip` for the gravity and
inertial actions, the kinematics of sticking contact for the table's), whose nearest grasp of
the taxonomy is the grasp it is meant to reach. Geometry in the hand frame (x, z: the plane of
the pads, y the grasp axis); every action here keeps the grasp axis horizontal along the
world's y, so that the hand frame's x-z plane is the world's x-z plane turned by the hand's
angle α (the hand's x from the world's x towards its z; α = 0: the fingers point down).
Parameters are SI; their defaults are physically grounded (the holding force m g / 2 μ, the
taxonomy's offset and turn steps) and stated in :data:`DEFAULTS`."""

from __future__ import annotations

import weakref
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Optional

import numpy as np

from .. import pose as P
from ..errors import ArgumentError, SceneError
from .slip import Body, Slip, simulate
from .taxonomy import grasp_distance
from .world import POST_FRICTION, POST_HALF, POST_X, POST_Y, WORK_POINT, HandPath, ramps

G = 9.81  # m/s², the default gravity's norm (a scene's own is used: ObjectModel.g)
RAMP = 0.05  # s, a grip change is ramped over this long (the linkage follows; a step springs the pads off)
ARM_LAG = 0.005  # s, toss-catch: how far the arm's hand lags its commanded braking (the joint servo, robot.tracking; measured: the box's toss brakes 5–6 ms late)
DEFAULTS = {
    "overdrive": 1.4,   # gravity-pivot: the gravity moment at the start over the pads' torsion capacity at the lowered grip
    "max_tilt": 0.5236,  # rad, gravity-pivot: the centre of mass at most this far from hanging at the start (30°: the hand turns the rest, the swing stays short; 150° overswung the bar 3 times in 4, docs)
    "pivot_time": 0.8,  # s, gravity-pivot: how long the grip stays low
    "slide_ratio": 0.8,  # gravity-slide: 2 μ N / m g while sliding (the object accelerates at (1 − ratio) g)
    "lag": 0.5236,      # rad, grip-pivot: the angle from the vertical at which the object lags the turning hand (30°)
    "turn_time": 1.2,   # s, grip-pivot and table-pivot: how long the hand turns
    "acceleration": 30.0,  # m/s², inertial-slide: the hand's downward jab (more than g: the object rises in the hand)
    "braking": 15.0,    # m/s², inertial-slide: the hand's stop after the jab, the grip firm again
    "jab_hold": 1.3,    # inertial-slide: 2 μ N / m g during the jab (holds the weight, lets the jab slide it)
    "press_hold": 1.5,  # push-down and table-pivot: 2 μ N / m g while the table pushes
    "approach": 0.02,   # m, push-down and table-pivot: the object's lowest point above the table at the start
    "speed": 0.03,      # m/s, push-down: the hand's descent; table-slide: its rise
    "rest_ratio": 0.5,  # table-slide: 2 μ N / m g while the object stands on the table (0.9 at +20 % friction and grip, −20 % mass: the table keeps part of the weight)
    "drop": 0.002,      # m, place-repick: the object's face above the table when the fingers open
    "clear": 0.06,      # m, place-repick: the hand's retreat and approach along its fingers
    "close_time": 1.0,  # s, place-repick: the fingers close on the object on the table this long before the lift
    "plan_iterations": 20,  # post-push: the motion-cone planner's iterations per grip tried (seed 0: the same plan on every machine; a push it finds, it finds at once)
    "push_speed": 0.01,  # m/s, post-push: the hand's speed along the plan (quasi-static: at 3 cm/s the pads chatter off a box)
    "toss": 12.0,       # m/s², toss-catch: the hand's upward acceleration, fingers up, the grip firm
    "toss_stop": 30.0,  # m/s², toss-catch: the hand's stop (more than g: the object flies on, free, while the fingers are open)
}
MAX_PLACE_TILT = np.radians(90.0) + 1e-9  # rad, place-repick: the hand placing at most this far from fingers-down (level)
MAX_PICK_TILT = np.radians(45.0)  # rad, place-repick: the hand picking at most this far from fingers-down
FINGER_ROOM = 0.008  # m, place-repick: the pads' lowest corner at least this far above the table (the IK keeps 5 mm)
TARGETS = 4  # place-repick: at most this many new grasps per grasp (other faces first)


@dataclass(frozen=True)
class ObjectModel:
    """What the actions need of an object: its ``scene`` (a :class:`regrasp.Scene3D`), the
    grasp ``taxonomy`` (:class:`~regrasp.dexterity.taxonomy.Taxonomy`), ``mass`` [kg],
    ``inertia`` (3, 3) [kg·m²] about the centre of mass (object frame), ``com`` (3,) [m], the
    pads' friction ``mu``, the scene's grip force ``grip`` [N] per pad and gravity ``g`` [m/s²]."""

    scene: object
    taxonomy: object
    mass: float
    inertia: np.ndarray
    com: np.ndarray
    mu: float
    grip: float
    g: float

    @classmethod
    def of(cls, scene, taxonomy) -> "ObjectModel":
        """The model of ``scene``'s object (a :class:`regrasp.Scene3D`) with its ``taxonomy``."""
        return cls(scene, taxonomy, float(scene.mass), np.asarray(scene.inertia, float), np.asarray(scene._core.com, float),
                   float(scene._core.grip_friction), float(scene._core.grip_force),
                   float(np.linalg.norm(scene._core.gravity)))

    @property
    def weight(self) -> float:
        """m g [N]."""
        return self.mass * self.g

    def holding(self, ratio: float) -> float:
        """The per-pad force [N] at which the pads' force capacity 2 μ N is ``ratio`` times the weight."""
        return ratio * self.weight / (2 * self.mu)


@dataclass(frozen=True)
class Setup:
    """An action on a grasp, ready to run: the hand's world ``start`` pose, its ``path`` (from
    ``start``), the ``grip`` schedule (:mod:`.world`), ``settle`` [s] after the path, the
    ``predicted`` in-hand pose at the end (None: the object is predicted to drop), the
    ``intended`` grasp's name, and the model's ``detail`` (for the record)."""

    start: np.ndarray
    path: HandPath
    grip: Callable[[float], Optional[float]]
    settle: float
    predicted: Optional[np.ndarray]
    intended: Optional[str]
    detail: dict = field(default_factory=dict)


# --- the geometry of a grasp in the hand ---------------------------------------------------------


def hand_pose(alpha: float, point=WORK_POINT) -> np.ndarray:
    """The TCP's world pose at ``point`` [m] with the grasp axis along the world's y and the
    hand's x at angle ``alpha`` [rad] from the world's x towards its z (0: fingers down)."""
    x = np.array([np.cos(alpha), 0.0, np.sin(alpha)])
    y = np.array([0.0, 1.0, 0.0])
    return np.concatenate([np.asarray(point, float), P.quat_from_matrix(np.column_stack([x, y, np.cross(x, y)]))])


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
    """The slip model's :class:`~.slip.Body` of ``obj`` at ``grasp``."""
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
    from .trial import tolerance

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


# --- the actions -----------------------------------------------------------------------------------


@dataclass(frozen=True)
class Action:
    """A regrasp action: ``name``, the ``resource`` it uses (``gravity``, ``inertia``,
    ``contact``), a one-line ``summary``; :meth:`applies` and :meth:`setup` per action."""

    name: str
    resource: str
    summary: str

    def applies(self, obj: ObjectModel, grasp) -> Optional[str]:
        """None when the action applies to ``grasp``, else why not."""
        raise NotImplementedError

    def setup(self, obj: ObjectModel, grasp, params: dict | None = None) -> Setup:
        """The :class:`Setup` of the action on ``grasp`` (``params``: overrides of :data:`DEFAULTS`)."""
        raise NotImplementedError

    def to_dict(self) -> dict:
        """The action's name, resource and summary (for the graph file)."""
        return {"name": self.name, "resource": self.resource, "summary": self.summary}


WHOLE = ("plan_iterations",)  # the DEFAULTS that count something


def _params(params: dict | None) -> dict:
    p = dict(DEFAULTS)
    for k, v in (params or {}).items():
        if k == "target":
            p[k] = v
            continue
        if k not in DEFAULTS:
            raise ArgumentError(f"invalid `params.{k}`: unknown parameter (known: {', '.join(DEFAULTS)})", f"params.{k}")
        if isinstance(v, bool) or not (isinstance(v, (int, float)) and np.isfinite(v) and v > 0):
            raise ArgumentError(f"invalid `params.{k}`: a number > 0 (got {v!r})", f"params.{k}")
        if k in WHOLE and v != int(v):
            raise ArgumentError(f"invalid `params.{k}`: a whole number ≥ 1 (got {v!r})", f"params.{k}")
        p[k] = float(v)
    return p


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


_RELEASE: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()  # scene -> {grasp pose: Release or why none}


def release(obj: ObjectModel, grasp):
    """The gripper's :class:`~.world.Release` of ``grasp``'s object: measured once per object and
    grasp in a :class:`~.world.HandWorld`, fingers down (:func:`~.world.release_timing`; the
    object then moves towards the fingertips when loose, as in both catches — the timing is
    the gripper's: fingers up it is the same within 2 ms). An ArgumentError naming ``grasp``
    when the gripper cannot let go and catch it."""
    from .world import HandWorld, release_timing

    cache = _RELEASE.setdefault(obj.scene, {})
    key = tuple(np.round(np.asarray(grasp.pose, float), 6))
    if key not in cache:
        try:
            cache[key] = release_timing(HandWorld(obj.scene, grasp.pose, hand_pose(0.0)))
        except SceneError as e:
            cache[key] = str(e)
    if isinstance(cache[key], str):
        raise ArgumentError(f"invalid `grasp`: {grasp.name}: {cache[key]}", "grasp")
    return cache[key]


def _catch_applies(obj: ObjectModel, grasp) -> Optional[str]:
    """Why a catch does not apply to ``grasp`` (None when it does)."""
    if _offset_step(obj, grasp, -1) is None:
        return "no grasp further towards the fingertips"
    try:
        release(obj, grasp)
    except ArgumentError as e:
        return str(e)
    return None


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


def _released(force: float, t0: float, delta: float):
    """The grip schedule: ``force`` [N], the fingers open for ``delta`` [s] from ``t0`` [s]."""
    return lambda t: None if t0 <= t < t0 + delta else force


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
        from ..robot.pads import LENGTH

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
        from ..execution.arm import grasp_of
        from ..robot.grip import least_force
        from ..robot.pads import Pads

        width, _ = grasp_of(obj.scene, grasp.pose)
        return least_force(width, "", Pads.of_scene(obj.scene), obj.mu)

    def applies(self, obj, grasp):
        return self._why_not(obj, grasp, DEFAULTS["rest_ratio"])

    def _why_not(self, obj, grasp, r: float) -> Optional[str]:
        """Why the slide cannot be done at the grip ``r`` (2 μ N / m g), or None."""
        from ..robot.ik import MIN_DISTANCE

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


POST_HOLDS = (1.5, 2.0, 3.0, 4.0)  # post-push: the grips tried (2 μ N / m g), the least the planner finds a push at
PLAN_TIME_CAP = 60.0  # s, post-push: a safety cap on the planner's time (its iterations limit it first)
POST_ROOM = 0.006  # m, post-push: the post's side at least this far from each pad (the IK keeps the gripper 5 mm off it)


class PostPush(Action):
    """A prehensile push against the workcell's post (thesis ch. 3–4): the hand level, its fingers
    towards the post (:data:`~.world.POST_X`), which passes between them. The motion-cone planner
    (:meth:`regrasp.Scene3D.plan`, inverse dynamics over the pads' limit surface) plans the push
    one offset step deeper into the hand with the post's face as a plane pusher of the post's
    friction and gravity across the push, at the least grip of :data:`POST_HOLDS` at which it
    finds one — the post's friction, pressed by the pads' sliding friction, must carry the weight
    (μ_post · 2μN ≥ m g). The hand renders the plan with the object held still by the post
    (sticking): at knot k the TCP is O ∘ X_k⁻¹, O the object's world pose at contact and X_k its
    planned pose in the hand; the hand comes in at ``speed`` and follows the plan at ``push_speed``."""

    ALPHA = np.pi / 2  # rad, the hand level, its fingers along the world's +x (at the post)

    def __init__(self):
        super().__init__("post-push", "contact", "push it deeper against a post, the motion planned by motion cones")

    def _plan(self, obj, grasp, iterations: int):
        """(grip ratio, the plan) or why there is none (cached per grasp)."""
        cache = _PLANS.setdefault(obj.taxonomy, {})
        key = (grasp.name, iterations)
        if key in cache:
            return cache[key]
        step = _offset_step(obj, grasp, +1)
        if step is None:
            out = "no grasp further towards the palm"
        elif grasp.width / 2 - POST_HALF[1] < POST_ROOM:
            out = f"the post ({2e3 * POST_HALF[1]:.0f} mm) does not pass between pads {grasp.width * 1e3:.1f} mm apart"
        else:
            goal = P.compose(np.array([0.0, 0.0, step, 1.0, 0.0, 0.0, 0.0]), grasp.pose)
            out = f"the motion-cone planner finds no push at a grip up to {POST_HOLDS[-1]} times the holding force"
            for ratio in POST_HOLDS:
                try:
                    plan = post_scene(obj, grasp.pose, goal, obj.holding(ratio)).plan(
                        seed=0, max_iterations=iterations, time_limit=PLAN_TIME_CAP)
                except (ArgumentError, SceneError) as e:  # no scene file, or the pads do not touch it at the start or the goal
                    out = f"no push to plan: {e}"
                    break
                if plan.found and plan.valid:
                    out = (ratio, plan)
                    break
        cache[key] = out
        return out

    def applies(self, obj, grasp):
        plan = self._plan(obj, grasp, int(DEFAULTS["plan_iterations"]))
        return plan if isinstance(plan, str) else None

    def setup(self, obj, grasp, params=None):
        p = _params(params)
        plan = self._plan(obj, grasp, int(p["plan_iterations"]))
        if isinstance(plan, str):
            raise ArgumentError(f"invalid `grasp`: post-push does not apply to {grasp.name}: {plan}", "grasp")
        ratio, plan = plan
        X = np.asarray(plan.poses, float)
        reach = -lowest(grasp, obj.taxonomy.vertices)[2]
        press = 0.0005  # m, the object pressed this far into the post at contact (soft contact)
        contact = hand_pose(self.ALPHA, (POST_X - reach + press, POST_Y, WORK_POINT[2]))
        start = hand_pose(self.ALPHA, (POST_X - reach - p["approach"], POST_Y, WORK_POINT[2]))
        O = P.compose(contact, X[0])  # the object's world pose, held by the post
        knots = [P.compose(O, P.inverse(x)) for x in X]
        path = HandPath.line(start, contact, 1.5 * p["approach"] / p["speed"])
        t0 = path.times[-1]
        for a, b in zip(knots, knots[1:]):
            path = path.then(HandPath.line(a, b, max(float(np.linalg.norm(b[:3] - a[:3])) / p["push_speed"], 0.05),
                                           profile=lambda s: s))
        t1 = path.times[-1]
        path = path.then(HandPath.line(knots[-1], P.compose(knots[-1], np.array([0.0, 0.0, p["approach"], 1.0, 0.0, 0.0, 0.0])), 1.0))
        low = obj.holding(ratio)
        grip = ramps((0.0, obj.grip), (t0 - RAMP, obj.grip), (t0, low), (t1, low), (t1 + RAMP, obj.grip))
        pose = X[-1]
        return Setup(start, path, grip, 0.3, pose, _intended(obj, pose),
                     {"grip": low, "hold": ratio, "knots": len(X), "push": float(X[-1][2] - X[0][2])})


_PLANS: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()  # taxonomy -> {(grasp name, iterations): _plan}


def post_scene(obj: ObjectModel, start, goal, force: float, friction: float = POST_FRICTION):
    """The :class:`regrasp.Scene3D` of a push against the post with the hand level: ``obj``'s object
    file's ``[object]`` (an ArgumentError naming ``scene`` when the scene has no readable file),
    its pads at ``force`` [N] each, gravity along the hand's −x, the post's face a plane pusher
    (``friction``, by default the post's) pushing towards the palm (+z), the task from in-hand
    pose ``start`` to ``goal`` (1 mm, 1°)."""
    import tomllib

    from ..scene.spatial import Scene3D
    from ..workcell.file import toml_value

    path = getattr(obj.scene, "path", None)
    if path is None:
        raise ArgumentError("invalid `scene`: a post push needs the object's scene file (load it from a file)", "scene")
    try:
        data = tomllib.loads(Path(path).read_text())
    except (OSError, tomllib.TOMLDecodeError) as e:
        raise ArgumentError(f"invalid `scene`: cannot read the object's scene file {str(path)!r}: {e}", "scene") from None
    lines = ["dimension = 3", 'name = "post-push"']
    for table, values in (("object", data.get("object", {})), ("grasp", dict(data.get("grasp", {}), force=float(force)))):
        lines += ["", f"[{table}]"]
        for k, v in values.items():
            try:
                lines.append(f"{k} = {toml_value(v)}")
            except ValueError as e:
                raise SceneError(f"scene field `{table}.{k}`: {e}", f"{table}.{k}") from None
    lines += ["", "[gravity]", "direction = [-1.0, 0.0, 0.0]", f"g = {obj.g!r}"]
    lines += ["", "[[pushers]]", 'name = "post"', f"friction = {float(friction)!r}", "plane = true", "normal = [0.0, 0.0, 1.0]"]
    lines += ["", "[task]", f"start = {toml_value(np.asarray(start, float))}", f"goal = {toml_value(np.asarray(goal, float))}",
              "tolerance = [0.001, 0.001, 0.001, 0.0175]"]
    return Scene3D.from_toml("\n".join(lines) + "\n", Path(path).parent)


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
        from ..robot.ik import MIN_DISTANCE

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


def _corners(reach: float, width: float = 0.0) -> np.ndarray:
    """The corners (hand frame) [m] of a box about the fingers' tips: across the pads' face, at
    y = ±``width``/2, from ``reach`` [m] below the TCP (:func:`~.world.finger_reach`) to the pads'
    top."""
    from ..robot.pads import HALF_WIDTH, LENGTH

    return np.array([[x, y, z] for x in (-HALF_WIDTH, HALF_WIDTH) for y in {-width / 2, width / 2}
                     for z in (-reach, LENGTH / 2)])


def _fingers_clear(obj: ObjectModel, alpha: float, height: float, room: float = FINGER_ROOM) -> bool:
    """Whether the fingers' tips stay ``room`` [m] above the table with the TCP at ``height`` [m]
    and the hand at angle ``alpha`` [rad]."""
    from .world import finger_reach

    R = P.quat_matrix(hand_pose(alpha)[3:])
    return height + float(np.min((_corners(finger_reach(obj.scene)) @ R.T)[:, 2])) >= room


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
        from .world import finger_reach

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
    from ..robot.model import tcp_height
    from ..robot.pads import Pads

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


ACTIONS = {a.name: a for a in (GravityPivot(), GravitySlide(), GripPivot(), DropCatch(), InertialSlide(), TossCatch(),
                                PushDown(), TableSlide(), PostPush(), TablePivot(), PlaceRepick(), ToppleRepick())}


def action(name: str) -> Action:
    """The action ``name`` (:data:`ACTIONS`), or an ArgumentError naming ``action``."""
    if name not in ACTIONS:
        raise ArgumentError(f"invalid `action`: unknown action {name!r} (known: {', '.join(ACTIONS)})", "action")
    return ACTIONS[name]
