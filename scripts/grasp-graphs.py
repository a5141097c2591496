"""Measures the grasp graph of each bundled object (prism, cylinder, box, bar) with the arm in MuJoCo
(`regrasp.dexterity.graph.build_graph`), writes each graph to OUT/NAME-graph.json and its
picture to OUT/NAME-graph.png, and prints the README's table: per object and action, the
grasps it applies to, its runs and its success rate (the share of runs that reached the grasp
its model predicts). Usage: python scripts/grasp-graphs.py [--trials N] [--workers K] [--out DIR] [--objects A,B]
[--actions A,B]."""

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
    a = ap.parse_args()
    actions = None if a.actions is None else tuple(a.actions.split(","))
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    total, rows, seconds = 0, [], 0.0
    for name in a.objects.split(","):
        t0 = time.perf_counter()
        g = build_graph(object_path(name), Settings(trials=a.trials, seed=a.seed, actions=actions), workers=a.workers, progress=True)
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
        n = sum(e.trials for e in g.edges)
        total += n
        print(f"{name}: {len(g.nodes)} grasps ({sum(x['fits'] and x['holds'] for x in g.nodes)} held and fitting the "
              f"hand), {len(g.edges)} edges, {n} trials in {g.seconds:.0f} s", flush=True)
    print("\n| object | action | grasps it applies to | trials | success | dropped |")
    print("|---|---|---|---|---|---|")
    for name, action, r in rows:
        t = r["trials"]
        print(f"| {name} | {action} | {', '.join(r['grasps'])} | {t} | {r['hits'] / t:.0%} | {r['dropped'] / t:.0%} |"
              if t else f"| {name} | {action} | {', '.join(r['grasps'])} | 0 | — | — |")
    print(f"\n{total} trials in {seconds:.0f} s ({total / seconds:.2f} trials/s with {a.workers} workers)")
    (out / "summary.json").write_text(json.dumps({"trials": total, "seconds": seconds,
                                                  "rows": [[n, a_, r] for n, a_, r in rows]}, indent=1))


if __name__ == "__main__":
    main()
