#!/usr/bin/env python3
"""Prints the README's table of the arm's success (regrasp.execution.campaign): every bundled
example (or those named: bundled examples or scene files), ``--runs`` executions each with
friction, grip force and mass drawn within ±``--spread``, ``--workers`` processes; with the
smallest share of the pads' friction left unused through the arm's motion per run
(regrasp.execution.holding), the least and the median over the runs.

    python scripts/arm-statistics.py --runs 20 --spread 0.1 --workers 2 [--robot NAME] [--json out.json] [NAME ...]
"""

import argparse
import json
import sys
from concurrent.futures import ProcessPoolExecutor, as_completed

import numpy as np


def row(o) -> str:
    """The README's table row of an :class:`~regrasp.execution.campaign.Outcome`."""
    if o.refused:
        return f"| {o.name} | refused: {o.refused} | | | | {o.seconds:.0f} |"
    if not o.errors:
        return f"| {o.name} | 0/{o.runs} ({o.failures[0] if o.failures else ''}) | | | | {o.seconds:.0f} |"
    e = np.median(np.abs(np.array(o.errors)), axis=0)
    err = (f"{e[0] * 1e3:.2f} mm, {e[1] * 1e3:.2f} mm, {np.degrees(e[2]):.2f}°" if len(e) == 3
           else f"{e[0] * 1e3:.2f} mm, {np.degrees(e[1]):.2f}°")
    creep = np.array(o.max_creep, float)
    creep = "-" if np.all(np.isnan(creep)) else f"{np.nanmax(creep) * 1e3:.2f}"
    m = [x for x in o.margins if x is not None]
    margin = f"{min(m):.2f} ({np.median(m):.2f})" if m else "-"
    nominal = "" if not o.succeeded else " (nominal ✓)" if o.succeeded[0] else " (nominal ✗)"
    return f"| {o.name} | {o.successes}/{o.runs}{nominal} | {err} | {creep} | {margin} | {o.seconds:.0f} |"


def main() -> int:
    import regrasp
    from regrasp.execution.campaign import example

    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("names", nargs="*", help="bundled examples or scene files (.toml; default: every bundled example with a task)")
    ap.add_argument("--runs", type=int, default=20)
    ap.add_argument("--spread", type=float, default=0.1)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--closed-loop", action="store_true", help="the arm in the loop (MPC / re-planning)")
    ap.add_argument("--robot", help="the robot (regrasp.robot.kinds.ROBOTS; default: the workcell's)")
    ap.add_argument("--grip-sensing", help="what the grip loop measures (default: the gripper's, regrasp.robot.kinds.GRIPPER_SENSING): ideal, open-loop, sensor or "
                    "sensor:NOISE,DELAY,BANDWIDTH (regrasp.robot.sensing)")
    ap.add_argument("--no-noslip", action="store_true", help="without MuJoCo's no-slip post-processing (open loop)")
    ap.add_argument("--json", help="also write the outcomes here")
    a = ap.parse_args()
    from regrasp.robot.sensing import GripSensing

    sensing = GripSensing.parse(a.grip_sensing) if a.grip_sensing else None
    names = a.names or regrasp.examples.names()
    loop = "closed loop" if a.closed_loop else "open loop"
    loop += f", grip sensing {a.grip_sensing or 'the gripper’s default'}" + (", no no-slip" if a.no_noslip else "")
    print(f"| example | {loop}{', ' + a.robot if a.robot else ''}: success (±{a.spread:.0%}, {a.runs} runs) | median goal error | max creep [mm] | holding margin: least (median) | wall [s] |")
    print("|---|---|---|---|---|---|", flush=True)
    with ProcessPoolExecutor(a.workers) as pool:  # a row as each example completes
        jobs = [pool.submit(example, name, a.runs, a.spread, a.seed, a.closed_loop, a.robot, sensing, not a.no_noslip)
                for name in names]
        for job in as_completed(jobs):
            print(row(job.result()), flush=True)
    outs = [job.result() for job in jobs]
    if a.json:  # NaN (no creep measured in closed loop) as null; written atomically
        from regrasp.files import write_text

        clean = lambda v: None if isinstance(v, float) and v != v else v  # noqa: E731
        rows = [{k: ([clean(x) for x in v] if k == "max_creep" else v) for k, v in o.__dict__.items()} for o in outs]
        write_text(a.json, json.dumps(rows, indent=1, allow_nan=False))
    return 0


if __name__ == "__main__":
    sys.exit(main())
