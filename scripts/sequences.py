"""Plans regrasp sequences on measured grasp graphs (`regrasp.dexterity.sequence.plan`), executes
each end to end in MuJoCo in perturbed worlds, and prints the README's table: the sequence, its
actions with their rates, the prediction (with a chained graph: each step's rate measured after
the step before it), the product of the actions' own rates, and the measured success. Usage:
python scripts/sequences.py [--graphs DIR] [--runs N] [OBJECT:FROM:TO ...] (default: the
README's sequences; DIR holds NAME-graph.json, as scripts/grasp-graphs.py writes them)."""

from __future__ import annotations

import argparse
from collections import Counter
from pathlib import Path

from regrasp.dexterity.graph import GraspGraph, Settings, perturbations
from regrasp.dexterity.sequence import execute, plan

SEQUENCES = ("prism:g0:g3", "prism:g0:g5", "cylinder:g1:g4", "box:g6:g5", "bar:g9:g8")


def ended(runs: list, steps: int) -> str:
    """Where the runs ended: how many reached the goal, and the others by step and outcome."""
    done = sum(r.success for r in runs)
    misses = Counter((len(r.outcomes), r.outcomes[-1]) for r in runs if not r.success)
    rest = ", ".join(f"{n} {o} at step {k}" for (k, o), n in sorted(misses.items()))
    return f"{done} reached it" + (f"; {rest}" if rest else "") if steps else "-"


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--graphs", default="out/chained")
    ap.add_argument("--runs", type=int, default=20)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("sequences", nargs="*", default=list(SEQUENCES))
    a = ap.parse_args()
    print("| object | sequence | actions (rate used) | predicted | actions alone | measured | where the runs ended |")
    print("|---|---|---|---|---|---|---|")
    for item in a.sequences:
        name, start, goal = item.split(":")
        path = Path(a.graphs) / f"{name}-graph.json"
        if not path.is_file():
            print(f"| {name} | {start} → {goal} | no graph at {path} | | | | |")
            continue
        g = GraspGraph.load(path)
        s = plan(g, start, goal)
        spread = {k: g.settings[k] for k in ("spread", "shift", "turn")}
        runs = [execute(g.object["file"], s, p) for p in
                perturbations(Settings(trials=a.runs, seed=a.seed, **spread), f"sequence/{start}/{goal}")]
        acts = ", ".join(f"{x.action} to {x.target} ({x.p:.0%}{' after' if x.chained else ''})" for x in s.steps)
        measured = sum(r.success for r in runs) / len(runs)
        print(f"| {name} | {start} → {goal} | {acts} | {s.probability:.0%} | {s.independent:.0%} | {measured:.0%} "
              f"| {ended(runs, len(s.steps))} |", flush=True)


if __name__ == "__main__":
    main()
