"""Tunes one parameter of each of six actions per bundled object by a search in simulation
(`regrasp.dexterity.tune`) and prints the README's table: the default and tuned value, the
success rate of each on fresh worlds. Usage: python scripts/tune-actions.py [--trials N] (6 by
default) [--objects A,B] [--actions A,B] (all by default) [--out JSON]."""

from __future__ import annotations

import argparse
import json

from regrasp.dexterity.objects import OBJECTS, object_path
from regrasp.dexterity.tune import tune

SEARCH = [  # (action, parameter, candidates)
    ("gravity-slide", "slide_ratio", (0.6, 0.7, 0.8, 0.9)),
    ("inertial-slide", "acceleration", (20.0, 30.0, 40.0, 50.0)),
    ("gravity-pivot", "overdrive", (1.2, 1.4, 2.0, 3.0)),
    ("grip-pivot", "lag", (0.35, 0.52, 0.70, 0.87)),  # rad: 20°, 30°, 40°, 50°
    ("toss-catch", "toss_stop", (20.0, 30.0, 40.0, 50.0)),
    ("table-slide", "rest_ratio", (0.3, 0.4, 0.5, 0.6)),
]


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--trials", type=int, default=6)
    ap.add_argument("--objects", default=",".join(OBJECTS))
    ap.add_argument("--actions", default=",".join(s[0] for s in SEARCH))
    ap.add_argument("--out", default=None)
    a = ap.parse_args()
    only = set(a.actions.split(","))
    rows = []
    print("| object | action | parameter | default | tuned | success, default | success, tuned | runs each |")
    print("|---|---|---|---|---|---|---|---|")
    for name in a.objects.split(","):
        for action, param, values in SEARCH:
            if action not in only:
                continue
            try:
                t = tune(object_path(name), action, param, values, a.trials)
            except Exception as e:  # an action that applies to no grasp of this object
                print(f"| {name} | {action} | {param} | — | — | — | — | {e} |", flush=True)
                continue
            rows.append({"object": name, **t.to_dict()})
            print(f"| {name} | {action} | {param} | {t.default:g} | {t.best:g} | {t.default_rate:.0%} | "
                  f"{t.tuned_rate:.0%} | {t.trials} |", flush=True)
    if a.out:
        with open(a.out, "w") as f:
            json.dump(rows, f, indent=1)


if __name__ == "__main__":
    main()
