"""A perturbed world (thesis §5.1, robustness): how the world a plan is executed in differs from
the scene it was planned in. One type for every rig (the planner's view, the free gripper, the
arm, the dexterity hand): factors on the fingers' (pads') friction, the grip force, the object's
mass and the features' (pushers', table's) friction, and the object's start in the hand moved
(a shift and a turn about the grasp axis, or another pose)."""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, replace

import numpy as np

from ..errors import ArgumentError

#: How the features' friction is drawn by :meth:`Perturbation.draw`: kept at ``base``'s (the
#: features have the friction the plan assumed), a factor of its own, or the fingers' factor.
FEATURE_DRAWS = ("nominal", "drawn", "finger")


@dataclass(frozen=True)
class Perturbation:
    """Factors on the physics of the executed world (1: as planned) and the object's start.

    ``finger_friction``: on the pads' Coulomb coefficient; ``grip``: on the grip force;
    ``mass``: on the object's mass (and inertia); ``feature_friction``: on every feature's and
    the table's coefficient; ``shift`` (3,) [m] (hand frame) and ``turn`` [rad] (about the grasp
    axis, +y: z towards x) move the object's start in the hand; ``pose`` (7,) (m, unit
    quaternion) replaces that start (None: the plan's or grasp's), e.g. where a previous action
    left it."""

    finger_friction: float = 1.0
    grip: float = 1.0
    mass: float = 1.0
    feature_friction: float = 1.0
    shift: tuple = (0.0, 0.0, 0.0)
    turn: float = 0.0
    pose: tuple | None = None

    def __post_init__(self):
        for k in ("finger_friction", "grip", "mass", "feature_friction"):
            v = getattr(self, k)
            if isinstance(v, bool) or not isinstance(v, (int, float, np.integer, np.floating)) \
                    or not (math.isfinite(v) and 0 < v <= 1e3):
                raise ArgumentError(f"invalid `perturbation.{k}`: a positive factor, at most 1000 (got {v!r:.60})",
                                    f"perturbation.{k}")
            object.__setattr__(self, k, float(v))
        s = np.asarray(self.shift, float) if isinstance(self.shift, (list, tuple, np.ndarray)) else None
        if s is None or s.shape != (3,) or not np.all(np.isfinite(s)) or np.max(np.abs(s)) > 1.0:
            raise ArgumentError(f"invalid `perturbation.shift`: 3 finite numbers [m], at most 1 m (got {self.shift!r:.60})",
                                "perturbation.shift")
        object.__setattr__(self, "shift", tuple(map(float, s)))
        if isinstance(self.turn, bool) or not isinstance(self.turn, (int, float, np.integer, np.floating)) \
                or not math.isfinite(self.turn) or abs(self.turn) > math.pi:
            raise ArgumentError(f"invalid `perturbation.turn`: an angle in [-π, π] rad (got {self.turn!r:.60})",
                                "perturbation.turn")
        object.__setattr__(self, "turn", float(self.turn))
        if self.pose is not None:
            q = np.asarray(self.pose, float) if isinstance(self.pose, (list, tuple, np.ndarray)) else None
            if q is None or q.shape != (7,) or not np.all(np.isfinite(q)) or np.linalg.norm(q[3:]) < 1e-6:
                raise ArgumentError(f"invalid `perturbation.pose`: [x, y, z, qw, qx, qy, qz] (m, quaternion) "
                                    f"(got {self.pose!r:.80})", "perturbation.pose")
            object.__setattr__(self, "pose", tuple(map(float, q)))

    @property
    def factors(self) -> tuple[float, float, float, float]:
        """``(finger_friction, grip, mass, feature_friction)``."""
        return self.finger_friction, self.grip, self.mass, self.feature_friction

    @property
    def nominal(self) -> bool:
        """Whether the world is the scene's: every factor 1, the start unmoved."""
        return self.factors == (1.0, 1.0, 1.0, 1.0) and not any(self.shift) and not self.turn and self.pose is None

    @property
    def friction(self) -> float:
        """The fingers' factor (the name of the planar engine's and the hand's old types)."""
        return self.finger_friction

    @property
    def pusher(self) -> float:
        """The features' factor (the name of the planar engine's old type)."""
        return self.feature_friction

    def scene(self, scene):
        """The planar ``scene`` with this world's physics (:meth:`~regrasp.Scene.scaled`): what
        the quasi-static simulator runs in."""
        return scene.scaled(self.finger_friction, self.grip, self.mass, self.feature_friction)

    def at(self, pose) -> "Perturbation":
        """The same physics, the object starting at ``pose`` ``[x, y, z, qw, qx, qy, qz]`` (m, unit
        quaternion), with no shift or turn."""
        return replace(self, shift=(0.0, 0.0, 0.0), turn=0.0, pose=tuple(map(float, pose)))

    @classmethod
    def draw(cls, rng, spread: float, *, features: str = "nominal", shift: float | None = None,
             turn: float | None = None, base: "Perturbation | None" = None) -> "Perturbation":
        """A world drawn by ``rng`` (a ``numpy.random.Generator``): each factor uniform in
        [1 − ``spread``, 1 + ``spread``] times ``base``'s (default: nominal); the features'
        friction by ``features`` (:data:`FEATURE_DRAWS`); with ``shift`` [m] the start moved
        uniformly in a square of that half-side (x, z: y is the pads' axis), with ``turn`` [rad]
        turned uniformly in ±``turn``. Draws in that order, so a seed gives the same world."""
        if features not in FEATURE_DRAWS:
            raise ArgumentError(f"invalid `features`: one of {', '.join(FEATURE_DRAWS)} (got {features!r:.60})", "features")
        if isinstance(spread, bool) or not isinstance(spread, (int, float)) or not 0 <= spread < 1:
            raise ArgumentError(f"invalid `spread`: a relative spread in [0, 1) (got {spread!r:.60})", "spread")
        b = base or cls()
        u = rng.uniform(1 - spread, 1 + spread, 4 if features == "drawn" else 3)
        feature = {"nominal": b.feature_friction, "drawn": b.feature_friction * float(u[-1]),
                   "finger": b.finger_friction * float(u[0])}[features]
        s, t = np.zeros(3), 0.0
        if shift is not None:
            xz = rng.uniform(-shift, shift, 2)
            s = np.array([xz[0], 0.0, xz[1]])
        if turn is not None:
            t = float(rng.uniform(-turn, turn))
        return cls(b.finger_friction * float(u[0]), b.grip * float(u[1]), b.mass * float(u[2]), feature,
                   tuple(np.asarray(b.shift) + s), b.turn + t, b.pose)


def _deprecated(old: str) -> None:
    warnings.warn(f"`{old}` is `regrasp.Perturbation` now; the old name will be removed", DeprecationWarning,
                  stacklevel=3)


class PlanarEnginePerturbation:
    """The planar engine's old type (``regrasp.mujoco.planar.Perturbation``): ``friction`` on
    fingers and, unless ``pusher_friction`` is given, features; gives a :class:`Perturbation`
    (with a DeprecationWarning)."""

    def __new__(cls, friction: float = 1.0, grip: float = 1.0, mass: float = 1.0,  # type: ignore[misc]
                pusher_friction: float | None = None) -> Perturbation:
        _deprecated("regrasp.mujoco.planar.Perturbation")
        return Perturbation(friction, grip, mass, friction if pusher_friction is None else pusher_friction)

    @staticmethod
    def draw(spread: float, rng, base: Perturbation | None = None) -> Perturbation:
        """The old draw: fingers, grip and mass drawn, the features' friction with the fingers'."""
        _deprecated("regrasp.mujoco.planar.Perturbation.draw")
        return Perturbation.draw(rng, spread, features="finger", base=base)


class ArmScales:
    """The arm's old type (``regrasp.execution.arm.Scales``): the features at their nominal
    friction unless ``feature_friction`` is given; gives a :class:`Perturbation` (with a
    DeprecationWarning)."""

    def __new__(cls, finger_friction: float = 1.0, grip: float = 1.0, mass: float = 1.0,  # type: ignore[misc]
                feature_friction: float = 1.0) -> Perturbation:
        _deprecated("regrasp.execution.arm.Scales")
        return Perturbation(finger_friction, grip, mass, feature_friction)


class HandPerturbation:
    """The dexterity hand's old type (``regrasp.dexterity.world.Perturbation``): ``shift`` [m],
    ``turn`` [rad], ``pose`` (m, unit quaternion); gives a :class:`Perturbation` (with a
    DeprecationWarning)."""

    def __new__(cls, friction: float = 1.0, grip: float = 1.0, mass: float = 1.0,  # type: ignore[misc]
                shift: tuple = (0.0, 0.0, 0.0),
                turn: float = 0.0, pose: tuple | None = None) -> Perturbation:
        _deprecated("regrasp.dexterity.world.Perturbation")
        return Perturbation(friction, grip, mass, 1.0, shift, turn, pose)

    @staticmethod
    def draw(rng, spread: float, shift: float, turn: float) -> Perturbation:
        """The old draw: fingers, grip and mass drawn, then the start's shift and turn."""
        _deprecated("regrasp.dexterity.world.Perturbation.draw")
        return Perturbation.draw(rng, spread, shift=shift, turn=turn)
