"""The motion-cone batches (regrasp against the numpy reference of the same equations)."""

from __future__ import annotations

import numpy as np

from ..reference import cones as reference
from ..scene.planar import Scene
from .timing import _median_cpu, _median_time


def _cone_batch(scene: Scene, pusher: str, params, poses, batch, reps: int, baseline_reps: int) -> dict:
    """One batch of n cones: Rust (threads) against a per-cone numpy loop and vectorized numpy."""
    n = len(poses)
    loop = np.array([reference.generators_numpy(params, q) for q in poses[: min(n, 2000)]])
    vec = reference.generators_numpy_batch(params, poses)
    diff = max(np.abs(batch.generators[: len(loop)] - loop).max(), np.abs(batch.generators - vec).max())
    t_rust = _median_time(lambda: scene.motion_cones(poses, pusher), reps)
    t_loop = _median_time(lambda: [reference.generators_numpy(params, q) for q in poses], baseline_reps)
    t_vec = _median_time(lambda: reference.generators_numpy_batch(params, poses), reps)
    # CPU time too: the batch spreads over threads, so its wall time flatters it on several cores
    c_rust = _median_cpu(lambda: scene.motion_cones(poses, pusher), reps)
    c_vec = _median_cpu(lambda: reference.generators_numpy_batch(params, poses), reps)
    return {
        f"cone_batch_{n}": {
            "median_s": t_rust,
            "baseline_median_s": t_loop,
            "ratio": t_loop / t_rust,
            "baseline": "numpy, one cone per call (thesis equations)",
            "n": n,
            "max_abs_diff": float(diff),
        },
        f"cone_batch_{n}_vs_vectorized_numpy": {
            "median_s": t_rust,
            "baseline_median_s": t_vec,
            "ratio": t_vec / t_rust,
            "baseline": f"numpy, vectorized over poses (einsum); in CPU time {c_vec / c_rust:.1f}x",
            "n": n,
            "cpu_median_s": c_rust, "baseline_cpu_median_s": c_vec, "cpu_ratio": c_vec / c_rust,
            "max_abs_diff": float(np.abs(batch.generators - vec).max()),
        },
    }


def _membership(params, poses, twists, batch, reps: int) -> dict:
    """Exact membership of n twists (one per pose)."""
    n = len(poses)
    got = batch.contains(twists)
    ref = reference.classify_numpy_batch(params, poses, twists)
    t_rust = _median_time(lambda: batch.contains(twists), reps)
    t_vec = _median_time(lambda: reference.classify_numpy_batch(params, poses, twists), reps)
    return {f"membership_batch_{n}": {
        "median_s": t_rust,
        "baseline_median_s": t_vec,
        "ratio": t_vec / t_rust,
        "baseline": "numpy, vectorized over poses",
        "n": n,
        "disagreements": int((got != ref).sum()),
    }}


def _single_cone(scene: Scene, pusher: str, params, q0, reps: int, m: int = 2000) -> dict:
    """One cone from Python, call by call."""
    t_one = _median_time(lambda: [scene.motion_cone(q0, pusher).generators for _ in range(m)], reps) / m
    t_np = _median_time(lambda: [reference.generators_numpy(params, q0) for _ in range(m)], reps) / m
    return {"cone_single_call": {
        "median_s": t_one,
        "baseline_median_s": t_np,
        "ratio": t_np / t_one,
        "baseline": "numpy, one cone per call",
        "n": 1,
    }}


def _projection(scene: Scene, pusher: str, poses, twists, reps: int) -> dict:
    """Projection onto the exact cone (no numpy baseline: against the polyhedral projection
    called one by one)."""
    k = min(len(poses), 20_000)
    sub = scene.motion_cones(poses[:k], pusher)
    t_proj = _median_time(lambda: sub.project(twists[:k]), reps)
    t_poly = _median_time(
        lambda: [scene.motion_cone(q, pusher).project_polyhedral(t) for q, t in zip(poses[:500], twists[:500])], 1
    ) * (k / 500)
    return {f"project_exact_batch_{k}": {
        "median_s": t_proj,
        "baseline_median_s": t_poly,
        "ratio": t_poly / t_proj,
        "baseline": "polyhedral projection (NNLS) called one by one from Python",
        "n": k,
    }}
