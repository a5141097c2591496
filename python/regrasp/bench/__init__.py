"""End-to-end speed probe (``regrasp bench``): the Rust core through the Python API against
plain numpy implementations of the same equations, measured in the same run.

Each entry reports the median wall time of the regrasp call, the median of the baseline and
their ratio (baseline / regrasp), plus the largest difference between the two answers.
"""

from __future__ import annotations

import numpy as np

from .. import progress
from .. import examples as bundled
from ..errors import MissingExtraError
from ..reference import cones as reference
from ..scene.planar import Scene
from .cones import _cone_batch, _membership, _projection, _single_cone
from .planners import run_hard_plans, run_limit_surface, run_node_cost, run_plan3d, run_planner
from .solvers import run_mncp, run_mncp_scaling, run_mpc, run_mpc_horizons
from .startup import run_startup
from .timing import _random_poses
from .worlds import run_arm_steps, run_grasp_graph, run_ik, run_mujoco, run_plan_only, run_world_motion

#: cones per batch, repetitions of the timed regrasp calls and of the slow baselines (``regrasp bench``)
CONES, REPS, BASELINE_REPS = 100_000, 11, 3


#: the settings of :func:`run` for a quick look (``regrasp bench --quick``)
QUICK = {"n": 10_000, "reps": 5, "baseline_reps": 1}


def run(n: int = CONES, reps: int = REPS, baseline_reps: int = BASELINE_REPS, scene_path=None,
        pusher: str = "left") -> dict:
    """Every measurement (see the module notes): the cone batches on ``n`` random poses of the
    scene (default: the low-friction block), then the solver, planner, MuJoCo and MPC probes.
    A baseline that was skipped (its extra not installed) has None as its time and ratio."""
    # on the ellipsoidal limit surface: the numpy baselines implement that model
    scene = Scene.load(scene_path or bundled.path("block-low-friction")).with_limit_surface("ellipsoid")
    rng = np.random.default_rng(0)
    poses = _random_poses(scene, n, rng)
    params = reference.RefParams.from_scene(scene, pusher)
    twists = rng.normal(size=(n, 3)) * np.array([1.0, 1.0, 1.0 / scene.length])
    batch = scene.motion_cones(poses, pusher)
    benchmarks = [
        ("cone batch", lambda: _cone_batch(scene, pusher, params, poses, batch, reps, baseline_reps)),
        ("membership", lambda: _membership(params, poses, twists, batch, reps)),
        ("single cone", lambda: _single_cone(scene, pusher, params, poses[0], reps)),
        ("projection", lambda: _projection(scene, pusher, poses, twists, reps)),
        ("MNCP solver", lambda: _unless_missing("the MNCP solver against IPOPT", lambda: run_mncp(reps=reps))),
        ("MNCP scaling", lambda: _unless_missing("the MNCP solver's scaling against IPOPT", run_mncp_scaling)),
        ("planner", run_planner),
        ("planner per node", lambda: _unless_missing("the planner's cost per node against OMPL", run_node_cost)),
        ("hard plans", run_hard_plans),
        ("limit surfaces", run_limit_surface),
        ("MuJoCo", lambda: _unless_missing("MuJoCo's speed", run_mujoco)),
        ("MPC", lambda: _unless_missing("the MPC step against SciPy", run_mpc)),
        ("MPC horizons", lambda: run_mpc_horizons(max(3, reps))),
        ("3-D planner", run_plan3d),
        ("world motion", run_world_motion),
        ("arm IK", lambda: _unless_missing("the arm's inverse kinematics", run_ik)),
        ("arm steps", lambda: _unless_missing("MuJoCo's speed with the arm", run_arm_steps)),
        ("plan only", lambda: _unless_missing("the trajectory without simulating (the arm)", run_plan_only)),
        ("grasp graph", lambda: _unless_missing("the grasp graph (MuJoCo, the arm)", run_grasp_graph)),
        ("CLI start", lambda: run_startup(reps)),
    ]
    results = {}
    with progress.bar(len(benchmarks), "bench", unit="benchmark") as bar:
        for name, measure in benchmarks:
            bar.set_postfix_str(name)
            results.update(measure())
            bar.update(1)
    return results


def _unless_missing(what: str, probe) -> dict:
    """``probe()``, or nothing when it needs an optional dependency that is not installed (said
    on stderr, with the extra that brings it)."""
    try:
        return probe()
    except MissingExtraError as e:
        progress.note(f"bench: {what} skipped: it needs {e.what} (pip install 'regrasp[{e.extra}]')")
        return {}


def format_results(res: dict) -> str:
    """The benchmark results of :func:`run` as a table: one row per benchmark, with regrasp's time,
    the baseline's and their ratio (``-`` for a skipped baseline, or a row without one)."""
    lines = [f"{'benchmark':42s} {'regrasp':>12s} {'baseline':>12s} {'ratio':>9s}  baseline"]
    for name, r in res.items():
        base, ratio = r["baseline_median_s"], r["ratio"]
        base_text = f"{'-':>12s}" if base is None else f"{base * 1e3:10.3f}ms"
        ratio_text = f"{'-':>9s}" if ratio is None else f"{ratio:8.1f}x"
        lines.append(f"{name:42s} {r['median_s'] * 1e3:10.3f}ms {base_text} {ratio_text}  {r['baseline']}")
    return "\n".join(lines)
