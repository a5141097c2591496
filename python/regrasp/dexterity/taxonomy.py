"""The grasp taxonomy of a rigid object for the parallel-jaw gripper (the 2F-85): its discrete
grasps, found from the object's vertices (a box, a convex mesh, an extruded outline), each
checked to hold under gravity (thesis §1.1.1, ICRA 2014 "Extrinsic dexterity").

Frames: the gripper's (TCP) frame has its origin midway between the pads' faces at their
centres, y the grasp axis towards the left pad, z from the fingers towards the palm (the
fingers point along −z), x = y × z. A grasp's in-hand ``pose`` is the object frame's pose in the
TCP frame, ``[x, y, z, qw, qx, qy, qz]`` (m, unit quaternion). In the pads' plane (x, z) a turn
by an angle θ goes from x towards z (a rotation by −θ about +y, :func:`regrasp.pose.planar_quat`).

A flat pad touches only the object's convex hull, so the grasps are those of the hull
(scipy's ``ConvexHull``, its coplanar triangles merged into faces):

1. face pairs A, B with opposite normals whose polygons, seen along the normal, overlap in a
   region of positive area (the *contact region*), at a width (the planes' distance) within
   ``width_range``; A against the left pad (its normal onto +y), and the other way round;
2. for each edge of the region, the turn about the grasp axis that makes the edge face the
   palm (its outward normal onto +z) and the one that makes it face the fingertips (onto −z);
3. the object centred between the pads (its extent along y symmetric about 0), the region's
   centroid at x = 0 and at z = f h for each fraction f of ``offsets``, h the region's extent
   along z: f > 0 puts the object deeper in the hand (towards the palm); and, for each fraction
   f of ``lateral`` (none by default), at x = f w, z = 0, w the region's extent along x: the
   object held off its centre across the fingers, sticking out to one side (a bar held near an
   end, the classic gravity pivot's start: a quarter turn hangs it along the fingers);
4. candidates that place the object identically up to its symmetry (:func:`grasp_distance`
   below 1e-6 times its size) are one grasp, the first in the enumeration order kept (face
   pairs by index, A on the left first, the region's edges in turn, palm before fingertips,
   ``offsets`` then ``lateral`` in order);
5. each checked to hold under gravity at grip force N per pad with pad friction μ: the patch is
   the region within the pad's face (|x| ≤ 11 mm, |z| ≤ 18.75 mm), uniformly pressed; its two
   pads' ellipsoidal limit surface holds the weight in the worst hand orientation when
   ``(m g / 2μN)² (1 + (d / k)²) ≤ 1`` (d the centre of mass's distance from the grasp axis
   through the patch's centroid, k the patch's mean distance from its centroid: force capacity
   2 μ N, torsion capacity 2 k μ N; the worst gravity lies in the pads' plane, across d).
"""

from __future__ import annotations

import numbers
from dataclasses import dataclass, field

import numpy as np

from .. import pose as P
from ..errors import ArgumentError
from ..extras import need
from ..polygon import signed_area
from ..robot.pads import HALF_WIDTH, LENGTH

TOLERANCE = 1e-6  # rad between faces' normals; × the object's size [m] for planes, corners and symmetric grasps
WIDTH_RANGE = (0.0, 0.085)  # m, the 2F-85's opening
OFFSETS = (-0.35, 0.0, 0.35)  # the region's centroid at z = f h (f > 0: towards the palm)
LATERAL = ()  # the region's centroid at x = f w, z = 0 (an object file's `[taxonomy] lateral`)
PAD = np.array([[-HALF_WIDTH, -LENGTH / 2], [HALF_WIDTH, -LENGTH / 2], [HALF_WIDTH, LENGTH / 2],
                [-HALF_WIDTH, LENGTH / 2]])  # the pad's face (x, z) [m] in the TCP frame, counter-clockwise
NEGLIGIBLE = 1e-6  # a patch smaller than this share of the pad's face bears nothing


@dataclass(frozen=True, eq=False)
class Face:
    """A face of the object's convex hull: its outward unit ``normal`` (3,), the plane's
    ``offset`` [m] (``normal · p = offset`` on it) and its ``polygon`` (k, 3) [m], the corners
    counter-clockwise about the normal (object frame)."""

    normal: np.ndarray
    offset: float
    polygon: np.ndarray


@dataclass(frozen=True, eq=False)
class Grasp:
    """A grasp: ``name`` (``g0``, ``g1``, ...), a readable ``label``, the hull ``faces`` (left,
    right) on the pads (indices into :attr:`Taxonomy.faces`), ``angle`` [rad] the turn about the
    grasp axis (x towards z) from the least turn taking the left face's normal onto +y
    (:func:`regrasp.pose.turn_onto`), in (−π, π]: between two grasps on the same faces, their
    difference is the object's turn; ``offset`` [m] the contact region's centroid along z (+:
    towards the palm), ``width`` [m] between the pads, the in-hand ``pose`` (7,), whether it
    ``holds`` the weight in every hand orientation, its ``margin`` = 1 − (m g / 2μN) √(1 +
    (d/k)²), the share of the pads' capacity left in the worst orientation (−1 without a patch),
    the patch's ``torsion_k`` k [m] (its mean distance from its centroid), ``patch_area``
    [m²] and ``lateral`` [m] the region's centroid along x (0 but for the taxonomy's
    ``lateral`` grasps)."""

    name: str
    label: str
    faces: tuple
    angle: float
    offset: float
    width: float
    pose: np.ndarray
    holds: bool
    margin: float
    torsion_k: float
    patch_area: float
    lateral: float = 0.0

    def to_dict(self) -> dict:
        """The grasp as JSON-able values (lists, floats)."""
        return {"name": self.name, "label": self.label, "faces": [int(f) for f in self.faces],
                "angle": float(self.angle), "offset": float(self.offset), "width": float(self.width),
                "pose": [float(x) for x in self.pose], "holds": bool(self.holds), "margin": float(self.margin),
                "torsion_k": float(self.torsion_k), "patch_area": float(self.patch_area),
                "lateral": float(self.lateral)}

    @classmethod
    def from_dict(cls, d) -> "Grasp":
        """The grasp of :meth:`to_dict`'s dict (``lateral`` optional: 0, as files written
        before it have it); an ArgumentError naming the field at fault."""
        if not isinstance(d, dict):
            raise ArgumentError(f"invalid `grasp`: a dict (got {type(d).__name__})", "grasp")
        return cls(_field(d, "name", _text), _field(d, "label", _text), _field(d, "faces", _faces),
                   _field(d, "angle", _angle), _field(d, "offset", _length), _field(d, "width", _width),
                   _field(d, "pose", _pose), _field(d, "holds", _flag), _field(d, "margin", _real),
                   _field(d, "torsion_k", _real), _field(d, "patch_area", _real),
                   _field(d, "lateral", _real) if "lateral" in d else 0.0)


@dataclass(frozen=True, eq=False)
class Taxonomy:
    """The grasps of an object: its hull ``vertices`` (n, 3) [m] (object frame), the hull's
    ``faces`` (:class:`Face`) and the ``grasps`` (:class:`Grasp`, in the enumeration order)."""

    vertices: np.ndarray
    faces: tuple
    grasps: tuple
    pad: np.ndarray = field(default_factory=lambda: PAD.copy())

    def grasp(self, name: str) -> Grasp:
        """The grasp ``name``, or an ArgumentError naming ``grasp``."""
        for g in self.grasps:
            if g.name == name:
                return g
        known = ", ".join(g.name for g in self.grasps)
        raise ArgumentError(f"invalid `grasp`: unknown grasp {name!r} (known: {known})", "grasp")

    def nearest(self, pose) -> tuple:
        """(name, distance [m]) of the grasp nearest to the in-hand ``pose`` by
        :func:`grasp_distance`; an ArgumentError naming ``taxonomy`` when there is none."""
        if not self.grasps:
            raise ArgumentError("invalid `taxonomy`: it has no grasps", "taxonomy")
        placed = P.transform_rows(np.array([g.pose for g in self.grasps]), self.vertices)
        d = _hausdorff(placed, P.transform(_check_pose(pose), self.vertices))
        i = int(np.argmin(d))
        return self.grasps[i].name, float(d[i])

    def classify(self, pose, tolerance: float) -> str | None:
        """The name of the grasp nearest to ``pose``, None when it is farther than ``tolerance`` [m]."""
        tolerance = _number(tolerance, "tolerance", 0.0, True)
        name, d = self.nearest(pose)
        return name if d <= tolerance else None

    def patch_centre(self, grasp: Grasp) -> np.ndarray:
        """The centroid (x, z) [m] of ``grasp``'s patch in the TCP frame (the contact region's
        when the pads touch no patch)."""
        eps = TOLERANCE * _size(self.vertices)
        try:
            region = _region(self.faces, grasp.faces, grasp.pose, eps)
        except IndexError:
            region = np.zeros((0, 2))
        if len(region) < 3:
            raise ArgumentError(f"invalid `grasp`: {grasp.name}'s faces {grasp.faces} do not face each other "
                                "at its pose", "grasp")
        patch = _patch(region, eps, self.pad)
        return _centroid(patch if len(patch) else region)


def taxonomy(vertices, mass: float, com, grip_force: float, friction: float, gravity: float = 9.81,
             width_range=WIDTH_RANGE, offsets=OFFSETS, pad=None, lateral=LATERAL) -> Taxonomy:
    """The grasp taxonomy (see the module's doc) of the object with ``vertices`` (n ≥ 4, 3) [m],
    ``mass`` [kg], centre of mass ``com`` (3,) [m] (object frame), held at ``grip_force`` [N]
    per pad with the pads' ``friction`` μ under ``gravity`` [m/s²]; pad widths within
    ``width_range`` (m, m), the region's centroid at z = f h for f in ``offsets`` (in (−½, ½))
    and at x = f w for f in ``lateral`` (in (−½, ½), not 0; none by default);
    ``pad``: the pad's face (k, 2) (x, z) [m] in the TCP frame, convex, counter-clockwise (default
    the 2F-85's whole face, :data:`PAD`; :func:`pad_disc` for a rubber tip). An ArgumentError
    naming the argument at fault."""
    V = _check_vertices(vertices)
    weight = _number(mass, "mass") * _number(gravity, "gravity", 0.0, True)
    grip, mu = _number(grip_force, "grip_force"), _number(friction, "friction")
    com = _check_com(com)
    lo, hi = _check_width_range(width_range)
    fractions = _check_offsets(offsets)
    sideways = _check_lateral(lateral)
    pad = PAD.copy() if pad is None else _check_pad(pad)
    faces, V = _hull(V)
    eps = TOLERANCE * _size(V)
    kept: list = []
    for a, b in _antipodal(faces, lo - eps, hi + eps):
        for pair in ((a, b), (b, a)):
            for c in _candidates(faces, V, pair, fractions, sideways, eps):
                placed = P.transform(c["pose"], V)
                box = np.r_[placed.min(axis=0), placed.max(axis=0)]
                # a Hausdorff distance below eps needs the bounding boxes within eps: checked first
                near = [k["placed"] for k in kept if np.all(np.abs(k["box"] - box) < eps)]
                if not near or np.min(_hausdorff(np.array(near), placed)) >= eps:
                    kept.append(dict(c, placed=placed, box=box, pair=pair))
    return Taxonomy(V, faces, tuple(_grasp(f"g{i}", c, com, weight, mu, grip, eps, pad) for i, c in enumerate(kept)), pad)


def taxonomy_of(scene, **kw) -> Taxonomy:
    """The taxonomy of a :class:`regrasp.Scene3D`'s object (its mesh, mass, centre of mass, grip
    force, pad friction, gravity's norm and pad: a disc of its ``pad_radius``, :func:`pad_disc`);
    ``kw``: :func:`taxonomy`'s ``width_range``, ``offsets``, ``pad``, ``lateral`` (default the
    object file's ``[taxonomy] lateral`` when the scene was loaded by
    :func:`regrasp.dexterity.objects.load_object`; none for a scene loaded otherwise)."""
    kw.setdefault("pad", pad_disc(float(scene.pad_radius)))
    kw.setdefault("lateral", getattr(scene, "taxonomy_lateral", LATERAL))
    return taxonomy(np.asarray(scene.mesh()[0], float), float(scene.mass), scene.com,
                    float(scene.grip_force), float(scene.pad_friction),
                    float(np.linalg.norm(scene.gravity)), **kw)


def grasp_distance(vertices, a, b) -> float:
    """The symmetric Hausdorff distance [m] between the ``vertices`` (n, 3) [m] placed by in-hand
    poses ``a`` and ``b``: max over each set of the distance to the nearest point of the other.
    Zero exactly when ``a`` and ``b`` place the object identically up to its symmetry."""
    V = np.asarray(vertices, float)
    return float(_hausdorff(P.transform(a, V)[None], P.transform(b, V))[0])


def box_vertices(size) -> np.ndarray:
    """The 8 corners (8, 3) [m] of a box of full ``size`` (3,) [m] centred at the origin."""
    s = np.array([[i, j, k] for i in (-1, 1) for j in (-1, 1) for k in (-1, 1)], float)
    return s * np.asarray(size, float) / 2


def extruded_vertices(outline, thickness: float) -> np.ndarray:
    """The vertices (2n, 3) [m] of ``outline`` (n, 2) [m] in the object's x-z plane extruded by
    ±``thickness``/2 [m] along y."""
    o = np.asarray(outline, float)
    return np.concatenate([np.column_stack([o[:, 0], np.full(len(o), y), o[:, 1]])
                           for y in (-thickness / 2, thickness / 2)])


# --- the hull and the candidates -----------------------------------------------------------------


def _size(V) -> float:
    """The object's size [m]: twice the farthest vertex's distance from the vertices' mean."""
    V = np.asarray(V, float)
    return 2 * float(np.max(np.linalg.norm(V - V.mean(axis=0), axis=1)))


def _hull(V) -> tuple:
    """(faces, hull vertices): the convex hull's triangles merged by plane (normals within
    :data:`TOLERANCE` rad, offsets within TOLERANCE × size), faces in a fixed order (by normal)."""
    spatial = need("scipy.spatial", "robot")
    try:
        hull = spatial.ConvexHull(V)
    except spatial.QhullError as e:
        raise ArgumentError(f"invalid `vertices`: no convex hull ({str(e).splitlines()[0]})", "vertices") from None
    V = V[hull.vertices]
    n, d = hull.equations[:, :3], -hull.equations[:, 3]
    eps, group = TOLERANCE * _size(V), np.full(len(n), -1)
    for i in range(len(n)):
        if group[i] < 0:
            same = (np.linalg.norm(n - n[i], axis=1) < TOLERANCE) & (np.abs(d - d[i]) < eps) & (group < 0)
            group[same] = i
    faces = [_face(hull.points[np.unique(hull.simplices[group == i])], n[group == i].mean(axis=0))
             for i in np.unique(group)]
    faces.sort(key=lambda f: tuple(-np.round(f.normal, 6)))
    return tuple(faces), V


def _face(p, n) -> Face:
    """The face with corners ``p`` (k, 3) [m] (any order) and outward normal ``n`` (3,)."""
    n = n / np.linalg.norm(n)
    t1, t2 = P.tangents(n)
    c = p.mean(axis=0)
    p = p[np.argsort(np.arctan2((p - c) @ t2, (p - c) @ t1))]
    return Face(n, float(np.mean(p @ n)), p)


def _antipodal(faces, lo: float, hi: float) -> list:
    """Index pairs (i < j) of faces with opposite normals (within :data:`TOLERANCE` rad) whose
    planes are ``lo`` to ``hi`` [m] apart."""
    return [(i, j) for i in range(len(faces)) for j in range(i + 1, len(faces))
            if np.linalg.norm(faces[i].normal + faces[j].normal) < TOLERANCE
            and lo <= faces[i].offset + faces[j].offset <= hi]


def _candidates(faces, V, pair: tuple, fractions: tuple, lateral: tuple, eps: float):
    """The candidate grasps (dicts) of face ``pair`` (left, right): per edge of the contact
    region, palm then fingertips, per offset fraction, then per lateral fraction."""
    q0 = np.r_[0.0, 0.0, 0.0, P.turn_onto(faces[pair[0]].normal, [0.0, 1.0, 0.0])]
    region = _region(faces, pair, q0, eps)
    width = faces[pair[0]].offset + faces[pair[1]].offset
    for i, (p, q) in enumerate(zip(region, np.roll(region, -1, axis=0))):
        theta = np.arctan2(p[0] - q[0], q[1] - p[1])  # the edge's outward normal (dz, −dx), from x towards z
        for side, target in (("palm", np.pi / 2), ("fingertips", -np.pi / 2)):
            angle = float(np.arctan2(np.sin(target - theta), np.cos(target - theta)))
            turn = P.compose(P.planar_to_spatial([0.0, 0.0, angle]), q0)
            r = P.planar_rotate(angle, region.T).T
            c, h, y = _centroid(r), float(np.ptp(r[:, 1])), P.transform(turn, V)[:, 1]
            w = float(np.ptp(r[:, 0]))
            for x, z in [(0.0, f * h) for f in fractions] + [(f * w, 0.0) for f in lateral]:
                t = np.array([x - c[0], -(y.max() + y.min()) / 2, z - c[1]])
                yield {"edge": i, "side": side, "angle": angle, "offset": z, "lateral": x, "width": width,
                       "pose": np.r_[t, turn[3:]], "region": r + t[[0, 2]]}


def _grasp(name: str, c: dict, com, weight: float, mu: float, grip: float, eps: float, pad=PAD) -> Grasp:
    """The :class:`Grasp` of candidate ``c``, its hold checked."""
    holds, margin, k, area = _hold(c["region"], P.transform(c["pose"], com), weight, mu, grip, eps, pad)
    label = f"faces {c['pair'][0]}|{c['pair'][1]}, edge {c['edge']} to {c['side']}, offset {c['offset'] * 1e3:+.1f} mm"
    if c["lateral"]:
        label += f", lateral {c['lateral'] * 1e3:+.1f} mm"
    return Grasp(name, label, tuple(c["pair"]), c["angle"], float(c["offset"]), float(c["width"]), c["pose"],
                 holds, margin, k, area, float(c["lateral"]))


def _hold(region, com, weight: float, mu: float, grip: float, eps: float, pad=PAD) -> tuple:
    """(holds, margin, k [m], patch area [m²]) of the contact ``region`` (k, 2) (TCP x, z) with
    the centre of mass at ``com`` (3,) (TCP frame), ``weight`` m g [N]: margin = 1 − (m g / 2μN)
    √(1 + (d/k)²) (see the module's doc); −1 when the patch is negligible."""
    patch = _patch(region, eps, pad)
    if not len(patch):
        return False, -1.0, 0.0, 0.0
    area, c = _area(patch), _centroid(patch)
    k = _mean_distance(patch, c)
    margin = 1.0 - weight / (2 * mu * grip) * float(np.hypot(1.0, np.hypot(com[0] - c[0], com[2] - c[1]) / k))
    return margin >= 0, margin, k, area


# --- convex polygons (x, z), counter-clockwise ---------------------------------------------------


def _region(faces, pair, pose, eps: float) -> np.ndarray:
    """The contact region (k, 2) [m] of faces ``pair`` placed by ``pose``: their polygons seen
    along y (x, z), intersected."""
    a, b = (_flat(P.transform(pose, faces[i].polygon)[:, [0, 2]]) for i in pair)
    return _clean(_clip(a, b), eps)


def _patch(region, eps: float, pad=PAD) -> np.ndarray:
    """The pad's patch (k, 2) [m] of ``region``: its part on the pad's face ``pad``; empty (0, 2)
    when that is smaller than :data:`NEGLIGIBLE` of the face."""
    patch = _clean(_clip(region, pad), eps)
    return patch if len(patch) and _area(patch) > NEGLIGIBLE * _area(pad) else np.zeros((0, 2))


def pad_disc(radius: float, sides: int = 64) -> np.ndarray:
    """A rubber tip's face: the disc of ``radius`` [m] at the pad's centre (a ``sides``-gon, the
    2F-85's face clipped to it), (k, 2) (x, z) [m], counter-clockwise — the pad of a 3-D scene
    (``grasp.pad_radius``), as the simulated pads (:meth:`regrasp.robot.pads.Pads.of_scene`)."""
    a = 2 * np.pi * np.arange(sides) / sides
    return _clip(radius * np.column_stack([np.cos(a), np.sin(a)]), PAD)


def _check_pad(pad) -> np.ndarray:
    p = _array(pad, "pad", "a convex polygon (k >= 3, 2) [m], counter-clockwise")
    if p.ndim != 2 or p.shape[1] != 2 or len(p) < 3 or not np.all(np.isfinite(p)) or signed_area(p) <= 0:
        raise ArgumentError(f"invalid `pad`: a convex polygon (k >= 3, 2) [m], counter-clockwise (got shape "
                            f"{p.shape})", "pad")
    return p


def _flat(p) -> np.ndarray:
    return p if signed_area(p) > 0 else p[::-1]


def _clip(subject, clip) -> np.ndarray:
    """The intersection (k, 2) of convex polygons ``subject`` and ``clip`` (counter-clockwise),
    by Sutherland–Hodgman: ``subject`` cut by each edge of ``clip`` in turn."""
    out = np.asarray(subject, float)
    for a, b in zip(clip, np.roll(clip, -1, axis=0)):
        if len(out) == 0:
            break
        s = (b[0] - a[0]) * (out[:, 1] - a[1]) - (b[1] - a[1]) * (out[:, 0] - a[0])  # ≥ 0: inside
        pts = []
        for p, q, sp, sq in zip(out, np.roll(out, -1, axis=0), s, np.roll(s, -1)):
            if sp >= 0:
                pts.append(p)
            if (sp >= 0) != (sq >= 0):
                pts.append(p + (q - p) * sp / (sp - sq))
        out = np.array(pts).reshape(-1, 2)
    return out


def _clean(p, eps: float) -> np.ndarray:
    """Polygon ``p`` without corners within ``eps`` [m] of the line through their neighbours
    (repeated or straight ones); empty (0, 2) when fewer than 3 are left."""
    pts = list(np.asarray(p, float))
    i = 0
    while len(pts) >= 3 and i < len(pts):
        a, b, c = pts[i - 1], pts[i], pts[(i + 1) % len(pts)]
        ac = c - a
        if abs(ac[0] * (b[1] - a[1]) - ac[1] * (b[0] - a[0])) <= eps * max(float(np.linalg.norm(ac)), eps) \
                or np.linalg.norm(b - a) <= eps:
            pts.pop(i)
            i = max(i - 1, 0)
        else:
            i += 1
    return np.array(pts).reshape(-1, 2) if len(pts) >= 3 else np.zeros((0, 2))


def _area(p) -> float:
    return signed_area(p)


def _centroid(p) -> np.ndarray:
    """The centroid (2,) of polygon ``p`` (k, 2) (shoelace)."""
    p = np.asarray(p, float)
    q = np.roll(p, -1, axis=0)
    w = p[:, 0] * q[:, 1] - q[:, 0] * p[:, 1]
    return ((p + q) * w[:, None]).sum(axis=0) / (3 * w.sum())


def _mean_distance(p, c) -> float:
    """The mean distance [m] of the uniformly covered convex polygon ``p`` (k, 2) from ``c``
    (2,) inside it: per edge, ∫∫ r dA over the triangle (c, edge) = h³/6 [t √(1 + t²) + asinh t]
    between the edge's ends (h the edge line's distance from c, t the position along it / h),
    summed over the area."""
    a, b = np.asarray(p, float) - c, np.roll(np.asarray(p, float), -1, axis=0) - c
    e = (b - a) / np.linalg.norm(b - a, axis=1)[:, None]
    h = a[:, 0] * e[:, 1] - a[:, 1] * e[:, 0]  # signed: > 0 for a counter-clockwise triangle
    m = np.where(np.abs(h) > 0, np.abs(h), 1.0)
    G = lambda t: t * np.sqrt(1 + t * t) + np.arcsinh(t)  # noqa: E731
    I = np.sign(h) * m ** 3 / 6 * (G(np.sum(b * e, axis=1) / m) - G(np.sum(a * e, axis=1) / m))
    return float(I.sum() / _area(p))


def _hausdorff(A, B) -> np.ndarray:
    """The symmetric Hausdorff distances (m,) between each point set ``A`` (m, n, 3) and ``B`` (n, 3)."""
    B = np.asarray(B, float)
    D = [np.sum((a[:, None, :] - B[None, :, :]) ** 2, axis=-1) for a in np.asarray(A, float)]  # (n, n) each
    return np.sqrt(np.array([max(d.min(axis=0).max(), d.min(axis=1).max()) for d in D]))


# --- arguments -----------------------------------------------------------------------------------


def _number(value, field: str, low: float = 0.0, closed: bool = False) -> float:
    """``value`` as a finite float > ``low`` (≥ with ``closed``), or an ArgumentError naming ``field``."""
    ok = isinstance(value, numbers.Real) and not isinstance(value, bool) and np.isfinite(float(value)) \
        and (float(value) >= low if closed else float(value) > low)
    if not ok:
        raise ArgumentError(f"invalid `{field}`: a number {'>=' if closed else '>'} {low:g} (got {value!r})", field)
    return float(value)


def _array(value, field: str, shape: str) -> np.ndarray:
    try:
        a = np.asarray(value, float)
    except (TypeError, ValueError):
        raise ArgumentError(f"invalid `{field}`: {shape} (got {value!r})", field) from None
    return a


def _check_vertices(vertices) -> np.ndarray:
    V = _array(vertices, "vertices", "an (n, 3) array of numbers")
    if V.ndim != 2 or V.shape[1] != 3 or len(V) < 4 or not np.all(np.isfinite(V)):
        raise ArgumentError(f"invalid `vertices`: an (n >= 4, 3) array of finite numbers [m] (got shape {V.shape})",
                            "vertices")
    s = np.linalg.svd(V - V.mean(axis=0), compute_uv=False)
    if s[2] <= 1e-9 * s[0]:
        raise ArgumentError("invalid `vertices`: they lie in a plane (the object needs a volume)", "vertices")
    return V


def _check_com(com) -> np.ndarray:
    c = _array(com, "com", "a point (3,) [m]")
    if c.shape != (3,) or not np.all(np.isfinite(c)):
        raise ArgumentError(f"invalid `com`: a point (3,) of finite numbers [m] (got {com!r})", "com")
    return c


def _check_width_range(width_range) -> tuple:
    w = _array(width_range, "width_range", "(min, max) [m]")
    if w.shape != (2,) or not np.all(np.isfinite(w)) or not 0 <= w[0] <= w[1]:
        raise ArgumentError(f"invalid `width_range`: (min, max) [m] with 0 <= min <= max (got {width_range!r})",
                            "width_range")
    return float(w[0]), float(w[1])


def _check_offsets(offsets) -> tuple:
    f = _array(offsets, "offsets", "fractions in (-0.5, 0.5)")
    if f.ndim != 1 or len(f) == 0 or not np.all(np.abs(f) < 0.5):
        raise ArgumentError(f"invalid `offsets`: one or more fractions in (-0.5, 0.5) (got {offsets!r})", "offsets")
    return tuple(float(x) for x in f)


def _check_lateral(lateral) -> tuple:
    f = _array(lateral, "lateral", "fractions in (-0.5, 0.5), not 0")
    if f.ndim != 1 or not np.all((np.abs(f) < 0.5) & (f != 0)):
        raise ArgumentError(f"invalid `lateral`: fractions in (-0.5, 0.5), not 0 (got {lateral!r})", "lateral")
    return tuple(float(x) for x in f)


def _check_pose(pose) -> np.ndarray:
    q = _array(pose, "pose", "[x, y, z, qw, qx, qy, qz]")
    if q.shape != (7,) or not np.all(np.isfinite(q)) or np.linalg.norm(q[3:]) < 1e-9:
        raise ArgumentError(f"invalid `pose`: [x, y, z, qw, qx, qy, qz] finite, a non-zero quaternion (got {pose!r})",
                            "pose")
    return np.r_[q[:3], q[3:] / np.linalg.norm(q[3:])]


def _field(d: dict, key: str, parse):
    """``parse(d[key])``, or an ArgumentError naming ``key``."""
    try:
        return parse(d[key])
    except (KeyError, TypeError, ValueError, ArgumentError):
        raise ArgumentError(f"invalid `{key}`: missing or malformed (got {d.get(key)!r})", key) from None


def _text(v) -> str:
    if not isinstance(v, str):
        raise TypeError(type(v).__name__)
    return v


def _real(v) -> float:
    if isinstance(v, bool) or not isinstance(v, numbers.Real) or not np.isfinite(float(v)):
        raise ValueError(v)
    return float(v)


def _length(v) -> float:
    """A length or offset [m] within the largest object size (10 m)."""
    x = _real(v)
    if abs(x) > 10.0:
        raise ValueError(v)
    return x


def _width(v) -> float:
    """A grasp width [m], > 0 and at most 10 m."""
    x = _length(v)
    if x <= 0:
        raise ValueError(v)
    return x


def _angle(v) -> float:
    """An angle [rad] within a turn either way."""
    x = _real(v)
    if abs(x) > 2 * np.pi:
        raise ValueError(v)
    return x


def _flag(v) -> bool:
    if not isinstance(v, bool):
        raise TypeError(type(v).__name__)
    return v


def _faces(v) -> tuple:
    if len(v) != 2 or not all(isinstance(i, int) and not isinstance(i, bool) and i >= 0 for i in v):
        raise ValueError(v)
    return int(v[0]), int(v[1])


def _pose(v) -> np.ndarray:
    q = np.array([_real(x) for x in v])
    if q.shape != (7,) or abs(np.linalg.norm(q[3:]) - 1) > 1e-6 or np.max(np.abs(q[:3])) > 10.0:
        raise ValueError(v)
    return q


#: The classification tolerance: this share of the object's size (its hull's largest extent)
#: [m/m]; a trial ends in a grasp when within it (:mod:`.trial`).
CLASSIFICATION_TOLERANCE = 0.15


def classification_tolerance(taxonomy) -> float:
    """The classification tolerance [m] of ``taxonomy``'s object."""
    v = np.asarray(taxonomy.vertices, float)
    return CLASSIFICATION_TOLERANCE * float(np.max(np.ptp(v, axis=0)))
