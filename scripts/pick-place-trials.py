#!/usr/bin/env python3
"""Prints the README's pick-regrasp-place row of each object: ``--trials`` randomized trials
(the object's pick pose on the table: ±50 mm and ±0.3 rad about the default; the place pose
shifted by the default shift; finger and feature friction ×[1 − spread, 1 + spread]), each
planned (regrasp.execution.pick_place) and executed in MuJoCo with the arm.

    python scripts/pick-place-trials.py --trials 50 --spread 0.2 [--json out.jsonl] NAME ...
"""

import argparse
import json
import sys

import numpy as np


def trial(s, wc, rng, k: int, spread: float) -> dict:
    from regrasp.errors import RegraspError
    from regrasp.execution import pick_place as pp
    from regrasp import Perturbation
    from regrasp.execution import World, execute

    xy = np.array(pp.DEFAULT_PICK) + rng.uniform(-0.05, 0.05, 2)
    pick = pp.table_pose(s, wc, xy, 0.0, rng.uniform(-0.3, 0.3))
    place = np.r_[pick[0] + pp.DEFAULT_SHIFT[0], pick[1] + pp.DEFAULT_SHIFT[1], pick[2:]]
    f = float(rng.uniform(1 - spread, 1 + spread))
    try:
        r = pp.pick_place(s, wc, place=place, pick=pick, seed=k)
    except RegraspError as e:
        return dict(k=k, friction=f, planned=False, success=False, why=str(e)[:300])
    run = execute(World(s, rig="arm"), r, perturbation=Perturbation(finger_friction=f, feature_friction=f))
    x = run.detail
    return dict(k=k, friction=f, planned=True, planning_time_s=r.planning_time, switch_overs=r.switch_overs,
                success=bool(run.success), held=bool(x.held), place_error=[float(e) for e in run.goal_error])


def main() -> int:
    import regrasp
    from regrasp.execution import default_workcell

    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("names", nargs="+", help="bundled planar examples")
    ap.add_argument("--trials", type=int, default=50)
    ap.add_argument("--spread", type=float, default=0.2)
    ap.add_argument("--seed", type=int, default=7)
    ap.add_argument("--json", help="also write every trial here (JSON lines)")
    a = ap.parse_args()
    print("| object | placed | planned | median place error | median planning time (max) |")
    print("|---|---|---|---|---|")
    for name in a.names:
        s = regrasp.load_scene(regrasp.examples.path(name))
        wc = default_workcell(s)
        rng = np.random.default_rng(a.seed)
        rows = [trial(s, wc, rng, k, a.spread) for k in range(a.trials)]
        if a.json:
            with open(a.json, "a") as f:
                for r in rows:
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
