"""The gripper's world-frame SE(3) trajectory that executes a plan in a workcell, pure kinematics
(no arm): each push is rendered by a fixed feature (:mod:`regrasp.execution.assignment`), the
gripper moving so that the feature, fixed in the world, makes the planned virtual-pusher motion
(thesis Fig 1-7).

At a plan knot k of a push, with ``P_k`` the pusher's contact frame in the gripper frame and
``F`` the feature's contact frame in the world, the gripper's world pose is ``G_k = F ∘ P_k⁻¹``
(so ``G_k ∘ P_k = F``). Over step k the pusher moves in the gripper frame by the step's pusher
twist ξ (3-D plans' ``pusher_twist``, expressed in the object frame at the step's start ``O``;
otherwise the object's own twist, a sticking pusher): ``P(s) = O exp(s ξ) O⁻¹ P_{k-1}``, s in
[0, 1]. A sticking pusher keeps the object still in the world while the gripper moves around it.

Around each push (one builder each: :func:`_transfer`, :func:`_approach`, :func:`_push`,
:func:`_retreat`): a transfer up to the safe height, over (the switch-over's turn is made there)
and down to a pre-contact pose ``timing.clearance`` away from the feature along its push
direction (:data:`SLIDE_GAP` under an edge it slides under lengthwise), the approach, the push
and the retreat by that distance. The safe height is the
top of every feature's body (:meth:`Workcell.top`) + the clearance + the larger of the object's
reach from the gripper origin and how far the gripper's body (a capsule ``envelope`` long along
its +z, :data:`GRIPPER_ENVELOPE`, :data:`GRIPPER_RADIUS`) hangs below its origin at the
orientations the transfer turns between, so that neither object nor gripper comes within the
clearance of the workcell there. Under a feature that pushes downward (a
ledge), the transfers go down and up beside it, on the robot's side, moved off the feature
until the object and the gripper's body (:data:`GRIPPER_RADIUS`) are the clearance past its
end: along an edge square to the grasp axis (:data:`ALONG_MAX`; an edge between the fingers,
pushing the top of an object held below it, passes between them only lengthwise: the slide,
:data:`SLIDE_GAP` below the edge, is part of the approach and of the retreat, at the transfer
speeds), else horizontally across the feature.

Refused (ExecutionError), naming the push: an object going deeper than
:data:`~regrasp.execution.motion_check.PENETRATION_LIMIT` into its feature's contact plane during the push (its points along its
edges, :func:`edge_points`, behind the plane, within a face's rectangle). Refused, naming the push
or the transfer, the body hit and the depth: the object (a solid,
:mod:`regrasp.execution.collision`) in the table or a feature's body
(:func:`regrasp.workcell.shapes`) at any sample — deeper than :data:`~regrasp.execution.motion_check.TOUCH`, or, in a push's
approach, push and retreat, deeper than :data:`~regrasp.execution.motion_check.PENETRATION_LIMIT` into that push's own feature.
A push whose motion is refused so is rendered by the next contact that serves it
(:func:`~regrasp.execution.assignment.candidates`); the first refusal is raised when none is left."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .. import pose as P
from ..errors import ArgumentError, ExecutionError
from .layout import default_workcell
from ..workcell.description import CLEARANCE, Workcell
from ..workcell.shapes import EDGE_RADIUS
from .assignment import MAX_TILT, Assignment, candidates
from .motion_check import _Check, _what, object_points

#: The gripper's body kept clear in transfers: a capsule from the gripper's origin (the TCP)
#: along its +z (to the palm and the flange), ``GRIPPER_ENVELOPE`` [m] long, of radius
#: ``GRIPPER_RADIUS`` [m] (the Robotiq 2F-85, measured on its model: 0.155 m from the TCP along
#: +z, its linkage ±76 mm along the grasp axis and ±38 mm across it). Pointing down, only its
#: radius hangs below the origin.
GRIPPER_ENVELOPE = 0.16
GRIPPER_RADIUS = 0.085
#: A feature pushes downward when its push direction is within this angle [rad] of the world's −z.
DOWNWARD = np.pi / 3
#: Under a downward-pushing edge the transfers come and go along it (its contact frame's x)
#: when that is this close to square to the grasp axis (|cos| of the angle), else across it
#: (its y): an edge between the fingers, over an object held below its top, passes between them
#: only lengthwise.
ALONG_MAX = 0.1
#: The gap [m] between the object and a feature it slides under lengthwise (the pre-contact
#: pose's distance there, instead of ``Timing.clearance``): the edge passes between the fingers
#: below the gripper's housing, so the slide and the retreat along it are part of the approach
#: and the retreat (kept the contact clearance from the arm).
SLIDE_GAP = 0.003
#: A free move (transfer, approach, retreat) follows the minimum-jerk profile s(τ) = 10τ³ − 15τ⁴ + 6τ⁵
#: (zero speed and acceleration at both ends: no jolt on the held object); its peak speed is this
#: many times its mean, so its duration is stretched by it to keep the peak at the Timing's speed.
EASE_PEAK = 1.875


def eased(tau):
    """The minimum-jerk progress s(τ) = 10τ³ − 15τ⁴ + 6τ⁵ in [0, 1] at times τ in [0, 1] (of a move)."""
    tau = np.asarray(tau, float)
    return tau ** 3 * (10 - 15 * tau + 6 * tau ** 2)


@dataclass(frozen=True)
class Timing:
    """Speeds and spacing of a world motion, stated once: the gripper's speed while pushing,
    approaching and retreating (``push_speed`` [m/s], ``push_turn`` [rad/s]) and in free transfers
    and sliding lengthwise under an edge (``move_speed`` [m/s], ``move_turn`` [rad/s]); the
    ``clearance`` [m] of pre-contact poses; the
    longest time between samples ``sample_period`` [s]; the ``dwell`` [s] held at each push's end
    (a real arm lags its reference under the push's load: it settles there before retreating)."""
    push_speed: float = 0.01
    push_turn: float = 0.2
    move_speed: float = 0.1
    move_turn: float = 1.0
    clearance: float = CLEARANCE
    sample_period: float = 0.02
    dwell: float = 0.25

    def __post_init__(self):
        for k in ("push_speed", "push_turn", "move_speed", "move_turn", "clearance", "sample_period", "dwell"):
            v = getattr(self, k)
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not (math.isfinite(v) and 0 < v <= 1e3):
                raise ArgumentError(f"invalid `timing.{k}`: a number in (0, 1000] (got {v!r:.40})", f"timing.{k}")


@dataclass
class WorldMotion:
    """A timed world-frame motion of the gripper holding the object, per sample: ``times`` (n,)
    [s]; ``gripper`` (n, 7) the gripper's world pose (m, unit quaternion); ``object`` (n, 7) the
    object's world pose; ``in_hand`` (n, 7) the object's pose in the gripper frame; ``labels``
    (one of :data:`~regrasp.execution.trajectory.LABELS` per sample); ``push`` (n,) the push index of approach, push and retreat samples (−1 in transfers);
    ``grip_force`` (n,) [N] per finger. ``assignments``: the feature of each push; ``knots``:
    ``(path index, sample index)`` of each plan knot of each push (a knot shared by two pushes
    appears once for each); ``safe_height`` [m]: the highest safe height of its transfers; ``workcell``; ``timing``;
    ``penetration`` [m] per push: how far the object's points (:func:`edge_points`) go behind
    the feature's contact plane (within a face's rectangle) during the push (0 for a sticking push of a convex object; a
    plan whose object turns against its pusher, e.g. a pivot on a patch, can go through a face
    larger than the patch); ``scene``: the scene's name; ``envelope`` [m]: the length of the gripper's
    body along its +z kept clear in transfers at the safe height."""
    times: np.ndarray
    gripper: np.ndarray
    object: np.ndarray
    in_hand: np.ndarray
    labels: list
    push: np.ndarray
    grip_force: np.ndarray
    assignments: list
    knots: list
    safe_height: float
    workcell: Workcell
    timing: Timing = field(default_factory=Timing)
    penetration: list = field(default_factory=list)
    scene: str = ""
    envelope: float = GRIPPER_ENVELOPE

    @property
    def duration(self) -> float:
        """The motion's duration [s]."""
        return float(self.times[-1])

    def html(self, scene=None) -> str:
        """The motion's browser view, a self-contained HTML page (see
        :func:`regrasp.viz.viewer.motion_html`): with ``scene``, the gripper holding its object;
        without, the gripper as its axes."""
        from ..viz.viewer import motion_html

        return motion_html(scene, self)

    def _repr_html_(self) -> str:
        """Jupyter's display: the motion's browser view in a frame (the gripper as its axes)."""
        from ..viz.viewer import iframe

        return iframe(self.html())

    def to_trajectory(self, arm=None):
        """The motion as a :class:`~regrasp.execution.trajectory.Trajectory` for the trajectory
        file (docs/trajectory-file.md): of a free gripper (robot None, no joints), or with
        ``arm`` (an :class:`~regrasp.execution.arm.ArmTrajectory` of this motion) the robot's
        name, joint names, and per sample the arm's times [s] (time-parametrised within its joint
        limits) with its joint positions [rad], velocities [rad/s] and accelerations [rad/s²]."""
        from .trajectory import PushRecord, Trajectory

        if arm is not None and len(arm.q) != len(self.times):
            raise ArgumentError(f"invalid `arm`: {len(self.times)} samples of joint positions (got {len(arm.q)})", "arm")
        robot, names, q = (None, [], np.zeros((len(self.times), 0))) if arm is None else \
            (arm.robot, list(arm.joint_names), np.asarray(arm.q, float))
        times = self.times.copy() if arm is None else np.array(arm.times, float)
        qd, qdd = (None, None) if arm is None else (getattr(arm, "qd", None), getattr(arm, "qdd", None))
        return Trajectory(self.scene or "scene", self.workcell.name, robot, names, times,
                          q, self.gripper.copy(), self.grip_force.copy(),
                          list(self.labels), self.push.copy(),
                          [PushRecord(a.pusher, a.feature, a.first, a.last, a.frame.copy(), a.tilt, d)
                           for a, d in zip(self.assignments, self.penetration)], qd, qdd)

    def to_dict(self) -> dict:
        """The motion as JSON-ready lists: per-sample arrays, and per push its pusher, feature,
        path indices, feature frame (m, unit quaternion), gravity tilt [rad] and penetration [m]."""
        return {
            "workcell": self.workcell.name,
            "duration_s": self.duration,
            "times": self.times.tolist(), "gripper": self.gripper.tolist(), "object": self.object.tolist(),
            "in_hand": self.in_hand.tolist(), "labels": list(self.labels), "push": self.push.tolist(),
            "grip_force": self.grip_force.tolist(),
            "pushes": [{"pusher": a.pusher, "feature": a.feature, "first": a.first, "last": a.last,
                        "frame": a.frame.tolist(), "tilt": a.tilt, "penetration": d}
                       for a, d in zip(self.assignments, self.penetration)],
            "knots": [list(k) for k in self.knots],
            "safe_height": self.safe_height,
        }


def _plan_arrays(scene, plan):
    from ..planning.plan import Plan

    if not isinstance(plan, Plan):
        raise ArgumentError(f"invalid `plan`: a regrasp Plan (got {type(plan).__name__})", "plan")
    plan.check_for(scene)
    dim = scene.dimension
    poses = np.asarray(plan.poses, float)
    if dim == 2:
        O = np.array([P.planar_to_spatial(q) for q in poses])
    else:
        O = poses.copy()
        O[:, 3:] /= np.linalg.norm(O[:, 3:], axis=1, keepdims=True)
    twists = plan.pusher_twists if dim == 3 else [None] * len(poses)
    return poses, O, list(plan.pushers), twists


def grip_force(scene) -> float:
    """The scene's grip force per finger [N]."""
    return float(scene.grip_force)


class _Samples:
    """The samples of a world motion as it is built: times [s], gripper and in-hand poses, labels
    and push indices; moves along straight lines (:meth:`move`) or by single samples
    (:meth:`emit`)."""

    def __init__(self, timing: Timing):
        self.timing = timing
        self.t, self.G, self.O, self.label, self.push = [0.0], [], [], [], []

    def mark(self) -> int:
        """The number of samples so far (for :meth:`rollback`)."""
        return len(self.G)

    def rollback(self, n: int):
        """Drop the samples after the first ``n``."""
        self.t, self.G, self.O = self.t[:n] if n else [0.0], self.G[:n], self.O[:n]
        self.label, self.push = self.label[:n], self.push[:n]

    def first(self, G, Oh):
        self.G.append(np.asarray(G, float)), self.O.append(np.asarray(Oh, float))
        self.label.append("start"), self.push.append(-1)

    def emit(self, G, Oh, label, k, dt):
        self.t.append(self.t[-1] + dt)
        self.G.append(np.asarray(G, float)), self.O.append(np.asarray(Oh, float))
        self.label.append(label), self.push.append(k)

    def steps(self, a, b, v, w) -> tuple[int, float]:
        """The number of samples and the time [s] to go from pose ``a`` to ``b`` at ``v`` [m/s], ``w`` [rad/s]."""
        T = max(np.linalg.norm(b[:3] - a[:3]) / v, P.quat_angle(a[3:], b[3:]) / w, self.timing.sample_period)
        return max(1, math.ceil(T / self.timing.sample_period - 1e-9)), T

    def move(self, to, Oh, label, k, fast: bool):
        """A straight move of the gripper to ``to`` holding the object at ``Oh``, at the
        transfer speeds (``fast``) or the push speeds at its peak, minimum-jerk (:func:`eased`)."""
        a, tm = self.G[-1], self.timing
        if np.linalg.norm(to[:3] - a[:3]) < 1e-12 and P.quat_angle(a[3:], to[3:]) < 1e-12:
            return
        v, w = (tm.move_speed, tm.move_turn) if fast else (tm.push_speed, tm.push_turn)
        n, T = self.steps(a, to, v / EASE_PEAK, w / EASE_PEAK)
        Gs = P.interpolate(a, to, eased(np.arange(1, n + 1) / n))
        Gs[-1] = to
        t0 = self.t[-1]
        self.t += list(t0 + T * np.arange(1, n + 1) / n)
        self.G += list(Gs)
        self.O += [np.asarray(Oh, float)] * n
        self.label += [label] * n
        self.push += [k] * n


@dataclass(frozen=True)
class _Layout:
    """What the segment builders share: the plan's object poses ``O`` (n, 7) and pusher twists,
    the workcell's top + the clearance ``safe`` [m], the object's ``reach`` [m], the timing and
    the gripper's ``envelope`` [m], the ``robot``'s base position [m] (transfers beside a
    downward-pushing feature go down on its side), the ``spans`` of the workcell's contacts
    (their kinds, axes and reach [m], :func:`spans`)."""
    O: np.ndarray
    twists: list
    safe: float
    reach: float
    timing: Timing
    envelope: float = GRIPPER_ENVELOPE
    robot: np.ndarray | None = None
    spans: dict = field(default_factory=dict)

    def lifted(self, G, *others):
        """``G`` raised to the safe height of its orientation and ``others``' (:meth:`height`)."""
        return np.r_[G[:2], max(G[2], *(float(self.height(g)) for g in (G, *others))), G[3:]]

    def height(self, G):
        """The safe height [m] of a gripper at pose ``G``'s orientation (or of each row of an
        (n, 7) array): the workcell's top + the clearance + the larger of the object's reach and
        how far the gripper's body hangs below its origin (its +z's world z is 1 − 2(qx² + qy²))."""
        q = np.asarray(G, float)[..., 3:]
        z = 1.0 - 2.0 * (q[..., 1] ** 2 + q[..., 2] ** 2)
        return self.safe + np.maximum(self.reach, GRIPPER_RADIUS + np.maximum(0.0, -self.envelope * z))

    def along(self, G, a: Assignment):
        """How the gripper at pose ``G`` leaves push ``a``'s feature when it pushes downward
        (None for other features): ``(d, lengthwise)``, ``d`` a unit direction towards the robot.
        Along an edge (its frame's x, sloped as the edge) when that is within
        :data:`ALONG_MAX` of square to the grasp axis (an edge between the fingers passes
        between them only lengthwise), else horizontally across the feature (its frame's y)."""
        R = P.quat_matrix(a.frame[3:])
        if R[2, 2] > -np.cos(DOWNWARD):
            return None
        grasp = P.quat_rotate(G[3:], [0.0, 1, 0])
        body = self.spans.get(a.feature)
        if body is not None and body[0] == "edge" and abs(R[:, 0] @ grasp) <= ALONG_MAX:
            d, lengthwise = R[:, 0].copy(), True
        else:
            d = np.r_[R[:2, 1], 0.0]
            d = d / np.linalg.norm(d) if np.linalg.norm(d) > 1e-9 else np.r_[1.0, 0, 0]
            lengthwise = False
        if self.robot is not None and d[:2] @ (self.robot[:2] - G[:2]) < 0:
            d = -d  # on the robot's side: the arm does not reach over the feature
        return d, lengthwise

    def beside(self, G, a: Assignment):
        """``G`` moved off a downward-pushing feature (:meth:`along`) until the object and the
        gripper's body are the clearance past the feature's end (None for other features)."""
        way = self.along(G, a)
        if way is None:
            return None
        d = way[0]
        _, axes, half = self.spans.get(a.feature, ("", np.eye(3)[:2], np.zeros(2)))
        end = float((a.frame[:3] - G[:3]) @ d) + float(half @ np.abs(axes @ d))
        return np.r_[G[:3] + (max(end, self.reach) + self.reach + self.timing.clearance + GRIPPER_RADIUS) * d, G[3:]]

    def gap(self, G, a: Assignment) -> float:
        """The pre-contact distance [m] of push ``a`` with the gripper at ``G``'s orientation:
        :data:`SLIDE_GAP` under a feature it slides under lengthwise, else the clearance."""
        way = self.along(G, a)
        return SLIDE_GAP if way is not None and way[1] else self.timing.clearance

    def meet(self, a: Assignment, pusher):
        """The gripper's pose in contact with push ``a``'s feature and its pre-contact pose
        (:func:`meeting`, :meth:`gap` away), for the pusher's contact frame ``pusher``
        (gripper frame)."""
        G0, _ = meeting(a.frame, pusher, 0.0)
        return meeting(a.frame, pusher, self.gap(G0, a))

    def contact(self, a: Assignment):
        """The gripper's pose in contact at push ``a``'s start and its pre-contact pose."""
        return self.meet(a, P.compose(self.O[a.first], a.contact.frame))


def spans(contacts) -> dict:
    """Each contact's body (:meth:`Workcell.contacts`; an edge's bar, a corner's tip of radius
    :data:`~regrasp.workcell.shapes.EDGE_RADIUS`): name → (kind, its frame's x and y axes in
    the world (2, 3), how far [m] it reaches from the frame's origin along each (2,))."""
    out = {}
    for c in contacts:
        R = P.quat_matrix(c.frame[3:])
        half = ((c.length / 2 + EDGE_RADIUS, EDGE_RADIUS) if c.kind == "edge" else
                (float(c.extent[0]), float(c.extent[1])) if c.kind == "face" else (EDGE_RADIUS, EDGE_RADIUS))
        out[c.name] = (c.kind, R[:, :2].T.copy(), np.asarray(half, float))
    return out


def meeting(frame, pusher, clearance: float) -> tuple[np.ndarray, np.ndarray]:
    """(G0, pre): the gripper's world pose at which the feature's contact ``frame`` (world; m,
    unit quaternion) meets the pusher's contact frame ``pusher`` (gripper frame), ``G0 = F ∘ P⁻¹``,
    and the pre-contact pose ``clearance`` [m] back from it along the feature's push direction."""
    G0 = P.compose(frame, P.inverse(pusher))
    away = clearance * P.quat_rotate(np.asarray(frame, float)[3:], [0.0, 0, 1])
    return G0, np.r_[G0[:3] + away, G0[3:]]


class Segments:
    """Free moves of the gripper from world pose ``start`` (m, unit quaternion) built by the
    world motion's segment builders — the switch-overs of a closed loop: :meth:`retreat`,
    :meth:`transfer`, :meth:`approach`, each holding the object at a given in-hand pose; ``safe``
    [m]: the workcell's top + the clearance (``Workcell.top()``), ``reach`` [m] the object's from
    the gripper origin, ``envelope`` [m] the gripper body's length, ``robot`` the robot base's
    position [m] (or None), ``contacts`` the workcell's (:meth:`Workcell.contacts`, for the
    transfers beside a downward-pushing feature). :attr:`times` [s] and
    :attr:`poses` (m, unit quaternion): the samples so far, ``start`` at time 0 first."""

    def __init__(self, timing: Timing, safe: float, reach: float, start, envelope: float = GRIPPER_ENVELOPE,
                 robot=None, contacts=()):
        self.samples = _Samples(timing)
        self.samples.first(start, np.r_[0.0, 0, 0, 1, 0, 0, 0])
        self.layout = _Layout(np.zeros((0, 7)), [], float(safe), float(reach), timing, float(envelope),
                              None if robot is None else np.asarray(robot, float), spans(contacts))

    @property
    def times(self) -> list:
        """The samples' times [s]."""
        return self.samples.t[:len(self.samples.G)]

    @property
    def poses(self) -> list:
        """The samples' gripper world poses (m, unit quaternion)."""
        return self.samples.G

    def retreat(self, a: Assignment, Oh):
        """Back from push ``a``'s feature by the pre-contact distance (and off a downward one), holding ``Oh``."""
        _retreat(self.samples, self.layout, a, Oh)

    def transfer(self, pre, a: Assignment, Oh):
        """Up to the safe height, over and down to push ``a``'s pre-contact pose ``pre``, holding ``Oh``."""
        _transfer(self.samples, self.layout, a, pre, Oh)

    def meeting(self, a: Assignment, pusher):
        """The gripper's pose in contact with push ``a``'s feature and its pre-contact pose, for
        the pusher's contact frame ``pusher`` (gripper frame; :meth:`_Layout.meet`)."""
        return self.layout.meet(a, pusher)

    def approach(self, G0, a: Assignment, Oh):
        """Into contact ``G0`` with push ``a``'s feature at the push speeds, holding ``Oh``."""
        _approach(self.samples, self.layout, a, G0, Oh)


def _transfer(S: _Samples, L: _Layout, a: Assignment, pre, Oh=None):
    """Up to the safe height, over, and down to push ``a``'s pre-contact pose ``pre`` (beside a
    downward-pushing feature: over to beside it, down, and across, or, sliding under it
    lengthwise, along it as part of the approach), holding ``Oh`` (default: the plan's pose at
    the push's start)."""
    Oh = L.O[a.first] if Oh is None else Oh
    side = L.beside(pre, a)
    here = S.G[-1]
    S.move(L.lifted(here, pre), Oh, "transfer", -1, True)
    for to in [L.lifted(pre, here)] if side is None else [L.lifted(side, here), side]:
        S.move(to, Oh, "transfer", -1, True)
    lengthwise = side is not None and L.along(pre, a)[1]
    S.move(pre, Oh, "approach" if lengthwise else "transfer", a.index if lengthwise else -1, True)


def _approach(S: _Samples, L: _Layout, a: Assignment, G0, Oh=None):
    """From the pre-contact pose into contact ``G0`` at the push speeds."""
    S.move(G0, L.O[a.first] if Oh is None else Oh, "approach", a.index, False)


def _push(S: _Samples, L: _Layout, a: Assignment, knots: list):
    """Push ``a``'s steps: the gripper moving so that the feature renders the pusher's motion
    (see the module's doc); appends each knot's ``(path index, sample index)`` to ``knots``."""
    O, Pk = L.O, P.compose(L.O[a.first], a.contact.frame)
    knots.append((a.first, len(S.G) - 1))
    for k in range(a.first + 1, a.last + 1):
        xo = np.array(P.twist_between(O[k - 1], O[k]))
        xp = xo if L.twists[k] is None else np.asarray(L.twists[k], float)
        Gk_end = P.compose(a.frame, P.inverse(_moved(O[k - 1], xp, 1.0, Pk)))
        n, T = S.steps(S.G[-1], Gk_end, L.timing.push_speed, L.timing.push_turn)
        for i in range(1, n + 1):
            s = i / n
            Ps = _moved(O[k - 1], xp, s, Pk)
            Os = O[k] if i == n else P.integrate(O[k - 1], xo, s)
            S.emit(P.compose(a.frame, P.inverse(Ps)), Os, "push", a.index, T / n)
        Pk = _moved(O[k - 1], xp, 1.0, Pk)
        knots.append((k, len(S.G) - 1))


def _dwell(S: _Samples, L: _Layout, a: Assignment):
    """Holds the push's end for ``timing.dwell`` (a real arm lags its reference under the push's
    load: it settles there before retreating)."""
    n = math.ceil(L.timing.dwell / L.timing.sample_period - 1e-9)
    for _ in range(n):
        S.emit(S.G[-1], L.O[a.last], "push", a.index, L.timing.dwell / n)


def _retreat(S: _Samples, L: _Layout, a: Assignment, Oh=None):
    """Back by the pre-contact distance (:meth:`_Layout.gap`) along the feature's push
    direction, then (beside a downward-pushing feature) off it: across it, or along it as part of
    the retreat."""
    G, Oh = S.G[-1], L.O[a.last] if Oh is None else Oh
    away = L.gap(G, a) * P.quat_rotate(a.frame[3:], [0.0, 0, 1])
    S.move(np.r_[G[:3] + away, G[3:]], Oh, "retreat", a.index, False)
    side = L.beside(S.G[-1], a)
    if side is not None:
        lengthwise = L.along(S.G[-1], a)[1]
        S.move(side, Oh, "retreat" if lengthwise else "transfer", a.index if lengthwise else -1, True)


def world_motion(scene, plan, workcell: Workcell | None = None, timing: Timing = Timing(), start=None,
                 max_tilt: float = MAX_TILT, envelope: float = GRIPPER_ENVELOPE, exclude=()) -> WorldMotion:
    """The gripper's world motion executing ``plan`` (a :class:`~regrasp.Plan` of ``scene``) in
    ``workcell`` (default: :func:`~regrasp.execution.default_workcell` of the scene), timed by
    ``timing``; ``start``: the gripper's world pose (m, unit quaternion) to begin from (default:
    above the first push's pre-contact pose, at the safe height); ``max_tilt`` [rad]: the most a
    push may turn the plan's gravity from the world's (default
    :data:`~regrasp.execution.assignment.MAX_TILT`; see :func:`~regrasp.execution.assign`);
    ``envelope`` [m]: the length of the gripper's body along its +z (default
    :data:`GRIPPER_ENVELOPE`), kept clear of the workcell in transfers at the safe height;
    ``exclude``: ``(push index, contact name)`` pairs not to use (e.g. where the arm cannot
    follow the push, :func:`~regrasp.execution.arm.arm_motion`).
    ExecutionError naming the push when no feature serves it or the object would go deeper than
    :data:`~regrasp.execution.motion_check.PENETRATION_LIMIT` into its feature, and naming the push or transfer and the body
    when the object would hit the table or a feature (see the module's doc)."""
    from ..scene.planar import Scene
    from ..scene.spatial import Scene3D

    if not isinstance(scene, (Scene, Scene3D)):
        raise ArgumentError(f"invalid `scene`: a regrasp Scene or Scene3D (got {type(scene).__name__})", "scene")
    if scene.dimension == 2 and scene.kind != "grasp":
        raise ArgumentError("invalid `scene`: a surface scene has no gripper to move (a [grasp] scene is needed)", "scene")
    if not isinstance(timing, Timing):
        raise ArgumentError(f"invalid `timing`: a Timing (got {type(timing).__name__})", "timing")
    if isinstance(envelope, bool) or not isinstance(envelope, (int, float)) or not (math.isfinite(envelope) and 0 <= envelope <= 10):
        raise ArgumentError(f"invalid `envelope`: a length in [0, 10] m (got {envelope!r:.40})", "envelope")
    workcell = default_workcell(scene) if workcell is None else workcell
    if not isinstance(workcell, Workcell):
        raise ArgumentError(f"invalid `workcell`: a Workcell (got {type(workcell).__name__})", "workcell")
    poses, O, pushers, twists = _plan_arrays(scene, plan)
    if len(poses) < 2:
        raise ArgumentError("invalid `plan`: it has no pushes (one path entry)", "plan.path")
    reach = float(np.linalg.norm(P.transform_rows(O, object_points(scene)), axis=2).max())
    safe = workcell.top() + timing.clearance
    contacts = workcell.contacts()
    options = candidates(scene, poses, pushers, workcell, max_tilt, contacts)
    L = _Layout(O, twists, safe, reach, timing, float(envelope), np.asarray(workcell.robot.base[:3], float),
                spans(contacts))
    S = _Samples(timing)
    check = _Check(scene, workcell, contacts)
    knots, assignments, depth = [], [], []
    for choices in options:
        first_error = None
        for a in choices:          # the best contact first; another when its motion collides
            if (a.index, a.feature) in exclude:
                continue
            n0, k0 = S.mark(), len(knots)
            G0, pre = L.contact(a)
            if not S.G:
                S.first(L.lifted(pre) if start is None else _check_start(start), O[a.first])
            _transfer(S, L, a, pre)
            _approach(S, L, a, G0)
            _push(S, L, a, knots)
            _dwell(S, L, a)
            _retreat(S, L, a)
            try:
                d = check(S, n0, a, assignments)
            except (ArgumentError, ExecutionError) as e:
                first_error = first_error or e
                S.rollback(n0)
                del knots[k0:]
                continue
            assignments.append(a), depth.append(d)
            break
        else:
            if first_error is None:
                a = choices[0]
                raise ExecutionError(f"{_what(a)}: every contact of workcell `{workcell.name}` that serves it is "
                                     f"excluded ({', '.join(c.feature for c in choices)})",
                                     f"plan.path[{a.first + 1}].pusher")
            raise first_error
    n0 = S.mark()
    S.move(L.lifted(S.G[-1]), O[-1], "transfer", -1, True)
    check(S, n0, None, assignments)
    G, Oh = np.array(S.G), np.array(S.O)
    W = P.compose_rows(G, Oh)
    return WorldMotion(np.array(S.t[:len(G)]), G, W, Oh, S.label, np.array(S.push, int), np.full(len(G), grip_force(scene)),
                       assignments, knots, float(np.max(L.height(G))), workcell, timing, depth, scene.name,
                       float(envelope))


def _moved(O, xi, s: float, Pk) -> np.ndarray:
    """The pusher frame ``Pk`` (gripper frame) moved by ``s`` of the pusher twist ``xi`` (m/s,
    rad/s) expressed in the object frame ``O`` (m, unit quaternion): ``O exp(s xi) O⁻¹ Pk``."""
    return P.compose(P.integrate(O, xi, s), P.inverse(O), Pk)


def _check_start(start) -> np.ndarray:
    s0 = np.asarray(start, float) if isinstance(start, (list, tuple, np.ndarray)) else None
    if s0 is None or s0.shape != (7,) or not np.all(np.isfinite(s0)) or np.linalg.norm(s0[3:]) < 1e-6:
        raise ArgumentError(f"invalid `start`: a pose [x, y, z, qw, qx, qy, qz] (m, quaternion) (got {start!r:.80})", "start")
    return np.r_[s0[:3], s0[3:] / np.linalg.norm(s0[3:])]
