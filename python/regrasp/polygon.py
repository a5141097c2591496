"""Simple polygons in the plane, as (n, 2) vertex arrays (any length unit): the turn of three
points, the signed area and triangulation by ear clipping."""

from __future__ import annotations

import numpy as np


def cross(o, a, b) -> float:
    """The z component of (a − o) × (b − o): positive when o, a, b turn counter-clockwise."""
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])


def signed_area(p) -> float:
    """The signed area of polygon ``p`` (positive when counter-clockwise; unit squared)."""
    p = np.asarray(p, float)
    return 0.5 * float(np.sum(p[:, 0] * np.roll(p[:, 1], -1) - np.roll(p[:, 0], -1) * p[:, 1]))


def _ear(p, idx: list, k: int) -> bool:
    """Whether corner ``k`` of the remaining polygon ``idx`` is an ear: convex, no other vertex
    in its triangle."""
    i, j, m = idx[k - 1], idx[k], idx[(k + 1) % len(idx)]
    a, b, c = p[i], p[j], p[m]
    if cross(a, b, c) <= 1e-15:
        return False  # reflex (or flat) corner
    return not any(cross(a, b, p[o]) >= 0 and cross(b, c, p[o]) >= 0 and cross(c, a, p[o]) >= 0
                   for o in idx if o not in (i, j, m))


def triangulate(p) -> list:
    """Triangles (index triples, counter-clockwise) of a simple counter-clockwise polygon ``p``,
    by ear clipping; a numerically degenerate rest is fanned."""
    idx, out = list(range(len(p))), []
    while len(idx) > 3:
        k = next((k for k in range(len(idx)) if _ear(p, idx, k)), None)
        if k is None:
            return out + [[idx[0], idx[k], idx[k + 1]] for k in range(1, len(idx) - 1)]
        out.append([idx[k - 1], idx[k], idx[(k + 1) % len(idx)]])
        idx.pop(k)
    return out + [idx]
