"""The arm doing a thesis regrasp (Fig 4-5, pivot-single-3d) in its default workcell: the
README's animation docs/arm-pivot-single-3d.gif. Run: python docs/arm_video.py [OUT.gif]"""

import sys
import time
from pathlib import Path

import regrasp
from regrasp.execution.arm import arm_motion, execute_arm
from regrasp.robot.video import Camera, Recorder

NAME = "pivot-single-3d"
FPS = 6  # frames per second of simulated time (the GIF plays in real time)
SIZE = (400, 300)


def main(out: Path) -> None:
    scene = regrasp.load_scene(regrasp.examples.path(NAME))
    plan = regrasp.plan(scene, seed=0)
    am = arm_motion(scene, plan)
    rec: dict = {}

    def observe(robot):
        if "r" not in rec:
            target = am.motion.assignments[0].frame[:3] + [0.0, 0.0, 0.1]  # above the pushing feature
            rec["r"] = Recorder(robot.model, robot.data, FPS, SIZE, Camera(target=target, distance=0.6, azimuth=30,
                                                                          elevation=-10), shadows=False)
        rec["r"].capture()

    t = time.perf_counter()
    r = execute_arm(scene, plan, am.motion, observe=observe, trajectory=am.trajectory)
    rec["r"].save(out)
    print(f"{NAME}: success {r.success}, goal error {r.goal_error}, {rec['r'].frames} frames, "
          f"{time.perf_counter() - t:.0f} s -> {out}")


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).parent / f"arm-{NAME}.gif")
