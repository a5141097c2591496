#!/usr/bin/env python3
"""Prints the README's comparison of the rigs, nominal world, each bundled example's seed-0 plan
in its default workcell: the free-flying gripper (regrasp.execution.free_gripper: the planner's
single-contact pads, no arm), the arm with the old single-contact pads (one contact per pad whose
elliptic cone is the ellipsoidal limit surface) and the arm with the distributed-contact pads
(regrasp.robot.pads: a grid of sliding point contacts over the scene's pad shape).

    python scripts/rig-comparison.py [NAME ...]
"""

import sys

import numpy as np


def fmt(r, dim: int) -> str:
    e = np.abs(np.asarray(r.goal_error, float))
    err = f"{e[0] * 1e3:.2f} mm, {e[1] * 1e3:.2f} mm, {np.degrees(e[2]):.2f}°" if dim == 2 else \
        f"{e[0] * 1e3:.2f} mm, {np.degrees(e[1]):.2f}°"
    return f"{'yes' if r.success else 'no'} ({err})"


def row(name: str) -> str:
    import regrasp
    from regrasp.errors import RegraspError
    from regrasp.execution import execute_free_gripper, world_motion
    from regrasp.execution.arm import arm_motion, execute_arm
    from regrasp.robot.pads import single_contact

    scene = regrasp.load_scene(regrasp.examples.path(name))
    if scene.task is None:
        return f"| {name} | no task | | |"
    plan = regrasp.plan(scene, seed=0)
    try:
        free = fmt(execute_free_gripper(scene, plan, world_motion(scene, plan)), scene.dimension)
    except RegraspError as e:
        free = f"refused ({type(e).__name__})"
    try:
        am = arm_motion(scene, plan)
    except RegraspError as e:
        why = str(e).split(";")[0]
        return f"| {name} | {free} | refused: {why[:160]} | refused |"
    single = execute_arm(scene, plan, am.motion, trajectory=am.trajectory, pads=single_contact(scene))
    grid = execute_arm(scene, plan, am.motion, trajectory=am.trajectory)
    return f"| {name} | {free} | {fmt(single, scene.dimension)} | {fmt(grid, scene.dimension)} |"


def main() -> int:
    import regrasp

    names = sys.argv[1:] or regrasp.examples.names()
    print("| example | free-flying gripper | arm, single-contact pads | arm, distributed pads |")
    print("|---|---|---|---|")
    for name in names:
        print(row(name), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
