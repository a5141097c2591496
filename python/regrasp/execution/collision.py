"""Collision of the held object with the workcell's bodies (:func:`regrasp.workcell.shapes`) at
the samples of a world motion.

The object is a solid (:class:`Solid`): a planar scene's outline extruded ±``THICKNESS``/2 along
the grasp axis (y; ``regrasp.mujoco.model.THICKNESS``, as in the MuJoCo model), made of the
outline's convex pieces; a 3-D scene's mesh (convex: its triangles' planes bound it) or sphere.
How deep the object is in a body at a sample (:func:`depths`) is the deepest of

* the object's surface points (its vertices and points along its edges, :data:`SPACING` apart)
  inside the body, and
* the body's core points (:meth:`Shape.core_points`: a box's corners and edges, a capsule's
  axis, a sphere's centre) within the body's rounding of the object's inside,

so an edge of either solid crossing the other is found (two polyhedra overlap only so) to about
the spacing. Samples whose object is farther from a body than its reach are skipped, as are
runs of points (:data:`CHUNK`) whose bounding ball is away from the body or the object."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import pose as P
from ..workcell.shapes import Shape

#: Spacing [m] of the points along the object's edges and the bodies' edges.
SPACING = 2e-3


#: Points are checked in runs of this many consecutive ones (spatially close, along an edge),
#: each bounded by a ball, a run's points only where its ball comes near.
CHUNK = 6


def _chunks(pts) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``pts`` (k, 3) in runs of :data:`CHUNK` (the last padded with its last point): (c, CHUNK, 3),
    the runs' centres (c, 3) and radii (c,) [m]."""
    pad = -len(pts) % CHUNK
    runs = np.concatenate([pts, np.repeat(pts[-1:], pad, axis=0)]).reshape(-1, CHUNK, 3)
    c = (runs.min(axis=1) + runs.max(axis=1)) / 2
    return runs, c, np.linalg.norm(runs - c[:, None], axis=2).max(axis=1)


@dataclass(frozen=True)
class Solid:
    """The object as a solid in its frame: ``points`` (k, 3) [m] on its surface (vertices and
    edges); ``pieces``: convex pieces, each ``(A (m, 3), b (m,))`` holding the points ``A p <= b``
    (``A``'s rows unit outward normals); ``sphere`` [m]: the radius of a sphere object (then no
    pieces; 0 otherwise); ``reach`` [m]: the farthest surface point from the frame's origin."""
    points: np.ndarray
    pieces: list
    sphere: float
    reach: float

    def __post_init__(self):
        object.__setattr__(self, "runs", _chunks(self.points))   # the points in runs (see depths)

    def distance(self, pts) -> np.ndarray:
        """The signed distance [m] of object-frame points ``pts`` (n, 3) from the solid (< 0
        inside; outside, a lower bound: the farthest of a piece's planes)."""
        pts = np.asarray(pts, float)
        if self.sphere > 0:
            return np.linalg.norm(pts, axis=-1) - self.sphere
        return np.min([np.max(np.einsum("nj,pj->np", pts, A) - b, axis=-1) for A, b in self.pieces], axis=0)


def _along(a, b, spacing) -> np.ndarray:
    n = max(1, int(np.ceil(np.linalg.norm(b - a) / spacing)))
    return a + np.linspace(0, 1, n + 1)[:, None] * (b - a)


def _planes(v, faces) -> tuple[np.ndarray, np.ndarray]:
    """The outward unit normals and offsets of a convex solid's ``faces`` (index triples or more;
    the first three points span each) of vertices ``v``."""
    c = v.mean(axis=0)
    A, b = [], []
    for f in faces:
        n = np.cross(v[f[1]] - v[f[0]], v[f[2]] - v[f[0]])
        if np.linalg.norm(n) < 1e-15:
            continue
        n = n / np.linalg.norm(n)
        if n @ (v[f[0]] - c) < 0:
            n = -n
        A.append(n), b.append(float(n @ v[f[0]]))
    return np.array(A), np.array(b)


def solid(scene) -> Solid:
    """The object of ``scene`` (planar grasp or 3-D) as a :class:`Solid` (see the module's doc)."""
    if scene.dimension == 2:
        from ..mujoco.model import THICKNESS, convex_pieces

        h = THICKNESS / 2
        out = np.asarray(scene.outline, float)
        pieces = []
        for piece in convex_pieces(out):
            q = np.asarray(piece, float)
            v = np.vstack([np.c_[q[:, 0], np.full(len(q), y), q[:, 1]] for y in (-h, h)])
            m = len(q)
            A, b = _planes(v, [(i, (i + 1) % m, i + m) for i in range(m)])  # the sides
            pieces.append((np.vstack([A, [[0.0, -1.0, 0.0], [0.0, 1.0, 0.0]]]), np.r_[b, h, h]))  # and the faces ±h
        corners = [np.array([p[0], y, p[1]]) for p in out for y in (-h, h)]
        segs = [(corners[2 * i + j], corners[(2 * i + 2 + j) % len(corners)]) for i in range(len(out)) for j in (0, 1)]
        segs += [(corners[2 * i], corners[2 * i + 1]) for i in range(len(out))]
        pts = np.vstack([_along(a, b, SPACING) for a, b in segs])
        return Solid(pts, pieces, 0.0, float(np.max(np.linalg.norm(pts, axis=1))))
    r = scene.sphere
    if r is not None:
        a = np.linspace(0, 2 * np.pi, max(8, int(2 * np.pi * r / SPACING)), endpoint=False)
        c, s, z = r * np.cos(a), r * np.sin(a), np.zeros_like(a)
        pts = np.vstack([np.c_[c, s, z], np.c_[c, z, s], np.c_[z, c, s]])
        return Solid(pts, [], float(r), float(r))
    pts, pieces = [], []
    for v, t in scene.parts():  # a non-convex object: one convex piece per part
        v, t = np.asarray(v, float), np.asarray(t, int)
        edges = sorted({tuple(sorted((int(a), int(b)))) for tri in t for a, b in zip(tri, np.roll(tri, -1))})
        pts += [v] + [_along(v[a], v[b], SPACING) for a, b in edges]
        pieces.append(_planes(v, t))
    pts = np.vstack(pts)
    return Solid(pts, pieces, 0.0, float(np.max(np.linalg.norm(pts, axis=1))))


def cores(shapes: list[Shape]) -> list:
    """The core points of ``shapes`` in runs, for :func:`depths` (made once for many calls)."""
    return [_chunks(s.core_points(SPACING)) for s in shapes]


def depths(body: Solid, shapes: list[Shape], poses, core_runs: list | None = None) -> np.ndarray:
    """How deep [m] the object (``body``) is in each of ``shapes`` at each of its world ``poses``
    (n, 7) (m, unit quaternion): (n, len(shapes)), > 0 inside; otherwise not in it (≤ 0, or −inf
    where none of the points checked came near); ``core_runs``: :func:`cores` of the shapes."""
    W = np.asarray(poses, float)
    if body.sphere > 0:  # exact: the centre's depth in the body plus the radius
        return np.stack([s.depth(W[:, :3]) + body.sphere for s in shapes], axis=1).reshape(len(W), len(shapes))
    out = np.full((len(W), len(shapes)), -np.inf)
    runs, centres, radii = body.runs
    core_runs = cores(shapes) if core_runs is None else core_runs
    for i, s in enumerate(shapes):
        js = np.flatnonzero(s.depth(W[:, :3]) > -(body.reach + 1e-9))
        if not len(js):
            continue
        R, t = P.quat_matrices(W[js, 3:]), W[js, :3]
        d = np.full(len(js), -np.inf)
        # the object's points in the body
        jj, cc = np.nonzero(s.depth(np.einsum("nij,cj->nci", R, centres) + t[:, None]) > -radii - 1e-9)
        if len(jj):
            world = runs[cc] @ R[jj].transpose(0, 2, 1) + t[jj, None]
            np.maximum.at(d, jj, s.depth(world).max(axis=1))
        # the body's core points in the object: runs whose ball comes near the object's
        cruns, ccent, crad = core_runs[i]
        rel = ccent[None] - t[:, None]                                              # (m, c, 3)
        jj, cc = np.nonzero(np.einsum("mci,mci->mc", rel, rel) <= (body.reach + crad + s.radius + 1e-9) ** 2)
        if len(jj):
            near = body.distance(np.einsum("ni,nij->nj", rel[jj, cc], R[jj])) <= crad[cc] + s.radius + 1e-9
            jj, cc = jj[near], cc[near]
        if len(jj):
            local = (cruns[cc] - t[jj, None]) @ R[jj]                                    # R^T (core - t)
            e = s.radius - body.distance(local.reshape(-1, 3)).reshape(len(jj), CHUNK)
            np.maximum.at(d, jj, e.max(axis=1))
        out[js, i] = d
    return out
