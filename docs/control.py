"""Closed-loop control experiments (issue 6; thesis §5.2, Figs 5-8..5-11), in MuJoCo.

1. The thesis' four control cases on the aluminium block (block-low-friction): tracking a plan,
   a wrong start-pose estimate (5 mm, 5°), pokes during execution, and a poke that needs
   re-planning (the side pusher cannot raise the block, Fig 5-11): figures docs/control-*.png.
2. 50 random trials per bundled planar grasp example with friction, grip force and mass each
   drawn within ±20%, a start error (±2 mm, ±2°) and a poke (±2 mm, ±2° at 0.5–1.5 s): success
   of the nominal plan open loop, the robust plan (±20% cones) open loop, the MPC tracking the
   nominal plan, and the MPC with robust cones tracking the robust plan.
3. Fixtureless fixturing: the fixtureless plan of block-fixtureless open loop under ±50%.
4. Only the physics wrong, open loop: worlds at the corners of ±40% (friction, grip force, mass;
   pushers' friction 40% low), nominal plans against robust plans for ±40%.

Run ``python docs/control.py [--trials N]`` after ``make build``; it prints Markdown tables and
writes docs/control.json.
"""

import argparse
import json
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

import regrasp
from regrasp.control.loop import Poke, control
from regrasp import Perturbation
from regrasp.viz.plotting import plot_control

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ["block-low-friction", "block-high-friction", "block-xztheta", "t-shape", "block-tilted-gripper",
            "block-fixtureless"]
SPREAD = {"pusher_friction": 0.2, "finger_friction": 0.2, "grip_force": 0.2, "mass": 0.2}
METHODS = ("open_loop_nominal", "open_loop_robust", "mpc", "mpc_robust")


def load(name):
    return regrasp.Scene.load(ROOT / "examples" / f"{name}.toml")


def cases():
    s = load("block-low-friction")
    plan = regrasp.plan(s, seed=0).to_json()
    runs = {
        "tracking": {},
        "start-error": {"start_error": [0.005, 0.0, np.radians(5)]},
        "pokes": {"pokes": [Poke(0.8, np.array([0.002, -0.002, 0.0])), Poke(2.0, np.array([-0.002, 0.0, np.radians(3)]))]},
        "replan": {"pokes": [Poke(1.8, np.array([0.0, -0.005, 0.0]))]},
    }
    out = {}
    for name, kw in runs.items():
        r = control(s, plan, engine="mujoco", **kw)
        ol = control(s, plan, engine="mujoco", policy="open_loop", **kw)
        plot_control(s, r, ROOT / "docs" / f"control-{name}.png", extra={"open loop": ol})
        out[name] = {"mpc": r.to_json(), "open_loop": ol.to_json()}
        print(f"{name}: MPC {'success' if r.success else 'failure'} ({r.replans} re-plans, {r.t[-1]:.1f} s), "
              f"open loop {'success' if ol.success else 'failure'}")
    return out


def trial(args):
    name, k = args
    s = load(name)
    rng = np.random.default_rng(10_000 + k)
    pert = Perturbation.draw(rng, 0.2, features="finger")
    start_error = np.r_[rng.uniform(-0.002, 0.002, 2), np.radians(rng.uniform(-2, 2))]
    poke = Poke(rng.uniform(0.5, 1.5), np.r_[rng.uniform(-0.002, 0.002, 2), np.radians(rng.uniform(-2, 2))])
    robust = s.robust(SPREAD)
    nominal_plan = regrasp.plan(s, seed=k).to_json()
    rp = regrasp.plan(robust, seed=k, time_limit=5.0)
    robust_plan = rp.to_json() if rp.found else None
    out = {"perturb": [pert.friction, pert.grip, pert.mass], "robust_plan": robust_plan is not None}
    common = dict(engine="mujoco", pokes=[poke], start_error=start_error, perturb=pert, seed=k)
    res = {
        "open_loop_nominal": control(s, nominal_plan, policy="open_loop", **common),
        "open_loop_robust": control(s, robust_plan, policy="open_loop", **common) if robust_plan else None,
        "mpc": control(s, nominal_plan, **common),
        "mpc_robust": control(s, robust_plan, controller_scene=robust, **common) if robust_plan else None,
    }
    for m, r in res.items():
        out[m] = None if r is None else {"success": r.success, "replans": r.replans, "step_s": r.mpc_step_median_s,
                                         "failure": r.failure, "error": r.goal_error.tolist()}
    return name, k, out


def trials(n):
    jobs = [(e, k) for e in EXAMPLES for k in range(n)]
    table = {e: [] for e in EXAMPLES}
    t0 = time.perf_counter()
    with ProcessPoolExecutor() as ex:
        for name, k, out in ex.map(trial, jobs):
            table[name].append(out)
    print(f"{len(jobs)} trials in {time.perf_counter() - t0:.0f} s")
    print("| example | nominal plan, open loop | robust plan, open loop | MPC (nominal plan) | MPC (robust cones and plan) | MPC re-plans (mean) | MPC step median |")
    print("|---|---|---|---|---|---|---|")
    summary = {}
    for e, rows in table.items():
        cell = {}
        for m in METHODS:
            ok = [r[m]["success"] for r in rows if r[m] is not None]
            cell[m] = (sum(ok), len(ok))
        rep = np.mean([r["mpc"]["replans"] for r in rows])
        step = np.median([r["mpc"]["step_s"] for r in rows])
        summary[e] = {m: {"success": c[0], "runs": c[1]} for m, c in cell.items()}
        summary[e]["mpc_replans_mean"] = float(rep)
        summary[e]["mpc_step_median_s"] = float(step)
        fmt = lambda c: f"{c[0]}/{c[1]}" if c[1] else "no robust plan"  # noqa: E731
        print(f"| {e} | {fmt(cell['open_loop_nominal'])} | {fmt(cell['open_loop_robust'])} | **{fmt(cell['mpc'])}** | "
              f"{fmt(cell['mpc_robust'])} | {rep:.2f} | {1e3 * step:.2f} ms |")
    return summary, table


CORNER_SPREAD = 0.4


def physics_trial(args):
    name, k = args
    s = load(name)
    # plans of seed k // 8, world at corner k % 8 of friction, grip, mass within ±40%, pushers'
    # friction 40% low
    f, g, m = ((1 + CORNER_SPREAD * (2 * ((k % 8 >> b) & 1) - 1)) for b in range(3))
    pert = Perturbation(f, g, m, feature_friction=1 - CORNER_SPREAD)
    u = {key: CORNER_SPREAD for key in SPREAD}
    nominal = regrasp.plan(s, seed=k // 8).to_json()
    rp = regrasp.plan(s.robust(u), seed=k // 8, time_limit=5.0)
    out = {"nominal": control(s, nominal, engine="mujoco", policy="open_loop", perturb=pert),
           "robust": control(s, rp.to_json(), engine="mujoco", policy="open_loop", perturb=pert) if rp.found else None}
    return name, {key: None if r is None else {"success": r.success, "error": r.goal_error.tolist()} for key, r in out.items()}


def physics_only(n):
    """Open loop, only the physics wrong: worlds at the corners of ±40% in friction, grip force
    and mass with the pushers' friction 40% low; nominal plans against plans with robust cones
    for ±40% (thesis §5.1)."""
    jobs = [(e, k) for e in EXAMPLES for k in range(n)]
    rows = {e: [] for e in EXAMPLES}
    with ProcessPoolExecutor() as ex:
        for name, out in ex.map(physics_trial, jobs):
            rows[name].append(out)
    print("| example | nominal plan: success | largest error x, z [mm] | robust plan: success | largest error x, z [mm] |")
    print("|---|---|---|---|---|")
    summary = {}
    for e, r in rows.items():
        cells = {}
        for key in ("nominal", "robust"):
            xs = [x[key] for x in r if x[key] is not None]
            err = np.max(np.abs([x["error"] for x in xs]), axis=0) * 1e3 if xs else np.full(3, np.nan)
            cells[key] = {"success": sum(x["success"] for x in xs), "runs": len(xs), "max_error_mm": err[:2].tolist()}
        summary[e] = cells
        c = [cells["nominal"], cells["robust"]]
        print(f"| {e} | {c[0]['success']}/{c[0]['runs']} | {c[0]['max_error_mm'][0]:.2f}, {c[0]['max_error_mm'][1]:.2f} | "
              f"{c[1]['success']}/{c[1]['runs']} | {c[1]['max_error_mm'][0]:.2f}, {c[1]['max_error_mm'][1]:.2f} |")
    return summary


def fixtureless(n):
    """Fixtureless plan against the nominal plan, open loop, with finger friction, grip force and
    mass each within ±50% (the table's friction as modelled)."""
    s = load("block-fixtureless")
    plans = {"fixtureless": regrasp.plan(s.fixtureless(), seed=0).to_json(), "nominal": regrasp.plan(s, seed=0).to_json()}
    out = {}
    for name, plan in plans.items():
        row = {"runs": n}
        for engine in ("mujoco", "quasistatic"):
            runs = []
            for k in range(n):
                d = Perturbation.draw(np.random.default_rng(20_000 + k), 0.5, features="finger")
                pert = Perturbation(d.finger_friction, d.grip, d.mass, feature_friction=1.0)
                r = control(s, plan, engine=engine, policy="open_loop", perturb=pert)
                runs.append({"success": r.success, "goal_error": r.goal_error.tolist(),
                             "factors": [d.friction, d.grip, d.mass]})
            row[engine] = runs
            row["success" if engine == "mujoco" else "success_quasistatic"] = sum(r["success"] for r in runs)
            miss = [r for r in runs if not r["success"]]
            print(f"{name} plan of block-fixtureless, open loop in {engine}, ±50% finger friction/grip/mass: "
                  f"{n - len(miss)}/{n}" + "".join(
                      f"\n  miss: error x, z {1e3 * r['goal_error'][0]:+.2f}, {1e3 * r['goal_error'][1]:+.2f} mm, "
                      f"θ {1e3 * r['goal_error'][2]:+.1f} mrad at friction/grip/mass ×{r['factors'][0]:.2f}/"
                      f"{r['factors'][1]:.2f}/{r['factors'][2]:.2f}" for r in miss))
        out[name] = row
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--trials", type=int, default=50)
    ap.add_argument("--only", choices=["cases", "fixtureless", "trials", "physics"], action="append",
                    help="run only these parts (results merged into docs/control.json)")
    a = ap.parse_args()
    parts = a.only or ["cases", "fixtureless", "trials", "physics"]
    f = ROOT / "docs" / "control.json"
    out = json.loads(f.read_text()) if f.exists() else {}
    if "cases" in parts:
        out["cases"] = cases()
    if "fixtureless" in parts:
        out["fixtureless"] = fixtureless(20)
    if "trials" in parts:
        out["trials"], out["trial_rows"] = trials(a.trials)
    if "physics" in parts:
        out["physics_only"] = physics_only(40)
    f.write_text(json.dumps(out, indent=1, default=float))


if __name__ == "__main__":
    main()
