"""`regrasp bench` and `regrasp demo`."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from .. import examples
from ..scene.planar import Scene
from ..files import Outputs, check_writable
from . import (CANNOT, MAX_CONES, OK, add_command, check_count, given, planner_default, plural, pusher_runs, rounded, refuse_flags,
               seed_arg)

def cmd_bench(a) -> int:
    from .. import bench

    check_count(a, "n", 1, MAX_CONES)
    refuse_flags(a, ("verbose",), "with bench", "it reads no scene files whose notes it could print")
    if a.quick:
        refuse_flags(a, ("n",), "with --quick", f"--quick measures {bench.QUICK['n']:,} cones; give one of them")
    res = bench.run(**(bench.QUICK if a.quick else given(a, "n")))
    print(json.dumps(res, allow_nan=False) if a.json else bench.format_results(res))
    return OK


def cmd_demo(a) -> int:
    from ..planning.plan import plan
    from ..sim.quasistatic import replay_plan
    from ..extras import have

    out = Path(a.out)
    check_writable(out / "t-shape-plan.json", "--out", create_folder=True)
    path = examples.path("t-shape")
    scene = Scene.load(path)
    t = scene.task
    print(f"demo: regrasp of the T-shaped object ({path.name}) from {t.start.tolist()} to {t.goal.tolist()}")
    p = plan(scene, **given(a, "seed"))
    print(f"  {'plan found' if p.found else 'NO plan found'} in {1e3 * p.planning_time_s:.2f} ms: {plural(len(p.poses) - 1, 'step')}, "
          f"{plural(p.switch_overs, 'switch-over')} ({pusher_runs(p.pushers)})")
    print(f"  every step sticks along its length by the exact motion-cone test: {p.valid}")
    # the motion cones the first push relies on, and the plan replayed in the quasi-static simulator
    first = p.pushers[1] if len(p.pushers) > 1 else scene.pusher_names[0]
    rep = replay_plan(scene, p)
    print(f"  replayed in the quasi-static simulator: final pose {rounded(rep.final_pose, 4)} (m, m, rad), "
          f"error {rounded(1e3 * rep.goal_error[:2], 2)} mm / {round(float(np.degrees(rep.goal_error[2])), 2) + 0.0:.2f} deg, "
          f"{'within' if rep.success else 'outside'} the tolerance")
    out.mkdir(parents=True, exist_ok=True)
    figures = have("matplotlib")
    with Outputs() as outs:  # all or none
        outs.write(out / "t-shape-plan.json", lambda tmp: p.save(tmp))
        if figures:
            _demo_figures(outs, out, scene, p, rep, first)
    print(f"wrote {out}/t-shape-plan.json" + (f", t-shape-plan.png, t-shape-plan.gif, t-shape-replay.png, cone-{first}.png"
                                              if figures else ""))
    if not figures:
        print("figures skipped: pip install 'regrasp[plot]'")
    return OK if p.found else CANNOT


def _demo_figures(outs, out: Path, scene, p, rep, first: str) -> None:
    """The demo's figures and animation (matplotlib), staged in ``outs``."""
    from ..viz.plotting import animate_plan, plot_motion_cone, plot_plan, plot_replay

    start = scene.task.start
    outs.write(out / "t-shape-plan.png", lambda tmp: plot_plan(scene, p, tmp))
    outs.write(out / "t-shape-plan.gif", lambda tmp: animate_plan(scene, p, tmp))
    outs.write(out / f"cone-{first}.png", lambda tmp: plot_motion_cone(scene.motion_cone(start, first), tmp))
    outs.write(out / "t-shape-replay.png", lambda tmp: plot_replay(scene, rep, tmp))


def add_parsers(sub) -> None:
    from .. import bench

    b = add_command(sub, "bench", "speed probe against numpy baselines", "regrasp bench --quick", cmd_bench)
    b.add_argument("--json", action="store_true", help="print the results as JSON")
    b.add_argument("--quick", action="store_true", help=f"{bench.QUICK['n']:,} cones instead of -n, fewer repetitions "
                   f"({bench.QUICK['reps']} instead of {bench.REPS})")
    b.add_argument("-n", type=int, help=f"cones per batch, 1 to {MAX_CONES} (default: {bench.CONES:,})")

    d = add_command(sub, "demo", "the bundled example end to end, writing its figures", "regrasp demo --out out/demo",
                    cmd_demo)
    d.add_argument("--out", default="out/demo", help="directory for the files (created)")
    d.add_argument("--seed", type=seed_arg, help=f"the planner's seed ({planner_default('seed')})")
