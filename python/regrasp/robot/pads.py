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


@dataclass(frozen=True)
class Pads:
    """The pads' contact grid: ``columns`` across (x) by ``rows`` along the finger (z) spheres of
    radius ``radius`` [m], spread over the real pad face (22 mm x 37.5 mm), the outer spheres'
    centres ``radius`` inside its edges."""

    columns: int = 3
    rows: int = 7
    radius: float = 0.001

    def points(self) -> np.ndarray:
        """The spheres' centres in the pad body's frame, shape (columns · rows, 3) [m]."""
        xs = np.linspace(-HALF_WIDTH + self.radius, HALF_WIDTH - self.radius, self.columns)
        zs = np.linspace(self.radius, LENGTH - self.radius, self.rows)
        return np.array([[x, FACE_Y + self.radius, z] for z in zs for x in xs])


PAD_SOLREF = (0.02, 1.0)  # a compliant (silicone) pad: every sphere of the grid bears load (a stiffer one
# lets a tilt of a few mrad put the whole grip on one row)
PAD_SOLIMP = (0.9, 0.95, 0.003, 0.5, 2.0)


def add_pads(spec, body, pads: Pads, friction: float) -> None:
    """Replaces the contact geoms of pad ``body`` (an ``MjsBody`` of ``spec``) by ``pads``'s grid
    of spheres with Coulomb friction ``friction`` and no torsional or rolling friction."""
    mujoco = need("mujoco", "robot")
    for g in list(body.geoms):
        if g.contype or g.conaffinity:
            spec.delete(g)
    for i, p in enumerate(pads.points()):
        body.add_geom(name=f"{body.name}_contact{i}", type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[pads.radius, 0, 0],
                      pos=p, condim=3, friction=[friction, 0, 0], priority=2, solref=PAD_SOLREF, solimp=PAD_SOLIMP,
                      mass=0, rgba=[0.2, 0.2, 0.2, 1], group=3)
