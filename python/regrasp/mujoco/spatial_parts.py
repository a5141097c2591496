"""The 3-D scene's pieces of a MuJoCo world (:mod:`.world` builds it): the object (a sphere, a
convex mesh, or convex parts) with the scene's mass, centre of mass and inertia; the pads at its
extreme points along the grasp axis (one contact each, or a ring of 8 points: the quasi-static
model's pad); the pushers' features (a 1.5 mm sphere behind a point pusher, a capsule behind a
line pusher, a thin plate behind a patch, a slab for a plane)."""

from __future__ import annotations

import numpy as np

from ..pose import compose, quat_from_matrix, tangents
from .model import FEATURE_BITS, OBJECT_BITS, PAD_BITS, add_geom, add_pad_sphere, add_pads, set_inertial

PARK = np.array([0.0, 0.0, 5.0])
R_FEATURE = 0.0015
PLANE_HALF = 0.15  # m, half the side of a plane feature (a floor or a wall)
PAD_BALL = 0.001  # m, the small spheres of a ring pad


def _shift(v) -> np.ndarray:
    """The translation by ``v`` as a pose."""
    return np.r_[v, 1, 0, 0, 0]


def _quat(t1, t2, n) -> np.ndarray:
    """The quaternion [w, x, y, z] of the frame with axes t1, t2, n."""
    return quat_from_matrix(np.c_[t1, t2, n])


def add_feature_geoms(body, scene, name: str, friction: float):
    """The pusher's feature in its frame: a 1.5 mm sphere behind a point pusher, a capsule behind a
    line pusher, a thin plate behind a patch, a thick slab whose top face is the plane z = 0 of
    the feature's frame for a plane (see :func:`plane_frame`)."""
    kw = dict(bits=FEATURE_BITS, friction=[friction], condim=3)
    if scene.is_plane(name):
        return add_geom(body, "box", [PLANE_HALF, PLANE_HALF, 0.005], pos=[0.0, 0.0, -0.005], **kw)
    pts, n, _ = scene.pusher_spec(name)
    pts, n = np.asarray(pts, float), np.asarray(n, float) / np.linalg.norm(n)
    if len(pts) == 1:
        return add_geom(body, "sphere", [R_FEATURE], pos=pts[0] - n * R_FEATURE, **kw)
    if len(pts) == 2:
        return add_geom(body, "capsule", [R_FEATURE], fromto=np.ravel(pts - n * R_FEATURE), **kw)
    t1, t2 = tangents(n)
    c = pts.mean(axis=0)
    e1, e2 = np.abs((pts - c) @ t1).max(), np.abs((pts - c) @ t2).max()
    return add_geom(body, "box", [e1, e2, 0.0015], pos=c - n * 0.0015, quat=_quat(t1, t2, n), **kw)


def add_object3d(spec, scene, s0, mesh, mass_scale: float):
    """The object at pose ``s0`` on a free joint: a sphere, the scene's convex ``mesh``
    (vertices, triangles) or, for a non-convex object, one mesh geom per convex part (MuJoCo
    collides each as its convex hull: exact for a convex part); the inertia is the scene's."""
    m = scene.mass * mass_scale
    I = np.asarray(scene.inertia, float) * mass_scale
    body = spec.worldbody.add_body(name="object", pos=s0[:3], quat=s0[3:])
    body.add_freejoint()
    full = [I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2]]
    set_inertial(body, scene.com, m, full=full)
    kw = dict(bits=OBJECT_BITS, friction=[0.0], condim=4)
    if scene.sphere:
        return add_geom(body, "sphere", [scene.sphere], **kw)
    parts = scene.parts()
    if len(parts) > 1:
        for k, (v, t) in enumerate(parts):
            spec.add_mesh(name=f"obj_{k}", uservert=np.ravel(v).tolist(), userface=np.ravel(t).tolist())
            add_geom(body, "mesh", [], meshname=f"obj_{k}", **kw)
        return None
    v, t = mesh
    spec.add_mesh(name="obj", uservert=np.ravel(v).tolist(), userface=np.ravel(t).tolist())
    return add_geom(body, "mesh", [], meshname="obj", **kw)


def add_pads3d(parent, scene, s0, vertices, friction_scale: float, pad: str):
    """The pads at the object's extreme points (of its mesh's ``vertices``) along ±Y at pose
    ``s0``: one contact each (:func:`add_pad_sphere`, torsional friction (2/3) r μ) or,
    ``pad="ring"``, 8 point contacts on a ring at 2/3 of the pad's radius (the quasi-static
    model's pad)."""
    mu = scene.pad_friction * friction_scale
    k = scene.pad_limit_surface_k
    R = scene.sphere
    w = np.array([compose(s0, _shift(x))[:3] for x in vertices])
    ys = [s0[1] + sign * R if R else np.max(sign * w[:, 1]) * sign for sign in (1, -1)]

    def geoms(body, sign):
        if pad != "ring":
            return add_pad_sphere(body, sign, mu, k)
        for a in 2 * np.pi * (np.arange(8) + 0.5) / 8:
            add_geom(body, "sphere", [PAD_BALL], PAD_BITS, [mu], pos=[k * np.cos(a), sign * PAD_BALL, k * np.sin(a)],
                     mass=0.01, condim=3)

    add_pads(parent, ys, geoms)
