"""Timing helpers of the speed probe: medians of wall times, random admissible poses, a planner run's first-solution time."""

from __future__ import annotations

import time

import numpy as np

from ..scene.planar import Scene


def _median_time(fn, reps: int) -> float:
    ts = []
    for _ in range(reps):
        t0 = time.perf_counter()
        fn()
        ts.append(time.perf_counter() - t0)
    return float(np.median(ts))


def _median_cpu(fn, reps: int) -> float:
    """The median CPU time of ``fn()`` [s]: this process's, every thread (rayon's too) counted."""
    ts = []
    for _ in range(reps):
        t0 = time.process_time()
        fn()
        ts.append(time.process_time() - t0)
    return float(np.median(ts))


def _random_poses(scene: Scene, n: int, rng) -> np.ndarray:
    out = np.empty((0, 3))
    while len(out) < n:
        q = np.column_stack(
            [rng.uniform(-0.02, 0.02, 2 * n), rng.uniform(-0.035, 0.035, 2 * n), rng.uniform(-0.6, 0.6, 2 * n)]
        )
        out = np.vstack([out, q[scene.admissible(q)]])
    return out[:n]


def first_time(r) -> float:
    """The time to the first plan [s] (before the anytime refinement), else the planning time."""
    return r.first_time_s if r.first_time_s is not None else r.planning_time_s
