"""The one builder of every MuJoCo world, on ``mujoco.MjSpec``: a :class:`Layout` says what the
world holds — the scene's object at its start, who holds it (pads fixed in the world: the
planner's view; pads on a driven gripper: the free-flying gripper; a robot's own hand), the
pushers' features (parked mocap bodies put where a push needs them, or driven bodies), a
workcell's fixed features, the world :class:`~regrasp.Perturbation` — and :func:`build` makes
it, for the planar execution (:mod:`.planar`), the pushes in the planner's view (:mod:`.push`),
the 3-D execution (:mod:`.spatial`), the free-flying gripper
(:mod:`regrasp.execution.free_gripper`), the arm (:mod:`regrasp.execution.arm`) and the hand of
the regrasp actions (:mod:`regrasp.dexterity.world`). The pieces are :mod:`.model`'s (planar)
and :mod:`.spatial_parts`' (3-D)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable, Optional

import numpy as np

from ..errors import ArgumentError
from ..scene.perturbation import Perturbation
from . import model as M
from .spatial_parts import PARK as PARK3D, add_feature_geoms, add_object3d, add_pads3d

#: Who holds the object: pads fixed in the world, pads on a driven gripper, a robot's own hand.
HOLDERS = ("fixed", "gripper", "robot")
#: How the pushers' features move: mocap bodies parked until a push (``parked``), driven bodies.
FEATURES = ("parked", "driven")
#: Where a planar world parks the pushers' features until a push needs them [m].
PARK = np.array([0.0, 5.0, 0.0])


@dataclass(frozen=True)
class Layout:
    """What a world holds: ``scene`` (planar or 3-D) and its object at ``start`` (planar
    ``[x, z, theta]`` or ``[x, y, z, qw, qx, qy, qz]``, m); ``holder`` (:data:`HOLDERS`) on a
    ``spatial`` driven body or a planar one (default: spatial for a 3-D scene or in a workcell);
    the features of ``pushers``, moved as ``features`` (:data:`FEATURES`); ``workcell``'s table
    and features, fixed; the ``perturbation`` (pads', features' and the workcell's friction, the
    object's mass); ``pad`` (3-D: ``point`` or ``ring``); ``object_rgba``; ``name``."""

    scene: object
    start: object
    holder: str = "fixed"
    spatial: Optional[bool] = None
    pushers: tuple = ()
    features: str = "parked"
    workcell: object = None
    perturbation: Perturbation = field(default_factory=Perturbation)
    pad: str = "point"
    object_rgba: Optional[tuple] = None
    name: str = ""

    def __post_init__(self):
        if self.holder not in HOLDERS:
            raise ArgumentError(f"invalid `holder`: one of {', '.join(HOLDERS)} (got {self.holder!r:.40})", "holder")
        if self.features not in FEATURES:
            raise ArgumentError(f"invalid `features`: one of {', '.join(FEATURES)} (got {self.features!r:.40})",
                                "features")
        if self.pad not in ("point", "ring"):
            raise ArgumentError(f"invalid `pad`: 'point' or 'ring' (got {self.pad!r:.40})", "pad")


def gravity(layout: Layout) -> np.ndarray:
    """The world's gravity [m/s²]: the scene's (planar: in the X-Z plane of the grasp), or in a
    workcell the world's −z with the scene's magnitude."""
    s = layout.scene
    if layout.workcell is not None:
        g = s.gravity[1] if s.dimension == 2 else float(np.linalg.norm(s.gravity))
        return np.array([0.0, 0.0, -g])
    if s.dimension == 2:
        gdir, g = s.gravity
        return np.array([gdir[0] * g, 0.0, gdir[1] * g])
    return np.asarray(s.gravity, float)


def build(layout: Layout, contact: M.Contact = M.Contact(), spec=None, extra: Optional[Callable] = None):
    """The world of ``layout`` as a ``mujoco.MjSpec`` (``.compile()`` it; ``.to_xml()`` is its
    MJCF), with ``contact``'s settings; into ``spec`` when given (a robot's, ``holder`` "robot":
    its hand holds the object, nothing else is added to it); ``extra(spec)`` adds fixed geoms of
    the world body last (a post, the edges a push renders)."""
    L, s, pert = layout, layout.scene, layout.perturbation
    if spec is None:
        spec = M.new_spec(L.name or s.name, gravity(L), contact)
    if L.workcell is not None:
        add_workcell_geoms(spec, _scaled(L.workcell, pert.feature_friction))
    mesh = None
    if s.dimension == 2:
        body = M.add_object(spec, s, L.start, mass_scale=pert.mass)
    else:
        v, t = s.mesh()
        mesh = (np.asarray(v, float), np.asarray(t, int))
        add_object3d(spec, s, np.asarray(L.start, float), mesh, pert.mass)
        body = spec.body("object")
    if L.object_rgba is not None:
        for g in body.geoms:
            g.rgba = list(L.object_rgba)
    if L.holder != "robot":
        spatial = (s.dimension == 3 or L.workcell is not None) if L.spatial is None else L.spatial
        hold = spec.worldbody if L.holder == "fixed" else M.add_driven_body(spec.worldbody, "gripper", spatial)
        if s.dimension == 2:
            M.add_planar_pads(hold, s, friction_scale=pert.finger_friction)
        else:
            add_pads3d(hold, s, np.asarray(L.start, float), mesh[0], pert.finger_friction, L.pad)
    for i, p in enumerate(L.pushers):
        _add_feature(spec, L, p, i)
    if extra is not None:
        extra(spec)
    if L.holder != "robot":
        M.add_grip_motors(spec)
    return spec


def _add_feature(spec, L: Layout, p: str, i: int) -> None:
    """Pusher ``p``'s feature (the ``i``-th): a parked mocap body or a driven one, ``feature_p``."""
    s, k = L.scene, L.perturbation.feature_friction
    name = f"feature_{p}"
    if s.dimension == 2:
        if L.features == "parked":
            M.add_feature(spec, s, p, name, k, PARK)
        else:
            M.add_feature_geom(M.add_driven_body(spec.worldbody, name), s, p, k)
        return
    body = (spec.worldbody.add_body(name=name, mocap=True, pos=PARK3D + [0.1 * i, 0, 0]) if L.features == "parked"
            else M.add_driven_body(spec.worldbody, name, spatial=True))
    add_feature_geoms(body, s, p, s.pusher_spec(p)[2] * k)


def add_workcell_geoms(spec, workcell) -> None:
    """The table and every feature of ``workcell`` as fixed geoms of ``spec``'s world body, their
    physical bodies (:func:`regrasp.workcell.shapes.shapes`), colliding with the object (and a
    robot's collision geoms)."""
    from ..workcell.shapes import shapes

    for sh in shapes(workcell):
        M.add_geom(spec.worldbody, sh.kind, sh.size, bits=M.FEATURE_BITS, condim=3, friction=[sh.friction],
                   name=sh.name, pos=sh.pose[:3], quat=sh.pose[3:])


def _scaled(wc, k: float):
    """``wc`` with every feature's and the table's friction times ``k``."""
    if k == 1.0:
        return wc
    from dataclasses import replace

    return replace(wc, table=replace(wc.table, friction=wc.table.friction * k),
                   features=tuple(replace(f, friction=f.friction * k) for f in wc.features))


def creep(scene, pose=None, duration: float = 2.0, contact: M.Contact = M.Contact()) -> float:
    """How far [m] a planar scene's object slides in the grasp while simply held (pads fixed, no
    pusher) for ``duration`` [s] from ``pose`` (default: the task's start): rigid Coulomb friction
    holds it still; soft contact (:data:`~.model.SOFT`) lets it creep."""
    start = scene.task.start if pose is None else pose
    rig = M.Rig(build(Layout(scene, start, "fixed", name=f"{scene.name}-held"), contact), contact, scene.grip_force)
    for _ in range(int(0.1 / contact.timestep)):
        rig.step()
    first = M.planar_pose(rig.model, rig.data, "object")
    for _ in range(int(duration / contact.timestep)):
        rig.step()
    return float(np.linalg.norm(M.planar_pose(rig.model, rig.data, "object")[:2] - first[:2]))
