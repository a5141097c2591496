"""The robot's bodies as convex shapes for drawing (the world view, :mod:`regrasp.viz.world_data`):
each arm and gripper body that moves with the arm joints alone (the fingers, which the view draws
at the object, left out) as the convex hull of its collision geoms in the body's frame, and the
bodies' world poses along a joint trajectory (MuJoCo's forward kinematics). Plain numbers: m,
poses ``[x, y, z, qw, qx, qy, qz]``."""

from __future__ import annotations

import numpy as np

from ..extras import need

#: Points on a unit circle for the round primitives (sphere, capsule, cylinder, ellipsoid).
ROUND = 16
#: A body's hull is made of its points' extremes along this many directions (a light shape
#: for the page: at most this many vertices).
DIRECTIONS = 96
#: The most frames of body poses kept for a trajectory (every k-th sample, the last always).
MAX_FRAMES = 600


def _round_points(kind: int, size, mujoco) -> np.ndarray:
    """Points on a primitive geom of MuJoCo type ``kind`` and ``size`` in its own frame [m]."""
    g = mujoco.mjtGeom
    a = 2 * np.pi * np.arange(ROUND) / ROUND
    ring = np.c_[np.cos(a), np.sin(a), np.zeros(ROUND)]
    if kind == g.mjGEOM_BOX:
        return np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float) * size[:3]
    if kind == g.mjGEOM_CYLINDER:
        return np.vstack([ring * size[0] + [0, 0, h] for h in (-size[1], size[1])])
    lat = np.linspace(-np.pi / 2, np.pi / 2, 7)
    sphere = np.vstack([np.c_[ring[:, :2] * np.cos(b), np.full(ROUND, np.sin(b))] for b in lat])
    if kind == g.mjGEOM_SPHERE:
        return sphere * size[0]
    if kind == g.mjGEOM_CAPSULE:
        cap = sphere * size[0]
        return np.vstack([cap[cap[:, 2] <= 0] - [0, 0, size[1]], cap[cap[:, 2] >= 0] + [0, 0, size[1]]])
    if kind == g.mjGEOM_ELLIPSOID:
        return sphere * size[:3]
    return np.zeros((0, 3))  # planes, height fields: not drawn


def _geom_points(model, g: int, mujoco) -> np.ndarray:
    """Geom ``g``'s points in its body's frame [m]."""
    from ..pose import quat_rotate

    if model.geom_type[g] == mujoco.mjtGeom.mjGEOM_MESH:
        m = model.geom_dataid[g]
        local = model.mesh_vert[model.mesh_vertadr[m]:model.mesh_vertadr[m] + model.mesh_vertnum[m]].astype(float)
    else:
        local = _round_points(model.geom_type[g], model.geom_size[g], mujoco)
    return quat_rotate(model.geom_quat[g], local) + model.geom_pos[g] if len(local) else local


def drawn_bodies(robot) -> list[int]:
    """The ids of ``robot``'s bodies with collision geoms whose pose the arm joints alone set
    (no other joint between them and the world)."""
    m = robot.model
    arm = {int(m.jnt_bodyid[m.jnt_qposadr.tolist().index(a)]) for a in robot.arm_qpos}
    out = []
    for b in sorted({int(m.geom_bodyid[g]) for g in robot.robot_geoms}):
        k, ok = b, True
        while k > 0 and ok:
            ok = m.body_jntnum[k] == 0 or k in arm
            k = int(m.body_parentid[k])
        if ok:
            out.append(b)
    return out


def body_shapes(robot) -> list[dict]:
    """Per drawn body (:func:`drawn_bodies`): its ``name``, the convex hull of its collision geoms
    (the pads' contact grid left out) as ``vertices`` (body frame, m) and ``triangles`` (indices,
    outward)."""
    from scipy.spatial import ConvexHull

    mujoco = need("mujoco", "robot")
    m = robot.model
    pads = {g for side in robot.pad_geoms for g in side}
    out = []
    for b in drawn_bodies(robot):
        pts = [_geom_points(m, g, mujoco) for g in robot.robot_geoms if m.geom_bodyid[g] == b and g not in pads]
        pts = np.vstack([p for p in pts if len(p)] or [np.zeros((0, 3))])
        if len(pts) < 4 or np.linalg.matrix_rank(pts - pts.mean(axis=0), tol=1e-6) < 3:
            continue
        hull = ConvexHull(_extremes(pts))
        tris = [_outward(hull.points, s, hull.points[hull.vertices].mean(axis=0)) for s in hull.simplices]
        used = sorted({i for t in tris for i in t})
        index = {i: k for k, i in enumerate(used)}
        out.append({"name": m.body(b).name, "body": b, "vertices": np.round(hull.points[used], 5).tolist(),
                    "triangles": [[index[i] for i in t] for t in tris]})
    return out


def _extremes(pts) -> np.ndarray:
    """The points of ``pts`` (n, 3) farthest along :data:`DIRECTIONS` directions spread over the
    sphere (a Fibonacci lattice): the hull of these is the drawn shape."""
    k = np.arange(DIRECTIONS) + 0.5
    z, phi = 1 - 2 * k / DIRECTIONS, np.pi * (1 + 5 ** 0.5) * k
    d = np.c_[np.sqrt(1 - z * z) * np.cos(phi), np.sqrt(1 - z * z) * np.sin(phi), z]
    return pts[np.unique(np.argmax(pts @ d.T, axis=0))]


def _outward(v, tri, centre) -> list[int]:
    """Triangle ``tri`` of points ``v`` ordered so its normal points away from ``centre``."""
    a, b, c = (v[i] for i in tri)
    return [int(tri[0]), int(tri[1]), int(tri[2])] if np.cross(b - a, c - a) @ (a - centre) >= 0 \
        else [int(tri[0]), int(tri[2]), int(tri[1])]


def body_poses(robot, qs, bodies) -> np.ndarray:
    """World poses (len(qs), len(bodies), 7) of body ids ``bodies`` at each joint configuration
    of ``qs`` (n, joints) [rad]; the robot's state is restored after."""
    mujoco = need("mujoco", "robot")
    m, d = robot.model, robot.data
    keep = d.qpos.copy()
    out = np.empty((len(qs), len(bodies), 7))
    try:
        for i, q in enumerate(np.asarray(qs, float)):
            d.qpos[robot.arm_qpos] = q
            mujoco.mj_kinematics(m, d)
            out[i, :, :3], out[i, :, 3:] = d.xpos[bodies], d.xquat[bodies]
    finally:
        d.qpos[:] = keep
        mujoco.mj_kinematics(m, d)
    return out


def arm_view(robot, qs) -> dict:
    """The world view's data of ``robot`` along joint configurations ``qs`` (n, joints) [rad], one
    per world-motion sample: ``bodies`` (:func:`body_shapes`), ``every`` (the stride of the kept
    samples, at most :data:`MAX_FRAMES` of them, the last always), ``samples`` (their indices) and
    ``poses`` (frames × bodies × 7)."""
    shapes = body_shapes(robot)
    qs = np.asarray(qs, float)
    every = max(1, int(np.ceil(len(qs) / MAX_FRAMES)))
    idx = sorted({*range(0, len(qs), every), len(qs) - 1})
    poses = body_poses(robot, qs[idx], [s["body"] for s in shapes])
    return {"robot": robot.name, "bodies": [{k: s[k] for k in ("name", "vertices", "triangles")} for s in shapes],
            "every": every, "samples": idx, "poses": np.round(poses, 5).tolist()}


def trajectory_view(robot: str, base_pose, qs) -> dict:
    """:func:`arm_view` of robot ``robot`` (a name the registry knows) standing at world
    ``base_pose`` (m, unit quaternion) along joint configurations ``qs`` (n, joints) [rad]."""
    from .model import build

    return arm_view(build(robot, base_pose, table=None), qs)
