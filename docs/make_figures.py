"""Regenerate the figures of the README: `python docs/make_figures.py` (after `make build`)."""

from pathlib import Path

import regrasp
from regrasp.viz.plotting import plot_motion_cone

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "docs"

if __name__ == "__main__":
    block = regrasp.Scene.load(ROOT / "examples" / "block-low-friction.toml")
    plot_motion_cone(block.with_grip_force(5.0).motion_cone([0, 0, 0], "left"), OUT / "cone-left-5N.png")
    plot_motion_cone(block.motion_cone([0, 0, 0], "left"), OUT / "cone-left-20N.png")
    xzt = regrasp.Scene.load(ROOT / "examples" / "block-xztheta.toml")
    plot_motion_cone(xzt.with_grip_force(5.0).motion_cone([0, 0, 0], "corner"), OUT / "cone-corner-5N.png")
    from regrasp.viz.plotting import animate_plan, plot_plan

    for name in ("t-shape", "block-xztheta", "block-low-friction", "block-high-friction"):
        sc = regrasp.Scene.load(ROOT / "examples" / f"{name}.toml")
        p = regrasp.plan(sc, seed=0)
        plot_plan(sc, p, OUT / f"plan-{name}.png")
        if name in ("t-shape", "block-xztheta"):
            animate_plan(sc, p, OUT / f"plan-{name}.gif")
    # 3-D plans: GIFs (seed 0)
    from regrasp.viz.plotting3d import animate_plan3d

    for name, fps in (("pivot-3d", 6), ("pivot-single-3d", 6), ("ball-roll-3d", 4), ("pivot-90-3d", 4), ("offset-pivot-3d", 6),
                      ("bracket-pivot-3d", 6)):
        s3 = regrasp.Scene3D.load(ROOT / "examples" / f"{name}.toml")
        animate_plan3d(s3, s3.plan(seed=0), OUT / f"plan-{name}.gif", frames_per_step=fps)
    print("wrote", *sorted(p.name for p in OUT.glob("*.png")), *sorted(p.name for p in OUT.glob("*.gif")))
