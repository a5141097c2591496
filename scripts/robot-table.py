#!/usr/bin/env python3
"""Prints the docs' table of every bundled example on every bundled robot
(regrasp.execution.campaign): each planned (seed 0) and executed once in the nominal world with
the arm, open loop; a cell is the success against the task's tolerance with the goal error, or
the refusal (or failure) and its reason. ``--workers`` processes.

    python scripts/robot-table.py --workers 2 [--robots ur5e-2f85,ur5e-parallel,panda-parallel,panda-hand] [--json out.json] [NAME ...]
    python scripts/robot-table.py --from out.json   # the table again, from the outcomes written
"""

import argparse
import json
import re
import sys
from concurrent.futures import ProcessPoolExecutor, as_completed

import numpy as np

ROBOTS = ("ur5e-2f85", "ur5e-parallel", "panda-parallel", "panda-hand")
#: A cell's reason is cut to this many characters (the JSON keeps it whole).
REASON = 200
#: Where a refusal names the cause behind every contact's exclusion.
FOLLOW = "where the arm could not follow: "


def run(name: str, robot: str):
    """The :class:`~regrasp.execution.campaign.Outcome` of one nominal run, or the reason it
    could not start (the robot's extra not installed)."""
    from regrasp.errors import RegraspError
    from regrasp.execution.campaign import example

    try:
        return example(name, 1, 0.0, 0, False, robot)
    except RegraspError as e:  # e.g. the robot file's model is not installed
        from regrasp.execution.campaign import Outcome

        return Outcome(name, refused=f"{type(e).__name__}: {e}")


def cell(o) -> str:
    """A table cell: ✓ with the goal error, or ✗/refused with the reason."""
    def why(s: str) -> str:  # the reason: no exception name, poses or list of excluded contacts; cut
        s = s.split(": ", 1)[-1] if s.split(": ", 1)[0].endswith("Error") else s
        s = s.split(FOLLOW)[-1]  # where the arm could not follow the push: the cause
        s = re.sub(r" ?\[-?[0-9.e]+(, -?[0-9.e]+)+\]", "", s)  # poses
        return (s if len(s) <= REASON else s[:REASON - 1] + "…").replace("|", "/")

    if o.refused:
        return f"refused: {why(o.refused)}"
    if o.failures:
        return f"✗ stopped: {why(o.failures[0])}"
    e = np.abs(np.array(o.errors[0]))
    err = f"{e[0] * 1e3:.2f} mm, {np.degrees(e[-1]):.2f}°" if len(e) == 2 else \
        f"{np.hypot(e[0], e[1]) * 1e3:.2f} mm, {np.degrees(e[2]):.2f}°"
    return f"{'✓' if o.successes else '✗ outside tolerance'} ({err})"


def print_table(names, robots, out) -> None:
    """The markdown table: a row per example, a column per robot."""
    print(f"| example | {' | '.join(robots)} |")
    print("|---|" + "---|" * len(robots))
    for n in names:
        print(f"| {n} | {' | '.join(cell(out[n, r]) for r in robots)} |")


def main() -> int:
    import regrasp

    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("names", nargs="*", help="bundled examples (default: all)")
    ap.add_argument("--robots", default=",".join(ROBOTS), help="comma-separated robot names or robot files")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--json", help="also write every outcome here")
    ap.add_argument("--from", dest="source", help="print the table of a --json file written before (no runs)")
    a = ap.parse_args()
    if a.source:
        from regrasp.execution.campaign import Outcome

        rows = json.loads(open(a.source).read())
        names, robots = list(dict.fromkeys(r["example"] for r in rows)), list(dict.fromkeys(r["robot"] for r in rows))
        out = {(r["example"], r["robot"]): Outcome(**{k: v for k, v in r.items() if k not in ("example", "robot")})
               for r in rows}
        print_table(names, robots, out)
        return 0
    names, robots = a.names or regrasp.examples.names(), a.robots.split(",")
    out = {}
    with ProcessPoolExecutor(a.workers) as pool:
        jobs = {pool.submit(run, n, r): (n, r) for n in names for r in robots}
        for k, job in enumerate(as_completed(jobs), 1):
            out[jobs[job]] = job.result()
            print(f"[{k}/{len(jobs)}] {jobs[job][0]} on {jobs[job][1]}: {cell(out[jobs[job]])}", file=sys.stderr, flush=True)
    print_table(names, robots, out)
    if a.json:
        from regrasp.files import write_text

        rows = [{"example": n, "robot": r, **{k: v for k, v in out[n, r].__dict__.items() if k != "max_creep"}}
                for n in names for r in robots]
        write_text(a.json, json.dumps(rows, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
