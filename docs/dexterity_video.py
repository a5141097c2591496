"""One GIF per regrasp action (regrasp.dexterity.actions), each on a bundled object and grasp
where it reaches its intended grasp in the nominal world (the pivots on the bar): docs/action-NAME.gif, close on the hand, in real time (the catches, over in a
fraction of a second, in slow motion: SLOW). Run: python
docs/dexterity_video.py [FOLDER [ACTION ...]] (every action of SHOWN, or the ones named)."""

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
VIEW = {"toss-catch": (150.0, 0.03)}  # (azimuth [deg], the target's lift [m]) where the default's view is blocked
SLOW = {"drop-catch": 8, "toss-catch": 8}  # the actions played slower than real time (captured at FPS times this)
SHOWN = [  # (action, object, grasp, params)
    ("gravity-slide", "box", "g4", {}),
    ("inertial-slide", "box", "g3", {}),
    ("drop-catch", "box", "g7", {}),
    ("toss-catch", "box", "g7", {}),
    ("post-push", "box", "g6", {}),
    ("push-down", "prism", "g0", {}),
    ("table-slide", "box", "g7", {}),
    ("table-pivot", "prism", "g1", {}),
    ("place-repick", "box", "g6", {"target": "g12"}),
    ("topple-repick", "box", "g7", {"target": "g12"}),
    ("grip-pivot", "bar", "g0", {}),
    ("gravity-pivot", "bar", "g9", {}),
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
            slow = SLOW.get(action, 1)
            azimuth, lift = VIEW.get(action, (60.0, -0.02))
            rec["r"] = Recorder(world.robot.model, world.robot.data, FPS * slow, SIZE,
                                Camera(target=np.asarray(target, float) + [0.0, 0.0, lift], distance=0.32,
                                       azimuth=azimuth, elevation=-10), shadows=False, slow=slow)
        rec["r"].capture()

    t = time.perf_counter()
    r = Runner(scene, tax, g, setup).run(observe=observe)
    rec["r"].save(out)
    print(f"{action} on the {name} from {grasp}: meant to reach {setup.intended}, reached {r.outcome}; "
          f"{rec['r'].frames} frames{f' ({SLOW[action]} times slower than real time)' if action in SLOW else ''}, "
          f"{time.perf_counter() - t:.0f} s -> {out}", flush=True)


if __name__ == "__main__":
    folder = Path(sys.argv[1] if len(sys.argv) > 1 else Path(__file__).parent)
    only = set(sys.argv[2:])
    for action, name, grasp, params in SHOWN:
        if only and action not in only:
            continue
        record(action, name, grasp, params, folder / f"action-{action}.gif")
