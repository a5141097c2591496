"""3-D plans executed in MuJoCo (issue 7): for every bundled 3-D example, the plan of seed 0
replayed in the quasi-static simulator and executed in MuJoCo in the world's view (features
fixed, the gripper driven) and in the planner's view (pads fixed, features driven), open loop,
and in the world's view closed loop by re-planning from the measured pose; then
pivot-3d with its fixture touching the block with an edge (a line contact) instead of its face,
in MuJoCo with point pads and with ring pads, and in our simulator at the default and a 20x finer
time step. Prints Markdown tables and writes docs/execution3d.json.

Run ``python docs/execution3d.py`` after ``make build`` (a few minutes on 2 cores)."""

import json
import time
from pathlib import Path

import numpy as np

from regrasp.mujoco.spatial import execute_plan3d
from regrasp.scene.spatial import Scene3D

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ["offset-3d", "light-side-3d", "pivot-single-3d", "pivot-3d", "block-3d", "prism-3d", "ball-roll-3d"]
EDGE = [[-0.025, -0.005, -0.04], [-0.025, 0.005, -0.04]]  # the fixture's edge along the grasp axis


def _err(r) -> str:
    e = r["goal_error"]
    return f"{1e3 * e[0]:+.2f}, {1e3 * e[1]:+.2f}, {1e3 * e[2]:+.2f} / {1e3 * e[3]:.2f}"


def _row(r) -> dict:
    return {"goal_error": list(map(float, r["goal_error"])), "success": bool(r["success"])}


def edge_variant() -> Scene3D:
    """pivot-3d with the fixture's bottom edge (two points along Y) instead of its face."""
    text = (ROOT / "examples" / "pivot-3d.toml").read_text()
    face = "points = [[-0.025, -0.005, -0.04], [-0.025, 0.005, -0.04], [-0.025, 0.005, -0.03], [-0.025, -0.005, -0.03]]"
    assert face in text, "pivot-3d's corner pusher changed: update EDGE"
    return Scene3D.from_toml(text.replace(face, f"points = {EDGE}").replace('name = "pivot-3d"', 'name = "pivot-3d-edge"'))


def main():
    out = {"examples": {}}
    print("| example | quasi-static: error x, y, z [mm] / angle [mrad] | MuJoCo world's view | MuJoCo planner's view "
          "| within tolerance (open loop, all three) | MuJoCo world's view, re-planning: error (re-plans) |")
    print("|---|---|---|---|---|---|")
    for name in EXAMPLES:
        s = Scene3D.load(ROOT / "examples" / f"{name}.toml")
        p = s.plan(seed=0)
        t0 = time.perf_counter()
        qs, world, planner = s.replay(p), execute_plan3d(s, p), execute_plan3d(s, p, view="planner")
        closed = execute_plan3d(s, p, feedback=True)
        ok = qs["success"] and world["success"] and planner["success"]
        out["examples"][name] = {"quasistatic": _row(qs), "mujoco_world": _row(world), "mujoco_planner": _row(planner),
                                 "mujoco_world_replanning": {**_row(closed), "replans": closed["replans"]},
                                 "seconds": time.perf_counter() - t0}
        print(f"| {name} | {_err(qs)} | {_err(world)} | {_err(planner)} | {'yes' if ok else 'no'} "
              f"| {_err(closed)} ({closed['replans']}){'' if closed['success'] else ' outside'} |", flush=True)
    s = edge_variant()
    p = s.plan(seed=0)
    runs = {
        "mujoco_point_pads": execute_plan3d(s, p),
        "mujoco_ring_pads": execute_plan3d(s, p, pad="ring"),
        "quasistatic": s.replay(p),
        "quasistatic_fine": s.replay(p, dt=0.25 / 20),
    }
    out["pivot_edge"] = {k: _row(r) for k, r in runs.items()}
    print("\npivot-3d with the fixture's edge instead of its face (plan of seed 0):")
    for k, r in runs.items():
        print(f"  {k:18s} error {_err(r)}  {'within' if r['success'] else 'outside'} the tolerance")
    (ROOT / "docs" / "execution3d.json").write_text(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
