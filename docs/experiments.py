"""The thesis' two pushing experiments (Figs 3-6, 3-7) in the quasi-static complementarity
simulator, with MuJoCo's soft-contact result for the same scene beside it:

* a linear horizontal push at 20 N grip and 10 mm/s (the gripper moves in −X in the world; in
  the grasp the pusher moves +X): with a low-friction pusher the object drifts down in −Z;
* pivoting at 20 N grip and 10°/s, the pusher (the bottom face's line contact) turning about the
  centre of the object's bottom face.

Run `python docs/experiments.py` (after `make build`); it writes docs/fig-3-6-push.png and
docs/fig-3-7-pivot.png and prints the final poses.
"""

from pathlib import Path

import numpy as np

import regrasp
from regrasp.mujoco import push as mujoco_sim
from regrasp.sim import quasistatic
from regrasp.viz.plotting import save_time_figure

ROOT = Path(__file__).resolve().parents[1]


def horizontal_push(out: Path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    text = (ROOT / "examples" / "block-low-friction.toml").read_text()
    fig, ax = plt.subplots(1, 2, figsize=(11, 4))
    rows = []
    for mu, color in (("0.25", "tab:blue"), ("0.05", "tab:red")):
        s = regrasp.Scene.from_toml(text.replace("friction = 0.25", f"friction = {mu}"))
        twist = [0.01, 0.0, 0.0]
        qs = quasistatic.simulate_push(s, [0, 0, 0], "left", twist, 1.5, 0.05)
        mj = mujoco_sim.simulate_push(s, [0, 0, 0], "left", twist, 1.5)
        for a, k, name in ((ax[0], 0, "x"), (ax[1], 1, "z")):
            a.plot(qs["t"], 1e3 * qs["pose"][:, k], color=color, label=f"quasi-static, pusher mu {mu}")
            a.plot(mj["t"], 1e3 * mj["pose"][:, k], ls="--", color=color,
                   label=f"MuJoCo, pusher mu {mu}")
        rows.append((mu, qs["pose"][-1], mj["pose"][-1]))
    ax[0].set_ylabel("object x in the grasp [mm]")
    ax[1].set_ylabel("object z in the grasp [mm]")
    save_time_figure(fig, ax, "horizontal push, 20 N grip, 10 mm/s: the object drifts down (−Z) when the pusher cannot carry its weight\n"
                     "(MuJoCo: soft contact lets it creep down even when rigid Coulomb friction would hold it)", out)
    return rows


def pivot(out: Path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    s = regrasp.Scene.load(ROOT / "examples" / "block-low-friction.toml")
    w = np.radians(10.0)
    c = np.array([0.0, -0.04])  # centre of the bottom face
    twist = [w * c[1], -w * c[0], w]  # rotation about c
    qs = quasistatic.simulate_push(s, [0, 0, 0], "bottom", twist, 3.0, 0.05)
    mj = mujoco_sim.simulate_push(s, [0, 0, 0], "bottom", twist, 3.0)
    fig, ax = plt.subplots(1, 2, figsize=(11, 4))
    ax[0].plot(qs["t"], np.degrees(qs["pose"][:, 2]), label="quasi-static")
    ax[0].plot(mj["t"], np.degrees(mj["pose"][:, 2]), "--", label="MuJoCo")
    ax[0].plot(qs["t"], np.degrees(w * qs["t"]), ":", color="0.5", label="pusher (commanded)")
    ax[0].set_ylabel("object angle in the grasp [deg]")
    for k, name in ((0, "x"), (1, "z")):
        ax[1].plot(qs["t"], 1e3 * qs["pose"][:, k], label=f"quasi-static {name}")
        ax[1].plot(mj["t"], 1e3 * mj["pose"][:, k], "--", label=f"MuJoCo {name}")
    ax[1].set_ylabel("object position in the grasp [mm]")
    save_time_figure(fig, ax, "pivoting at 20 N grip and 10 deg/s about the centre of the bottom face: the pusher slips,"
                     " the object turns about half as far", out)
    return qs["pose"][-1], mj["pose"][-1]


if __name__ == "__main__":
    for mu, q, m in horizontal_push(ROOT / "docs" / "fig-3-6-push.png"):
        print(f"push, pusher mu {mu}: quasi-static {np.round(q, 5).tolist()}  MuJoCo {np.round(m, 5).tolist()}")
    q, m = pivot(ROOT / "docs" / "fig-3-7-pivot.png")
    print(f"pivot: quasi-static {np.round(q, 5).tolist()} ({np.degrees(q[2]):.1f} deg)  "
          f"MuJoCo {np.round(m, 5).tolist()} ({np.degrees(m[2]):.1f} deg)")
