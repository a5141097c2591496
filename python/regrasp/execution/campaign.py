"""Success rates of plans executed by the arm in perturbed worlds: each bundled example planned
once (its default planner settings, seed 0), turned into a world motion in its default workcell
and into the arm's joint trajectory (IK once), then executed ``runs`` times in MuJoCo with the
finger friction, the features' friction, the grip force and the object's mass each drawn
uniformly within ±``spread`` of nominal (:class:`~regrasp.execution.arm.Scales`). The README's
table is printed by ``scripts/arm-statistics.py``."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import RegraspError


@dataclass
class Outcome:
    """One example's runs: ``name``; ``runs`` executed; ``successes``; per run the goal error
    (``errors``, planar ``[x, z, theta]`` or 3-D ``[position, angle]``), ``max_creep`` [m];
    ``refused``: why the example could not be executed (no plan, no feature, the arm), else
    None; ``seconds`` of wall time."""
    name: str
    runs: int = 0
    successes: int = 0
    errors: list = field(default_factory=list)
    max_creep: list = field(default_factory=list)
    refused: str | None = None
    seconds: float = 0.0

    @property
    def rate(self) -> float:
        """Share of the runs that succeeded (nan without runs)."""
        return self.successes / self.runs if self.runs else float("nan")


def draws(runs: int, spread: float, seed: int):
    """``runs`` :class:`~regrasp.execution.arm.Scales`, each factor uniform in [1 − spread,
    1 + spread] (the first run nominal)."""
    from .arm import Scales

    rng = np.random.default_rng(seed)
    out = [Scales()]
    for _ in range(runs - 1):
        f = rng.uniform(1 - spread, 1 + spread, 4)
        out.append(Scales(*map(float, f)))
    return out[:runs]


def example(name: str, runs: int, spread: float, seed: int = 0) -> Outcome:
    """The :class:`Outcome` of bundled example ``name`` (see the module's doc)."""
    import time

    import regrasp

    from . import world_motion
    from .arm import build_robot, execute_arm, solve_arm

    t0 = time.perf_counter()
    out = Outcome(name)
    scene = regrasp.load_scene(regrasp.examples.path(name))
    try:
        plan = regrasp.plan(scene, seed=0)
        motion = world_motion(scene, plan)
        robot, _, _, tcp = build_robot(scene, motion)
        trajectory = solve_arm(robot, motion, tcp)
    except RegraspError as e:
        out.refused = f"{type(e).__name__}: {e}"
        out.seconds = time.perf_counter() - t0
        return out
    for scales in draws(runs, spread, seed):
        r = execute_arm(scene, plan, motion, scales=scales, trajectory=trajectory)
        out.runs += 1
        out.successes += int(r.success)
        out.errors.append([float(x) for x in r.goal_error])
        out.max_creep.append(r.max_creep)
    out.seconds = time.perf_counter() - t0
    return out
