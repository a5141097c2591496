"""Plans executed in MuJoCo (issue 5): for every planar grasp example, the plan of seed 0
replayed in the quasi-static simulator and executed in MuJoCo (figures docs/exec-NAME.png), then
20 open-loop executions (plans of seeds 0..19) with friction, grip force and mass each drawn
uniformly within ±10% (success table), and the creep of a held object with and without our
contact settings. Run `python docs/execution.py` after `make build`; it prints a Markdown table
and writes docs/execution.json."""

import json
import time
from pathlib import Path

import numpy as np

import regrasp
from regrasp import Perturbation
from regrasp.mujoco.planar import execute_plan
from regrasp.mujoco.model import SOFT
from regrasp.mujoco.world import creep
from regrasp.viz.plotting import plot_replay
from regrasp.sim.quasistatic import replay_plan

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ["block-low-friction", "block-high-friction", "block-xztheta", "t-shape", "block-tilted-gripper"]


def main(runs: int = 20, spread: float = 0.1):
    out = {}
    for name in EXAMPLES:
        s = regrasp.Scene.load(ROOT / "examples" / f"{name}.toml")
        p = regrasp.plan(s, seed=0).to_json()
        qs = replay_plan(s, p)
        mj = execute_plan(s, p)
        plot_replay(s, mj, ROOT / "docs" / f"exec-{name}.png", extra={"quasi-static": qs})
        ok, errs, slips, t0 = 0, [], [], time.perf_counter()
        failures = []
        for k in range(runs):
            pk = regrasp.plan(s, seed=k).to_json()
            rep = execute_plan(s, pk, Perturbation.draw(np.random.default_rng(1000 + k), spread, features="finger"))
            ok += rep.success
            errs.append(np.abs(rep.goal_error))
            slips.append(rep.max_pusher_slip)
            if not rep.success:
                failures.append({"seed": k, "goal_error": rep.goal_error.tolist()})
        e = np.array(errs)
        out[name] = {
            "success": ok, "runs": runs, "spread": spread,
            "median_error_mm": (1e3 * np.median(e[:, :2], axis=0)).tolist(),
            "max_error_mm": (1e3 * e[:, :2].max(axis=0)).tolist(),
            "max_error_deg": float(np.degrees(e[:, 2].max())),
            "median_slip_mm": float(1e3 * np.median(slips)),
            "failures": failures,
            "creep_um_ours": 1e6 * creep(s, duration=2.0),
            "creep_um_soft": 1e6 * creep(s, duration=2.0, contact=SOFT),
            "seconds": time.perf_counter() - t0,
        }
    (ROOT / "docs" / "execution.json").write_text(json.dumps(out, indent=1))
    print("| example | success (±10%) | median error x, z [mm] | max error x, z [mm] / θ [deg] | creep held 2 s, ours / soft [µm] |")
    print("|---|---|---|---|---|")
    for name, r in out.items():
        print(f"| {name} | {r['success']}/{r['runs']} | {r['median_error_mm'][0]:.3f}, {r['median_error_mm'][1]:.3f} | "
              f"{r['max_error_mm'][0]:.2f}, {r['max_error_mm'][1]:.2f} / {r['max_error_deg']:.2f} | "
              f"{r['creep_um_ours']:.2f} / {r['creep_um_soft']:.0f} |")


if __name__ == "__main__":
    main()
