"""Unit quaternions ``[w, x, y, z]`` (the order of the core's poses ``[x, y, z, qw, qx, qy, qz]``)
in numpy: the rotation matrix, rotating vectors, the quaternion of a rotation matrix, slerp.
The pose algebra itself (compose, inverse, log, exp) is the core's (``_core.se3_*``)."""

from __future__ import annotations

import numpy as np


def matrix(q) -> np.ndarray:
    """The 3 x 3 rotation matrix of quaternion ``q`` (normalized first)."""
    w, x, y, z = np.asarray(q, float) / np.linalg.norm(q)
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ])


def rotate(q, v) -> np.ndarray:
    """Vector(s) ``v`` (shape (3,) or (n, 3)) rotated by quaternion ``q``."""
    return np.asarray(v, float) @ matrix(q).T


def from_matrix(R) -> np.ndarray:
    """The unit quaternion (w >= 0) of rotation matrix ``R`` (Shepperd's method: the largest of
    the four squared components is computed first, so it is accurate for every rotation)."""
    R = np.asarray(R, float)
    t = np.trace(R)
    d = np.array([t, R[0, 0], R[1, 1], R[2, 2]])
    k = int(np.argmax(d))
    if k == 0:
        r = np.sqrt(1 + t)
        q = [r / 2, (R[2, 1] - R[1, 2]) / (2 * r), (R[0, 2] - R[2, 0]) / (2 * r), (R[1, 0] - R[0, 1]) / (2 * r)]
    else:
        i, j, m = k - 1, k % 3, (k + 1) % 3
        r = np.sqrt(1 + R[i, i] - R[j, j] - R[m, m])
        q = np.empty(4)
        q[0] = (R[m, j] - R[j, m]) / (2 * r)
        q[1 + i], q[1 + j], q[1 + m] = r / 2, (R[j, i] + R[i, j]) / (2 * r), (R[m, i] + R[i, m]) / (2 * r)
    q = np.asarray(q, float)
    q /= np.linalg.norm(q)
    return -q if q[0] < 0 else q


def slerp(a, b, s: float) -> np.ndarray:
    """The quaternion a fraction ``s`` in [0, 1] of the way from ``a`` to ``b`` along the
    shortest rotation between them (spherical linear interpolation)."""
    a, b = np.asarray(a, float) / np.linalg.norm(a), np.asarray(b, float) / np.linalg.norm(b)
    d = float(a @ b)
    if d < 0:
        b, d = -b, -d
    if d > 1 - 1e-12:
        q = a + s * (b - a)
    else:
        th = np.arccos(d)
        q = (np.sin((1 - s) * th) * a + np.sin(s * th) * b) / np.sin(th)
    return q / np.linalg.norm(q)
