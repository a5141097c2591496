"""One GIF per regrasp action (regrasp.dexterity.actions), each on a bundled object and grasp
where it reaches its intended grasp in the nominal world (or, for the pivots, where it was
measured): docs/action-NAME.gif, close on the hand, in real time. Run: python
docs/dexterity_video.py [FOLDER]"""

import sys
import time
from pathlib import Path

import numpy as np

from regrasp.dexterity.actions import ACTIONS, ObjectModel
from regrasp.dexterity.objects import load_object
from regrasp.dexterity.taxonomy import taxonomy_of
from regrasp.dexterity.trial import Runner
from regrasp.robot.video import Camera, Recorder

FPS = 15  # frames per second of simulated time (the GIF plays in real time)
SIZE = (320, 240)
SHOWN = [  # (action, object, grasp, params)
    ("gravity-slide", "box", "g4", {}),
    ("inertial-slide", "box", "g3", {}),
    ("drop-catch", "box", "g7", {}),
    ("toss-catch", "box", "g7", {}),
    ("post-push", "box", "g6", {}),
    ("push-down", "prism", "g0", {}),
    ("table-pivot", "prism", "g1", {}),
    ("place-repick", "box", "g6", {"target": "g12"}),
    ("topple-repick", "box", "g7", {"target": "g12"}),
    ("grip-pivot", "box", "g17", {}),
    ("gravity-pivot", "box", "g17", {}),
]


def record(action: str, name: str, grasp: str, params: dict, out: Path) -> None:
    scene = load_object(name)
    tax = taxonomy_of(scene)
    obj = ObjectModel.of(scene, tax)
    g = tax.grasp(grasp)
    setup = ACTIONS[action].setup(obj, g, params)
    rec: dict = {}

    def observe(world):
        if "r" not in rec:
            target = world.object_pose()[:3]
            rec["r"] = Recorder(world.robot.model, world.robot.data, FPS, SIZE,
                                Camera(target=np.asarray(target, float) - [0.0, 0.0, 0.02], distance=0.32,
                                       azimuth=60, elevation=-10), shadows=False)
        rec["r"].capture()

    t = time.perf_counter()
    r = Runner(scene, tax, g, setup).run(observe=observe)
    rec["r"].save(out)
    print(f"{action} on the {name} from {grasp}: meant to reach {setup.intended}, reached {r.outcome}; "
          f"{rec['r'].frames} frames, {time.perf_counter() - t:.0f} s -> {out}", flush=True)


if __name__ == "__main__":
    folder = Path(sys.argv[1] if len(sys.argv) > 1 else Path(__file__).parent)
    for action, name, grasp, params in SHOWN:
        record(action, name, grasp, params, folder / f"action-{action}.gif")
