"""What the browser view draws, as plain numbers: the scene and plan described in the gripper
frame (the planner's view: the gripper fixed, the object and its pushers moving), in 3-D for
planar scenes too. Lengths in metres, poses ``[x, y, z, qw, qx, qy, qz]`` of the object frame.

A planar scene (poses ``[x, z, theta]`` in the gripper's x-z plane) becomes its outline extruded
across the jaw direction y; a planar pusher's points become a face (a line pusher) or an edge
(a point pusher) across that thickness. Pushers are drawn as small bodies on the outside of the
object, their contact face at the pusher's points: one point is a corner (a pyramid), a line an
edge (a wedge), a patch a block face; 3-D plane pushers are drawn where they touch.
"""

from __future__ import annotations

import numpy as np

from ..polygon import signed_area, triangulate
from ..pose import planar_to_spatial, quat_rotate, tangents

#: depth of a pusher's body behind its contact, as a fraction of the object's size
FEATURE_DEPTH = 0.25
#: length of the drawn axes, as a fraction of the object's size
AXIS_LENGTH = 0.7
#: half-size of the ground square, as a multiple of the object's size
GROUND_HALF = 2.0


def extrude(outline, thickness: float):
    """The prism of a simple polygon (x, z) across y in [-thickness/2, thickness/2]: vertices
    (2n, 3) and outward triangles (caps by ear clipping, walls as quads)."""
    p = np.asarray(outline, float)
    if signed_area(p) < 0:
        p = p[::-1]
    n, h = len(p), thickness / 2
    v = np.array([[x, y, z] for y in (-h, h) for x, z in p])
    caps = triangulate(p)
    # a counter-clockwise (x, z) polygon: its normal is x × z = -y, so the cap at -h as is
    tris = [[a, b, c] for a, b, c in caps] + [[n + a, n + c, n + b] for a, b, c in caps]
    for i in range(n):
        j = (i + 1) % n
        tris += [[i, n + i, j], [j, n + i, n + j]]
    return v, [list(map(int, x)) for x in tris]


def _outward(v, tris, centre) -> list:
    """Triangles of a convex body turned so their normals (right-hand rule) point away from
    ``centre``."""
    out = []
    for t in tris:
        a, b, c = v[t[0]], v[t[1]], v[t[2]]
        n = np.cross(b - a, c - a)
        out.append([int(t[0]), int(t[2]), int(t[1])] if n @ ((a + b + c) / 3 - centre) < 0 else list(map(int, t)))
    return out


def feature_mesh(points, normal, depth: float):
    """The body of a pusher touching the object at ``points`` (object frame) with ``normal``
    (into the object): its kind ("corner", "edge" or "face"), vertices and outward triangles.
    The contact face (or edge, or tip) is at the points; the body lies on the -normal side."""
    p, n = np.asarray(points, float).reshape(-1, 3), np.asarray(normal, float)
    n = n / np.linalg.norm(n)
    c = p.mean(axis=0)
    d = p - c
    d -= np.outer(d @ n, n)
    _, s, vt = np.linalg.svd(d) if len(d) > 1 else (None, np.zeros(1), np.eye(3))
    rank = int(np.sum(s > 1e-9 * max(1.0, depth)))
    t1, t2 = (vt[0], np.cross(n, vt[0])) if rank >= 1 else tangents(n)
    back = c - depth * n
    w = 0.6 * depth
    if rank == 0:
        base = [back + w * (i * t1 + j * t2) for i, j in ((1, 1), (-1, 1), (-1, -1), (1, -1))]
        v = np.array([c, *base])
        tris = [[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 1], [1, 2, 3], [1, 3, 4]]
        return "corner", v, _outward(v, tris, v.mean(axis=0))
    a, b = (d @ t1).min(), (d @ t1).max()
    if rank == 1:
        v = np.array([c + a * t1, c + b * t1, back + a * t1 + w * t2, back + b * t1 + w * t2,
                      back + a * t1 - w * t2, back + b * t1 - w * t2])
        tris = [[0, 1, 3], [0, 3, 2], [0, 4, 5], [0, 5, 1], [2, 3, 5], [2, 5, 4], [0, 2, 4], [1, 5, 3]]
        return "edge", v, _outward(v, tris, v.mean(axis=0))
    e, f = (d @ t2).min(), (d @ t2).max()
    face = [c + i * t1 + j * t2 for i, j in ((a, e), (b, e), (b, f), (a, f))]
    v = np.array(face + [x - depth * n for x in face])
    tris = [[0, 1, 2], [0, 2, 3], [4, 6, 5], [4, 7, 6]] + \
        [t for i in range(4) for t in ([i, (i + 1) % 4, 4 + (i + 1) % 4], [i, 4 + (i + 1) % 4, 4 + i])]
    return "face", v, _outward(v, tris, v.mean(axis=0))


def _features(pushers, depth: float) -> list:
    """The drawn bodies of ``pushers`` (name, points, normal in the object frame)."""
    out = []
    for name, pts, normal in pushers:
        kind, v, t = feature_mesh(pts, normal, depth)
        out.append({"name": name, "kind": kind, "points": np.asarray(pts, float).tolist(),
                    "normal": (np.asarray(normal, float) / np.linalg.norm(normal)).tolist(),
                    "vertices": v.tolist(), "triangles": t})
    return out


def _with_features(v, features) -> np.ndarray:
    """The object's vertices and its pushers' bodies' (object frame)."""
    return np.concatenate([np.asarray(v, float)] + [np.asarray(f["vertices"], float) for f in features])


def _world(poses, v):
    """The vertices ``v`` (object frame) at every pose: (poses, vertices, 3)."""
    return np.array([quat_rotate(q[3:], v) + q[:3] for q in np.asarray(poses, float)])


def ground(poses, vertices, gravity, size: float, support=None) -> dict:
    """The ground: a square perpendicular to gravity under the object (through its lowest point
    over ``poses``), or the scene's support (``support``: a dict with ``point`` [m] and ``normal``).
    ``poses``: object poses in the gripper frame ([x, z, theta] in m, m, rad, or [x, y, z, qw, qx, qy,
    qz] in m); ``vertices`` [m] in the object frame; ``size`` [m]: the object's size (the square's
    half side is GROUND_HALF times it)."""
    if support is not None:
        up, point = np.asarray(support["normal"], float), np.asarray(support["point"], float)
    else:
        up = -np.asarray(gravity, float) / np.linalg.norm(gravity)
        w = _world(poses, np.asarray(vertices, float))
        level = float((w @ up).min())
        mid = w.reshape(-1, 3).mean(axis=0)
        point = mid - (mid @ up - level) * up
    t1, t2 = tangents(up)
    return {"point": point.tolist(), "normal": up.tolist(), "t1": t1.tolist(), "t2": t2.tolist(),
            "half": GROUND_HALF * size, "support": None if support is None else support.get("name")}


def jaws(poses, vertices, pad: float, width: float, size: float) -> dict:
    """The parallel gripper in its own frame: two fingers (pads of radius ``pad`` at y = ±width/2,
    the pads' centres at the origin's x, z) and the palm joining them above the object (+z, past
    its highest point over ``poses``; ``vertices``: the object's and its pushers' bodies')."""
    top = float(_world(poses, np.asarray(vertices, float))[..., 2].max())
    return {"width": float(width), "pad": float(pad), "thickness": 0.25 * max(pad, 0.1 * size),
            "breadth": 1.6 * pad, "palm_z": max(top, 2 * pad) + 0.25 * size}


def framing(d: dict) -> dict:
    """``d`` with where the camera looks (``center``) and the half-extent to fit (``extent``) [m]
    (the object over its poses, the ground's centre and the palm), and the ``axes``."""
    pts = [_world(d["poses"], np.asarray(d["vertices"], float)).reshape(-1, 3), [d["ground"]["point"]]]
    if d["jaws"] is not None:
        pts.append([[0.0, 0.0, d["jaws"]["palm_z"] + d["jaws"]["thickness"]]])
    pts = np.concatenate([np.asarray(x, float) for x in pts])
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    d["center"], d["extent"] = ((lo + hi) / 2).tolist(), float(max((hi - lo).max() / 2, d["size"]))
    # the gripper frame's axes (x, y, z) at its origin, drawn red, green, blue
    d["axes"] = {"origin": [0.0, 0.0, 0.0], "length": AXIS_LENGTH * d["size"]}
    return d


def feature_edges(v, t, angle: float = 0.35) -> list:
    """The edges (vertex index pairs) of a closed mesh where its faces meet at more than
    ``angle`` [rad]: what outlines the goal pose."""
    v, t = np.asarray(v, float), np.asarray(t, int)
    n = np.cross(v[t[:, 1]] - v[t[:, 0]], v[t[:, 2]] - v[t[:, 0]])
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    faces = {}
    for f, tri in enumerate(t):
        for a, b in ((tri[0], tri[1]), (tri[1], tri[2]), (tri[2], tri[0])):
            faces.setdefault((min(a, b), max(a, b)), []).append(f)
    return [[int(a), int(b)] for (a, b), fs in faces.items()
            if len(fs) != 2 or n[fs[0]] @ n[fs[1]] < np.cos(angle)]


def planar_description(scene, plan_poses, plan_pushers) -> dict:
    """The view's data for a planar :class:`~regrasp.Scene` (see the module doc); ``plan_poses``:
    object poses [x, z, theta] (m, m, rad) in the gripper frame, ``plan_pushers`` their pusher names."""
    outline = np.asarray(scene.outline, float)
    size = float(np.linalg.norm(outline - outline.mean(axis=0), axis=1).max())
    grasp = scene.kind == "grasp"
    shape, a, b = scene.pad if grasp else ("circle", 0.0, 0.0)
    pad = float(a) if shape == "circle" else 0.5 * float(max(a, b))
    thick = max(4 * pad, 0.25 * size) if grasp else 0.25 * size
    v, t = extrude(outline, thick)
    task = scene.task
    start = task.start if task is not None else np.zeros(3)
    poses = [planar_to_spatial(q) for q in (plan_poses if plan_poses is not None else [start])]
    h = thick / 2
    pushers = []
    for p in scene.pushers:
        pts = [[x, y, z] for x, z in p.points for y in ((-h, h) if len(p.points) <= 2 else (0.0,))]
        pushers.append((p.name, pts, [p.normal[0], 0.0, p.normal[1]]))
    gdir, g = scene.gravity
    gravity = [float(gdir[0]), 0.0, float(gdir[1])]
    feats = _features(pushers, FEATURE_DEPTH * size)
    support = None if grasp else {"name": "surface", "point": [0.0, h, 0.0], "normal": [0.0, -1.0, 0.0]}
    return framing({
        "dimension": 2, "edges": feature_edges(v, t),
        "vertices": v.tolist(), "triangles": t, "marks": [0] * len(t), "sphere": None, "size": size,
        "poses": poses, "pushers_of_steps": list(plan_pushers) if plan_pushers is not None else [None],
        "pusher_points": {p.name: [[x, 0.0, z] for x, z in p.points] for p in scene.pushers},
        "planes": {},
        "features": feats,
        "pad": pad,
        # a rectangular pad: its half-sizes (x, z)
        "pad_rect": None if shape == "circle" else [0.5 * float(a), 0.5 * float(b)],
        "jaws": jaws(poses, _with_features(v, feats), pad, thick, size) if grasp else None,
        "ground": ground(poses, v, gravity, size, support),
        "gravity": {"direction": gravity, "g": float(g), "in_plane": not grasp},
        "goal": planar_to_spatial(task.goal) if task is not None else None,
    })


def spatial_description(scene, plan_poses, plan_pushers, marks) -> dict:
    """The view's data for a :class:`~regrasp.Scene3D` (see the module doc); ``plan_poses``: object
    poses [x, y, z, qw, qx, qy, qz] (m, unit quaternion) in the gripper frame, ``plan_pushers``
    their pusher names."""
    v, t = scene.surface()
    v = np.asarray(v, float)
    size = float(np.linalg.norm(v, axis=1).max())
    start, goal, _ = scene.task
    poses = [list(map(float, q)) for q in (plan_poses if plan_poses is not None else [start])]
    contacts = np.concatenate(scene.pad_contacts(start))
    width = float(contacts[:, 1].max() - contacts[:, 1].min())
    gvec = np.asarray(scene.gravity, float)
    gn = float(np.linalg.norm(gvec))
    gdir = gvec / gn if gn > 0 else np.array([0.0, 0.0, -1.0])
    names = list(scene.pusher_names)
    planes = {n: scene.pusher_normal(n).tolist() for n in names if scene.is_plane(n)}
    support = None
    for n, normal in planes.items():
        if np.dot(normal, -gdir) > 0.99:  # a floor: the ground through the object's lowest point
            w = _world(poses, v)
            support = {"name": n, "normal": normal, "point": (w.reshape(-1, 3)[np.argmin(w.reshape(-1, 3) @ normal)]).tolist()}
    pushers = [(n, scene.pusher_points(n), scene.pusher_normal(n))
               for n in names if not scene.is_plane(n)]
    feats = _features(pushers, FEATURE_DEPTH * size)
    return framing({
        "dimension": 3, "edges": feature_edges(v, t),
        "vertices": v.tolist(), "triangles": np.asarray(t, int).tolist(), "marks": list(map(int, marks)),
        "sphere": scene.sphere, "size": size,
        "poses": poses, "pushers_of_steps": list(plan_pushers) if plan_pushers is not None else [None],
        "pusher_points": {n: scene.pusher_points(n).tolist() for n in names},
        # plane pushers: their normals (gripper frame); the page finds where they touch
        "planes": planes,
        "features": feats,
        "pad": float(scene.pad_radius), "pad_rect": None,
        "jaws": jaws(poses, _with_features(v, feats), float(scene.pad_radius), width, size),
        "ground": ground(poses, v, gdir, size, support),
        "gravity": {"direction": gdir.tolist(), "g": gn, "in_plane": False},
        "goal": list(map(float, goal)),
    })
