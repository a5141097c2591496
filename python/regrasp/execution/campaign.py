"""Success rates of plans executed by the arm in perturbed worlds: each bundled example planned
once (its default planner settings, seed 0), turned into a world motion in its default workcell
and into the arm's joint trajectory (IK once), then executed ``runs`` times in MuJoCo with the
finger friction, the features' friction, the grip force and the object's mass each drawn
uniformly within ±``spread`` of nominal (:class:`~regrasp.Perturbation`), each run through
:func:`~regrasp.execution.execute` and judged against the task. With
``closed_loop``, each run has the arm in the loop instead (the MPC for planar scenes,
re-planning in 3-D; :mod:`~regrasp.execution.arm_loop`). The README's table is printed by
``scripts/arm-statistics.py``."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import RegraspError
from ..scene.perturbation import Perturbation


@dataclass
class Outcome:
    """One example's runs: ``name``; ``runs`` executed; ``successes`` (within the task's
    tolerance of its goal, :func:`~regrasp.execution.execute`); per run the goal error against
    the task (``errors``, planar ``[x, z, theta]`` or 3-D ``[position, angle]``), ``max_creep`` [m];
    ``refused``: why the example could not be executed (no plan, no feature, the arm), else
    None; ``seconds`` of wall time; ``failures``: why runs stopped early (the arm refused to go
    on in a perturbed world; each counts as a failed run); ``margins``: per run the smallest
    share of the pads' friction left unused through the arm's motion in that run's world (the
    nominal trajectory's :mod:`~regrasp.execution.holding` ratio × mass / (finger friction ×
    grip); None: not tested, a 3-D scene or closed loop); ``succeeded``: per run whether it
    succeeded (the first run is the nominal world, :func:`draws`)."""
    name: str
    runs: int = 0
    successes: int = 0
    errors: list = field(default_factory=list)
    max_creep: list = field(default_factory=list)
    refused: str | None = None
    seconds: float = 0.0
    failures: list = field(default_factory=list)
    margins: list = field(default_factory=list)
    succeeded: list = field(default_factory=list)

    @property
    def rate(self) -> float:
        """Share of the runs that succeeded (nan without runs)."""
        return self.successes / self.runs if self.runs else float("nan")


def draws(runs: int, spread: float, seed: int):
    """``runs`` :class:`~regrasp.Perturbation`, each of the four factors uniform in [1 − spread,
    1 + spread] (the first run nominal)."""
    rng = np.random.default_rng(seed)
    out = [Perturbation()]
    for _ in range(runs - 1):
        out.append(Perturbation.draw(rng, spread, features="drawn"))
    return out[:runs]


def example(name: str, runs: int, spread: float, seed: int = 0, closed_loop: bool = False,
            robot: str | None = None, sensing=None, noslip: bool = True) -> Outcome:
    """The :class:`Outcome` of bundled example ``name`` (or a scene file's path, ``….toml``; see
    the module's doc); ``closed_loop``:
    each run with the arm in the loop (:func:`~regrasp.execution.arm_loop.control_arm`) instead
    of the open-loop joint trajectory; ``robot``: the robot (default: the workcell's); ``sensing``:
    what the grip loop measures (:class:`~regrasp.robot.sensing.GripSensing`; None: the gripper's
    default, :func:`~regrasp.execution.arm.grip_sensing`); ``noslip``: MuJoCo's no-slip
    post-processing (``World.noslip``)."""
    import time

    import regrasp

    from .execute import World, arm_motion_of, execute

    t0 = time.perf_counter()
    out = Outcome(name)
    scene = regrasp.load_scene(name if name.endswith(".toml") else regrasp.examples.path(name))
    if scene.task is None:
        out.refused = "no task (the object rests on a surface: nothing to regrasp)"
        return out
    try:
        plan = regrasp.plan(scene, seed=0)
        world = World(scene, rig="arm", robot=robot, grip_sensing=sensing, noslip=noslip)
        holding = None
        if not closed_loop:  # solved once, here: an arm that cannot do the plan refuses the example
            holding = arm_motion_of(world, plan).trajectory.holding
    except RegraspError as e:
        out.refused = f"{type(e).__name__}: {e}"
        out.seconds = time.perf_counter() - t0
        return out
    for scales in draws(runs, spread, seed):
        try:
            r = execute(world, plan, loop="closed" if closed_loop else "open", perturbation=scales)
        except RegraspError as e:  # the arm could not go on in this world: a failed run
            out.failures.append(f"{type(e).__name__}: {e}")
            out.runs += 1
            out.succeeded.append(False)
            continue
        out.runs += 1
        out.successes += int(r.success)
        out.succeeded.append(bool(r.success))
        worst = None if holding is None else 1 - (1 - holding.smallest) * scales.mass / (scales.finger_friction * scales.grip)
        out.margins.append(worst)
        e = r.goal_error  # against the task; 3-D as [position, angle]
        out.errors.append([float(x) for x in (e if scene.dimension == 2 else (np.linalg.norm(e[:3]), e[3]))])
        out.max_creep.append(float("nan") if r.max_creep is None else r.max_creep)
    out.seconds = time.perf_counter() - t0
    return out
