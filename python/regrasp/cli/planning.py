"""`regrasp plan`: a regrasp plan for a planar or a 3-D scene."""

from __future__ import annotations

import json
import sys

from ..errors import ArgumentError
from ..planning.plan import POSE_SIZE, Plan, same_file, plan
from ..scene import load_scene
from . import CANNOT, OK, floats, mode_scene, planner_default, pusher_runs, reject_flags, seed_arg

PLANAR_ONLY = ("robust", "fixtureless", "uncertainty", "propagation", "plot", "animate")


def _scene_for(a):
    """The scene to plan on: a 3-D scene as it is (no planar-only flags), a planar one in the
    cone mode of the flags."""
    scene = load_scene(a.scene)
    if scene.dimension == 3:
        reject_flags(a, PLANAR_ONLY, "it plans with the inverse dynamics only; use --html for a view")
        return scene
    if a.html:
        raise ArgumentError("invalid `--html`: 3-D scenes only (planar: --plot, --animate)", "--html")
    return mode_scene(scene, a)


def _endpoints(scene, a):
    """--start and --goal (None: the scene's task)."""
    n = POSE_SIZE[scene.dimension]
    start = None if a.start is None else floats(a.start, n, "--start")
    goal = None if a.goal is None else floats(a.goal, n, "--goal")
    if scene.task is None and (start is None or goal is None):
        raise ArgumentError("invalid `scene`: it has no [task]; give --start and --goal", "task")
    return start, goal


def _figures(scene, p: Plan, a) -> None:
    """--plot, --animate (planar) and --html (3-D)."""
    if a.plot:
        from ..viz.plotting import plot_plan

        plot_plan(scene, p, a.plot)
    if a.animate:
        from ..viz.plotting import animate_plan

        animate_plan(scene, p, a.animate)
    if a.html:
        from ..viz.viewer import write_html

        write_html(scene, p, a.html)


def summary(scene, p: Plan) -> str:
    """What `regrasp plan` prints without --json."""
    head = "plan found" if p.found else f"no plan found ({p.stop_reason}); best partial plan"
    solves = f", {p.solves} inverse/forward solves" if p.dimension == 3 else ""
    lines = [f"{scene.name}: {head}: {len(p.poses) - 1} steps, {p.switch_overs} switch-overs, {p.nodes} nodes{solves}, "
             f"{1e3 * p.planning_time_s:.2f} ms ({p.propagation}, seed {p.seed})",
             "  pushes: " + pusher_runs(p.pushers)]
    if p.dimension == 2:
        lines.append(f"  every step sticks along its length (exact test): {p.valid} (smallest margin "
                     f"{min(p.step_margins, default=0):.3f})")
    else:
        lines.append(f"  every step passes the step check (inverse or forward dynamics): {p.valid}")
    if not p.found:
        lines.append(f"  the best partial plan ends {1e3 * p.goal_distance:.2f} mm (metric) from the goal")
    return "\n".join(lines)


def cmd_plan(a) -> int:
    scene = _scene_for(a)
    if a.out and same_file(a.out, a.scene):
        raise ArgumentError(f"invalid `--out`: {a.out} is the scene file", "--out")
    start, goal = _endpoints(scene, a)
    settings = {k: v for k, v in (("seed", a.seed), ("time_limit", a.time_limit), ("propagation", a.propagation))
                if v is not None}
    p = plan(scene, start, goal, **settings)
    if a.out:
        p.save(a.out)
    _figures(scene, p, a)
    print(json.dumps(p.to_json()) if a.json else summary(scene, p))
    if not p.found:
        print(f"regrasp: no plan found: {p.stop_reason}", file=sys.stderr)
        return CANNOT
    return OK


def add_parsers(sub) -> None:
    pl = sub.add_parser("plan", help="plan a regrasp (T-RRT* with motion-cone propagation)")
    pl.add_argument("scene")
    pl.add_argument("--out", metavar="PLAN.json")
    pl.add_argument("--seed", type=seed_arg, help=f"random seed, a whole number >= 0 ({planner_default('seed')})")
    pl.add_argument("--time-limit", type=float, help=f"planning budget [s] ({planner_default('time_limit')})")
    pl.add_argument("--propagation", choices=["motion_cone", "stable_check", "mncp"],
                    help=f"planar only: how steps are made ({planner_default('propagation')})")
    pl.add_argument("--start", help="x,z,theta; 3-D: x,y,z,qw,qx,qy,qz (default: the scene's task)")
    pl.add_argument("--goal", help="x,z,theta; 3-D: x,y,z,qw,qx,qy,qz (default: the scene's task)")
    pl.add_argument("--plot", metavar="PNG")
    pl.add_argument("--animate", metavar="GIF")
    pl.add_argument("--json", action="store_true")
    pl.add_argument("--robust", action="store_true",
                    help="plan with robust motion cones for the scene's [uncertainty] (or --uncertainty)")
    pl.add_argument("--uncertainty", metavar="P,F,N,M",
                    help="relative spreads of pusher friction, finger friction, grip force, mass (implies --robust)")
    pl.add_argument("--fixtureless", action="store_true",
                    help="plan only with fixtureless-fixturing pushes (invariant to mass, grip force, finger friction)")
    pl.add_argument("--html", metavar="HTML", help="3-D scenes: an interactive 3-D view of the plan (self-contained page)")
    pl.set_defaults(fn=cmd_plan)
