"""One trial of a regrasp action: the world built at the grasp (:class:`~.world.HandWorld`, in a
perturbed world), the arm run along the action's path under its grip schedule, and the outcome
classified to the nearest grasp of the taxonomy — ``dropped`` when the pads no longer hold the
object, ``other`` when it is held but farther than the classification tolerance from every
grasp (:data:`TOLERANCE` of the object's size), ``unstable`` when MuJoCo's integration blew up
(it then resets the state: nothing after it is the action's doing; a failed run), ``refused``
when the action could not be set up in that world (e.g. a perturbed grip force beyond the
gripper's range; a failed run). A trial may begin where another action ended: the hand moves to
the action's start (:func:`transfer`, as between two actions of a sequence) first."""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Optional

import numpy as np

from ..errors import ArgumentError
from .taxonomy import CLASSIFICATION_TOLERANCE as TOLERANCE, classification_tolerance as tolerance, grasp_distance
from ..scene.perturbation import Perturbation
from .world import HandPath, HandWorld, constant, hand_pose, solve_path

DROPPED, OTHER, UNSTABLE, REFUSED = "dropped", "other", "unstable", "refused"
TRANSFER_SPEED = 0.25  # m/s, the hand's move between two actions (and 1 rad/s turning)
TRANSFER_LIFT = 0.1  # m, a move between two actions that cannot turn the hand in place turns it this much higher
TRANSFER_SETTLE = 0.2  # s, the hand held still at the end of a move between two actions


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


def classify(world: HandWorld, taxonomy) -> tuple:
    """(outcome, distance [m], in-hand pose or None) of ``world`` now."""
    if world.unstable():
        return UNSTABLE, float("nan"), None
    if not world.held():
        return DROPPED, float("nan"), None
    pose = world.in_hand()
    name, dist = taxonomy.nearest(pose)
    return (name if dist <= tolerance(taxonomy) else OTHER), float(dist), pose


def _line(a, b) -> "HandPath":
    """The hand's move from world pose ``a`` to ``b`` at :data:`TRANSFER_SPEED` (and 1 rad/s)."""
    from ..pose import quat_angle

    return HandPath.line(a, b, max(0.5, float(np.linalg.norm(a[:3] - b[:3])) / TRANSFER_SPEED, quat_angle(a[3:], b[3:])))


def transfer(robot, here, start) -> tuple:
    """(the hand's path, the arm's joint path) between two actions, from TCP pose ``here`` to
    ``start``: straight, or else (a turn the arm cannot make in place, e.g. fingers up to
    fingers down) through the hand level :data:`TRANSFER_LIFT` above the higher end, turned one
    way or the other. An IKError (ArgumentError) when none can be followed."""
    here, start = np.asarray(here, float), np.asarray(start, float)
    ways = [None] + [hand_pose(a, ((here[0] + start[0]) / 2, (here[1] + start[1]) / 2,
                                   max(here[2], start[2]) + TRANSFER_LIFT)) for a in (np.pi / 2, -np.pi / 2)]
    error: Optional[ArgumentError] = None
    for way in ways:
        path = _line(here, start) if way is None else _line(here, way).then(_line(way, start))
        try:
            return path, solve_path(robot, path, robot.q)
        except ArgumentError as e:
            error = error or e
    raise error  # type: ignore[misc]


class Runner:
    """Runs trials of one action's :class:`~.actions.Setup` on one grasp of ``scene``: the arm's
    joint path is solved once (IK in the nominal world) and reused by every trial. With
    ``lead_in`` (a TCP pose (7,), a grip force [N]) each trial starts with the hand there (where
    the action before it ended) and moves to the action's start by :func:`transfer` at that grip."""

    def __init__(self, scene, taxonomy, grasp, setup, robot: str | None = None, lead_in: tuple | None = None,
                 action: str | None = None):
        self.scene, self.taxonomy, self.grasp, self.setup, self.robot = scene, taxonomy, grasp, setup, robot
        self.lead_in, self.action = lead_in, action
        self._world: Optional[HandWorld] = None
        self.q: Optional[np.ndarray] = None
        self.move: Optional[tuple] = None

    def world(self, perturbation: Perturbation = Perturbation()) -> HandWorld:
        """The world of a trial, at its start: compiled and the arm's paths solved (IK) on first
        use, reset after."""
        if self._world is None:
            hand = self.setup.start if self.lead_in is None else np.asarray(self.lead_in[0], float)
            w = HandWorld(self.scene, self.grasp.pose, hand, perturbation, self.robot)
            move = None if self.lead_in is None else transfer(w.robot, w.robot.tcp_pose(), self.setup.start)
            self.q = solve_path(w.robot, self.setup.path, w.robot.q if move is None else move[1][-1])
            self._world, self.move = w, move  # only once every path is solved: an IK error leaves none
            return w
        return self._world.reset(perturbation)

    def run(self, perturbation: Perturbation = Perturbation(), observe=None) -> TrialResult:
        """One trial in the world ``perturbation`` (``observe(world)``: called every control period)."""
        t0 = time.perf_counter()
        w = self.world(perturbation)
        if self.move is not None:
            w.follow(*self.move, constant(float(self.lead_in[1])), TRANSFER_SETTLE, observe)
        w.follow(self.setup.path, self.q, self.setup.grip, self.setup.settle, observe)
        outcome, dist, pose = classify(w, self.taxonomy)
        return TrialResult(outcome, dist, pose, time.perf_counter() - t0)

    def run_in(self, world, loop: str, perturbation: Perturbation, observe=None):
        """One trial run by :func:`regrasp.execution.execute` in ``world`` (the arm, open loop, the
        runner's scene and robot): an :class:`~regrasp.execution.Execution` judged against the
        action's task — its intended grasp (success: the trial reached it); without one, the
        model's predicted in-hand pose (success: held within the classification tolerance of it)
        or, predicted to drop, the drop (success: dropped; ``goal_error`` empty).
        ``goal_error`` ``[d]``: the distance [m] of the final in-hand pose from the task's pose
        (:func:`~.taxonomy.grasp_distance`); ``detail`` the :class:`TrialResult`."""
        from ..execution.execute import check_hand_world

        check_hand_world(world, loop, perturbation, "a regrasp action")
        if world.scene is not self.scene and getattr(world.scene, "name", None) != self.scene.name:
            raise ArgumentError(f"invalid `world.scene`: the runner's scene {self.scene.name!r}", "world.scene")
        if world.robot is not None and world.robot != self.robot:
            raise ArgumentError(f"invalid `world.robot`: the runner's robot {self.robot!r}", "world.robot")
        r = self.run(perturbation, observe)
        final = self._world.in_hand()
        s = self.setup
        goal = self.taxonomy.grasp(s.intended).pose if s.intended is not None else s.predicted
        err = np.zeros(0) if goal is None else np.array([grasp_distance(self.taxonomy.vertices, final, goal)])
        if s.intended is not None:
            ok = r.outcome == s.intended
        elif goal is not None:
            ok = r.outcome not in (DROPPED, UNSTABLE, REFUSED) and err[0] <= tolerance(self.taxonomy)
        else:
            ok = r.outcome == DROPPED
        step = {"action": self.action, "from": self.grasp.name, "to": s.intended, "reached": r.outcome}
        return execution(world, loop, perturbation, final, err, ok, [step], r)


def execution(world, loop, perturbation, final, err, success: bool, steps: list, detail):
    """The :class:`~regrasp.execution.Execution` of a run of regrasp actions that left the object
    at in-hand pose ``final`` (m, unit quaternion) ``err`` [m] from its task's pose, ``success``
    or not, with its per-step records ``steps`` and the runner's own ``detail``."""
    from ..execution.execute import Execution

    err = np.asarray(err, float)
    return Execution(bool(success), err, err.copy(), bool(success), np.asarray(final, float), world, loop,
                     perturbation, detail=detail, steps=steps)
