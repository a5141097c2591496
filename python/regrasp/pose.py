"""Pose helpers in numpy, in one place. 3-D poses are ``[x, y, z, qw, qx, qy, qz]`` (m, unit
quaternion ``[w, x, y, z]``), body twists ``[vx, vy, vz, wx, wy, wz]`` (m/s, rad/s); planar poses
``[x, z, theta]`` (m, m, rad) in the x-z plane, a turn by theta (x towards z) being a rotation by
-theta about +y. The SE(3) algebra itself (compose, inverse, log, exp) is the core's
(``_core.se3_*``); here: quaternions (matrix, rotating vectors, from a matrix, slerp, angle),
planar poses (their quaternion and 3-D pose, compose, inverse, rotate), the frame of a normal,
twists between poses and frames, and 3-D poses in numpy (compose, inverse, integrate a twist,
from a frame, map points (by one pose or many), interpolate, a turn about x or z)."""

from __future__ import annotations

import math

import numpy as np

from . import _core

# --- quaternions -------------------------------------------------------------------------------


def quat_matrix(q) -> np.ndarray:
    """The 3 x 3 rotation matrix of quaternion ``q`` ``[w, x, y, z]`` (normalized first)."""
    w, x, y, z = np.asarray(q, float) / np.linalg.norm(q)
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ])


def quat_matrices(q) -> np.ndarray:
    """The (n, 3, 3) rotation matrices of quaternions ``q`` (n, 4) ``[w, x, y, z]`` (normalized first)."""
    q = np.asarray(q, float)
    w, x, y, z = (q / np.linalg.norm(q, axis=1, keepdims=True)).T
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], axis=-1),
        np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], axis=-1),
        np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], axis=-1),
    ], axis=1)


def quat_rotate(q, v) -> np.ndarray:
    """Vector(s) ``v`` (shape (3,) or (n, 3), any unit) rotated by quaternion ``q``."""
    return np.asarray(v, float) @ quat_matrix(q).T


def quat_from_matrix(R) -> np.ndarray:
    """The unit quaternion (w >= 0) of rotation matrix ``R`` (Shepperd's method: the largest of
    the four squared components is computed first, so it is accurate for every rotation)."""
    R = np.asarray(R, float)
    t = np.trace(R)
    k = int(np.argmax([t, R[0, 0], R[1, 1], R[2, 2]]))
    q = np.empty(4)
    if k == 0:
        r = np.sqrt(1 + t)
        q[:] = [r / 2, (R[2, 1] - R[1, 2]) / (2 * r), (R[0, 2] - R[2, 0]) / (2 * r), (R[1, 0] - R[0, 1]) / (2 * r)]
    else:
        i, j, m = k - 1, k % 3, (k + 1) % 3
        r = np.sqrt(1 + R[i, i] - R[j, j] - R[m, m])
        q[0] = (R[m, j] - R[j, m]) / (2 * r)
        q[1 + i], q[1 + j], q[1 + m] = r / 2, (R[j, i] + R[i, j]) / (2 * r), (R[m, i] + R[i, m]) / (2 * r)
    q /= np.linalg.norm(q)
    return -q if q[0] < 0 else q


def slerp(a, b, s) -> np.ndarray:
    """The quaternion a fraction ``s`` in [0, 1] of the way from ``a`` to ``b`` along the
    shortest rotation between them (spherical linear interpolation); ``s`` may be an array (n,),
    giving (n, 4)."""
    a, b = np.asarray(a, float) / np.linalg.norm(a), np.asarray(b, float) / np.linalg.norm(b)
    s = np.asarray(s, float)[..., None]
    d = float(a @ b)
    if d < 0:
        b, d = -b, -d
    if d > 1 - 1e-12:
        q = a + s * (b - a)
    else:
        th = np.arccos(d)
        q = (np.sin((1 - s) * th) * a + np.sin(s * th) * b) / np.sin(th)
    return q / np.linalg.norm(q, axis=-1, keepdims=True)


def quat_angle(a, b) -> float:
    """Angle [rad] in [0, pi] of the rotation between quaternions ``a`` and ``b`` ([w, x, y, z],
    normalized first); accurate for small angles too (an arctangent, not an arccosine)."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    (aw, ax, ay, az), (bw, bx, by, bz) = (a / np.linalg.norm(a)).tolist(), (b / np.linalg.norm(b)).tolist()
    # the vector part of a⁻¹ b, written out: np.cross on one pair costs more than the rest (called per IK step)
    vx = aw * bx - bw * ax - (ay * bz - az * by)
    vy = aw * by - bw * ay - (az * bx - ax * bz)
    vz = aw * bz - bw * az - (ax * by - ay * bx)
    return 2 * math.atan2(math.sqrt(vx * vx + vy * vy + vz * vz), abs(aw * bw + ax * bx + ay * by + az * bz))


# --- frames ------------------------------------------------------------------------------------


def tangents(n) -> tuple:
    """Two unit vectors ``t1, t2`` completing the direction ``n`` (normalized first) to the
    right-handed orthonormal frame ``(t1, t2, n)``."""
    n = np.asarray(n, float) / np.linalg.norm(n)
    a = np.array([1.0, 0, 0]) if abs(n[0]) < 0.9 else np.array([0, 1.0, 0])
    t1 = np.cross(n, a)
    t1 /= np.linalg.norm(t1)
    return t1, np.cross(n, t1)


# --- planar poses ------------------------------------------------------------------------------


def planar_quat(theta: float) -> np.ndarray:
    """The quaternion ``[w, x, y, z]`` of the planar angle ``theta`` [rad] (a rotation by −theta
    about +y)."""
    return np.array([np.cos(theta / 2), 0.0, -np.sin(theta / 2), 0.0])


def planar_to_spatial(q) -> list:
    """The planar pose ``q`` ``[x, z, theta]`` (m, m, rad) as a 3-D pose ``[x, 0, z, qw, qx, qy, qz]``."""
    x, z, th = (float(v) for v in q)
    return [x, 0.0, z, *map(float, planar_quat(th))]


def spatial_to_planar(q) -> np.ndarray:
    """The 3-D pose ``q`` ``[x, y, z, qw, qx, qy, qz]`` (m, unit quaternion) as a planar pose
    ``[x, z, theta]`` (m, m, rad) in the x-z plane (the inverse of :func:`planar_to_spatial`;
    y and any turn off the plane dropped)."""
    q = np.asarray(q, float)
    R = quat_matrix(q[3:])
    return np.array([q[0], q[2], np.arctan2(R[2, 0], R[0, 0])])


def planar_compose(a, b) -> np.ndarray:
    """Planar pose composition ``a ∘ b`` of poses ``[x, z, theta]`` (m, m, rad)."""
    c, s = np.cos(a[2]), np.sin(a[2])
    return np.array([a[0] + c * b[0] - s * b[1], a[1] + s * b[0] + c * b[1], a[2] + b[2]])


def planar_inverse(a) -> np.ndarray:
    """The inverse of a planar pose ``a`` ``[x, z, theta]`` (m, m, rad)."""
    c, s = np.cos(a[2]), np.sin(a[2])
    return np.array([-(c * a[0] + s * a[1]), -(-s * a[0] + c * a[1]), -a[2]])


def planar_rotate(theta: float, v) -> np.ndarray:
    """The planar vector ``v`` ``[x, z]`` (any unit) turned by ``theta`` [rad] (x towards z)."""
    c, s = np.cos(theta), np.sin(theta)
    return np.array([c * v[0] - s * v[1], s * v[0] + c * v[1]])


# --- twists ------------------------------------------------------------------------------------


def body_twist(a, b) -> np.ndarray:
    """Planar: the constant body twist taking pose ``a`` to pose ``b`` in unit time (planar log map)."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    c, s = np.cos(a[2]), np.sin(a[2])
    d = np.array([c * (b[0] - a[0]) + s * (b[1] - a[1]), -s * (b[0] - a[0]) + c * (b[1] - a[1])])
    w = b[2] - a[2]
    if abs(w) < 1e-9:
        return np.array([d[0], d[1], w])
    # inverse of V(w) = [[sin w / w, −(1−cos w)/w], [(1−cos w)/w, sin w / w]]
    A, B = np.sin(w) / w, (1 - np.cos(w)) / w
    det = A * A + B * B
    lin = np.array([A * d[0] + B * d[1], -B * d[0] + A * d[1]]) / det
    return np.array([lin[0], lin[1], w])


def integrate_pose(q, u, t: float) -> np.ndarray:
    """Planar: the pose reached from ``q`` after moving for ``t`` s with constant body twist ``u``."""
    q, u = np.asarray(q, float), np.asarray(u, float)
    w = u[2] * t
    lin = u[:2] * t
    if abs(w) < 1e-9:
        a, b = 1 - w * w / 6, w / 2
    else:
        a, b = np.sin(w) / w, (1 - np.cos(w)) / w
    d = np.array([a * lin[0] - b * lin[1], b * lin[0] + a * lin[1]])
    c, s = np.cos(q[2]), np.sin(q[2])
    return np.array([q[0] + c * d[0] - s * d[1], q[1] + s * d[0] + c * d[1], q[2] + w])


def twist_in(rel, u) -> list:
    """Body twist ``u`` (m/s, rad/s) of a frame B expressed in frame A, where the pose ``rel`` =
    A⁻¹B (m, unit quaternion) (the adjoint): ``[R v + p × (R ω), R ω]``."""
    rel, u = np.asarray(rel, float), np.asarray(u, float)
    w = quat_rotate(rel[3:], u[3:])
    return (quat_rotate(rel[3:], u[:3]) + np.cross(rel[:3], w)).tolist() + w.tolist()


def twist_between(a, b) -> list:
    """The constant body twist (m/s, rad/s) taking pose ``a`` to pose ``b`` (m, unit quaternion)
    in unit time (SE(3) log, the core's)."""
    return list(_core.se3_log([float(x) for x in a], [float(x) for x in b]))


# --- SE(3) poses (the core's algebra, numpy in and out) ----------------------------------------


def compose(*poses) -> np.ndarray:
    """The composition ``a ∘ b ∘ ...`` of poses ``[x, y, z, qw, qx, qy, qz]`` (m, unit quaternion)."""
    out = [float(x) for x in poses[0]]
    for p in poses[1:]:
        out = _core.se3_compose(out, [float(x) for x in p])
    return np.array(out)


def inverse(a) -> np.ndarray:
    """The inverse of pose ``a`` ``[x, y, z, qw, qx, qy, qz]`` (m, unit quaternion)."""
    return np.array(_core.se3_inverse([float(x) for x in a]))


def integrate(pose, twist, t: float = 1.0) -> np.ndarray:
    """``pose ∘ exp(t · twist)``: pose (m, unit quaternion), body twist (m/s, rad/s), ``t`` [s]."""
    return np.array(_core.se3_integrate([float(x) for x in pose], [float(x) for x in twist], float(t)))


def from_frame(R, p) -> np.ndarray:
    """The pose ``[x, y, z, qw, qx, qy, qz]`` of the frame with rotation matrix ``R`` (columns: its
    axes) and origin ``p`` [m]."""
    return np.concatenate([np.asarray(p, float), quat_from_matrix(R)])


def transform(pose, v) -> np.ndarray:
    """Point(s) ``v`` [m] (shape (3,) or (n, 3)) of a frame mapped by its pose (m, unit quaternion)
    into the reference frame: ``R v + p``."""
    pose = np.asarray(pose, float)
    return quat_rotate(pose[3:], v) + pose[:3]


def transform_rows(poses, v) -> np.ndarray:
    """Points ``v`` (k, 3) [m] of a frame mapped by each of its poses (n, 7) (m, unit quaternion):
    (n, k, 3), ``R_i v + p_i``."""
    poses = np.asarray(poses, float)
    return np.asarray(v, float) @ quat_matrices(poses[:, 3:]).transpose(0, 2, 1) + poses[:, None, :3]


def interpolate(a, b, s) -> np.ndarray:
    """The pose a fraction ``s`` in [0, 1] of the way from pose ``a`` to pose ``b`` (m, unit
    quaternion), the position along the straight line and the rotation by :func:`slerp`; ``s``
    may be an array (n,), giving (n, 7)."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    return np.concatenate([a[:3] + np.asarray(s, float)[..., None] * (b[:3] - a[:3]), slerp(a[3:], b[3:], s)], axis=-1)


def quat_multiply(a, b) -> np.ndarray:
    """The product ``a b`` of quaternions ``[w, x, y, z]`` (rows of (n, 4) arrays, or single ones)."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    w1, v1, w2, v2 = a[..., :1], a[..., 1:], b[..., :1], b[..., 1:]
    return np.concatenate([w1 * w2 - np.sum(v1 * v2, axis=-1, keepdims=True),
                           w1 * v2 + w2 * v1 + np.cross(v1, v2)], axis=-1)


def compose_rows(a, b) -> np.ndarray:
    """Row by row ``a[i] ∘ b[i]`` of two (n, 7) arrays of poses (m, unit quaternion)."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    w, u, p = a[:, 3:4], a[:, 4:], b[:, :3]
    rotated = p + 2 * np.cross(u, np.cross(u, p) + w * p)  # R(a's quaternion) p
    q = quat_multiply(a[:, 3:], b[:, 3:])
    return np.concatenate([a[:, :3] + rotated, q / np.linalg.norm(q, axis=1, keepdims=True)], axis=1)


def turn_onto(u, v) -> np.ndarray:
    """The unit quaternion ``[w, x, y, z]`` of the least turn taking the direction ``u`` onto
    ``v`` (neither zero): about ``u × v`` by their angle; a half turn about a direction normal
    to ``u`` when they are opposite."""
    u, v = np.asarray(u, float) / np.linalg.norm(u), np.asarray(v, float) / np.linalg.norm(v)
    c = np.cross(u, v)
    s = float(np.linalg.norm(c))
    angle = np.arctan2(s, float(u @ v))  # accurate near 0 and near a half turn
    axis = c / s if s > 0 else tangents(u)[0]
    return np.r_[np.cos(angle / 2), np.sin(angle / 2) * axis]


def z_turn(phi: float) -> np.ndarray:
    """The pose (no translation) of a turn by ``phi`` [rad] about +z."""
    return np.array([0.0, 0.0, 0.0, np.cos(phi / 2), 0.0, 0.0, np.sin(phi / 2)])


def x_turn(beta: float) -> np.ndarray:
    """The pose (no translation) of a turn by ``beta`` [rad] about +x."""
    return np.array([0.0, 0.0, 0.0, np.cos(beta / 2), np.sin(beta / 2), 0.0, 0.0])
