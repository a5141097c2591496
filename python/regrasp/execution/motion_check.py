"""The checks of a world motion (thesis §4.4 rendered in a workcell): the object's edges may go
at most :data:`PENETRATION_LIMIT` behind the contact plane of the feature it is pushed against
(else the plan is not rendered exactly: it goes through the feature), and no deeper than
:data:`TOUCH` into the table or any other feature. A fault is an
:class:`~regrasp.errors.ExecutionError` naming the push (plan path) and the body."""

from __future__ import annotations

import numpy as np

from .. import pose as P
from ..errors import ArgumentError, ExecutionError
from ..workcell.shapes import shapes
from . import collision
from .assignment import Assignment


#: The deepest [m] the object may go into a feature during a push (the plan is rendered exactly
#: only if it does not go through it).
PENETRATION_LIMIT = 0.5e-3


#: How deep [m] the object may touch a body other than the push's own feature (numerical noise).
TOUCH = 1e-6


def object_points(scene) -> np.ndarray:
    """Points (k, 3) [m] of the object in its frame whose reach bounds the object's: the planar
    outline (in the x-z plane), a mesh's or box's vertices, a sphere's centre ± radius on each axis."""
    if scene.dimension == 2:
        out = np.asarray(scene.outline, float)
        return np.column_stack([out[:, 0], np.zeros(len(out)), out[:, 1]])
    r = scene.sphere
    if r is not None:
        return np.vstack([np.eye(3) * r, -np.eye(3) * r])
    return np.asarray(scene.mesh()[0], float)


#: The spacing [m] of the points along the object's edges at which its penetration is measured.
EDGE_SPACING = 1e-3


def edge_points(scene) -> np.ndarray:
    """Points (k, 3) [m] of the object in its frame along its edges, ``EDGE_SPACING`` apart: the
    planar outline's sides (x-z plane), a mesh's triangle edges, a sphere's 3 great circles."""
    if scene.dimension == 3 and scene.sphere is not None:
        r = scene.sphere
        a = np.linspace(0, 2 * np.pi, max(8, int(2 * np.pi * r / EDGE_SPACING)), endpoint=False)
        c, s_ = r * np.cos(a), r * np.sin(a)
        z = np.zeros_like(a)
        return np.vstack([np.c_[c, s_, z], np.c_[c, z, s_], np.c_[z, c, s_]])
    if scene.dimension == 2:
        v = object_points(scene)
        edges = [(v[i], v[(i + 1) % len(v)]) for i in range(len(v))]
    else:
        v, t = scene.surface()  # a non-convex object: its parts' edges
        v, t = np.asarray(v, float), np.asarray(t, int)
        edges = {tuple(sorted((int(a), int(b)))) for tri in t for a, b in ((tri[0], tri[1]), (tri[1], tri[2]), (tri[2], tri[0]))}
        edges = [(v[a], v[b]) for a, b in sorted(edges)]
    out = [v]
    for a, b in edges:
        n = max(1, int(np.ceil(np.linalg.norm(b - a) / EDGE_SPACING)))
        out.append(a + np.linspace(0, 1, n + 1)[:, None] * (b - a))
    return np.vstack(out)


class _Check:
    """The checks of a push's samples (see the module's doc): :func:`_penetration` and
    :func:`_collisions`, with the object's solid and the workcell's bodies made once."""

    def __init__(self, scene, workcell, contacts):
        self.scene, self.workcell = scene, workcell
        self.solid, self.bodies = collision.solid(scene), shapes(workcell)
        self.cores = collision.cores(self.bodies)
        self.points = edge_points(scene)
        self.extents = {c.name: c.extent for c in contacts}

    def __call__(self, S, n0: int, a, done: list) -> float:
        """Checks samples ``n0:`` of ``S`` (push ``a``'s, or the last transfer's when ``a`` is
        None; ``done``: the pushes before); returns push ``a``'s penetration [m]. ``S``: the world motion's samples (``G``, ``O``, ``label``, ``push``)."""
        if len(S.G) <= n0:
            return 0.0
        W = P.compose_rows(np.array(S.G[n0:]), np.array(S.O[n0:]))
        labels, push = S.label[n0:], np.array(S.push[n0:], int)
        d = 0.0 if a is None else _penetration(self, a, W[(push == a.index) & np.array([x == "push" for x in labels])])
        _collisions(self, W, labels, push, a, done[-1] if a is None else None)
        return d


def _what(a: Assignment) -> str:
    return f"push {a.index} (pusher `{a.pusher}`, plan path[{a.first}] to path[{a.last}])"


def _penetration(c: _Check, a: Assignment, W) -> float:
    """How far [m] the object, at world poses ``W`` (push ``a``'s push samples), goes behind the
    push's contact plane (within a face's rectangle); ExecutionError when more than
    :data:`PENETRATION_LIMIT`."""
    rel = P.compose_rows(np.repeat(P.inverse(a.frame)[None], len(W), axis=0), W)
    out = max(0.0, -_behind(P.transform_rows(rel, c.points).reshape(-1, 3), c.extents[a.feature]))
    if out > PENETRATION_LIMIT:
        raise ExecutionError(
            f"{_what(a)}: the object goes {out * 1e3:.2f} mm into feature `{a.feature}` of workcell "
            f"`{c.workcell.name}`, more than {PENETRATION_LIMIT * 1e3:g} mm (a smaller feature, e.g. a face just "
            f"larger than the pusher, lets it pivot)", f"plan.path[{a.first + 1}].pusher")
    return out


def _body(contact: str, names: list) -> str:
    """The body (``"table"`` or a feature's name) a contact of :meth:`Workcell.contacts` belongs to."""
    return next((n for n in names if contact == n or contact.startswith(n + ".")), contact)


def _collisions(c: _Check, W, labels, push, a, last):
    """ExecutionError naming the push (``a``) or transfer and the body when the object, at world
    poses ``W``, goes into the table or a feature: more than :data:`TOUCH` deep, or, in push
    ``a``'s approach, push and retreat, more than :data:`PENETRATION_LIMIT` into its own feature
    (``last``: the push before a final transfer)."""
    names = [b.name for b in c.bodies]
    D = collision.depths(c.solid, c.bodies, W, c.cores)
    limit = np.full(D.shape, TOUCH)
    if a is not None:
        limit[push == a.index, names.index(_body(a.feature, names))] = PENETRATION_LIMIT
    bad = np.argwhere(D > limit)
    if not len(bad):
        return
    j, i = bad[0]
    lo, hi = j, j + 1          # the segment: the run of samples around j with j's label and push
    while lo > 0 and labels[lo - 1] == labels[j] and push[lo - 1] == push[j]:
        lo -= 1
    while hi < len(labels) and labels[hi] == labels[j] and push[hi] == push[j]:
        hi += 1
    deepest = float(D[lo:hi, i].max())
    if a is None:
        what, a = f"the transfer after the last push ({_what(last)})", last
    elif push[j] >= 0:
        what = f"{_what(a)}, in its {labels[j]}" if labels[j] != "push" else _what(a)
    else:
        what = f"the transfer {'to' if np.all(push[:j] != a.index) else 'from'} {_what(a)}"
    if names[i] == "table":
        hit = f"goes {deepest * 1e3:.2f} mm below the table top of workcell `{c.workcell.name}`"
    else:
        hit = f"hits feature `{names[i]}` of workcell `{c.workcell.name}`, {deepest * 1e3:.2f} mm deep"
    if labels[j] == "start":
        raise ArgumentError(f"invalid `start`: there the object {hit}", "start")
    raise ExecutionError(f"{what}: the object {hit}", f"plan.path[{a.first + 1}].pusher")


def _behind(pts, extent) -> float:
    """The lowest z [m] of ``pts`` (k, 3) in a contact frame (0 when none is lower), counting
    only those within a face's half-sizes ``extent`` (an edge's or corner's zeros: all)."""
    if len(pts) and np.any(np.asarray(extent) > 0):
        pts = pts[np.all(np.abs(pts[:, :2]) <= np.asarray(extent) + 1e-9, axis=1)]
    return float(pts[:, 2].min()) if len(pts) else 0.0
