"""The physical bodies of a workcell, stated once, for the collision checks of a world motion and
for the MuJoCo geoms of an execution: the table is a slab :data:`TABLE_DEPTH` thick under its
top; a block is its box; a face is a plate :data:`PLATE_DEPTH` thick behind it; an edge (a line
feature) is the rim of a round bar, a capsule of radius :data:`EDGE_RADIUS` whose surface runs
along the edge, its axis that radius behind it (along the edge's −z), as long as the edge; a
corner (a point feature) is the ball tip of a post, a sphere of radius :data:`EDGE_RADIUS` just
behind the point (the post under it is not modelled, like a block's post).

Each body is a :class:`Shape` in MuJoCo's terms (``kind`` ``"box"``, ``"capsule"`` or
``"sphere"``, ``size`` as MuJoCo's geom size, ``pose`` the geom's world pose), so a model can be
built from :func:`shapes` alone::

    for s in shapes(workcell):
        add_geom(world, s.kind, s.size, name=s.name, pos=s.pose[:3], quat=s.pose[3:], ...)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import pose as P

#: Radius [m] of an edge's bar and of a corner's ball tip.
EDGE_RADIUS = 0.003
#: Thickness [m] of a face feature's plate.
PLATE_DEPTH = 0.01
#: Thickness [m] of the table's top slab.
TABLE_DEPTH = 0.05


@dataclass(frozen=True)
class Shape:
    """A workcell body: ``name`` (the feature's name, or ``"table"``); ``kind`` ``"box"``,
    ``"capsule"`` or ``"sphere"``; ``size`` as MuJoCo's geom size [m] (a box's 3 half-sizes, a
    capsule's radius and half-length along its z, a sphere's radius); ``pose`` (m, unit
    quaternion): its centre's world pose; ``friction`` with the object."""
    name: str
    kind: str
    size: np.ndarray
    pose: np.ndarray
    friction: float

    @property
    def radius(self) -> float:
        """The rounding [m] of the body about its core (:meth:`core_points`): a capsule's or a
        sphere's radius, 0 for a box."""
        return 0.0 if self.kind == "box" else float(self.size[0])

    @property
    def bound(self) -> float:
        """The radius [m] of a ball about the body's centre that holds it."""
        if self.kind == "box":
            return float(np.linalg.norm(self.size))
        return float(self.size[0] + (self.size[1] if self.kind == "capsule" else 0.0))

    @property
    def top(self) -> float:
        """The body's highest point [m] (world z)."""
        R = P.quat_matrix(self.pose[3:])
        if self.kind == "box":
            return float(self.pose[2] + np.abs(R[2]) @ self.size)
        return float(self.pose[2] + self.size[0] + (abs(R[2, 2]) * self.size[1] if self.kind == "capsule" else 0.0))

    def depth(self, pts) -> np.ndarray:
        """How deep [m] world points ``pts`` (..., 3) are inside the body (> 0 inside; otherwise
        minus their distance from it)."""
        local = np.einsum("...i,ij->...j", np.asarray(pts, float) - self.pose[:3], P.quat_matrix(self.pose[3:]))
        if self.kind == "box":
            q = np.abs(local) - self.size
            out = np.linalg.norm(np.maximum(q, 0.0), axis=-1) + np.minimum(q.max(axis=-1), 0.0)
            return -out
        if self.kind == "capsule":
            local = local.copy()
            local[..., 2] -= np.clip(local[..., 2], -self.size[1], self.size[1])
        return self.size[0] - np.linalg.norm(local, axis=-1)

    def core_points(self, spacing: float) -> np.ndarray:
        """World points (k, 3) [m] whose balls of radius :attr:`radius` make up the body's
        outermost parts: a box's corners and edges (``spacing`` [m] apart), a capsule's axis, a
        sphere's centre. A body pokes into a solid only if one of them comes within
        :attr:`radius` of its inside (or the solid's own edges enter the body)."""
        if self.kind == "sphere":
            return self.pose[None, :3].copy()
        if self.kind == "capsule":
            n = max(1, int(np.ceil(2 * self.size[1] / spacing)))
            z = np.linspace(-self.size[1], self.size[1], n + 1)
            return P.transform(self.pose, np.column_stack([np.zeros_like(z), np.zeros_like(z), z]))
        h, out = self.size, []
        for a in range(3):
            b, c = (a + 1) % 3, (a + 2) % 3
            n = max(1, int(np.ceil(2 * h[a] / spacing)))
            t = np.linspace(-h[a], h[a], n + 1)
            for sb in (-1, 1):
                for sc in (-1, 1):
                    e = np.zeros((n + 1, 3))
                    e[:, a], e[:, b], e[:, c] = t, sb * h[b], sc * h[c]
                    out.append(e)
        return P.transform(self.pose, np.vstack(out))


def shapes(workcell: Workcell) -> list[Shape]:
    """The physical bodies (see the module's doc) of ``workcell``: the table first, then every
    feature in file order, each named after it."""
    t = workcell.table
    out = [Shape("table", "box", np.array([t.size[0] / 2, t.size[1] / 2, TABLE_DEPTH / 2]),
                 np.array([t.center[0], t.center[1], t.height - TABLE_DEPTH / 2, 1.0, 0, 0, 0]), t.friction)]
    for f in workcell.features:
        back = P.quat_rotate(f.pose[3:], [0.0, 0, 1])
        if f.kind == "block":
            out.append(Shape(f.name, "box", np.asarray(f.size, float) / 2, f.pose.copy(), f.friction))
        elif f.kind == "face":
            out.append(Shape(f.name, "box", np.array([f.size[0] / 2, f.size[1] / 2, PLATE_DEPTH / 2]),
                             np.r_[f.pose[:3] - back * PLATE_DEPTH / 2, f.pose[3:]], f.friction))
        elif f.kind == "edge":   # the capsule's z along the edge's x: a quarter turn about y
            r = np.sqrt(0.5)
            out.append(Shape(f.name, "capsule", np.array([EDGE_RADIUS, f.length / 2]),
                             np.r_[f.pose[:3] - back * EDGE_RADIUS, P.compose(f.pose, [0, 0, 0, r, 0, r, 0])[3:]],
                             f.friction))
        else:
            out.append(Shape(f.name, "sphere", np.array([EDGE_RADIUS]),
                             np.r_[f.pose[:3] - back * EDGE_RADIUS, f.pose[3:]], f.friction))
    return out
