"""What the world view draws, as plain numbers, in the world frame (z up, metres, poses
``[x, y, z, qw, qx, qy, qz]``): the workcell (the table as a slab on legs, each feature as a
convex body behind the contacts it offers: a block as its box, a face as a thin plate, an edge as
a wedge, a corner as a pyramid whose tip is the corner; the robot's base as a cylinder marker),
the world axes, and for a world motion (:class:`~regrasp.execution.WorldMotion`) the gripper's
jaws (in the gripper frame), the object's mesh (in its frame) and the motion's samples.
Every body's triangles face outward (the page culls back faces)."""

from __future__ import annotations

import itertools

import numpy as np

from .. import pose as P
from ..errors import ArgumentError
from .view_data import _outward, _world, feature_mesh, jaws

#: The table's drawn slab thickness under its top [m] and its legs' side [m].
TABLE_THICKNESS = 0.04
LEG_SIDE = 0.05
#: How deep [m] an edge's wedge and a corner's pyramid reach behind the contact, and a face
#: feature's plate thickness [m].
FEATURE_BODY = 0.03
PLATE_THICKNESS = 0.005
#: The robot base marker: a cylinder of this radius [m] and height [m] on the base pose, with
#: this many sides.
BASE_RADIUS = 0.075
BASE_HEIGHT = 0.12
BASE_SIDES = 24
#: The drawn world axes' length [m].
AXIS_LENGTH = 0.2


def convex_mesh(v) -> tuple[list, list]:
    """The vertices ``v`` (k, 3) [m] of a box-like convex body given as two rings of 4 (bottom,
    top, in order): vertices and outward triangles."""
    v = np.asarray(v, float)
    tris = [[0, 2, 1], [0, 3, 2], [4, 5, 6], [4, 6, 7]] + \
        [t for i in range(4) for t in ([i, (i + 1) % 4, 4 + (i + 1) % 4], [i, 4 + (i + 1) % 4, 4 + i])]
    return v.tolist(), _outward(v, tris, v.mean(axis=0))


def box_mesh(pose, half) -> tuple[list, list]:
    """A box of half-sizes ``half`` [m] centred on ``pose`` (m, unit quaternion): its 8 vertices
    (world) and outward triangles."""
    h = np.asarray(half, float)
    local = [[sx * h[0], sy * h[1], sz * h[2]] for sz in (-1, 1) for sx, sy in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
    return convex_mesh(P.transform(pose, np.array(local)))


def cylinder_mesh(pose, radius: float, height: float, sides: int = BASE_SIDES) -> tuple[list, list]:
    """A cylinder of ``radius`` [m] and ``height`` [m] standing on ``pose`` (m, unit quaternion;
    along its z): vertices and outward triangles."""
    a = 2 * np.pi * np.arange(sides) / sides
    ring = np.c_[radius * np.cos(a), radius * np.sin(a), np.zeros(sides)]
    v = np.vstack([ring, ring + [0, 0, height], [[0, 0, 0], [0, 0, height]]])
    tris = []
    for i in range(sides):
        j = (i + 1) % sides
        tris += [[i, j, sides + j], [i, sides + j, sides + i], [2 * sides, j, i], [2 * sides + 1, sides + i, sides + j]]
    w = P.transform(pose, v)
    return w.tolist(), _outward(w, tris, w[:-2].mean(axis=0))


def table_parts(table) -> list[dict]:
    """The table's drawn parts (its slab under the top, and 4 legs down to z = 0 when it stands
    above the floor): ``name``, ``vertices`` [m] and ``triangles`` each."""
    cx, cy = table.center
    sx, sy = np.asarray(table.size) / 2
    top = table.height
    out = []
    v, t = box_mesh([cx, cy, top - TABLE_THICKNESS / 2, 1, 0, 0, 0], [sx, sy, TABLE_THICKNESS / 2])
    out.append({"name": "table", "vertices": v, "triangles": t})
    leg = top - TABLE_THICKNESS
    if leg > 1e-3:
        for i, j in itertools.product((1, -1), (1, -1)):
            x, y = cx + i * (sx - LEG_SIDE / 2), cy + j * (sy - LEG_SIDE / 2)
            v, t = box_mesh([x, y, leg / 2, 1, 0, 0, 0], [LEG_SIDE / 2, LEG_SIDE / 2, leg / 2])
            out.append({"name": "table leg", "vertices": v, "triangles": t})
    return out


def feature_body(f) -> dict:
    """The drawn body of workcell feature ``f`` (see the module's doc) with its numbers from the
    workcell: ``name``, ``kind``, ``pose`` (m, unit quaternion), ``size`` [m] (block, face),
    ``length`` [m] (edge), ``vertices`` [m] (world) and outward ``triangles``."""
    z = P.quat_rotate(f.pose[3:], [0.0, 0.0, 1.0])
    if f.kind == "block":
        v, t = box_mesh(f.pose, np.asarray(f.size) / 2)
    elif f.kind == "face":
        sx, sy = np.asarray(f.size) / 2
        pts = P.transform(f.pose, np.array([[a, b, 0.0] for a in (-sx, sx) for b in (-sy, sy)]))
        _, v, t = feature_mesh(pts, z, PLATE_THICKNESS)
    elif f.kind == "edge":
        pts = P.transform(f.pose, np.array([[-f.length / 2, 0, 0], [f.length / 2, 0, 0]]))
        _, v, t = feature_mesh(pts, z, FEATURE_BODY)
    else:
        _, v, t = feature_mesh(np.asarray(f.pose[:3])[None], z, FEATURE_BODY)
    return {"name": f.name, "kind": f.kind, "pose": np.asarray(f.pose, float).tolist(),
            "size": None if f.size is None else np.asarray(f.size, float).tolist(),
            "length": f.length, "vertices": np.asarray(v, float).tolist(), "triangles": [list(map(int, x)) for x in t]}


def contact_owners(workcell) -> dict:
    """The feature (``"table"`` for the table) that owns each contact name of ``workcell``: a
    block's ``NAME.faces[i]`` etc. belong to ``NAME``."""
    return workcell.contact_owners()


def workcell_description(workcell) -> dict:
    """The world view's data of ``workcell``: ``name``, ``table`` (its numbers and ``parts``),
    ``features`` (:func:`feature_body` each), ``robot`` (name, base pose, its marker's mesh),
    ``axes`` (origin, length [m]) and the framing (``center``, ``extent`` [m])."""
    t = workcell.table
    v, tris = cylinder_mesh(workcell.robot.base, BASE_RADIUS, BASE_HEIGHT)
    d = {"name": workcell.name,
         "table": {"height": t.height, "size": t.size.tolist(), "center": t.center.tolist(), "friction": t.friction,
                   "parts": table_parts(t)},
         "features": [feature_body(f) for f in workcell.features],
         "robot": {"name": workcell.robot.name, "base": workcell.robot.base.tolist(), "radius": BASE_RADIUS,
                   "height": BASE_HEIGHT, "vertices": v, "triangles": tris},
         "axes": {"origin": [0.0, 0.0, 0.0], "length": AXIS_LENGTH}}
    pts = np.concatenate([np.asarray(p["vertices"]) for p in d["table"]["parts"]]
                         + [np.asarray(f["vertices"]) for f in d["features"]] + [np.asarray(v), np.zeros((1, 3))])
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    d["center"], d["extent"] = ((lo + hi) / 2).tolist(), float((hi - lo).max() / 2)
    return d


def gripper_description(view: dict, in_hand) -> dict:
    """The jaws in the gripper frame for the object of ``view`` (the scene's page data,
    :func:`regrasp.viz.viewer.description`) held at ``in_hand`` (n, 7) (m, unit quaternion): the
    fingers' inner faces at the object's extremes along y over those poses (``top``, ``bot`` [m]),
    the palm above it (``palm_z`` [m]), ``thickness`` and ``breadth`` [m] of the fingers, ``pad``
    radius [m]."""
    v = np.asarray(view["vertices"], float)
    w = _world(in_hand, v)
    J = jaws(in_hand, v, view["pad"], view["jaws"]["width"], view["size"])
    return {"top": float(w[..., 1].max()), "bot": float(w[..., 1].min()), "palm_z": J["palm_z"],
            "thickness": J["thickness"], "breadth": J["breadth"], "pad": view["pad"], "pad_rect": view["pad_rect"]}


def _object(view):
    """The object's mesh (object frame) of the scene's page data ``view`` (None: none)."""
    if not view:
        return None
    return {k: view[k] for k in ("vertices", "triangles", "marks", "edges", "size")}


def arm_checked(arm, samples: int):
    """The robot's drawing data ``arm`` (:func:`regrasp.robot.shapes.arm_view`: ``bodies`` with
    ``vertices`` [m] and ``triangles``, ``samples`` the motion's sample indices kept, ``poses``
    frames × bodies × 7) checked against a motion of ``samples`` samples; None stays None."""
    if arm is None:
        return None
    ok = isinstance(arm, dict) and {"bodies", "samples", "poses"} <= set(arm)
    if ok:
        idx, poses = np.asarray(arm["samples"]), np.asarray(arm["poses"], float)
        ok = (idx.ndim == 1 and len(idx) >= 1 and idx[0] == 0 and idx[-1] == samples - 1 and np.all(np.diff(idx) > 0)
              and poses.shape == (len(idx), len(arm["bodies"]), 7) and bool(np.all(np.isfinite(poses))))
    if not ok:
        raise ArgumentError("invalid `arm`: the robot's bodies and their poses at the motion's samples "
                            "(regrasp.robot.shapes.arm_view)", "arm")
    return {k: arm[k] for k in ("robot", "bodies", "samples", "poses") if k in arm}


def _arm_points(arm) -> np.ndarray:
    """Every drawn body's vertices in the world at the first, middle and last kept frame [m]."""
    poses = np.asarray(arm["poses"], float)
    out = [np.zeros((0, 3))]
    for f in {0, len(poses) // 2, len(poses) - 1}:
        for b, body in enumerate(arm["bodies"]):
            out.append(P.transform(poses[f, b], np.asarray(body["vertices"], float)))
    return np.vstack(out)


def motion_description(view, motion, arm=None) -> dict:
    """The world view's data of ``motion`` (a :class:`~regrasp.execution.WorldMotion`) of the
    scene whose page data is ``view`` (None: no object, the gripper drawn as its axes): the workcell (:func:`workcell_description`), the object's
    mesh, the gripper (:func:`gripper_description`), the samples (``times`` [s], ``gripper`` and
    ``object`` world poses (m, unit quaternion), ``labels``, ``push``) and per push its pusher,
    contact (``feature``), owning feature (``body``), contact kind, ``frame`` (m, unit
    quaternion), edge ``length`` [m], face ``extent`` [m] and path indices; ``arm``: the robot's
    bodies along the motion (:func:`arm_checked`; None: the gripper alone). The framing holds the
    workcell, the gripper's path with the object around it, and the arm."""
    d = workcell_description(motion.workcell)
    owners = contact_owners(motion.workcell)
    contacts = {c.name: c for c in motion.workcell.contacts()}
    pushes = []
    for a in motion.assignments:
        c = contacts[a.feature]
        pushes.append({"index": a.index, "pusher": a.pusher, "feature": a.feature, "body": owners[a.feature],
                       "kind": c.kind, "frame": np.asarray(a.frame, float).tolist(), "length": c.length,
                       "extent": np.asarray(c.extent, float).tolist(), "first": a.first, "last": a.last})
    d.update(scene=view["name"] if view else motion.scene, object=_object(view),
             gripper=gripper_description(view, motion.in_hand) if view and view["jaws"] else None,
             samples={"times": np.asarray(motion.times, float).tolist(), "gripper": np.asarray(motion.gripper, float).tolist(),
                      "object": np.asarray(motion.object, float).tolist(), "labels": list(motion.labels),
                      "push": np.asarray(motion.push, int).tolist()},
             pushes=pushes, arm=arm_checked(arm, len(motion.times)))
    path = np.asarray(motion.gripper, float)[:, :3]
    reach = 1.5 * float(view["size"]) if view else 0.05  # the object and the jaws about the path
    pts = [path, path + reach, path - reach]
    if d["arm"] is not None:
        pts.append(_arm_points(d["arm"]))
    return _framed(d, np.vstack(pts))


def _framed(d: dict, pts) -> dict:
    """``d`` with its framing (``center``, ``extent`` [m]) grown to hold the points ``pts`` [m]."""
    c, e = np.asarray(d["center"]), d["extent"]
    pts = np.vstack([np.asarray(pts, float), c - e, c + e])
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    d["center"], d["extent"] = ((lo + hi) / 2).tolist(), float((hi - lo).max() / 2)
    return d


def still_description(view: dict, workcell, hand_pose=None) -> dict:
    """The world view's data of ``workcell`` with the object of ``view`` (the scene's page data)
    where it starts: on the table at ``workcell.object.pose``, or held at the scene's start in the
    gripper at ``hand_pose`` (m, unit quaternion; the gripper's world pose)."""
    d = workcell_description(workcell)
    d.update(scene=view["name"], object=_object(view), pushes=[])
    if workcell.object.on == "table":
        d.update(gripper=None, samples={"times": [0.0], "gripper": [None], "object": [workcell.object.pose.tolist()],
                                        "labels": ["start"], "push": [-1]})
    else:
        start = np.asarray(view["poses"][0], float)
        d.update(gripper=None if view["jaws"] is None else gripper_description(view, start[None]),
                 samples={"times": [0.0], "gripper": [list(map(float, hand_pose))],
                          "object": [P.compose(hand_pose, start).tolist()], "labels": ["start"], "push": [-1]})
    return d
