"""Measures the grasp graph of each bundled object (prism, cylinder, box, bar) with the arm in MuJoCo
(`regrasp.dexterity.graph.build_graph`), writes each graph to OUT/NAME-graph.json and its
picture to OUT/NAME-graph.png, and prints the README's table: per object and action, the
grasps it applies to, its runs and its success rate (the share of runs that reached the grasp
its model predicts). Usage: python scripts/grasp-graphs.py [--trials N] [--workers K] [--out DIR] [--objects A,B]
[--actions A,B] [--chain]; with --chain each action is also run from where every other action
left the object (`Settings.chain`) and a table of the chained rates against the actions' own
is printed."""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

from regrasp.dexterity.draw import draw_graph
from regrasp.dexterity.graph import Settings, build_graph
from regrasp.dexterity.objects import OBJECTS, object_path


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--trials", type=int, default=40)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", default="out/grasp-graphs")
    ap.add_argument("--objects", default=",".join(OBJECTS))
    ap.add_argument("--actions", default=None, help="only these actions, comma-separated (default: all)")
    ap.add_argument("--chain", action="store_true", help="also measure every action after every other (Settings.chain)")
    a = ap.parse_args()
    actions = None if a.actions is None else tuple(a.actions.split(","))
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    total, rows, seconds, chains = 0, [], 0.0, []
    for name in a.objects.split(","):
        t0 = time.perf_counter()
        g = build_graph(object_path(name), Settings(trials=a.trials, seed=a.seed, actions=actions, chain=a.chain), workers=a.workers, progress=True)
        seconds += time.perf_counter() - t0
        g.save(out / f"{name}-graph.json")
        draw_graph(g, out / f"{name}-graph.png")
        by: dict = {}
        for e in g.edges:
            r = by.setdefault(e.action, {"grasps": [], "trials": 0, "hits": 0, "dropped": 0})
            r["grasps"].append(e.source)
            r["trials"] += e.trials
            r["hits"] += e.outcomes.get(e.target, 0)
            r["dropped"] += e.outcomes.get("dropped", 0)
        for action, r in by.items():
            rows.append((name, action, r))
        n = sum(e.trials for e in g.edges) + sum(c.trials for c in g.chained)
        total += n
        chains.append((name, g))
        print(f"{name}: {len(g.nodes)} grasps ({sum(x['fits'] and x['holds'] for x in g.nodes)} held and fitting the "
              f"hand), {len(g.edges)} edges, {n} trials in {g.seconds:.0f} s", flush=True)
    print("\n| object | action | grasps it applies to | trials | success | dropped |")
    print("|---|---|---|---|---|---|")
    for name, action, r in rows:
        t = r["trials"]
        print(f"| {name} | {action} | {', '.join(r['grasps'])} | {t} | {r['hits'] / t:.0%} | {r['dropped'] / t:.0%} |"
              if t else f"| {name} | {action} | {', '.join(r['grasps'])} | 0 | — | — |")
    if a.chain:
        print_chains(chains)
    print(f"\n{total} trials in {seconds:.0f} s ({total / seconds:.2f} trials/s with {a.workers} workers)")
    (out / "summary.json").write_text(json.dumps({"trials": total, "seconds": seconds,
                                                  "rows": [[n, a_, r] for n, a_, r in rows]}, indent=1))


def print_chains(graphs: list) -> None:
    """Per object: the chained pairs, their runs, the share that reached the next edge's grasp
    after the previous action against the next action's own rate (both over the same pairs, the
    own rate weighted as the chained runs are), and how many pairs moved by more than 25 points."""
    print("\n| object | pairs (action after action) | runs | success after the previous action | success alone "
          "| pairs up > 25 points | pairs down > 25 points |")
    print("|---|---|---|---|---|---|---|")
    for name, g in graphs:
        runs = hits = alone = up = down = 0
        for c in g.chained:
            e = g.edges[c.edge]
            h = c.outcomes.get(e.target, 0)
            runs, hits, alone = runs + c.trials, hits + h, alone + e.success_rate * c.trials
            d = h / c.trials - e.success_rate if c.trials else 0.0
            up, down = up + (d > 0.25), down + (d < -0.25)
        if runs:
            print(f"| {name} | {len(g.chained)} | {runs} | {hits / runs:.0%} | {alone / runs:.0%} | {up} | {down} |")


if __name__ == "__main__":
    main()
