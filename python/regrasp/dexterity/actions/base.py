"""What every regrasp action shares (thesis §1.1.1): the object's model (:class:`ObjectModel`),
an action's ready-to-run :class:`Setup`, the :class:`Action` base class, the parameters'
:data:`DEFAULTS` and their checking, and the grip ramp :data:`RAMP`. The actions themselves are
in the family modules: :mod:`.gravity`, :mod:`.inertia`, :mod:`.table`, :mod:`.post`,
:mod:`.repick`; their registry in :mod:`.registry`."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable, Optional

import numpy as np

from ...errors import ArgumentError
from ..world import HandPath


G = 9.81  # m/s², the default gravity's norm (a scene's own is used: ObjectModel.g)
RAMP = 0.05  # s, a grip change is ramped over this long (the linkage follows; a step springs the pads off)
DEFAULTS = {
    "overdrive": 1.4,   # gravity-pivot: the gravity moment at the start over the pads' torsion capacity at the lowered grip
    "max_tilt": 0.5236,  # rad, gravity-pivot: the centre of mass at most this far from hanging at the start (30°: the hand turns the rest, the swing stays short; 150° overswung the bar 3 times in 4, docs)
    "pivot_time": 0.8,  # s, gravity-pivot: how long the grip stays low
    "slide_ratio": 0.8,  # gravity-slide: 2 μ N / m g while sliding (the object accelerates at (1 − ratio) g)
    "lag": 0.5236,      # rad, grip-pivot: the angle from the vertical at which the object lags the turning hand (30°)
    "turn_time": 1.2,   # s, grip-pivot and table-pivot: how long the hand turns
    "acceleration": 30.0,  # m/s², inertial-slide: the hand's downward jab (more than g: the object rises in the hand)
    "braking": 15.0,    # m/s², inertial-slide: the hand's stop after the jab, the grip firm again
    "jab_hold": 1.3,    # inertial-slide: 2 μ N / m g during the jab (holds the weight, lets the jab slide it)
    "press_hold": 1.5,  # push-down and table-pivot: 2 μ N / m g while the table pushes
    "approach": 0.02,   # m, push-down and table-pivot: the object's lowest point above the table at the start
    "speed": 0.03,      # m/s, push-down: the hand's descent; table-slide: its rise
    "rest_ratio": 0.5,  # table-slide: 2 μ N / m g while the object stands on the table (0.9 at +20 % friction and grip, −20 % mass: the table keeps part of the weight)
    "drop": 0.002,      # m, place-repick: the object's face above the table when the fingers open
    "clear": 0.06,      # m, place-repick: the hand's retreat and approach along its fingers
    "close_time": 1.0,  # s, place-repick: the fingers close on the object on the table this long before the lift
    "plan_iterations": 20,  # post-push: the motion-cone planner's iterations per grip tried (seed 0: the same plan on every machine; a push it finds, it finds at once)
    "push_speed": 0.01,  # m/s, post-push: the hand's speed along the plan (quasi-static: at 3 cm/s the pads chatter off a box)
    "toss": 12.0,       # m/s², toss-catch: the hand's upward acceleration, fingers up, the grip firm
    "toss_stop": 30.0,  # m/s², toss-catch: the hand's stop (more than g: the object flies on, free, while the fingers are open)
}


@dataclass(frozen=True)
class ObjectModel:
    """What the actions need of an object: its ``scene`` (a :class:`regrasp.Scene3D`), the
    grasp ``taxonomy`` (:class:`~regrasp.dexterity.taxonomy.Taxonomy`), ``mass`` [kg],
    ``inertia`` (3, 3) [kg·m²] about the centre of mass (object frame), ``com`` (3,) [m], the
    pads' friction ``mu``, the scene's grip force ``grip`` [N] per pad and gravity ``g`` [m/s²]."""

    scene: object
    taxonomy: object
    mass: float
    inertia: np.ndarray
    com: np.ndarray
    mu: float
    grip: float
    g: float

    @classmethod
    def of(cls, scene, taxonomy) -> "ObjectModel":
        """The model of ``scene``'s object (a :class:`regrasp.Scene3D`) with its ``taxonomy``."""
        return cls(scene, taxonomy, float(scene.mass), np.asarray(scene.inertia, float), scene.com,
                   float(scene.pad_friction), float(scene.grip_force),
                   float(np.linalg.norm(scene.gravity)))

    @property
    def weight(self) -> float:
        """m g [N]."""
        return self.mass * self.g

    def holding(self, ratio: float) -> float:
        """The per-pad force [N] at which the pads' force capacity 2 μ N is ``ratio`` times the weight."""
        return ratio * self.weight / (2 * self.mu)


@dataclass(frozen=True)
class Setup:
    """An action on a grasp, ready to run: the hand's world ``start`` pose, its ``path`` (from
    ``start``), the ``grip`` schedule (:mod:`~regrasp.dexterity.world`), ``settle`` [s] after the
    path, the ``predicted`` in-hand pose at the end (None: the object is predicted to drop), the
    ``intended`` grasp's name, and the model's ``detail`` (for the record)."""

    start: np.ndarray
    path: HandPath
    grip: Callable[[float], Optional[float]]
    settle: float
    predicted: Optional[np.ndarray]
    intended: Optional[str]
    detail: dict = field(default_factory=dict)


@dataclass(frozen=True)
class Action:
    """A regrasp action: ``name``, the ``resource`` it uses (``gravity``, ``inertia``,
    ``contact``), a one-line ``summary``; :meth:`applies` and :meth:`setup` per action."""

    name: str
    resource: str
    summary: str

    def applies(self, obj: ObjectModel, grasp) -> Optional[str]:
        """None when the action applies to ``grasp``, else why not."""
        raise NotImplementedError

    def setup(self, obj: ObjectModel, grasp, params: dict | None = None) -> Setup:
        """The :class:`Setup` of the action on ``grasp`` (``params``: overrides of :data:`DEFAULTS`)."""
        raise NotImplementedError

    def to_dict(self) -> dict:
        """The action's name, resource and summary (for the graph file)."""
        return {"name": self.name, "resource": self.resource, "summary": self.summary}


WHOLE = ("plan_iterations",)  # the DEFAULTS that count something


def _params(params: dict | None) -> dict:
    p = dict(DEFAULTS)
    for k, v in (params or {}).items():
        if k == "target":
            p[k] = v
            continue
        if k not in DEFAULTS:
            raise ArgumentError(f"invalid `params.{k}`: unknown parameter (known: {', '.join(DEFAULTS)})", f"params.{k}")
        if isinstance(v, bool) or not (isinstance(v, (int, float)) and np.isfinite(v) and v > 0):
            raise ArgumentError(f"invalid `params.{k}`: a number > 0 (got {v!r})", f"params.{k}")
        if k in WHOLE and v != int(v):
            raise ArgumentError(f"invalid `params.{k}`: a whole number ≥ 1 (got {v!r})", f"params.{k}")
        p[k] = float(v)
    return p
