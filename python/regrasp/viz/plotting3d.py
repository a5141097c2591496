"""Figures of 3-D plans: the object in the grasp at each step, pads and the active pusher drawn
(thesis Ch. 4)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..pose import quat_rotate, slerp, tangents
from .plotting import _save, checked_plan, pyplot, save_animation


def _plan3d(scene, plan):
    """The prelude of the 3-D figures: the object's mesh (vertices [m] in the object frame,
    triangles), the plan checked against ``scene`` and its poses (m, unit quaternion) as an array."""
    v, t = scene.surface()
    plan = checked_plan(plan, scene)
    return np.asarray(v, float), np.asarray(t, int), plan, np.asarray(plan.poses, float)


def _at(pose, v) -> np.ndarray:
    """Points ``v`` [m] of the object frame in the gripper frame at ``pose`` (m, unit quaternion)."""
    return quat_rotate(pose[3:], v) + pose[:3]


def _frames3d(poses, names, frames_per_step: int) -> list:
    """The animation's frames: (pose, pusher, step) with the position interpolated linearly and
    the orientation by slerp between consecutive poses (m, unit quaternion)."""
    seq = []
    for k in range(len(poses) - 1):
        a, b = poses[k], poses[k + 1]
        for s in np.linspace(0, 1, frames_per_step, endpoint=k == len(poses) - 2):
            seq.append((np.r_[a[:3] + s * (b[:3] - a[:3]), slerp(a[3:], b[3:], s)], names[k + 1], k + 1))
    return seq or [(poses[0], None, 0)]


def _pads3d(ax, w, r: float, alpha: float) -> None:
    """The two finger pads (discs of radius ``r`` [m] in x-z) where they hold the object's
    vertices ``w`` [m] (gripper frame)."""
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    a = np.linspace(0, 2 * np.pi, 40)
    for sgn in (1, -1):
        y = sgn * np.max(sgn * w[:, 1])
        ax.add_collection3d(Poly3DCollection([np.c_[r * np.cos(a), np.full(40, y), r * np.sin(a)]],
                                             facecolor="0.3", alpha=alpha))


def _pusher3d(ax, scene, name: str, pose, w, size: float) -> None:
    """The active pusher's contact points (red) at object ``pose`` (m, unit quaternion), with the
    object's vertices ``w`` [m] there; a plane also as a translucent square of half side 1.3 ``size`` [m]."""
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    if not scene.is_plane(name):
        pts = _at(pose, scene.pusher_points(name))
    else:  # where the object is lowest along the plane's normal (gripper frame)
        nrm = scene.pusher_normal(name)
        low = (w @ nrm).min()
        pts = w[w @ nrm < low + 1e-6 * size] if not scene.sphere else (pose[:3] - scene.sphere * nrm)[None]
        t1, t2 = tangents(nrm)
        sq = [pts[0] + 1.3 * size * (i * t1 + j * t2) for i, j in ((1, 1), (-1, 1), (-1, -1), (1, -1))]
        ax.add_collection3d(Poly3DCollection([sq], facecolor="tab:red", alpha=0.12))
    ax.scatter(pts[:, 0], pts[:, 1], pts[:, 2], color="tab:red", s=30)


def _axes3d(ax, centre, half: float) -> None:
    """Equal-scale 3-D axes of half-extent ``half`` [m] about ``centre`` [m], labelled, seen from
    the side."""
    for f, m in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), centre):
        f(m - half, m + half)
    ax.set_box_aspect((1, 1, 1))
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m] (grasp axis)")
    ax.set_zlabel("z [m]")
    ax.view_init(elev=18, azim=-60)


def animate_plan3d(scene, plan, path, fps: int = 12, frames_per_step: int = 6) -> Path:
    """A GIF of a 3-D plan: the object moving in the grasp (pads grey, the active pusher's
    contact points red); between poses the position is interpolated linearly and the
    orientation by slerp (``frames_per_step`` frames a step, ``fps`` frames a second)."""
    plt = pyplot()
    from matplotlib.animation import FuncAnimation, PillowWriter
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    from .viewer import marks

    v, t, plan, poses = _plan3d(scene, plan)
    seq = _frames3d(poses, plan.pushers, frames_per_step)
    size = float(np.linalg.norm(v, axis=1).max())
    face = np.where(marks(scene)[:, None] > 0, np.array([0.9, 0.6, 0.2]), np.array([0.56, 0.70, 0.85]))
    fig = plt.figure(figsize=(5.5, 5))
    ax = fig.add_subplot(projection="3d")

    def draw(i):
        ax.cla()
        pose, name, step = seq[i]
        w = _at(pose, v)
        ax.add_collection3d(Poly3DCollection(w[t], facecolor=face, edgecolor="k", linewidth=0.3 if len(t) < 200 else 0.05,
                                             alpha=0.9))
        _pads3d(ax, w, float(scene.pad_radius), 0.6)
        if name:
            _pusher3d(ax, scene, name, pose, w, size)
        _axes3d(ax, (0.0, 0.0, 0.0), 1.1 * size)
        ax.set_title(f"{scene.name}: step {step}/{len(poses) - 1}" + (f", pusher {name}" if name else ""), fontsize=9)

    anim = FuncAnimation(fig, draw, frames=len(seq), interval=1000 / fps)
    return save_animation(anim, fig, path, PillowWriter(fps=fps))


def _runs_text(pushers) -> str:
    """The pushes of a plan as runs of one pusher: ``left x3 -> bottom x2``."""
    runs: list = []
    for name in pushers[1:]:
        if runs and runs[-1][0] == name:
            runs[-1][1] += 1
        else:
            runs.append([name, 1])
    return " -> ".join(f"{n} x{c}" for n, c in runs) or "no pushes"


def plot_plan3d(scene, plan, path, intermediate: int = 3) -> Path:
    """A 3-D plan in one static figure (gripper frame, equal scale): the object's mesh as a
    wireframe at the start, at ``intermediate`` knots between and at the goal (each labelled with
    its step and pusher), the two finger pads, and the plan's pusher runs."""
    plt = pyplot()
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    v, t, plan, poses = _plan3d(scene, plan)
    names, last = plan.pushers, len(poses) - 1
    knots = sorted({0, last, *np.linspace(0, last, intermediate + 2).round().astype(int).tolist()})
    fig = plt.figure(figsize=(7, 6))
    ax = fig.add_subplot(projection="3d")
    cmap = plt.get_cmap("viridis")
    world = {k: _at(poses[k], v) for k in knots}
    for k, w in world.items():
        color = cmap(k / max(last, 1))
        label = "start" if k == 0 else "goal" if k == last else f"step {k} ({names[k]})"
        ax.add_collection3d(Poly3DCollection(w[t], facecolor=(*color[:3], 0.06 if 0 < k < last else 0.15),
                                             edgecolor=color, linewidth=0.4 if len(t) < 400 else 0.1))
        ax.plot([], [], color=color, label=label)
        c = w.mean(axis=0)
        ax.text(c[0], c[1], c[2], label if k in (0, last) else str(k), fontsize=8, color=color)
    pts = np.vstack(list(world.values()))
    _pads3d(ax, world[0], float(scene.pad_radius), 0.5)  # where the fingers hold it at the start
    ax.plot([], [], color="0.3", lw=6, alpha=0.5, label="finger pads")
    _axes3d(ax, (pts.max(axis=0) + pts.min(axis=0)) / 2, 1.2 * (float(np.ptp(pts, axis=0).max()) / 2 or 0.01))
    ax.legend(fontsize=7, loc="upper left")
    status = "plan found" if plan.found else "no plan found (best partial plan)"
    ax.set_title(f"{scene.name}: {status}, {last} steps\npushes: {_runs_text(names)}", fontsize=9)
    return _save(fig, path)
