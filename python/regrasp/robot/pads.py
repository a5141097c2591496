"""Distributed-contact finger pads: each pad's contact face is a grid of small spheres on the
2F-85's real pad (22 mm x 37.5 mm), so that the pad's resistance to sliding and twisting (its
limit surface) emerges from MuJoCo's point contacts. The spheres have no torsional or rolling
friction (``condim`` 3): no torsional-friction shortcut."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..extras import need

# the 2F-85 pad body's frame (Menagerie): the face at y = FACE_Y looks at the other finger (-y),
# spans x in [-HALF_WIDTH, HALF_WIDTH] and z in [0, LENGTH]
FACE_Y = -0.0066  # m
HALF_WIDTH = 0.011  # m
LENGTH = 0.0375  # m
PAD_FRICTION = 0.5  # the pads' default Coulomb friction (and a held test object's, robot.creep)


PAD_SOLREF = (0.02, 1.0)  # a compliant (silicone) pad: every sphere of the grid bears load (a stiffer one
# lets a tilt of a few mrad put the whole grip on one row)
PAD_SOLIMP = (0.9, 0.95, 0.003, 0.5, 2.0)
TIP_SOLREF = (0.005, 1.0)  # a scene's pad (Pads.of_scene), a small firm tip: with 0.02 s a held lamina turned
# ≈ 1.4 mrad/s under a 13 mN·m gravity torque (10 % of the tip's torsional capacity), with 0.005 s ≈ 0.3 mrad/s


@dataclass(frozen=True)
class Pads:
    """The pads' contact grid: ``columns`` across (x) by ``rows`` along the finger (z) spheres of
    radius ``radius`` [m], spread over the real pad face (22 mm x 37.5 mm), the outer spheres'
    centres ``radius`` inside its edges. With a ``shape`` — a scene's pad, ``("circle", r, r)``
    or ``("rectangle", width, height)`` [m] (``Scene.pad``): a rubber tip of that shape centred on
    the face — the grid spans the shape (clipped to the face) and keeps the spheres inside it.
    ``solref`` (s, −): the spheres' MuJoCo contact stiffness (:data:`PAD_SOLREF`). ``torsion``
    [m] > 0: the old single-contact model instead — one sphere at the face's centre with
    torsional friction ``torsion · μ`` (MuJoCo's elliptic cone there is the ellipsoidal limit
    surface; :meth:`single_contact`), for comparison."""

    columns: int = 3
    rows: int = 7
    radius: float = 0.001
    shape: tuple | None = None
    solref: tuple = PAD_SOLREF
    torsion: float = 0.0

    def points(self, face: tuple = (HALF_WIDTH, LENGTH / 2)) -> np.ndarray:
        """The spheres' centres in the pad body's frame, shape (k, 3) [m] (k = columns · rows
        without a ``shape``), on a ``face`` of half-width and half-length [m] centred at
        ``z = LENGTH / 2`` (the 2F-85's whole face by default; a smaller gripper pad's)."""
        hx, hz = float(face[0]), float(face[1])
        if self.torsion > 0:
            return np.array([[0.0, FACE_Y + self.radius, LENGTH / 2]])
        if self.shape is not None:
            kind, a, b = self.shape
            hx, hz = (min(a, hx), min(a, hz)) if kind == "circle" else (min(a / 2, hx), min(b / 2, hz))
        xs = np.linspace(-hx + self.radius, hx - self.radius, self.columns)
        zs = np.linspace(-hz + self.radius, hz - self.radius, self.rows)
        pts = np.array([[x, z] for z in zs for x in xs])
        if self.shape is not None and self.shape[0] == "circle":
            pts = pts[np.hypot(pts[:, 0], pts[:, 1]) <= min(self.shape[1], hx, hz) - self.radius + 1e-12]
        return np.column_stack([pts[:, 0], np.full(len(pts), FACE_Y + self.radius), pts[:, 1] + LENGTH / 2])

    @classmethod
    def of_scene(cls, scene) -> "Pads":
        """The grid of a scene's pad (``Scene.pad``, or a 3-D scene's disc of ``pad_radius``):
        5 x 5 spheres over the pad's shape (a circle keeps the 13 inside it)."""
        pad = scene.pad if scene.dimension == 2 else ("circle", scene.pad_radius, scene.pad_radius)
        if pad is None:
            return cls()
        return cls(5, 5, 0.001, (str(pad[0]), float(pad[1]), float(pad[2])), TIP_SOLREF)


def single_contact(scene) -> "Pads":
    """The old pad model of ``scene`` (:attr:`Pads.torsion`): one contact at the face's centre
    with the torsional friction of the scene's limit surface (planar ``pad_limit_surface_k``;
    3-D (2/3) × the pad's radius, a uniformly pressed disc's)."""
    k = scene.pad_limit_surface_k if scene.dimension == 2 else 2.0 / 3.0 * scene.pad_radius
    return Pads(1, 1, 0.001, None, TIP_SOLREF, float(k))


def face() -> tuple:
    """The 2F-85 pad's face: (half-width, half-length) [m]."""
    return (HALF_WIDTH, LENGTH / 2)


def add_pads(spec, body, pads: Pads, friction: float, face: tuple = (HALF_WIDTH, LENGTH / 2)) -> None:
    """Replaces the contact geoms of pad ``body`` (an ``MjsBody`` of ``spec``) by ``pads``'s grid
    of spheres on ``face`` (:meth:`Pads.points`) with Coulomb friction ``friction`` and no
    torsional or rolling friction."""
    mujoco = need("mujoco", "robot")
    for g in list(body.geoms):
        if g.contype or g.conaffinity:
            spec.delete(g)
    for i, p in enumerate(pads.points(face)):
        body.add_geom(name=f"{body.name}_contact{i}", type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[pads.radius, 0, 0],
                      pos=p, condim=4 if pads.torsion > 0 else 3, friction=[friction, pads.torsion * friction, 0],
                      priority=2, solref=pads.solref, solimp=PAD_SOLIMP,
                      mass=0, rgba=[0.2, 0.2, 0.2, 1], group=3)
