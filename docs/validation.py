"""The README's Table 3.2 analog: motion-cone predictions on each limit surface against the
quasi-static simulator, on every bundled planar example.

    python docs/validation.py [--pushes 10000] [--rings 3,8] [--json out.json]

For each example and each limit surface (``true``, ``ellipsoid``) the pushes of
``regrasp validate`` are drawn once (seed 0) and simulated with point-set pads of each number of
rings (3 is the simulator's default: 36 points a pad; 8, `regrasp validate`'s: 216). Prints a
markdown table: the agreement (strict, and counting an *ambiguous* push, where the object can
also stay in the grasp, as agreeing whichever outcome the simulator picks: see
``regrasp.mujoco.validation``), the disagreements by kind (predicted stick / simulated slip, and the reverse; and how
many of them are *withdrawing* pushes, whose contact (a line pusher's middle) moves away from the
object: the cone
lets gravity make the object follow the pusher, the simulator finds the object held by the pads
and the contact opening, both quasi-static solutions) and the agreement by kind of push (inside
the cone, near its boundary, random).
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np

from regrasp import examples
from regrasp.scene.planar import Scene
from regrasp.mujoco import validation as V
from regrasp.sim.quasistatic import support_kwargs


def withdrawing(scene: Scene, pusher: str, twist) -> bool:
    """Whether the pusher's contact (a line pusher's middle) moves away from the object (along
    minus its normal)."""
    p = scene.pusher(pusher)
    n, v = np.asarray(p.normal, float), np.asarray(twist, float)
    r = np.mean(p.points, axis=0)
    return bool(n @ (v[:2] + v[2] * np.array([-r[1], r[0]])) < -1e-9 * np.linalg.norm(v[:2]))


def run(path, model: str, pushes: int, rings: list[int]) -> list[dict]:
    scene = Scene.load(path).with_limit_surface(model)
    t0 = time.perf_counter()
    rows = V.samples(scene, pushes, 0)
    drawn = time.perf_counter() - t0
    pred = np.array([r[4] for r in rows])
    amb = np.array([r[5] for r in rows], bool)
    kind = np.array([r[1] for r in rows])
    away = np.array([withdrawing(scene, r[0], r[3]) for r in rows])
    out = []
    for n in rings:
        t0 = time.perf_counter()
        sim, ok = V._run_quasistatic(scene, rows, support_kwargs("points", rings=n), False)
        c = V._table(pred, sim, ok, np.ones(len(rows), bool))
        out.append({
            "scene": scene.name, "limit_surface": model, "rings": n, "pushes": pushes, "solved": int(ok.sum()),
            "agreement": float(((pred == sim) & ok).sum() / max(ok.sum(), 1)),
            "ambiguous": int((amb & ok).sum()),
            "agreement_either": float((((pred == sim) | amb) & ok).sum() / max(ok.sum(), 1)),
            "ambiguous_disagreements": int(((pred != sim) & ok & amb).sum()),
            "confusion": c,
            "withdrawing_disagreements": int(((pred != sim) & ok & away).sum()),
            "by_kind": {k: float(((pred == sim) & ok & (kind == k)).sum() / max(((kind == k) & ok).sum(), 1))
                        for k in V.KINDS},
            "draw_s": drawn, "simulate_s": time.perf_counter() - t0,
        })
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--pushes", type=int, default=10_000)
    ap.add_argument("--rings", default="3,8")
    ap.add_argument("--examples", help="comma-separated names (default: every planar example)")
    ap.add_argument("--json", metavar="OUT")
    a = ap.parse_args()
    rings = [int(x) for x in a.rings.split(",")]
    paths = examples.planar() if a.examples is None else [examples.path(n) for n in a.examples.split(",")]
    rows = []
    print("| example | limit surface | rings | agreement | either outcome | ambiguous | pred. stick, sim. slip "
          "| pred. slip, sim. stick | of them withdrawing | of them ambiguous | inside / near / random |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for p in paths:
        for model in ("true", "ellipsoid"):
            for r in run(p, model, a.pushes, rings):
                rows.append(r)
                c, k = r["confusion"], r["by_kind"]
                solved = "" if r["solved"] == r["pushes"] else f" ({r['solved']} solved)"
                print(f"| {r['scene']} | {model} | {r['rings']} | {100 * r['agreement']:.2f}%{solved} "
                      f"| {100 * r['agreement_either']:.2f}% | {r['ambiguous']} "
                      f"| {c['predicted_stick_simulated_slip']} | {c['predicted_slip_simulated_stick']} "
                      f"| {r['withdrawing_disagreements']} | {r['ambiguous_disagreements']} "
                      f"| {100 * k['inside']:.1f} / {100 * k['near']:.1f} / {100 * k['random']:.1f}% |", flush=True)
    if a.json:
        with open(a.json, "w") as f:
            json.dump(rows, f, indent=1)


if __name__ == "__main__":
    main()
