"""One trial of a regrasp action: the world built at the grasp (:class:`~.world.HandWorld`, in a
perturbed world), the arm run along the action's path under its grip schedule, and the outcome
classified to the nearest grasp of the taxonomy — ``dropped`` when the pads no longer hold the
object, ``other`` when it is held but farther than the classification tolerance from every
grasp (:data:`TOLERANCE` of the object's size), ``unstable`` when MuJoCo's integration blew up
(it then resets the state: nothing after it is the action's doing; a failed run), ``refused``
when the action could not be set up in that world (e.g. a perturbed grip force beyond the
gripper's range; a failed run)."""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Optional

import numpy as np

from .world import HandWorld, Perturbation, solve_path

DROPPED, OTHER, UNSTABLE, REFUSED = "dropped", "other", "unstable", "refused"
TOLERANCE = 0.15  # the classification tolerance: this share of the object's size (its hull's largest extent) [m/m]


@dataclass(frozen=True)
class TrialResult:
    """``outcome``: the grasp reached (a taxonomy name, :data:`DROPPED` or :data:`OTHER`);
    ``distance`` [m] to the nearest grasp (nan when dropped); ``pose`` the object's in-hand
    pose at the end (None when dropped); ``seconds`` of wall time."""

    outcome: str
    distance: float
    pose: Optional[np.ndarray]
    seconds: float

    def to_dict(self) -> dict:
        """The trial as JSON."""
        return {"outcome": self.outcome, "distance": None if not np.isfinite(self.distance) else float(self.distance),
                "pose": None if self.pose is None else [float(x) for x in self.pose], "seconds": float(self.seconds)}


def tolerance(taxonomy) -> float:
    """The classification tolerance [m] of ``taxonomy``'s object."""
    v = np.asarray(taxonomy.vertices, float)
    return TOLERANCE * float(np.max(np.ptp(v, axis=0)))


def classify(world: HandWorld, taxonomy) -> tuple:
    """(outcome, distance [m], in-hand pose or None) of ``world`` now."""
    if world.unstable():
        return UNSTABLE, float("nan"), None
    if not world.held():
        return DROPPED, float("nan"), None
    pose = world.in_hand()
    name, dist = taxonomy.nearest(pose)
    return (name if dist <= tolerance(taxonomy) else OTHER), float(dist), pose


class Runner:
    """Runs trials of one action's :class:`~.actions.Setup` on one grasp of ``scene``: the arm's
    joint path is solved once (IK in the nominal world) and reused by every trial."""

    def __init__(self, scene, taxonomy, grasp, setup, robot: str | None = None):
        self.scene, self.taxonomy, self.grasp, self.setup, self.robot = scene, taxonomy, grasp, setup, robot
        self._world: Optional[HandWorld] = None
        self.q: Optional[np.ndarray] = None

    def world(self, perturbation: Perturbation = Perturbation()) -> HandWorld:
        """The world of a trial, at the action's start: compiled and the arm's path solved (IK)
        on first use, reset after."""
        if self._world is None:
            self._world = HandWorld(self.scene, self.grasp.pose, self.setup.start, perturbation, self.robot)
            self.q = solve_path(self._world.robot, self.setup.path, self._world.robot.q)
            return self._world
        return self._world.reset(perturbation)

    def run(self, perturbation: Perturbation = Perturbation(), observe=None) -> TrialResult:
        """One trial in the world ``perturbation`` (``observe(world)``: called every control period)."""
        t0 = time.perf_counter()
        w = self.world(perturbation)
        w.follow(self.setup.path, self.q, self.setup.grip, self.setup.settle, observe)
        outcome, dist, pose = classify(w, self.taxonomy)
        return TrialResult(outcome, dist, pose, time.perf_counter() - t0)
