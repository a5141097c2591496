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

Around each push: a transfer down to a pre-contact pose ``timing.clearance`` away from the
feature along its push direction, the approach, the push, the retreat by the clearance, and a
transfer up to the safe height (every feature's top + clearance + the object's reach from the
gripper origin), over (the switch-over's turn is made there) and down to the next push. Under a
feature that pushes downward (a ledge), the transfers go down and up beside it, moved
horizontally across the feature by twice the object's reach and the clearance.

A push whose object goes below the table top (during its approach, push or retreat) is refused,
naming the push, as is one whose object goes deeper than :data:`PENETRATION_LIMIT` into its feature (its points
along its edges, :func:`edge_points`, behind the contact plane, within a face's rectangle) is
refused, naming the push."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .. import pose as P
from ..errors import ArgumentError
from ..workcell.default import default_workcell
from ..workcell.description import Workcell
from .assignment import MAX_TILT, Assignment, assign

#: The deepest [m] the object may go into a feature during a push (the plan is rendered exactly
#: only if it does not go through it).
PENETRATION_LIMIT = 0.5e-3
#: A feature pushes downward when its push direction is within this angle [rad] of the world's −z.
DOWNWARD = np.pi / 3
#: A free move (transfer, approach, retreat) follows the minimum-jerk profile s(τ) = 10τ³ − 15τ⁴ + 6τ⁵
#: (zero speed and acceleration at both ends: no jolt on the held object); its peak speed is this
#: many times its mean, so its duration is stretched by it to keep the peak at the Timing's speed.
EASE_PEAK = 1.875
#: Sample labels, in the order a push meets them.
LABELS = ("start", "transfer", "approach", "push", "retreat")


def eased(tau):
    """The minimum-jerk progress s(τ) = 10τ³ − 15τ⁴ + 6τ⁵ in [0, 1] at times τ in [0, 1] (of a move)."""
    tau = np.asarray(tau, float)
    return tau ** 3 * (10 - 15 * tau + 6 * tau ** 2)


@dataclass(frozen=True)
class Timing:
    """Speeds and spacing of a world motion, stated once: the gripper's speed while pushing,
    approaching and retreating (``push_speed`` [m/s], ``push_turn`` [rad/s]) and in free transfers
    (``move_speed`` [m/s], ``move_turn`` [rad/s]); the ``clearance`` [m] of pre-contact poses; the
    longest time between samples ``sample_period`` [s]; the ``dwell`` [s] held at each push's end
    (a real arm lags its reference under the push's load: it settles there before retreating)."""
    push_speed: float = 0.01
    push_turn: float = 0.2
    move_speed: float = 0.1
    move_turn: float = 1.0
    clearance: float = 0.02
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
    (one of :data:`LABELS` per sample); ``push`` (n,) the push index of approach, push and retreat samples (−1 in transfers);
    ``grip_force`` (n,) [N] per finger. ``assignments``: the feature of each push; ``knots``:
    ``(path index, sample index)`` of each plan knot of each push (a knot shared by two pushes
    appears once for each); ``safe_height`` [m] of transfers; ``workcell``; ``timing``;
    ``penetration`` [m] per push: how far the object's points (:func:`edge_points`) go behind
    the feature's contact plane (within a face's rectangle) during the push (0 for a sticking push of a convex object; a
    plan whose object turns against its pusher, e.g. a pivot on a patch, can go through a face
    larger than the patch); ``scene``: the scene's name."""
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
        name, joint names and joint positions [rad] per sample."""
        from .trajectory import PushRecord, Trajectory

        if arm is not None and len(arm.q) != len(self.times):
            raise ArgumentError(f"invalid `arm`: {len(self.times)} samples of joint positions (got {len(arm.q)})", "arm")
        robot, names, q = (None, [], np.zeros((len(self.times), 0))) if arm is None else \
            (arm.robot, list(arm.joint_names), np.asarray(arm.q, float))
        return Trajectory(self.scene or "scene", self.workcell.name, robot, names, self.times.copy(),
                          q, self.gripper.copy(), self.grip_force.copy(),
                          list(self.labels), self.push.copy(),
                          [PushRecord(a.pusher, a.feature, a.first, a.last, a.frame.copy(), a.tilt, d)
                           for a, d in zip(self.assignments, self.penetration)])

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


def object_points(scene) -> np.ndarray:
    """Points (k, 3) [m] of the object in its frame whose reach bounds the object's: the planar
    outline (in the x-z plane), a mesh's or box's vertices, a sphere's centre ± radius on each axis."""
    if scene.dimension == 2:
        out = np.asarray(scene.outline, float)
        return np.column_stack([out[:, 0], np.zeros(len(out)), out[:, 1]])
    r = scene._core.sphere
    if r is not None:
        return np.vstack([np.eye(3) * r, -np.eye(3) * r])
    return np.asarray(scene.mesh()[0], float)


#: The spacing [m] of the points along the object's edges at which its penetration is measured.
EDGE_SPACING = 1e-3


def edge_points(scene) -> np.ndarray:
    """Points (k, 3) [m] of the object in its frame along its edges, ``EDGE_SPACING`` apart: the
    planar outline's sides (x-z plane), a mesh's triangle edges, a sphere's 3 great circles."""
    if scene.dimension == 3 and scene._core.sphere is not None:
        r = scene._core.sphere
        a = np.linspace(0, 2 * np.pi, max(8, int(2 * np.pi * r / EDGE_SPACING)), endpoint=False)
        c, s_ = r * np.cos(a), r * np.sin(a)
        z = np.zeros_like(a)
        return np.vstack([np.c_[c, s_, z], np.c_[c, z, s_], np.c_[z, c, s_]])
    if scene.dimension == 2:
        v = object_points(scene)
        edges = [(v[i], v[(i + 1) % len(v)]) for i in range(len(v))]
    else:
        v, t = scene.mesh()
        v, t = np.asarray(v, float), np.asarray(t, int)
        edges = {tuple(sorted((int(a), int(b)))) for tri in t for a, b in ((tri[0], tri[1]), (tri[1], tri[2]), (tri[2], tri[0]))}
        edges = [(v[a], v[b]) for a, b in sorted(edges)]
    out = [v]
    for a, b in edges:
        n = max(1, int(np.ceil(np.linalg.norm(b - a) / EDGE_SPACING)))
        out.append(a + np.linspace(0, 1, n + 1)[:, None] * (b - a))
    return np.vstack(out)


def grip_force(scene) -> float:
    """The scene's grip force per finger [N]."""
    return float(scene.grip_force if scene.dimension == 2 else scene._core.grip_force)


def meeting(frame, pusher, clearance: float) -> tuple[np.ndarray, np.ndarray]:
    """(G0, pre): the gripper's world pose at which the feature's contact ``frame`` (world; m,
    unit quaternion) meets the pusher's contact frame ``pusher`` (gripper frame), ``G0 = F ∘ P⁻¹``,
    and the pre-contact pose ``clearance`` [m] back from it along the feature's push direction."""
    G0 = P.compose(frame, P.inverse(pusher))
    away = clearance * P.quat_rotate(np.asarray(frame, float)[3:], [0.0, 0, 1])
    return G0, np.r_[G0[:3] + away, G0[3:]]


class Segments:
    """A gripper motion being built sample by sample (the free moves of :func:`world_motion`,
    also the switch-overs of a closed loop): ``S`` holds per sample the times ``t`` [s] (one
    more: the next sample's start), gripper world poses ``G`` and in-hand object poses ``O``
    (m, unit quaternion), ``label`` and ``push`` index; ``safe`` [m] the transfers' height,
    ``reach`` [m] the object's from the gripper origin."""

    def __init__(self, timing: Timing, safe: float, reach: float, start=None, t0: float = 0.0):
        self.timing, self.safe, self.reach = timing, float(safe), float(reach)
        self.S: dict = {"t": [float(t0)], "G": [], "O": [], "label": [], "push": []}
        if start is not None:
            self.S["G"].append(np.asarray(start, float))

    def emit(self, G, Oh, label, k, dt):
        """Appends gripper pose ``G`` with in-hand pose ``Oh``, ``label``, push ``k``, ``dt`` [s] after the last."""
        S = self.S
        S["t"].append(S["t"][-1] + dt)
        S["G"].append(np.asarray(G, float)), S["O"].append(np.asarray(Oh, float))
        S["label"].append(label), S["push"].append(k)

    def steps(self, a, b, v, w) -> tuple[int, float]:
        """(samples, duration [s]) of a move from pose ``a`` to ``b`` at ``v`` [m/s], ``w`` [rad/s]."""
        T = max(np.linalg.norm(b[:3] - a[:3]) / v, P.quat_angle(a[3:], b[3:]) / w, self.timing.sample_period)
        return max(1, math.ceil(T / self.timing.sample_period - 1e-9)), T

    def move(self, to, Oh, label, k, v, w):
        """A minimum-jerk move from the last pose to ``to`` at peak speeds ``v`` [m/s], ``w`` [rad/s]."""
        S = self.S
        a = S["G"][-1]
        if np.linalg.norm(to[:3] - a[:3]) < 1e-12 and P.quat_angle(a[3:], to[3:]) < 1e-12:
            return
        n, T = self.steps(a, to, v / EASE_PEAK, w / EASE_PEAK)
        Gs = P.interpolate(a, to, eased(np.arange(1, n + 1) / n))
        Gs[-1] = to
        t0 = S["t"][-1]
        S["t"] += list(t0 + T * np.arange(1, n + 1) / n)
        S["G"] += list(Gs)
        S["O"] += [np.asarray(Oh, float)] * n
        S["label"] += [label] * n
        S["push"] += [k] * n

    def lifted(self, G):
        """Gripper pose ``G`` raised to the safe height (when below it)."""
        return np.r_[G[:2], max(G[2], self.safe), G[3:]]

    def beside(self, G, a):
        """``G`` moved horizontally across a downward-pushing feature (None for other features)."""
        z = P.quat_rotate(a.frame[3:], [0.0, 0, 1])
        if z[2] > -np.cos(DOWNWARD):
            return None
        d = P.quat_rotate(a.frame[3:], [0.0, 1, 0])
        d = np.r_[d[:2], 0.0]
        d = d / np.linalg.norm(d) if np.linalg.norm(d) > 1e-9 else np.r_[1.0, 0, 0]
        return np.r_[G[:3] + (2 * self.reach + self.timing.clearance) * d, G[3:]]

    def transfer(self, pre, a: Assignment, Oh):
        """Up to the safe height, over (beside ``a``'s feature when it pushes downward) and down
        to the pre-contact pose ``pre`` of push ``a``, holding in-hand pose ``Oh``."""
        tm = self.timing
        side = self.beside(pre, a)
        self.move(self.lifted(self.S["G"][-1]), Oh, "transfer", -1, tm.move_speed, tm.move_turn)
        for to in ([self.lifted(pre)] if side is None else [self.lifted(side), side]) + [pre]:
            self.move(to, Oh, "transfer", -1, tm.move_speed, tm.move_turn)

    def approach(self, G0, a: Assignment, Oh):
        """From the pre-contact pose to ``G0``, where ``a``'s feature touches the object, at push speed."""
        self.move(G0, Oh, "approach", a.index, self.timing.push_speed, self.timing.push_turn)

    def retreat(self, a: Assignment, Oh):
        """Back from ``a``'s feature by the clearance at push speed (and beside a downward one)."""
        tm, G = self.timing, self.S["G"][-1]
        away = tm.clearance * P.quat_rotate(a.frame[3:], [0.0, 0, 1])
        self.move(np.r_[G[:3] + away, G[3:]], Oh, "retreat", a.index, tm.push_speed, tm.push_turn)
        side = self.beside(self.S["G"][-1], a)
        if side is not None:
            self.move(side, Oh, "transfer", -1, tm.move_speed, tm.move_turn)


def world_motion(scene, plan, workcell: Workcell | None = None, timing: Timing = Timing(), start=None,
                 max_tilt: float = MAX_TILT) -> WorldMotion:
    """The gripper's world motion executing ``plan`` (a :class:`~regrasp.Plan` of ``scene``) in
    ``workcell`` (default: :func:`~regrasp.workcell.default_workcell` of the scene), timed by
    ``timing``; ``start``: the gripper's world pose (m, unit quaternion) to begin from (default:
    above the first push's pre-contact pose, at the safe height); ``max_tilt`` [rad]: the most a
    push may turn the plan's gravity from the world's (default
    :data:`~regrasp.execution.assignment.MAX_TILT`; see :func:`~regrasp.execution.assign`).
    ArgumentError naming the push when no feature serves it or the object would go deeper than
    :data:`PENETRATION_LIMIT` into its feature."""
    from ..scene.planar import Scene
    from ..scene.spatial import Scene3D

    if not isinstance(scene, (Scene, Scene3D)):
        raise ArgumentError(f"invalid `scene`: a regrasp Scene or Scene3D (got {type(scene).__name__})", "scene")
    if scene.dimension == 2 and scene.kind != "grasp":
        raise ArgumentError("invalid `scene`: a surface scene has no gripper to move (a [grasp] scene is needed)", "scene")
    if not isinstance(timing, Timing):
        raise ArgumentError(f"invalid `timing`: a Timing (got {type(timing).__name__})", "timing")
    workcell = default_workcell(scene) if workcell is None else workcell
    if not isinstance(workcell, Workcell):
        raise ArgumentError(f"invalid `workcell`: a Workcell (got {type(workcell).__name__})", "workcell")
    poses, O, pushers, twists = _plan_arrays(scene, plan)
    if len(poses) < 2:
        raise ArgumentError("invalid `plan`: it has no pushes (one path entry)", "plan.path")
    pts = object_points(scene)
    reach = max(float(np.max(np.linalg.norm(P.transform(o, pts), axis=1))) for o in O)
    safe = workcell.top() + timing.clearance + reach
    assignments = assign(scene, poses, pushers, workcell, max_tilt)
    force = grip_force(scene)

    seg = Segments(timing, safe, reach)
    S, emit, steps, move, lifted = seg.S, seg.emit, seg.steps, seg.move, seg.lifted

    knots = []
    for a in assignments:
        Pk = P.compose(O[a.first], a.contact.frame)
        G0, pre = meeting(a.frame, Pk, timing.clearance)
        if not S["G"]:
            s0 = lifted(pre) if start is None else _check_start(start)
            S["G"].append(s0), S["O"].append(O[a.first]), S["label"].append("start"), S["push"].append(-1)
        seg.transfer(pre, a, O[a.first])
        seg.approach(G0, a, O[a.first])
        knots.append((a.first, len(S["G"]) - 1))
        for k in range(a.first + 1, a.last + 1):
            xo = np.array(P.twist_between(O[k - 1], O[k]))
            xp = xo if twists[k] is None else np.asarray(twists[k], float)
            Gk_end = P.compose(a.frame, P.inverse(_moved(O[k - 1], xp, 1.0, Pk)))
            n, T = steps(S["G"][-1], Gk_end, timing.push_speed, timing.push_turn)
            for i in range(1, n + 1):
                s = i / n
                Ps = _moved(O[k - 1], xp, s, Pk)
                Os = O[k] if i == n else P.integrate(O[k - 1], xo, s)
                emit(P.compose(a.frame, P.inverse(Ps)), Os, "push", a.index, T / n)
            Pk = _moved(O[k - 1], xp, 1.0, Pk)
            knots.append((k, len(S["G"]) - 1))
        Gend = S["G"][-1]
        for _ in range(math.ceil(timing.dwell / timing.sample_period - 1e-9)):  # hold: the arm settles on the push's end
            emit(Gend, O[a.last], "push", a.index, timing.dwell / math.ceil(timing.dwell / timing.sample_period - 1e-9))
        seg.retreat(a, O[a.last])
    move(lifted(S["G"][-1]), O[-1], "transfer", -1, timing.move_speed, timing.move_turn)

    G, Oh = np.array(S["G"]), np.array(S["O"])
    W = P.compose_rows(G, Oh)
    labels, push = S["label"], np.array(S["push"], int)
    pts = edge_points(scene)
    depth = []
    extents = {c.name: c.extent for c in workcell.contacts()}
    for a in assignments:
        js = [j for j in np.flatnonzero(push == a.index) if labels[j] == "push"]
        rel = P.compose_rows(np.repeat(P.inverse(a.frame)[None], len(js), axis=0), W[js])
        depth.append(max(0.0, -min(_behind(P.transform(r, pts), extents[a.feature]) for r in rel)))
        near = np.flatnonzero(push == a.index)
        low = min(float(P.transform(W[j], pts)[:, 2].min()) for j in near) - workcell.table.height
        if low < -PENETRATION_LIMIT and a.feature != "table":
            raise ArgumentError(
                f"push {a.index} (pusher `{a.pusher}`, plan path[{a.first}] to path[{a.last}]): the object goes "
                f"{-low * 1e3:.1f} mm below the table top of workcell `{workcell.name}` at feature `{a.feature}` "
                f"(a feature higher above the table serves it)", f"plan.path[{a.first + 1}].pusher")
        if depth[-1] > PENETRATION_LIMIT:
            raise ArgumentError(
                f"push {a.index} (pusher `{a.pusher}`, plan path[{a.first}] to path[{a.last}]): the object goes "
                f"{depth[-1] * 1e3:.2f} mm into feature `{a.feature}` of workcell `{workcell.name}`, more than "
                f"{PENETRATION_LIMIT * 1e3:g} mm (a smaller feature, e.g. a face just larger than the pusher, "
                f"lets it pivot)", f"plan.path[{a.first + 1}].pusher")
    return WorldMotion(np.array(S["t"][:len(G)]), G, W, Oh, labels, push, np.full(len(G), force), assignments,
                       knots, float(safe), workcell, timing, depth, scene.name)


def _behind(pts, extent) -> float:
    """The lowest z [m] of ``pts`` (k, 3) in a contact frame (0 when none is lower), counting
    only those within a face's half-sizes ``extent`` (an edge's or corner's zeros: all)."""
    if np.any(np.asarray(extent) > 0):
        pts = pts[np.all(np.abs(pts[:, :2]) <= np.asarray(extent) + 1e-9, axis=1)]
    return float(pts[:, 2].min()) if len(pts) else 0.0


def _moved(O, xi, s: float, Pk) -> np.ndarray:
    """The pusher frame ``Pk`` (gripper frame) moved by ``s`` of the pusher twist ``xi`` (m/s,
    rad/s) expressed in the object frame ``O`` (m, unit quaternion): ``O exp(s xi) O⁻¹ Pk``."""
    return P.compose(P.integrate(O, xi, s), P.inverse(O), Pk)


def _check_start(start) -> np.ndarray:
    s0 = np.asarray(start, float) if isinstance(start, (list, tuple, np.ndarray)) else None
    if s0 is None or s0.shape != (7,) or not np.all(np.isfinite(s0)) or np.linalg.norm(s0[3:]) < 1e-6:
        raise ArgumentError(f"invalid `start`: a pose [x, y, z, qw, qx, qy, qz] (m, quaternion) (got {start!r:.80})", "start")
    return np.r_[s0[:3], s0[3:] / np.linalg.norm(s0[3:])]
