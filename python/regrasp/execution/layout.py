"""The default workcell of a scene, used when none is given: a table with the robot on it, a
fixture block (raised on a post) beside the robot that offers every pusher of the scene a contact (a block edge at
least as long as each line pusher, block corners for point pushers, block faces for patches; the
table top for planes and pushers from below), a ledge (a horizontal edge high above the table
that pushes downward, so a pusher that pushes the object along the scene's gravity needs no
tilt), a rod (a short vertical bar pushing towards the robot: side pushers need no tilt on it,
and it passes between the fingers) and a plate (a small face, just large enough for the scene's largest patch pusher, so an
object pivoting on a patch does not swing into a larger face). Each feature has the friction of
the pushers it serves, as the plan assumed it (:func:`feature_friction`).

The layout is made for the assignment of features to pushers (:mod:`.assignment`), so it lives
beside it; a :class:`~regrasp.workcell.Workcell` itself is a description (before 0.2:
``regrasp.workcell.default``)."""

from __future__ import annotations

import numpy as np

from ..errors import ArgumentError
from ..workcell.description import Feature, ObjectStart, Robot, Table, Workcell

#: The default layout, stated once: table top height [m], table size [m] and centre [m] (world
#: x-y), the robot (a UR5e at the world origin on the table top), the block's centre [m] (world
#: x-y), its smallest side [m] and how much longer [×] its sides are than the largest pusher.
#: Every feature has the friction of the pushers it serves (:func:`feature_friction`).
TABLE_HEIGHT = 0.75
TABLE_SIZE = (1.2, 0.8)
TABLE_CENTER = (0.5, 0.0)
ROBOT = "ur5e"
BLOCK_CENTER = (0.5, 0.25)
#: How high [m] above the table top the block's underside is (it stands on a post, not
#: modelled), so that an object pushed against its side edges stays clear of the table.
BLOCK_LIFT = 0.1
BLOCK_SIDE = 0.1
BLOCK_MARGIN = 1.5
#: The table's friction when it serves no pusher of the scene (no line, patch or plane pusher).
TABLE_FRICTION = 0.5
#: The ledge: its edge's centre [m] (world x-y), its height above the table top [m]; it runs
#: along world x and pushes along world −z, its length as the block's side.
LEDGE_CENTER = (0.5, -0.25)
LEDGE_HEIGHT = 0.3
#: The rod: a short vertical bar whose edge pushes along world −x (towards the robot): its centre
#: [m] (world x-y) and height above the table top [m]; ``ROD_MARGIN`` [×] the longest line
#: pusher long. A side pusher with the scene's gravity along its line needs no tilt on it, and,
#: thin (an edge's bar, ``workcell.shapes``) and short, it passes between the fingers below the
#: palm where a block's edge, 1.5 times as long with the block behind it, hits the gripper.
ROD_CENTER = (0.66, 0.05)
ROD_HEIGHT = 0.2
ROD_MARGIN = 1.05
#: The plate: its centre [m] (world x-y), height of its centre above the table [m]; it faces
#: world −x (towards the robot, like the rod: facing away, the gripper had to reach past it,
#: beyond the UR5e's reach) and is square, its side ``PLATE_MARGIN`` [×] the largest patch's
#: diameter (at least ``PLATE_MIN`` [m]).
PLATE_CENTER = (0.7, -0.1)
PLATE_HEIGHT = 0.15
PLATE_MARGIN = 1.02
PLATE_MIN = 0.005
#: Inclines: for a line pusher that no other feature serves within the assignment's ``MAX_TILT``
#: (its segment neither level nor plumb under the scene's gravity: a gripper rolled about its
#: grasp axis), a bar like the rod, laid along the pusher's segment as the scene's gravity holds
#: it, pushing along the pusher's normal (turned so that it pushes towards the robot): the first
#: centred at ``INCLINE_CENTER`` [m] (world x-y) ``INCLINE_HEIGHT`` [m] above the table, each next
#: ``INCLINE_STEP`` [m] further along world y.
INCLINE_CENTER = (0.45, -0.05)
INCLINE_HEIGHT = 0.2
INCLINE_STEP = -0.12


def pusher_extent(scene) -> tuple[float, float]:
    """The largest distance [m] between two contact points of one pusher of ``scene`` (a
    :class:`~regrasp.Scene` or :class:`~regrasp.Scene3D`; a plane's points at the task's start),
    and the largest pusher friction coefficient."""
    if scene.dimension == 2:
        specs = [(np.asarray(p.points, float), p.friction) for p in scene.pushers]
    else:
        specs = []
        for name in scene.pusher_names:
            pts, _, mu = scene.pusher_spec(name)
            specs.append((np.asarray(pts, float), mu))
    size = max((float(np.max(np.linalg.norm(p[:, None] - p[None], axis=-1))) for p, _ in specs), default=0.0)
    return size, max(mu for _, mu in specs)


def patch_extent(scene) -> float:
    """The largest diameter [m] of a patch pusher of ``scene`` (3 or more contact points, planes
    left out) about its points' centroid (twice the farthest point's distance); 0 without one."""
    if scene.dimension == 2:
        return 0.0
    out = 0.0
    for name in scene.pusher_names:
        pts = np.asarray(scene.pusher_spec(name)[0], float)
        if len(pts) >= 3 and not scene.is_plane(name):
            out = max(out, 2 * float(np.max(np.linalg.norm(pts - pts.mean(axis=0), axis=1))))
    return out


def pusher_kinds(scene) -> list[tuple[str, str, float]]:
    """``(name, kind, friction)`` of each pusher of ``scene``: kind ``point`` (one contact
    point), ``line`` (two), ``patch`` (three or more) or ``plane`` (a 3-D ``plane = true``)."""
    if scene.dimension == 2:
        return [(p.name, "point" if len(p.points) == 1 else "line", float(p.friction)) for p in scene.pushers]
    out = []
    for name in scene.pusher_names:
        pts, _, mu = scene.pusher_spec(name)
        n = len(np.asarray(pts).reshape(-1, 3))
        kind = "plane" if scene.is_plane(name) else "point" if n == 1 else "line" if n == 2 else "patch"
        out.append((name, kind, float(mu)))
    return out


def feature_friction(scene, kinds, default: float | None = None) -> float | None:
    """The friction of a feature that serves the pushers of ``scene`` of the given ``kinds``: the
    pushers' own coefficient (the plan assumed it: a feature with more friction would make a
    planned slip at the pusher stick), the largest where they differ; ``default`` when the scene
    has no pusher of those kinds."""
    mus = [mu for _, k, mu in pusher_kinds(scene) if k in kinds]
    return max(mus) if mus else default


def default_workcell(scene) -> Workcell:
    """The default workcell for ``scene`` (planar or 3-D; see the module's doc): named
    ``default-SCENE``, the object starting in the hand."""
    from ..scene.planar import Scene
    from ..scene.spatial import Scene3D

    if not isinstance(scene, (Scene, Scene3D)):
        raise ArgumentError(f"invalid `scene`: a regrasp Scene or Scene3D (got {type(scene).__name__})", "scene")
    size, mu = pusher_extent(scene)
    side = max(BLOCK_SIDE, BLOCK_MARGIN * size)
    lines = feature_friction(scene, ("line",), mu)
    table = Table(TABLE_HEIGHT, list(TABLE_SIZE), feature_friction(scene, ("line", "patch", "plane"), TABLE_FRICTION),
                  list(TABLE_CENTER))
    block = Feature("fixture", "block", [*BLOCK_CENTER, TABLE_HEIGHT + BLOCK_LIFT + side / 2, 1.0, 0.0, 0.0, 0.0], mu,
                    [side] * 3)
    ledge = Feature("ledge", "edge", [*LEDGE_CENTER, TABLE_HEIGHT + LEDGE_HEIGHT, 0.0, 1.0, 0.0, 0.0], lines,
                    length=side, index=1)
    r = np.sqrt(0.5)
    features = [block, ledge]
    if size > 0:  # its x along world z, its z (the push) along world −x: −90° about y
        features.append(Feature("rod", "edge", [*ROD_CENTER, TABLE_HEIGHT + ROD_HEIGHT, r, 0.0, -r, 0.0], lines,
                                length=ROD_MARGIN * size, index=len(features)))
    patch = patch_extent(scene)
    if patch > 0:  # the face's +z along world −x: −90° about y
        features.append(Feature("plate", "face", [*PLATE_CENTER, TABLE_HEIGHT + PLATE_HEIGHT, r, 0.0, -r, 0.0],
                                feature_friction(scene, ("patch",), mu),
                                [max(PLATE_MIN, PLATE_MARGIN * patch)] * 2, index=len(features)))
    robot = Robot(ROBOT, [0.0, 0.0, TABLE_HEIGHT, 1.0, 0.0, 0.0, 0.0])
    name, start = f"default-{scene.name}", ObjectStart("hand")
    inclines = _inclines(scene, Workcell(name, table, tuple(features), robot, start))
    return Workcell(name, table, tuple(features) + inclines, robot, start,
                    f"generated for scene {scene.name}: a table, a fixture block, a ledge"
                    + (", a rod" if size > 0 else "")
                    + (", a plate" if patch > 0 else "")
                    + (f", {len(inclines)} incline(s)" if inclines else ""))


def _start_pose(scene) -> np.ndarray:
    """The object's pose in the grasp at the task's start (identity without a task)."""
    t = scene.task
    if t is not None:  # the one Task type of both scenes
        return np.asarray(t.start, float)
    return np.zeros(3) if scene.dimension == 2 else np.array([0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0])


def _inclines(scene, cell: Workcell) -> tuple:
    """The inclines (see :data:`INCLINE_CENTER`) for the line pushers of ``scene`` that no
    contact of ``cell`` serves within ``MAX_TILT`` at the task's start."""
    from .. import pose as P
    from ..errors import ExecutionError
    from .assignment import candidates, gravity_in_gripper, pusher_contact

    start, g = _start_pose(scene), gravity_in_gripper(scene)
    R = P.quat_matrix(P.turn_onto(g, [0.0, 0.0, -1.0]))  # the gripper frame with the scene's gravity down
    O = P.planar_to_spatial(start) if scene.dimension == 2 else start
    out = []
    for name in scene.pusher_names:
        pc = pusher_contact(scene, name, start)
        if pc.kind != "line":
            continue
        try:
            candidates(scene, [start, start], [None, name], cell)
            continue
        except ExecutionError:
            pass
        F = P.quat_matrix(P.compose(O, pc.frame)[3:])  # the contact frame in the gripper frame
        e, d = R @ F[:, 0], R @ F[:, 2]                # along the segment, the push: world
        yaw = np.pi - np.arctan2(d[1], d[0]) if np.hypot(d[0], d[1]) > 1e-6 else -np.arctan2(e[1], e[0])
        Z = P.quat_matrix(P.z_turn(yaw)[3:])  # pushing towards the robot (world −x)
        e, d = Z @ e, Z @ d
        k = len(out)
        origin = [INCLINE_CENTER[0], INCLINE_CENTER[1] + k * INCLINE_STEP, TABLE_HEIGHT + INCLINE_HEIGHT]
        pose = P.from_frame(np.column_stack([e, np.cross(d, e), d]), origin)
        length = ROD_MARGIN * float(np.ptp(pc.footprint[:, 0]))
        out.append(Feature(f"incline-{name}", "edge", pose, pc.friction, length=length,
                           index=len(cell.features) + k))
    return tuple(out)

