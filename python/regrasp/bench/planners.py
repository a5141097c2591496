"""The planners: planar and 3-D plans of the bundled examples, the limit-surface models, the hard problems."""

from __future__ import annotations

import time

import numpy as np

from .. import examples as bundled
from ..extras import have, need
from ..scene.planar import Scene
from .timing import first_time


PLANNED_3D = ("offset-3d", "light-side-3d", "pivot-single-3d", "pivot-3d", "block-3d", "prism-3d", "ball-roll-3d",
              "pivot-90-3d", "offset-pivot-3d", "bracket-pivot-3d")


def run_plan3d(seeds: int = 10, examples=PLANNED_3D) -> dict:
    """3-D planning (T-RRT* over SE(3), inverse-dynamics steps): median planning time over
    ``seeds`` seeds per example, against the same search with each of its solves made by the
    IPOPT reference (the thesis' approach; estimated as solves x the median IPOPT time of the
    plan's first step solved forward, measured in the same run)."""
    from ..reference import mncp as mncp_reference
    from ..scene.spatial import Scene3D

    out = {}
    for name in examples:
        s = Scene3D.load(bundled.path(name))
        runs = [s.plan(seed=k, time_limit=60.0) for k in range(seeds)]
        t = float(np.median([first_time(r) for r in runs]))
        solves = float(np.median([r.solves for r in runs]))
        # the first step of the first plan, solved forward by IPOPT (the pusher moving with it)
        first = runs[0]
        p = s.quasistatic_problem(first.poses[0], first.pushers[1], 1.0)
        u = first.pusher_twists[1]
        times = []
        for _ in range(3 if have("casadi") else 0):  # the IPOPT baseline needs regrasp[reference]
            try:
                times.append(mncp_reference.solve(p, pusher_twist=u).solve_time_s)
            except Exception:  # noqa: BLE001 - a failed reference solve is left out
                pass
        t_ipopt = float(np.median(times)) if times else 0.0
        t_base = solves * t_ipopt if times else None  # None: skipped (valid JSON, not NaN)
        out[f"plan3d_{name}"] = {
            "median_s": t, "baseline_median_s": t_base, "ratio": None if t_base is None else t_base / max(t, 1e-9),
            "baseline": f"the same search with IPOPT solves ({solves:.0f} solves x {1e3 * t_ipopt:.1f} ms)"
                        if times else "IPOPT baseline skipped: " + ("every reference solve failed" if have("casadi")
                                                                    else "pip install 'regrasp[reference]'"),
            "found": sum(r.found for r in runs), "n": seeds, "median_solves": solves,
            "switch_overs": float(np.median([r.switch_overs for r in runs])),
        }
    return out


PLANNED = ("block-low-friction", "block-high-friction", "block-xztheta", "t-shape", "block-tilted-gripper")


def run_planner(seeds: int = 10, time_limit: float = 30.0, examples=PLANNED) -> dict:
    """The planner table (thesis Table 4.2): median planning time [s] over ``seeds`` seeds (each
    run stopped at ``time_limit`` [s]) for each
    example and each propagation, measured in the same run, with the baselines' ratios."""
    from ..planning.plan import plan

    out = {}
    for name in examples:
        scene = Scene.load(bundled.path(name))
        stats = {}
        for prop in ("motion_cone", "stable_check", "mncp"):
            runs = [plan(scene, seed=k, propagation=prop, time_limit=time_limit) for k in range(seeds)]
            stats[prop] = {
                "median_s": float(np.median([first_time(r) for r in runs])),
                "found": sum(r.found for r in runs),
                "valid": sum(r.found and r.valid for r in runs),
                "switch_overs": float(np.median([r.switch_overs for r in runs])),
                "nodes": float(np.median([r.nodes for r in runs])),
            }
        mc = stats["motion_cone"]
        for prop in ("stable_check", "mncp"):
            b = stats[prop]
            out[f"plan_{name}_vs_{prop}"] = {
                "median_s": mc["median_s"],
                "baseline_median_s": b["median_s"],
                "ratio": b["median_s"] / max(mc["median_s"], 1e-9),
                "baseline": f"same T-RRT*, {prop} propagation",
                "n": seeds,
                "found": mc["found"], "baseline_found": b["found"],
                "valid": mc["valid"], "baseline_valid": b["valid"],
                "switch_overs": mc["switch_overs"], "baseline_switch_overs": b["switch_overs"],
            }
    return out


#: the examples whose plans :func:`run_limit_surface` times on each limit surface
LIMIT_SURFACE_PLANS = PLANNED + ("hard/u-shape", "hard/point-pushers", "hard/thin-bar")


def run_limit_surface(seeds: int = 100, time_limit: float = 30.0, examples=LIMIT_SURFACE_PLANS) -> dict:
    """The planner on the exact limit surface against the ellipsoid, measured in the same run:
    per example the median time to a first plan [s] over ``seeds`` seeds on each, and their
    ratio, baseline over regrasp as everywhere in the bench (issue 17's target: above 0.5).
    The time to a first plan is heavy-tailed (t-shape: p90 1.7x the median), so the median of
    10–20 seeds moves by ±15% with the seeds drawn: hence 100 (about a minute in all)."""
    from ..planning.plan import plan

    out = {}
    for name in examples:
        scene = Scene.load(bundled.ROOT / f"{name}.toml")
        med = {}
        found = {}
        for model in ("true", "ellipsoid"):
            s = scene.with_limit_surface(model)
            runs = [plan(s, seed=k, time_limit=time_limit) for k in range(seeds)]
            med[model] = float(np.median([first_time(r) for r in runs]))
            found[model] = sum(r.found for r in runs)
        out[f"limit_surface_plan_{name.replace('/', '_')}"] = {
            "median_s": med["true"], "baseline_median_s": med["ellipsoid"],
            "ratio": med["ellipsoid"] / max(med["true"], 1e-9),
            "baseline": "the same planner on the ellipsoidal limit surface",
            "n": seeds, "found": found["true"], "baseline_found": found["ellipsoid"],
        }
    return out


#: issue 18's hard planar scenes (``regrasp/examples/hard/``, ``benches/scenes/`` in a clone)
HARD = tuple(sorted(p.stem for p in (bundled.ROOT / "hard").glob("*.toml")))


#: issue 18's targets for the hard scenes: the median and the 90th percentile of the time to a first plan [s]
HARD_TARGETS = (0.05, 0.2)


def run_hard_plans(seeds: int = 20, time_limit: float = 10.0, names=HARD) -> dict:
    """The hard planar scenes (:data:`HARD`): per scene, ``seeds`` plans (each stopped at
    ``time_limit`` [s]); the median and 90th percentile of the planning time (the time to the first
    plan, or to the answer "unreachable"), how many found a plan, how many of those pass the exact
    test along every step, how many were answered unreachable, the switch-overs (median, and the
    fewest over the seeds) of the final plans and (median) of the first ones, and the median time
    with the anytime refinement. No baseline: the targets are :data:`HARD_TARGETS`."""
    from ..planning.plan import plan

    out = {}
    for name in names:
        scene = Scene.load(bundled.ROOT / "hard" / f"{name}.toml")
        runs = [plan(scene, seed=k, time_limit=time_limit) for k in range(seeds)]
        t = np.array([first_time(r) for r in runs])
        found = [r for r in runs if r.found]
        switch = [r.switch_overs for r in found]
        first_switch = [r.first_switch_overs for r in found]
        median, p90 = float(np.median(t)), float(np.percentile(t, 90))
        refused = sum(r.stop_reason == "unreachable" for r in runs)
        out[f"hard_{name}"] = {
            "median_s": median, "p90_s": p90, "n": seeds, "found": len(found),
            "valid": sum(bool(r.valid) for r in found), "unreachable": refused,
            "switch_overs": float(np.median(switch)) if switch else None, "best_switch_overs": min(switch, default=None),
            "first_switch_overs": float(np.median(first_switch)) if first_switch else None,
            "refined_median_s": float(np.median([r.planning_time_s for r in runs])),
            "baseline_median_s": None, "ratio": None,
            "baseline": f"found {len(found)}/{seeds}, unreachable {refused}, "
                        f"p90 {p90 * 1e3:.1f} ms (targets: median < {HARD_TARGETS[0] * 1e3:.0f} ms, p90 < "
                        f"{HARD_TARGETS[1] * 1e3:.0f} ms), switch-overs {np.median(switch) if switch else '-'} "
                        f"(best {min(switch, default='-')})",
        }
    return out


#: the examples whose planar trees :func:`run_node_cost` times per node
NODE_COST_PLANS = PLANNED + ("hard/u-shape", "hard/thin-bar")


def ompl_rrtstar_cpu(nodes: int) -> tuple[float, int]:
    """(CPU time [s], nodes grown) of OMPL's RRT* growing a tree of ``nodes`` nodes in SE(2) (the
    planar pose space: ±5 cm, any turn) with a trivial validity checker (every state valid; each
    iteration adds a node), from one pose towards another it never stops at (its cost threshold
    is 0)."""
    ob, og = need("ompl.base", "bench"), need("ompl.geometric", "bench")
    space = ob.SE2StateSpace()
    bounds = ob.RealVectorBounds(2)
    bounds.setLow(-0.05)
    bounds.setHigh(0.05)
    space.setBounds(bounds)
    si = ob.SpaceInformation(space)
    si.setStateValidityChecker(ob.AllValidStateValidityChecker(si))
    si.setup()
    start, goal = space.allocState(), space.allocState()
    for state, (x, y, yaw) in ((start, (-0.02, 0.0, 0.0)), (goal, (0.02, 0.01, 0.5))):
        state.setX(x)
        state.setY(y)
        state.setYaw(yaw)
    problem = ob.ProblemDefinition(si)
    problem.setStartAndGoalStates(start, goal, 1e-9)
    planner = og.RRTstar(si)
    planner.setProblemDefinition(problem)
    planner.setup()
    done = ob.PlannerTerminationCondition(lambda: planner.numIterations() >= nodes - 1)
    t0 = time.process_time()
    planner.solve(done)
    seconds = time.process_time() - t0
    data = ob.PlannerData(si)
    planner.getPlannerData(data)
    return seconds, int(data.numVertices())


def run_node_cost(seeds: int = 10, examples=NODE_COST_PLANS) -> dict:
    """CPU time per tree node of the planar planner (T-RRT* with motion-cone steps, each checked
    exactly; the whole call from Python; ``search_per_node_s``: the core's search alone) per
    example, the median over ``seeds`` seeds, against OMPL's RRT* (:func:`ompl_rrtstar_cpu`, a
    trivial checker) grown to the same number of nodes in the same run; the ratio is OMPL's time
    per node over ours (issue 45's target: ≥ 0.5). Needs OMPL (``regrasp[bench]``)."""
    from ..planning.plan import plan

    ou = need("ompl.util", "bench")
    ou.setLogLevel(ou.LogLevel.LOG_WARN)  # no "Info:" lines per solve
    out = {}
    for name in examples:
        scene = Scene.load(bundled.ROOT / f"{name}.toml")
        ours, search, theirs, sizes = [], [], [], []
        for k in range(seeds):
            t0 = time.process_time()
            r = plan(scene, seed=k)
            ours.append((time.process_time() - t0) / max(r.nodes, 1))
            search.append(r.planning_time_s / max(r.nodes, 1))
            seconds, grown = ompl_rrtstar_cpu(max(r.nodes, 2))
            theirs.append(seconds / grown)
            sizes.append(r.nodes)
        t, t_base = float(np.median(ours)), float(np.median(theirs))
        out[f"plan_node_{name.replace('/', '_')}"] = {
            "median_s": t, "baseline_median_s": t_base, "ratio": t_base / max(t, 1e-12),
            "baseline": "OMPL's RRT* in SE(2), a trivial checker, the same number of nodes (CPU time per node)",
            "n": seeds, "median_nodes": float(np.median(sizes)),
            "search_per_node_s": float(np.median(search)),  # the core's own planning time (wall) per node
        }
    return out
