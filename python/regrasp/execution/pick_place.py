"""Pick-regrasp-place (thesis §6.2.5): the object lies on the table; the arm picks it with a
grasp it can reach, regrasps it in hand by pushes against the workcell's features, and places it
at a requested pose on the table with a grasp that can put it there.

**Grasps.** Planar scenes: the lamina stands on the table on an outline side (its plane vertical,
the thickness along the grasp axis, the gripper's y along the lamina's normal). A grasp is an
in-hand pose ``[x, z, theta]`` (m, m, rad); the gripper's world pose for an object at world pose
``W`` is ``G = W ∘ in_hand⁻¹``. Pick grasps hold the object at the scene's task start position
``[x, z]`` (where it is taken), place grasps at its task goal position (where it is needed)
(:func:`spots`), each with every ``theta`` on a :data:`THETA_STEP` grid for which the gripper's
palm axis (+z) is within :data:`~regrasp.execution.assignment.MAX_TILT` of the world's up (the
fingers point down at the object; the pushes need the plan's gravity that near the world's) and
the grasp centre is at least :data:`FINGER_CLEARANCE` (plus the place request's ``depth`` at the
place) above the table. A pick grasp is reachable when the arm's
IK (:func:`regrasp.robot.ik.solve_ik`, clear of the table and the features) reaches ``G`` and the
pose :data:`LIFT` above it; a place grasp likewise at the place pose.

**Choice.** Every (pick, place) pair is planned (:func:`regrasp.plan` from the pick grasp to
the place grasp; no plan when they are the same grasp) and rendered in the workcell
(:func:`~regrasp.execution.world_motion`); pairs are ranked by the regrasp's switch-overs, then
by its world motion's duration; the first whose grasps are reachable and whose whole motion the
arm can follow (:func:`~regrasp.execution.arm.solve_arm`) is chosen. World motions are rendered a switch-over count at a
time, the fewest first (a cheaper tier has no use for a dearer one's durations).

**Motion.** From :data:`LIFT` above the pick grasp: down to it, close, up, the regrasp's world
motion, over to :data:`LIFT` above the place grasp, down, open, up. The placement succeeds when
the object ends within :data:`PLACE_TOLERANCE` of the place pose.

3-D scenes are not supported yet (ArgumentError naming ``scene``)."""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from types import SimpleNamespace

import numpy as np

from .. import pose as P
from ..errors import ArgumentError, ExecutionError, RegraspError
from ..extras import need
from .layout import default_workcell
from ..workcell.description import Workcell
from .assignment import MAX_TILT
from .arm_loop import with_pushers
from .world_motion import EASE_PEAK, Timing, WorldMotion, eased, grip_force, world_motion

#: (m, rad): the placement succeeds when the object's final world pose is this close to the
#: place pose (position, angle).
PLACE_TOLERANCE = (0.005, math.radians(5.0))
#: Spacing [rad] of the in-hand angles tried as grasps.
THETA_STEP = math.radians(10.0)
#: The least height [m] of the grasp centre (the TCP) above the table at pick and place.
FINGER_CLEARANCE = 0.02
#: Height [m] above a pick or place grasp from which the gripper comes down and to which it lifts.
LIFT = 0.08
#: Speed [m/s] of the gripper coming down to and lifting from the table.
TABLE_SPEED = 0.05
#: Time [s] the gripper holds still while the fingers close or open.
GRIP_DWELL = 0.5
#: Where [m] on the table the object lies when the workcell does not say (``[x, y]``, world).
DEFAULT_PICK = (0.4, 0.0)
#: The default place: the pick pose moved by this [m] along the table (``[x, y]``, world).
DEFAULT_SHIFT = (0.15, -0.1)
#: Planner settings for each candidate regrasp (fast: many are planned).
PLAN_SETTINGS = {"time_limit": 0.2}
#: Rounds of re-planning without the pushers the arm could not follow.
MAX_ROUNDS = 3


@dataclass(frozen=True, eq=False)
class Grasp:
    """A candidate grasp: ``in_hand`` ``[x, z, theta]`` (m, m, rad), the object's planar pose in
    the gripper frame; ``gripper`` (7,) the gripper's world pose (m, unit quaternion) holding the
    object at the pick or place pose; ``tilt`` [rad] of its palm axis from the world's up."""
    in_hand: tuple
    gripper: np.ndarray
    tilt: float


@dataclass
class Candidate:
    """A (pick, place) pair: ``pick`` and ``place`` (:class:`Grasp`), the regrasp ``plan`` (None
    when the grasps are the same), ``switch_overs``, ``duration`` [s] of its world motion (0
    without a regrasp), ``motion`` (:class:`WorldMotion` or None), ``why`` (why it cannot be
    used, or ""), ``unserved``: the pusher of its plan that no feature serves (or None)."""
    pick: Grasp
    place: Grasp
    plan: object = None
    switch_overs: int = 0
    duration: float = 0.0
    motion: object = None
    why: str = ""
    unserved: str | None = None

    @property
    def cost(self) -> tuple:
        """(switch-overs, duration [s]): the ranking key."""
        return (self.switch_overs, self.duration)


@dataclass
class PickPlace:
    """A planned pick-regrasp-place: the ``scene``'s name; ``pick_pose`` and ``place_pose`` (7,)
    the object's world poses (m, unit quaternion); the chosen ``pick`` and ``place``
    (:class:`Grasp`); the regrasp ``plan`` (None without one), its ``switch_overs``; ``motion``:
    the whole :class:`WorldMotion` (pick and place moves are ``transfer`` samples, the grip force
    0 while the fingers are open); ``phases``: name → (first, last) sample index of ``approach``,
    ``close``, ``lift``, ``regrasp``, ``carry``, ``lower``, ``open``, ``retreat``; ``arm``
    (:class:`~regrasp.execution.arm.ArmTrajectory` of the motion); ``planning_time`` [s] of the
    whole choice (grasps, plans, reachability, world motions; not the robot model's build nor
    the chosen motion's joint trajectory); ``candidates``: every pair considered, ranked;
    ``without``: the pushers left out of the plans because the arm could not follow them (the
    gripper's own body against the feature: see docs/robot.md) or, where no pair got as far as
    the arm, because no feature of the workcell serves them."""
    scene: str
    pick_pose: np.ndarray
    place_pose: np.ndarray
    pick: Grasp
    place: Grasp
    plan: object
    switch_overs: int
    motion: WorldMotion
    phases: dict
    arm: object
    planning_time: float
    candidates: list = field(default_factory=list)
    without: list = field(default_factory=list)


def _check_planar(scene) -> None:
    from ..scene.planar import Scene

    if not isinstance(scene, Scene) or scene.kind != "grasp":
        raise ArgumentError("invalid `scene`: pick-place needs a planar [grasp] scene (3-D scenes are not "
                            "supported yet)", "scene")


def resting_angles(scene) -> list[float]:
    """The planar angles [rad] (in-plane turns of the object frame) at which the lamina rests
    stably on an outline side: the side's outward normal points down and the outline's centroid
    lies over the side (convex-hull sides only), in the outline's order."""
    out = np.asarray(scene.outline, float)
    hull = _hull(out)
    c = _centroid(out)
    angles = []
    for i in range(len(hull)):
        a, b = hull[i], hull[(i + 1) % len(hull)]
        d = (b - a) / np.linalg.norm(b - a)
        n = np.array([d[1], -d[0]])  # outward for a counter-clockwise hull
        s = float((c - a) @ d)
        if 1e-9 < s < float(np.linalg.norm(b - a)) - 1e-9:
            angles.append(float(-np.pi / 2 - math.atan2(n[1], n[0])))
    return [math.remainder(t, 2 * np.pi) for t in angles]


def table_pose(scene, workcell: Workcell, xy, angle: float, yaw: float = 0.0) -> np.ndarray:
    """The object's world pose (m, unit quaternion) resting on ``workcell``'s table at ``xy``
    ``[x, y]`` [m], turned by the planar ``angle`` [rad] in its plane and by ``yaw`` [rad] about
    the world's up (the lamina's plane is the world x-z plane at yaw 0)."""
    out = np.asarray(scene.outline, float)
    c, s = math.cos(angle), math.sin(angle)
    low = float(np.min(s * out[:, 0] + c * out[:, 1]))
    R = P.compose(P.z_turn(yaw), P.planar_to_spatial([0.0, 0.0, angle]))
    return np.r_[float(xy[0]), float(xy[1]), workcell.table.height - low, R[3:]]


def default_poses(scene, workcell: Workcell) -> tuple[np.ndarray, np.ndarray]:
    """(pick pose, place pose) of the object (m, unit quaternion) when not given: the pick pose is
    the workcell's object pose when ``object.on = "table"``, else the object resting at
    :data:`DEFAULT_PICK` on its stable side nearest its scene pose (upright); the place pose is
    the pick pose moved by :data:`DEFAULT_SHIFT` on the table."""
    if workcell.object.on == "table":
        pick = np.asarray(workcell.object.pose, float)
    else:
        pick = table_pose(scene, workcell, DEFAULT_PICK, min(resting_angles(scene), key=abs))
    return pick, np.r_[pick[0] + DEFAULT_SHIFT[0], pick[1] + DEFAULT_SHIFT[1], pick[2:]]


def _yaw(pose) -> float:
    y = P.quat_rotate(pose[3:], [0.0, 1.0, 0.0])
    return math.atan2(-y[0], y[1])


def grasps(scene, workcell: Workcell, object_pose, spot, depth: float = 0.0) -> list[Grasp]:
    """The candidate grasps of the object at world pose ``object_pose`` (m, unit quaternion) held
    at the in-hand position ``spot`` ``[x, z]`` [m]: every in-hand angle on the
    :data:`THETA_STEP` grid whose palm tilt is at most :data:`MAX_TILT` and whose TCP is at least
    :data:`FINGER_CLEARANCE` + ``depth`` [m] above the table; reachability is not checked here."""
    _check_planar(scene)
    W = np.asarray(object_pose, float)
    out = []
    for k in range(int(round(2 * np.pi / THETA_STEP))):
        th = math.remainder(k * THETA_STEP, 2 * np.pi)
        G = P.compose(W, P.inverse(P.planar_to_spatial([spot[0], spot[1], th])))
        up = P.quat_rotate(G[3:], [0.0, 0.0, 1.0])
        tilt = math.acos(max(-1.0, min(1.0, float(up[2]))))
        if tilt <= MAX_TILT + 1e-9 and G[2] - workcell.table.height >= FINGER_CLEARANCE + depth - 1e-12:
            out.append(Grasp((float(spot[0]), float(spot[1]), float(th)), G, tilt))
    return sorted(out, key=lambda g: g.in_hand[2])


def spots(scene) -> tuple:
    """(pick, place) in-hand positions ``[x, z]`` [m]: the scene's task start's and goal's (the
    grasp it is taken at, the grasp it is needed at); the origin without a task."""
    t = scene.task
    return (tuple(t.start[:2]), tuple(t.goal[:2])) if t is not None else ((0.0, 0.0), (0.0, 0.0))


def lifted(G, dz: float = LIFT) -> np.ndarray:
    """Pose ``G`` (m, unit quaternion) raised by ``dz`` [m] along the world's up."""
    return np.r_[G[0], G[1], G[2] + dz, G[3:]]


def _same(a: Grasp, b: Grasp) -> bool:
    return np.allclose(a.in_hand[:2], b.in_hand[:2], atol=1e-9) and \
        abs(math.remainder(a.in_hand[2] - b.in_hand[2], 2 * np.pi)) < 1e-9


def planned(scene, picks: list, places: list, seed: int = 0) -> list[Candidate]:
    """Every (pick, place) pair of :class:`Grasp` lists with its regrasp plan (none for the same
    grasp; ``why`` said when the planner finds none) and switch-overs; not yet rendered."""
    from ..planning.plan import plan as plan_regrasp

    out = []
    for a in picks:
        for b in places:
            c = Candidate(a, b)
            if not _same(a, b):
                try:
                    p = plan_regrasp(scene, start=list(a.in_hand), goal=list(b.in_hand), seed=seed, **PLAN_SETTINGS)
                except RegraspError as e:
                    c.why = str(e)
                else:
                    if not p.found or len(p.poses) < 2:
                        c.why = f"no regrasp plan ({p.stop_reason})"
                    else:
                        c.plan, c.switch_overs = p, int(p.switch_overs or 0)
            out.append(c)
    return out


def render(scene, workcell: Workcell, c: Candidate) -> Candidate:
    """Candidate ``c`` with its regrasp's world motion in ``workcell`` from :data:`LIFT` above
    the pick grasp and its ``duration`` [s] (``why`` said when no feature serves a push)."""
    if c.plan is not None and c.motion is None and not c.why:
        try:
            c.motion = world_motion(scene, c.plan, workcell, start=lifted(c.pick.gripper))
            c.duration = c.motion.duration
        except RegraspError as e:
            c.why = str(e)
            c.unserved = getattr(e, "pusher", None)
    return c


def rank(scene, workcell: Workcell, picks: list, places: list, seed: int = 0) -> list[Candidate]:
    """Every (pick, place) pair planned and rendered (:func:`planned`, :func:`render`), ranked
    by (switch-overs, duration), the unusable ones last: the brute-force reference of the choice."""
    out = [render(scene, workcell, c) for c in planned(scene, picks, places, seed)]
    return sorted(out, key=lambda c: (bool(c.why), c.cost))


def _move(a, b, speed: float, turn: float, period: float) -> np.ndarray:
    """Samples (n, 7) of a minimum-jerk move from pose ``a`` to ``b`` (excluding ``a``), its peak
    speed ``speed`` [m/s] / ``turn`` [rad/s], ``period`` [s] apart; returns (poses, duration [s])."""
    T = max(np.linalg.norm(np.subtract(b[:3], a[:3])) / speed, P.quat_angle(a[3:], b[3:]) / turn, period) * EASE_PEAK
    n = max(1, math.ceil(T / period - 1e-9))
    G = P.interpolate(a, b, eased(np.arange(1, n + 1) / n))
    G[-1] = b
    return G, T


def assemble(scene, workcell: Workcell, pick_pose, place_pose, c: Candidate, timing: Timing = Timing()):
    """The whole :class:`WorldMotion` of candidate ``c`` (pick, regrasp, place; see the module's
    doc) and its phases (name → (first, last) sample index)."""
    force = grip_force(scene)
    S = {"t": [0.0], "G": [lifted(c.pick.gripper)], "W": [np.asarray(pick_pose, float)], "f": [0.0]}
    phases = {}

    def resting(W):
        """The object's world pose per gripper pose: still on the table at ``W``."""
        return lambda G: np.asarray(W, float)

    def holding(in_hand):
        """The object's world pose per gripper pose: held at ``in_hand``."""
        return lambda G: P.compose(G, in_hand)

    def add(name, Gs, T, obj, f):
        first = len(S["G"])
        t0 = S["t"][-1]
        S["t"] += list(t0 + T * np.arange(1, len(Gs) + 1) / len(Gs))
        S["G"] += list(Gs)
        S["W"] += [obj(G) for G in Gs]
        S["f"] += [f] * len(Gs)
        phases[name] = (first, len(S["G"]) - 1)

    def dwell(name, obj, f):
        n = max(1, math.ceil(GRIP_DWELL / timing.sample_period - 1e-9))
        add(name, [S["G"][-1]] * n, GRIP_DWELL, obj, f)

    pick_in = P.planar_to_spatial(c.pick.in_hand)
    place_in = P.planar_to_spatial(c.place.in_hand)
    on_pick, on_place = resting(pick_pose), resting(place_pose)
    add("approach", *_move(S["G"][-1], c.pick.gripper, TABLE_SPEED, timing.move_turn, timing.sample_period), on_pick, 0.0)
    dwell("close", on_pick, force)
    held = holding(pick_in)
    add("lift", *_move(S["G"][-1], lifted(c.pick.gripper), TABLE_SPEED, timing.move_turn, timing.sample_period), held, force)
    first = len(S["G"])
    if c.motion is not None:
        m = c.motion
        S["t"] += list(S["t"][-1] + m.times[1:])
        S["G"] += list(m.gripper[1:])
        S["W"] += list(m.object[1:])
        S["f"] += [force] * (len(m.times) - 1)
    phases["regrasp"] = (first, len(S["G"]) - 1)
    held = holding(place_in)
    above = lifted(c.place.gripper)
    top = np.r_[above[:2], max(S["G"][-1][2], above[2]), above[3:]]
    Gs1, T1 = _move(S["G"][-1], top, timing.move_speed, timing.move_turn, timing.sample_period)
    Gs2, T2 = _move(top, above, timing.move_speed, timing.move_turn, timing.sample_period)
    Gs = np.vstack([Gs1, Gs2])
    add("carry", Gs, T1 + T2, held, force)
    add("lower", *_move(S["G"][-1], c.place.gripper, TABLE_SPEED, timing.move_turn, timing.sample_period), held, force)
    dwell("open", on_place, 0.0)
    add("retreat", *_move(S["G"][-1], lifted(c.place.gripper), TABLE_SPEED, timing.move_turn, timing.sample_period),
        on_place, 0.0)
    G, W = np.array(S["G"]), np.array(S["W"])
    n = len(G)
    labels, push = ["transfer"] * n, np.full(n, -1)
    labels[0] = "start"
    knots, assignments, depth = [], [], []
    if c.motion is not None:
        a, b = phases["regrasp"]
        labels[a:b + 1] = c.motion.labels[1:]
        push[a:b + 1] = c.motion.push[1:]
        knots = [(k, j - 1 + a) for k, j in c.motion.knots]
        assignments, depth = c.motion.assignments, c.motion.penetration
    # in_hand per sample: the object in the gripper frame (on the table: where the gripper sees it)
    in_hand = P.compose_rows(np.array([P.inverse(g) for g in G]), W)
    safe = c.motion.safe_height if c.motion is not None else float(lifted(c.pick.gripper)[2])
    motion = WorldMotion(np.array(S["t"]), G, W, in_hand, labels, push, np.array(S["f"]), assignments, knots,
                         safe, workcell, timing, depth, scene.name)
    return motion, phases


def _arm_robot(scene, workcell: Workcell, pick_pose, in_hand):
    """The robot in ``workcell`` (:func:`~regrasp.execution.arm.build_robot`) with the object,
    and the geoms the IK keeps clear of (the table and the features)."""
    from ..robot.ik import fixed_geoms
    from .arm import build_robot

    # build_robot reads only the motion's workcell, first in-hand pose and first object pose
    stub = SimpleNamespace(workcell=workcell, in_hand=[np.asarray(P.planar_to_spatial(in_hand))],
                           object=[np.asarray(pick_pose, float)])
    r, body, geoms, tcp = build_robot(scene, stub)
    avoid = fixed_geoms(r)
    return r, body, geoms, tcp, avoid


def reachable(robot, avoid, tcp, G) -> np.ndarray | None:
    """The arm's joints [rad] putting the TCP at gripper pose ``G`` ∘ ``tcp`` (from home, else on
    another branch of the arm: :func:`~regrasp.robot.ik.ik_solutions`), clear of ``avoid``, when it
    and the pose :data:`LIFT` above are reachable on one branch; else None."""
    from ..robot.ik import IKError, ik_solutions, solve_ik

    try:
        q = solve_ik(robot, P.compose(G, tcp), robot.kind.home, avoid=avoid)
        solve_ik(robot, P.compose(lifted(G), tcp), q, avoid=avoid)
        return q
    except IKError as e:
        if e.reason == "unreachable":  # beyond the arm's reach: on every branch
            return None
    for q in ik_solutions(robot, P.compose(G, tcp), avoid):
        try:
            solve_ik(robot, P.compose(lifted(G), tcp), q, avoid=avoid)
            return q
        except IKError:
            continue
    return None


def check_place(place, field_: str = "place", table=None) -> np.ndarray:
    """``place`` as a pose ``[x, y, z, qw, qx, qy, qz]`` (m, quaternion normalised), with ``table``
    (a workcell's) on it (:meth:`~regrasp.workcell.Table.off`); ArgumentError naming ``field_``
    otherwise."""
    a = np.asarray(place, float) if isinstance(place, (list, tuple, np.ndarray)) else None
    if a is None or a.shape != (7,) or not np.all(np.isfinite(a)) or np.linalg.norm(a[3:]) < 1e-6:
        raise ArgumentError(f"invalid `{field_}`: a pose x,y,z,qw,qx,qy,qz (m, quaternion) (got {place!r:.80})", field_)
    off = None if table is None else table.off(a)
    if off is not None:
        raise ArgumentError(f"invalid `{field_}`: the object's pose on the table: [{off[0]}] {off[1]} (got "
                            f"{a[off[0]]:g})", field_)
    return np.r_[a[:3], a[3:] / np.linalg.norm(a[3:])]


def pick_place(scene, workcell: Workcell | None = None, place=None, pick=None, depth: float = 0.0, seed: int = 0,
               timing: Timing = Timing()) -> PickPlace:
    """Plans a pick-regrasp-place of ``scene``'s object in ``workcell`` (default: the scene's
    :func:`~regrasp.execution.default_workcell`): from ``pick`` (the object's world pose on the
    table, m, unit quaternion; default :func:`default_poses`) to ``place`` (likewise); ``depth`` [m]: how much higher than
    :data:`FINGER_CLEARANCE` the fingers must stay above the table at the place (a pocket, a
    crowded shelf); ``seed`` of the planner. Returns the :class:`PickPlace` of the cheapest usable pair (see the module's
    doc); ExecutionError naming ``place`` when no pair is usable (no reachable pick or place
    grasp, or no regrasp between them the arm can follow)."""
    from .arm import object_load, solve_arm

    _check_planar(scene)
    workcell = default_workcell(scene) if workcell is None else workcell
    if not isinstance(workcell, Workcell):
        raise ArgumentError(f"invalid `workcell`: a Workcell (got {type(workcell).__name__})", "workcell")
    d_pick, d_place = default_poses(scene, workcell)
    pick_pose = d_pick if pick is None else check_place(pick, "pick", workcell.table)
    place_pose = d_place if place is None else check_place(place, "place", workcell.table)
    if isinstance(depth, bool) or not isinstance(depth, (int, float)) or not (0 <= depth < 1):
        raise ArgumentError(f"invalid `depth`: a height in [0, 1) m (got {depth!r:.40})", "depth")
    start, goal = spots(scene)
    r, body, _, tcp, avoid = _arm_robot(scene, workcell, pick_pose, (*start, 0.0))  # the model: not planning
    t0 = time.perf_counter()
    picks, places = grasps(scene, workcell, pick_pose, start), grasps(scene, workcell, place_pose, goal, depth)
    if not picks:
        raise ExecutionError("no pick grasp keeps the fingers above the table with the palm up", "pick")
    if not places:
        raise ExecutionError("no place grasp keeps the fingers above the table with the palm up", "place")
    seen: dict = {}

    def ok(g: Grasp) -> bool:
        key = id(g)
        if key not in seen:
            seen[key] = reachable(r, avoid, tcp, g.gripper) is not None
        return seen[key]

    planning, banned, cands, arm_why = time.perf_counter() - t0, set(), [], []
    for _ in range(MAX_ROUNDS):  # without the pushers the arm could not follow or no feature serves
        t1 = time.perf_counter()
        cands = planned(with_pushers(scene, [p for p in scene.pusher_names if p not in banned]), picks, places, seed)
        for c in cands:  # reachability first: it rules a grasp out for every pair
            if not c.why and not ok(c.pick):
                c.why = "the pick grasp is out of the arm's reach"
            elif not c.why and not ok(c.place):
                c.why = "the place grasp is out of the arm's reach"
        planning += time.perf_counter() - t1
        blocked: set = set()
        for s_ in sorted({c.switch_overs for c in cands if not c.why}):  # the fewest switch-overs first
            t1 = time.perf_counter()
            tier = sorted((render(scene, workcell, c) for c in cands if not c.why and c.switch_overs == s_),
                          key=lambda c: (bool(c.why), c.duration))
            planning += time.perf_counter() - t1
            for c in tier:  # within them the shortest motion
                if c.why:
                    continue
                motion, phases = assemble(scene, workcell, pick_pose, place_pose, c, timing)
                try:
                    arm = solve_arm(r, motion, tcp, object_load(scene, r, body, tcp, motion))
                except ExecutionError as e:
                    c.why = str(e)
                    arm_why.append(c.why)
                    k = getattr(e, "push", -1)
                    if 0 <= k < len(motion.assignments):
                        blocked.add(motion.assignments[k].pusher)
                    continue
                ranked = sorted(cands, key=lambda c: (bool(c.why), c.cost))
                return PickPlace(scene.name, pick_pose, place_pose, c.pick, c.place, c.plan, c.switch_overs, motion,
                                 phases, arm, planning, ranked, sorted(banned))
        if not blocked:  # no pair reached the arm: the pushers no feature serves
            blocked = {c.unserved for c in cands if c.unserved}
        if not blocked - banned or len(banned | blocked) >= len(scene.pusher_names):
            break
        banned |= blocked
    # the example: a pair that got as far as the arm (rendered, then refused by the hand or the
    # arm), else the first refused
    why = arm_why[0] if arm_why else next((c.why for c in cands if c.why), "no candidate")
    raise ExecutionError(f"no pick-regrasp-place reaches the place pose {np.round(place_pose, 4).tolist()}: "
                         f"{len(cands)} grasp pairs tried"
                         + (f" without pushers {', '.join(sorted(banned))}" if banned else "") + f" (e.g. {why})", "place")


def place_error(scene_pose, place_pose) -> tuple[float, float]:
    """(m, rad): how far the object's world pose ``scene_pose`` is from ``place_pose``."""
    return (float(np.linalg.norm(np.subtract(scene_pose[:3], place_pose[:3]))),
            P.quat_angle(scene_pose[3:], place_pose[3:]))


def _hull(pts) -> np.ndarray:
    """The counter-clockwise convex hull (k, 2) of 2-D points (monotone chain)."""
    from ..polygon import cross

    p = sorted(map(tuple, np.asarray(pts, float)))
    lower, upper = [], []
    for q in p:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], q) <= 1e-15:
            lower.pop()
        lower.append(q)
    for q in reversed(p):
        while len(upper) >= 2 and cross(upper[-2], upper[-1], q) <= 1e-15:
            upper.pop()
        upper.append(q)
    return np.array(lower[:-1] + upper[:-1])


def _centroid(p) -> np.ndarray:
    """The area centroid [m] of a simple polygon (k, 2)."""
    p = np.asarray(p, float)
    q = np.roll(p, -1, axis=0)
    c = p[:, 0] * q[:, 1] - q[:, 0] * p[:, 1]
    a = c.sum() / 2
    return np.array([((p[:, 0] + q[:, 0]) * c).sum(), ((p[:, 1] + q[:, 1]) * c).sum()]) / (6 * a)


@dataclass
class PickPlaceRun:
    """A pick-regrasp-place executed in MuJoCo: ``success`` (the object ends within
    :data:`PLACE_TOLERANCE` of the place pose); ``place_error`` (m, rad); ``final_pose`` (7,) the
    object's measured world pose (m, unit quaternion); ``held`` whether the object was still in
    the hand before it was lowered; ``duration`` [s] simulated; ``tracking`` of the held part
    (:class:`~regrasp.robot.tracking.Tracking`)."""
    success: bool
    place_error: tuple
    final_pose: np.ndarray
    held: bool
    duration: float
    tracking: object


#: Time [s] the arm holds still at the start while the fingers open, and at the end before the
#: object's pose is measured.
OPEN_TIME = 0.5


def execute_pick_place(scene, r: PickPlace, scales=None, observe=None, sensing=None) -> PickPlaceRun:
    """Executes the planned pick-regrasp-place ``r`` of ``scene`` in MuJoCo with its arm
    (:func:`~regrasp.execution.arm.build_robot`: the UR5e + 2F-85 with the scene's pads), in a
    world perturbed by ``scales`` (:class:`~regrasp.Perturbation`): the object on the
    table at the pick pose, the fingers open; the approach; the fingers close
    (:func:`~regrasp.execution.arm.close_on`); lift, regrasp, carry and lower under the grip
    force loop; the fingers open (:func:`~regrasp.robot.grip.open_gripper`); the retreat.
    ``observe(robot)`` is called after every control period (e.g. a video recorder);
    ``sensing``: what the grip loop measures (:class:`~regrasp.robot.sensing.GripSensing`; None: the gripper's default, :func:`~regrasp.execution.arm.grip_sensing`)."""
    mujoco = need("mujoco", "robot")
    from ..robot.grip import body_pose, open_gripper
    from ..robot.tracking import track
    from ..scene.perturbation import Perturbation
    from .arm import build_robot, close_on

    scales = Perturbation() if scales is None else scales
    rob, body, geoms, tcp = build_robot(scene, r.motion, scales=scales)
    m, d = rob.model, rob.data
    q, t = r.arm.q, r.arm.times
    rob.set_q(q[0])
    jq = m.jnt_qposadr[m.body_jntadr[body]]
    d.qpos[jq:jq + 7] = r.pick_pose
    open_gripper(rob)
    mujoco.mj_forward(m, d)
    obs = None if observe is None else (lambda _t: observe(rob))
    ph = r.phases

    def run(i, j, grip=None, settle=0.05):
        qs = q[i:j + 1].copy()
        qs[0] = rob.q  # from where the arm is (closing the fingers lets it sag a little)
        return track(rob, t[i:j + 1], qs, settle=settle, grip=grip, ease=False, observe=obs)

    track(rob, [0.0, OPEN_TIME], [q[0], q[0]], settle=0.0, ease=False, observe=obs)
    run(0, ph["approach"][1])
    grip = close_on(rob, body, geoms, float(grip_force(scene)) * scales.grip, sensing)
    tracking = run(ph["close"][1], ph["lower"][0] - 1, grip)
    held_pose = P.compose(P.compose(rob.tcp_pose(), P.inverse(tcp)), P.planar_to_spatial(r.place.in_hand))
    held = place_error(body_pose(d, body), held_pose)[0] < 0.02
    run(ph["lower"][0] - 1, ph["lower"][1], grip)
    open_gripper(rob)
    run(ph["lower"][1], ph["retreat"][1], settle=OPEN_TIME)
    final = body_pose(d, body)
    err = place_error(final, r.place_pose)
    ok = err[0] <= PLACE_TOLERANCE[0] and err[1] <= PLACE_TOLERANCE[1]
    return PickPlaceRun(bool(ok), err, final, bool(held), float(d.time), tracking)
