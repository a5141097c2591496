#!/usr/bin/env python3
"""Prints the README's pick-regrasp-place row of each object: ``--trials`` randomized trials
(the object's pick pose on the table: ±50 mm and ±0.3 rad about the default; the place pose
shifted by the default shift; finger and feature friction ×[1 − spread, 1 + spread]), each
planned (regrasp.execution.pick_place) and executed in MuJoCo with the arm.

    python scripts/pick-place-trials.py --trials 50 --spread 0.2 [--robot NAME] [--workers 2] [--json out.jsonl] NAME ...
"""

import argparse
import json
import sys
from concurrent.futures import ProcessPoolExecutor

import numpy as np


def draw(rng, spread: float) -> tuple:
    """One trial's random pick offset [m] (x, y), turn [rad] and friction scale."""
    xy = rng.uniform(-0.05, 0.05, 2)
    return xy, float(rng.uniform(-0.3, 0.3)), float(rng.uniform(1 - spread, 1 + spread))


def trial(name: str, robot, k: int, xy, turn: float, f: float) -> dict:
    import dataclasses

    import regrasp
    from regrasp import Perturbation
    from regrasp.errors import RegraspError
    from regrasp.execution import World, default_workcell, execute
    from regrasp.execution import pick_place as pp

    s = regrasp.load_scene(regrasp.examples.path(name))
    wc = default_workcell(s)
    if robot:
        wc = dataclasses.replace(wc, robot=dataclasses.replace(wc.robot, name=robot))
    pick = pp.table_pose(s, wc, np.array(pp.DEFAULT_PICK) + xy, 0.0, turn)
    place = np.r_[pick[0] + pp.DEFAULT_SHIFT[0], pick[1] + pp.DEFAULT_SHIFT[1], pick[2:]]
    try:
        r = pp.pick_place(s, wc, place=place, pick=pick, seed=k)
    except RegraspError as e:
        return dict(k=k, friction=f, planned=False, success=False, why=str(e)[:300])
    run = execute(World(s, rig="arm", workcell=wc), r, perturbation=Perturbation(finger_friction=f, feature_friction=f))
    x = run.detail
    return dict(k=k, friction=f, planned=True, planning_time_s=r.planning_time, switch_overs=r.switch_overs,
                success=bool(run.success), held=bool(x.held), place_error=[float(e) for e in run.goal_error])


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("names", nargs="+", help="bundled planar examples")
    ap.add_argument("--trials", type=int, default=50)
    ap.add_argument("--spread", type=float, default=0.2)
    ap.add_argument("--seed", type=int, default=7)
    ap.add_argument("--json", help="also write every trial here (JSON lines)")
    ap.add_argument("--robot", help="the robot (a name or a robot file; default: the workcell's)")
    ap.add_argument("--workers", type=int, default=1, help="trials run in this many processes")
    a = ap.parse_args()
    print("| object | placed | planned | median place error | median planning time (max) |")
    print("|---|---|---|---|---|")
    for name in a.names:
        rng = np.random.default_rng(a.seed)
        draws = [draw(rng, a.spread) for _ in range(a.trials)]
        rows = []
        with ProcessPoolExecutor(a.workers) as pool:  # each trial written as it ends, in order
            for r in pool.map(trial, *zip(*[(name, a.robot, k, *d) for k, d in enumerate(draws)])):
                rows.append(r)
                print(f"{name} trial {r['k']}: {'placed' if r['success'] else 'failed'}", file=sys.stderr, flush=True)
                if a.json:
                    with open(a.json, "a") as f:
                        f.write(json.dumps({"name": name, **r}) + "\n")
        done = [r for r in rows if r["planned"]]
        ok = sum(r["success"] for r in rows)
        err = np.median([r["place_error"] for r in done], axis=0) if done else [np.nan, np.nan]
        pt = [r["planning_time_s"] for r in done]
        print(f"| {name} | {ok}/{len(rows)} | {len(done)}/{len(rows)} | {err[0] * 1e3:.2f} mm, {np.degrees(err[1]):.2f}° | "
              f"{np.median(pt) if pt else float('nan'):.2f} s ({max(pt) if pt else float('nan'):.2f} s) |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
