"""Why the grip pivot misses its grasp: runs it once in the nominal world (the arm in MuJoCo) on a
grasp for lags of 30–70° and turn times of 1.2 and 3 s, and prints the model's turn and grip beside
MuJoCo's turn and where the centre of mass ended in the hand (x, z [mm]) against the target
grasp's. With --all: both gravity pivots, at their defaults, once each in the nominal world on
every grasp of the three bundled objects' graphs they apply to, and where each ended. Usage: python
scripts/pivot-shortfall.py [OBJECT GRASP] (default: prism g2) | --all."""

import sys

import numpy as np

from regrasp import pose as P
from regrasp.dexterity import actions as A
from regrasp.dexterity.graph import _object
from regrasp.dexterity.trial import Runner


def every_grasp() -> None:
    from regrasp.dexterity.graph import FIT, fitting
    from regrasp.dexterity.objects import OBJECTS

    for name in OBJECTS:
        scene, tax, obj = _object(name)
        clear = fitting(scene, tax)
        for g in (g for g in tax.grasps if g.holds and clear[g.name] >= FIT):  # the graph's grasps
            for action in ("gravity-pivot", "grip-pivot"):
                if A.action(action).applies(obj, g) is not None:
                    continue
                s = A.action(action).setup(obj, g)
                r = Runner(scene, tax, g, s).run()
                print(f"{name} {g.name} {action}: meant to reach {s.intended}, reached {r.outcome}", flush=True)


def main() -> None:
    if sys.argv[1:] == ["--all"]:
        return every_grasp()
    name, grasp = (sys.argv[1:3] if len(sys.argv) > 2 else ("prism", "g2"))
    scene, tax, obj = _object(name)
    g = tax.grasp(grasp)
    for lag in (30, 50, 70):
        for T in (1.2, 3.0):
            s = A.action("grip-pivot").setup(obj, g, {"lag": np.radians(lag), "turn_time": T})
            r = Runner(scene, tax, g, s).run()
            got = r.outcome
            if r.pose is not None:
                R = P.quat_matrix(r.pose[3:]) @ P.quat_matrix(g.pose[3:]).T
                com, want = P.transform(r.pose, obj.com), P.transform(tax.grasp(s.intended).pose, obj.com)
                got += (f": turned {np.degrees(np.arctan2(R[2, 0], R[0, 0])):.0f}° (x towards z), centre of mass at "
                        f"{np.round(com[[0, 2]] * 1e3, 1)} mm, {s.intended}'s at {np.round(want[[0, 2]] * 1e3, 1)} mm")
            print(f"lag {lag}°, {T} s: the model turns {np.degrees(s.detail['turn']):.0f}° at {s.detail['grip']:.2f} N "
                  f"to {s.intended}; MuJoCo: {got}", flush=True)


if __name__ == "__main__":
    main()
