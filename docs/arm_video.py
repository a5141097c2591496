"""The arm doing a thesis regrasp and a pick-regrasp-place in the default workcell: the README's
animations docs/arm-pivot-single-3d.gif (thesis Fig 4-5, the single-pusher pivot, the object
starting in the hand) and docs/arm-pick-place.gif (block-xztheta picked from the table,
regrasped against the workcell, placed). Run: python docs/arm_video.py [FOLDER]"""

import sys
import time
from pathlib import Path

import numpy as np

import regrasp
from regrasp.execution import pick_place as pp
from regrasp.execution.arm import arm_motion, execute_arm
from regrasp.robot.video import Camera, Recorder

FPS = 5  # frames per second of simulated time (the GIF plays in real time)
SIZE = (400, 300)


def recorder(target, distance: float = 0.6, azimuth: float = 30, elevation: float = -10):
    """An observe(robot) callback that records, and the dict its Recorder lands in."""
    rec: dict = {}

    def observe(robot):
        if "r" not in rec:
            rec["r"] = Recorder(robot.model, robot.data, FPS, SIZE,
                                Camera(target=np.asarray(target, float), distance=distance, azimuth=azimuth,
                                       elevation=elevation), shadows=False)
        rec["r"].capture()
    return observe, rec


def pivot(out: Path) -> None:
    name = "pivot-single-3d"
    scene = regrasp.load_scene(regrasp.examples.path(name))
    plan = regrasp.plan(scene, seed=0)
    am = arm_motion(scene, plan)
    observe, rec = recorder(am.motion.assignments[0].frame[:3] + [0.0, 0.0, 0.1])
    t = time.perf_counter()
    r = execute_arm(scene, plan, am.motion, observe=observe, trajectory=am.trajectory)
    rec["r"].save(out)
    print(f"{name}: success {r.success}, goal error {r.goal_error}, {rec['r'].frames} frames, "
          f"{time.perf_counter() - t:.0f} s -> {out}")


def pick_and_place(out: Path) -> None:
    name = "block-xztheta"
    scene = regrasp.load_scene(regrasp.examples.path(name))
    r = pp.pick_place(scene, seed=1)
    target = r.motion.gripper[:, :3].mean(axis=0) - [0.0, 0.0, 0.05]  # the gripper's path, framed
    observe, rec = recorder(target, distance=1.0, azimuth=200, elevation=-20)
    t = time.perf_counter()
    x = pp.execute_pick_place(scene, r, observe=observe)
    rec["r"].save(out)
    print(f"{name} pick-place: success {x.success}, place error {x.place_error}, {rec['r'].frames} frames, "
          f"{time.perf_counter() - t:.0f} s -> {out}")


if __name__ == "__main__":
    folder = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).parent
    pivot(folder / "arm-pivot-single-3d.gif")
    pick_and_place(folder / "arm-pick-place.gif")
