"""`regrasp plan`: a regrasp plan for a planar or a 3-D scene."""

from __future__ import annotations

import json
from pathlib import Path

from ..errors import ArgumentError
from ..files import Outputs
from .. import progress
from ..planning.plan import POSE_SIZE, Plan, plan, planner_defaults
from . import (ANIMATION_SUFFIXES, CANNOT, FIGURE_SUFFIXES, OK, add_command, add_limit_surface, add_verbose, check_number, check_outputs,
               floats, load, mode_scene, planner_default, plural, pusher_runs, refuse_flags, seed_arg)

#: the output options of `regrasp plan` and the file-name suffixes they take (None: any)
OUTPUTS = {"out": None, "partial_out": None, "plot": FIGURE_SUFFIXES, "animate": ANIMATION_SUFFIXES, "html": None}

PLANAR_ONLY = ("robust", "fixtureless", "uncertainty", "propagation")


def _scene_for(a):
    """The scene to plan on: a 3-D scene as it is (no planar-only flags), a planar one in the
    cone mode of the flags."""
    scene = load(a.scene, a)
    if scene.dimension == 3:
        refuse_flags(a, PLANAR_ONLY, "for a 3-D scene", "it plans with the inverse dynamics only, not with motion cones")
        return scene
    return mode_scene(scene, a)


def _endpoints(scene, a):
    """--start and --goal (None: the scene's task)."""
    n = POSE_SIZE[scene.dimension]
    start = None if a.start is None else floats(a.start, n, "--start")
    goal = None if a.goal is None else floats(a.goal, n, "--goal")
    if scene.task is None and (start is None or goal is None):
        raise ArgumentError("invalid `scene`: it has no [task]; give --start and --goal", "task")
    return start, goal


def _figure_writers(scene, p: Plan, a) -> list:
    """(option, path, write_fn) of --plot, --animate and --html given (planar or 3-D)."""
    from ..viz import plotting, plotting3d

    three = scene.dimension == 3
    out = []
    if a.plot:
        draw = plotting3d.plot_plan3d if three else plotting.plot_plan
        out.append(("--plot", a.plot, lambda tmp: draw(scene, p, tmp)))
    if a.animate:
        animate = plotting3d.animate_plan3d if three else plotting.animate_plan
        out.append(("--animate", a.animate, lambda tmp: animate(scene, p, tmp)))
    if a.html:
        from ..viz.viewer import write_html

        out.append(("--html", a.html, lambda tmp: write_html(scene, p, tmp)))
    return out


def _write_outputs(scene, p: Plan, a) -> list[str]:
    """Writes the outputs asked for, all or none (each atomically). A plan found: --out and the
    figures. None found: the best partial plan to --partial-out, else to --out when that file does
    not exist yet; figures only where no file exists yet (an existing output is left untouched).
    Returns what to say about the outputs: ``wrote PATH`` per file of a found plan (stdout), the
    partial plan's outputs (stderr)."""
    opt = "--partial-out" if not p.found and a.partial_out else "--out"
    plan_file = getattr(a, opt[2:].replace("-", "_"))
    writers = ([(opt, plan_file, lambda tmp: p.save(tmp))] if plan_file else []) + _figure_writers(scene, p, a)
    said = []
    with Outputs() as outs:
        for opt, path, write in writers:
            if not p.found and opt != "--partial-out" and Path(path).exists():
                said.append(f"{path} (`{opt}`) left unchanged: no plan found"
                            + ("; --partial-out PATH writes the best partial plan" if opt == "--out" else ""))
                continue
            Path(path).parent.mkdir(parents=True, exist_ok=True)
            outs.write(path, write)
            if p.found:
                said.append(f"wrote {path}")
            else:
                what = "plan" if opt in ("--out", "--partial-out") else "plan's figure"
                said.append(f"wrote the best partial {what} to {path} (`{opt}`)")
    return said


#: the warning of a planar plan found whose steps do not all pass the exact motion-cone test
SLIP_WARNING = ("warning: the plan was found by the {propagation} propagation, and some of its steps fail the exact "
                "motion-cone test (sticking along the whole step): executing it may slip (check it with "
                "`regrasp simulate`)")


def summary(scene, p: Plan) -> str:
    """What `regrasp plan` prints without --json."""
    head = "plan found" if p.found else f"no plan found ({p.stop_reason}); best partial plan"
    solves = f", {p.solves} inverse/forward solves" if p.dimension == 3 else ""
    lines = [f"{scene.name}: {head}: {plural(len(p.poses) - 1, 'step')}, {plural(p.switch_overs, 'switch-over')}, "
             f"{plural(p.nodes, 'node')}{solves}, "
             f"{1e3 * p.planning_time_s:.2f} ms ({p.propagation}, seed {p.seed})",
             "  pushes: " + pusher_runs(p.pushers)]
    if p.first_time_s is not None:
        lines.append(f"  first plan after {1e3 * p.first_time_s:.2f} ms with {plural(p.first_switch_overs, 'switch-over')}, "
                     "then refined (RRT*, setting `refine`)")
    if p.dimension == 2:
        lines.append(f"  every step sticks along its length (exact test): {p.valid} (smallest margin "
                     f"{min(p.step_margins, default=0):.3f})")
    else:
        lines.append(f"  every step passes the step check (inverse or forward dynamics): {p.valid}")
    if p.reason:
        lines.append(f"  unreachable: {p.reason}")
    elif not p.found:
        lines.append(f"  the best partial plan ends {1e3 * p.goal_distance:.2f} mm (metric) from the goal")
    return "\n".join(lines)


def cmd_plan(a) -> int:
    check_number(a, "time_limit", 0.0, what="planning budget [s]", finite=False)
    check_outputs(a, OUTPUTS, [a.scene])
    scene = _scene_for(a)
    start, goal = _endpoints(scene, a)
    settings = {k: v for k, v in (("seed", a.seed), ("time_limit", a.time_limit), ("propagation", a.propagation))
                if v is not None}
    limit = a.time_limit if a.time_limit is not None else planner_defaults(scene.dimension)["time_limit"]
    with progress.elapsed(limit, f"planning {scene.name}"):
        p = plan(scene, start, goal, **settings)
    said = _write_outputs(scene, p, a)
    print(json.dumps(p.to_json()) if a.json else summary(scene, p))
    if p.found and not a.json:
        print("\n".join(said), end="\n" if said else "")
    if p.found and p.dimension == 2 and not p.valid:
        progress.note(f"regrasp: {SLIP_WARNING.format(propagation=p.propagation)}")
    if not p.found:
        progress.note(f"regrasp: no plan found: {p.stop_reason}" + (f": {p.reason}" if p.reason else ""))
        for line in said:
            progress.note(f"regrasp: {line}")
        return CANNOT
    return OK


def add_parsers(sub) -> None:
    pl = add_command(sub, "plan", "plan a regrasp (T-RRT* with motion-cone propagation; 3-D: inverse dynamics)",
                     "regrasp plan t-shape.toml --out plan.json --plot plan.png --animate plan.gif\n"
                     "regrasp plan pivot-3d.toml --html plan.html", cmd_plan)
    pl.add_argument("scene", help="the scene file (planar or 3-D)")
    pl.add_argument("--out", metavar="PLAN.json",
                    help="write the plan file here (no plan found: the best partial plan, unless the file exists)")
    pl.add_argument("--partial-out", metavar="PLAN.json",
                    help="when no plan is found, write the best partial plan here (--out is then left alone)")
    pl.add_argument("--seed", type=seed_arg, help=f"random seed, a whole number >= 0 ({planner_default('seed')})")
    pl.add_argument("--time-limit", type=float,
                    help=f"planning budget [s], inf for none ({planner_default('time_limit')})")
    pl.add_argument("--propagation", choices=["motion_cone", "stable_check", "mncp"],
                    help=f"planar only: how steps are made ({planner_default('propagation')})")
    pl.add_argument("--start", help="x,z,theta; 3-D: x,y,z,qw,qx,qy,qz (default: the scene's task)")
    pl.add_argument("--goal", help="x,z,theta; 3-D: x,y,z,qw,qx,qy,qz (default: the scene's task)")
    pl.add_argument("--plot", metavar="PNG", help="draw the plan: object, pads and pushers at the poses "
                    "(3-D: a 3-D figure of start, goal and intermediate poses)")
    pl.add_argument("--animate", metavar="GIF", help="animate the plan (planar or 3-D)")
    pl.add_argument("--json", action="store_true", help="print the plan (the plan file's object) instead of the summary")
    pl.add_argument("--robust", action="store_true",
                    help="planar only: plan with robust motion cones for the scene's [uncertainty] (or --uncertainty)")
    pl.add_argument("--uncertainty", metavar="P,F,N,M", help="planar only: relative spreads of pusher friction, "
                    "finger friction, grip force, mass, each in [0, 1) (implies --robust)")
    pl.add_argument("--fixtureless", action="store_true", help="planar only: plan only with fixtureless-fixturing "
                    "pushes (invariant to mass, grip force, finger friction)")
    pl.add_argument("--html", metavar="HTML", help="an interactive view of the plan in the browser (self-contained page)")
    add_limit_surface(pl)
    add_verbose(pl)
