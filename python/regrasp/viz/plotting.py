"""Figures: the motion cone in wrench and twist space (thesis Fig 3-10)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .. import progress
from ..pose import body_twist, integrate_pose
from ..extras import need
from ..errors import ArgumentError
from ..files import atomic_write


def pyplot():
    """``matplotlib.pyplot`` with the non-interactive Agg backend (figures are written to files);
    needs the ``plot`` extra."""
    matplotlib = need("matplotlib", "plot")
    matplotlib.use("Agg")
    return need("matplotlib.pyplot", "plot")


def _lambda(A, Js, wg, p):
    """Positive root of (l u + ug)^T A (l u + ug) = 1, u = Js^-T p (see motion_cone.rs)."""
    JinvT = np.linalg.inv(Js).T
    u, ug = JinvT @ p, JinvT @ wg
    a, b, c = u @ A @ u, 2 * u @ A @ ug, ug @ A @ ug - 1
    return (-b + np.sqrt(b * b - 4 * a * c)) / (2 * a)


def checked_plan(plan, scene):
    """``plan`` (a :class:`~regrasp.Plan`: the drawings take data, they read no file) checked
    against ``scene``."""
    if not callable(getattr(plan, "check_for", None)):
        raise ArgumentError(f"invalid `plan`: a regrasp.Plan (Plan.load reads a file, Plan.from_json a dict; got "
                            f"{type(plan).__name__})", "plan")
    plan.check_for(scene, "plan")
    return plan


def boundary_samples(cone, n: int = 40):
    """Points on the boundary of the exact cone: for each boundary fan of the pusher's friction
    cone, pusher wrench directions p(t), the balancing wrench w_g + lambda p (object frame) and
    the twist ray. Returns a list of (wrenches (n, 3), twists (n, 3)) per fan."""
    A, Js, wg = cone.support_matrices
    E = cone.pusher_edges
    L = cone.scene.length
    S = np.array([1.0, 1.0, 1.0 / L])
    out = []
    for i, j in cone.boundary_segments:
        ei, ej = E[i] * S / np.linalg.norm(E[i] * S), E[j] * S / np.linalg.norm(E[j] * S)
        ws, ts = [], []
        for t in np.linspace(0, 1, n if i != j else 1):
            p = ((1 - t) * ei + t * ej) / S
            ray = cone.ray(p)
            # the wrench set's boundary point: the support's load of the ray (on either limit surface)
            ws.append(cone.classify(ray).support_wrench if ray is not None else wg + _lambda(A, Js, wg, p) * p)
            ts.append(ray)
        out.append((np.array(ws), np.array(ts)))
    return out


def plot_motion_cone(cone, path, title: str | None = None) -> Path:
    """Two 3-D panels: (left) wrench space: the limit surface, the pusher's friction cone shifted
    by gravity and their intersection (the wrench set); (right) twist space: the exact, curved
    motion cone, its polyhedral approximation and the gravity-free cone; beside them a chart of
    ray directions where the difference shows."""
    plt = pyplot()

    fig = plt.figure(figsize=(18, 6))
    samples = boundary_samples(cone)
    _wrench_panel(fig.add_subplot(1, 3, 1, projection="3d"), cone, samples)
    _twist_panel(fig.add_subplot(1, 3, 2, projection="3d"), cone, samples)
    _ray_chart(fig.add_subplot(1, 3, 3), cone, samples)
    q = cone.pose
    fig.suptitle(
        title
        or f"{cone.scene.name}: pusher '{cone.pusher}' at pose [{q[0]:.4f}, {q[1]:.4f}, {q[2]:.3f}]"
        f" — grip {cone.scene.grip_force} N, gravity uses {100 * cone.hold_ratio:.1f}% of the pad friction"
    )
    return _save(fig, path)


def _wrench_metric(scene):
    """Wrenches (rows) in the plotted metric: [f, moment about the COM / L]."""
    L, com = scene.length, scene.com

    def Wm(w):
        w = np.asarray(w, float)
        return np.stack([w[..., 0], w[..., 1], (w[..., 2] - (com[0] * w[..., 1] - com[1] * w[..., 0])) / L], axis=-1)

    return Wm


def _label3d(ax, labels, title: str) -> None:
    """Axis labels, title and legend of a 3-D panel."""
    ax.set_xlabel(labels[0])
    ax.set_ylabel(labels[1])
    ax.set_zlabel(labels[2])
    ax.set_title(title)
    ax.legend(loc="upper left", fontsize=8)


def _wrench_panel(ax, cone, samples) -> None:
    """Wrench space: the limit surface, the pusher's cone shifted by gravity, the wrench set."""
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    Wm = _wrench_metric(cone.scene)
    wg = cone.support_matrices[2]
    # the limit surface {Js^T w}: the support's load of twists in every direction (exact or
    # ellipsoidal, whichever the scene uses)
    uu, vv = np.meshgrid(np.linspace(0, 2 * np.pi, 40), np.linspace(1e-3, np.pi - 1e-3, 20))
    L = cone.scene.length
    sph = np.stack([np.cos(uu) * np.sin(vv), np.sin(uu) * np.sin(vv), np.cos(vv) / L], axis=-1)
    ell = Wm(np.array([[cone.classify(t).support_wrench for t in row] for row in sph]))
    ax.plot_wireframe(ell[..., 0], ell[..., 1], ell[..., 2], color="0.6", linewidth=0.3, alpha=0.5)
    # pusher cone shifted by gravity: apex at w_g
    E = cone.pusher_edges
    reach = 1.3 * np.max(np.linalg.norm(ell.reshape(-1, 3), axis=1))
    apex = Wm(wg)
    for i, j in cone.boundary_segments:
        ei, ej = Wm(E[i]), Wm(E[j])
        ei, ej = ei / np.linalg.norm(ei) * reach, ej / np.linalg.norm(ej) * reach
        ax.add_collection3d(Poly3DCollection([[apex, apex + ei, apex + ej]], alpha=0.15, color="tab:blue"))
    for e in E:
        es = Wm(e)
        ax.plot(*np.stack([apex, apex + es / np.linalg.norm(es) * reach]).T, color="tab:blue", lw=1)
    ax.scatter(*apex, color="k", s=20)
    ax.text(*apex, "  w_g", fontsize=8)
    for k, (ws, _) in enumerate(samples):
        ax.plot(*Wm(ws).T, color="tab:red", lw=2.5, label="wrench set boundary" if k == 0 else None)
    _label3d(ax, ("f_x [N]", "f_z [N]", "tau_com / L [N]"), "wrench space: limit surface, pusher cone + gravity")


def _twist_panel(ax, cone, samples) -> None:
    """Twist space (metric [COM velocity, L omega]): the exact cone, its polyhedral
    approximation and the gravity-free cone."""
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    Tm = cone.scene.metric_twist
    o = np.zeros(3)
    for k, (_, ts) in enumerate(samples):
        ts = Tm(ts)
        tris = [[o, ts[m], ts[m + 1]] for m in range(len(ts) - 1)]
        ax.add_collection3d(Poly3DCollection(tris, alpha=0.12, color="tab:red"))
        ax.plot(*ts.T, color="tab:red", lw=2, label="exact cone (curved)" if k == 0 else None)
    G = Tm(cone.generators)
    for k, g in enumerate(G):
        ax.plot(*np.stack([o, g]).T, color="tab:green", lw=2, label="polyhedral approximation" if k == 0 else None)
    for i, j in cone.boundary_segments:
        if i != j:
            ax.add_collection3d(Poly3DCollection([[o, G[i], G[j]]], alpha=0.12, color="tab:green"))
    for k, g in enumerate(Tm(cone.gravity_free_generators)):
        ax.plot(*np.stack([o, g]).T, color="k", ls="--", lw=1, label="gravity-free cone" if k == 0 else None)
    ax.set_xlim(-1, 1)
    ax.set_ylim(-1, 1)
    ax.set_zlim(-1, 1)
    _label3d(ax, ("v_com,x [m/s]", "v_com,z [m/s]", "L omega [m/s]"), "twist space: motion cone (unit twists)")


def _ray_chart(ax, cone, samples) -> None:
    """A chart of ray directions: angles about the cone's axis (twist space)."""
    Tm = cone.scene.metric_twist
    G, GF = Tm(cone.generators), Tm(cone.gravity_free_generators)
    axis = GF.sum(axis=0)
    axis /= np.linalg.norm(axis)
    # e2: the direction along which the cone spreads most; e1 = axis × e2 (its thin direction)
    off = GF - np.outer(GF @ axis, axis)
    evals, evecs = np.linalg.eigh(off.T @ off)
    e2 = evecs[:, -1]
    e1 = np.cross(axis, e2)

    def proj(r):
        # longitude along the cone (about e1, from the axis) and latitude across it
        r = np.atleast_2d(r)
        r = r / np.linalg.norm(r, axis=1)[:, None]
        return np.degrees(np.column_stack([np.arctan2(r @ e2, r @ axis), np.arcsin(np.clip(r @ e1, -1, 1))]))

    for k, (_, ts) in enumerate(samples):
        p = proj(Tm(ts))
        ax.plot(p[:, 0], p[:, 1], color="tab:red", lw=2.5, label="exact cone" if k == 0 else None)
    for name, Gs, style in (("polyhedral approximation", G, dict(color="tab:green", lw=1.5)),
                            ("gravity-free cone", GF, dict(color="k", ls="--", lw=1))):
        for k, (i, j) in enumerate(cone.boundary_segments):
            if i == j:
                continue
            p = proj(np.stack([Gs[i], Gs[j]]))
            ax.plot(p[:, 0], p[:, 1], label=name if k == 0 else None, **style)
        p = proj(Gs)
        ax.scatter(p[:, 0], p[:, 1], s=12, color=style["color"])
    ax.set_title("chart of ray directions (twist space)")
    ax.set_xlabel("longitude along the cone's widest spread [deg]")
    ax.set_ylabel("latitude across it [deg]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)


def _axes_pose(ax, t, q, label_prefix="", style=None):
    style = style or {}
    ax[0].plot(t, 1e3 * q[:, 0], label=f"{label_prefix}x", **style)
    ax[0].plot(t, 1e3 * q[:, 1], label=f"{label_prefix}z", **style)
    ax[1].plot(t, np.degrees(q[:, 2]), label=f"{label_prefix}theta", **style)


def plot_push(scene, tr: dict, pusher: str, twist, path) -> Path:
    """Object pose (m, m, rad) in the grasp and contact forces [N] over time [s] for one simulated
    push of ``twist`` (m/s, m/s, rad/s); the figure is written to ``path``."""
    plt = pyplot()

    fig, ax = plt.subplots(1, 3, figsize=(15, 4.2))
    t = tr["t"]
    _axes_pose(ax, t, tr["pose"])
    ax[0].set_ylabel("object position in the grasp [mm]")
    ax[1].set_ylabel("object angle in the grasp [deg]")
    wp, ws = tr["pusher_wrench"], tr["support_wrench"]
    ax[2].plot(t, wp[:, 0], label="pusher f_x")
    ax[2].plot(t, wp[:, 1], label="pusher f_z")
    ax[2].plot(t, ws[:, 0], "--", label="fingers f_x")
    ax[2].plot(t, ws[:, 1], "--", label="fingers f_z")
    ax[2].set_ylabel("force on the object (object frame) [N]")
    slip = tr["pusher_slip"] > 1e-6
    for a in ax:
        a.set_xlabel("t [s]")
        a.grid(alpha=0.3)
        a.legend(fontsize=8)
        if slip.any():
            a.fill_between(t, 0, 1, where=slip, color="tab:red", alpha=0.08, transform=a.get_xaxis_transform())
    fig.suptitle(f"{scene.name}: pusher '{pusher}', body twist {np.round(twist, 4).tolist()} "
                 f"(shaded: the pusher slips)")
    return _save(fig, path)


def plot_replay(scene, rep, path, extra=None) -> Path:
    """Planned against executed object pose in the grasp over a replayed plan."""
    plt = pyplot()

    fig, ax = plt.subplots(1, 2, figsize=(11, 4.2))
    _axes_pose(ax, rep.t, rep.planned, "planned ", dict(ls="--", color="0.5"))
    _axes_pose(ax, rep.t, rep.poses, f"{rep.engine} ")
    for name, r in (extra or {}).items():
        _axes_pose(ax, r.t, r.poses, f"{name} ", dict(ls=":"))
    ax[0].set_ylabel("object position in the grasp [mm]")
    ax[1].set_ylabel("object angle in the grasp [deg]")
    return save_time_figure(fig, ax, f"{scene.name}: plan replayed ({'success' if rep.success else 'outside tolerance'}, "
                            f"largest pusher slip {1e3 * rep.max_pusher_slip:.2f} mm)", path, fontsize=7)


def save_time_figure(fig, axes, title: str, path, fontsize: int = 8) -> Path:
    """Time on every x axis, a grid and a legend on each, the title, then :func:`_save`."""
    for a in axes:
        a.set_xlabel("t [s]")
        a.grid(alpha=0.3)
        a.legend(fontsize=fontsize)
    fig.suptitle(title)
    return _save(fig, path)


def _save(fig, path) -> Path:
    """Lays out, writes (creating the folder) and closes a figure."""
    plt = pyplot()

    fig.tight_layout()
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fmt = path.suffix[1:].lower() or "png"
    try:
        atomic_write(path, lambda tmp: fig.savefig(tmp, dpi=110, format=fmt))
    finally:
        plt.close(fig)
    return path


def save_animation(anim, fig, path, writer) -> Path:
    """Writes an animation atomically with ``writer`` (creating the folder) and closes its figure."""
    plt = pyplot()

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    try:
        with progress.bar(None, "animation frames", unit="frame") as bar:
            def advance(i: int, n: int) -> None:
                bar.total = n
                bar.update(1)

            atomic_write(path, lambda tmp: anim.save(str(tmp), writer=writer, progress_callback=advance))
    finally:
        plt.close(fig)
    return path


PUSHER_COLORS = ["tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple", "tab:brown", "tab:pink", "tab:olive"]


def animation_axes(scene, poses):
    """A figure and bare, equal-aspect axes framing the object at every pose of ``poses``
    (m, m, rad) (1 cm margin)."""
    plt = pyplot()

    pts = np.vstack([_object_at(scene, q) for q in poses])
    lo, hi = pts.min(axis=0) - 0.01, pts.max(axis=0) + 0.01
    fig, ax = plt.subplots(figsize=(5, 5 * (hi[1] - lo[1]) / max(hi[0] - lo[0], 1e-9)))
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_aspect("equal")
    ax.set_axis_off()
    return fig, ax


def _object_at(scene, q):
    c, s = np.cos(q[2]), np.sin(q[2])
    R = np.array([[c, -s], [s, c]])
    return scene.outline @ R.T + q[:2]


def _pusher_at(scene, q, name):
    p = scene.pusher(name)
    c, s = np.cos(q[2]), np.sin(q[2])
    R = np.array([[c, -s], [s, c]])
    return p.points @ R.T + q[:2], R @ p.normal


def _used_pushers(pushers, names) -> list[str]:
    """The pushers among ``names`` (the scene's, in its order) that steps ``pushers`` use (the
    legend lists only those)."""
    used = set(pushers[1:])
    return [nm for nm in names if nm in used]


def plot_plan(scene, plan, path) -> Path:
    """The object in the grasp (gripper frame) at the plan's knots, the finger pad, and each
    push coloured by its pusher (thesis Figs 4-11..4-14); beside it the pose over the steps."""
    plt = pyplot()
    from matplotlib.patches import Circle, Polygon

    plan = checked_plan(plan, scene)
    names = scene.pusher_names
    color = {n: PUSHER_COLORS[i % len(PUSHER_COLORS)] for i, n in enumerate(names)}
    poses = plan.poses
    fig, ax = plt.subplots(1, 2, figsize=(13, 5.5), gridspec_kw={"width_ratios": [1.2, 1]})
    a = ax[0]
    n = len(poses)
    for i, q in enumerate(poses):
        last = i in (0, n - 1)
        pusher = plan.pushers[i]
        col = "k" if i == 0 else color[pusher]
        a.add_patch(Polygon(_object_at(scene, q), closed=True, fill=last, alpha=0.15 if last else 0.5,
                            edgecolor=col, facecolor=col, lw=1.5 if last else 0.6))
        if pusher is not None:
            pts, nrm = _pusher_at(scene, q, pusher)
            a.plot(*pts.T, "-o", color=color[pusher], ms=3, lw=3)
    if scene.task is not None:
        a.add_patch(Polygon(_object_at(scene, scene.task.goal), closed=True, fill=False, ls="--", edgecolor="0.3", lw=1.2))
    pad = scene.pad
    if pad is not None:
        a.add_patch(Circle((0, 0), pad[1], color="0.2", alpha=0.6, zorder=5))
    for nm in _used_pushers(plan.pushers, names):
        a.plot([], [], color=color[nm], lw=3, label=f"pusher {nm}")
    a.plot([], [], "k", label="start (filled)")
    a.plot([], [], "--", color="0.3", label="goal")
    a.set_aspect("equal")
    a.autoscale_view()
    a.set_xlabel("x in the gripper frame [m]")
    a.set_ylabel("z in the gripper frame [m]")
    a.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    a.set_title("object in the grasp at the plan's knots (pad in grey)")
    b = ax[1]
    k = np.arange(n)
    b.plot(k, 1e3 * poses[:, 0], "-o", ms=3, label="x [mm]")
    b.plot(k, 1e3 * poses[:, 1], "-o", ms=3, label="z [mm]")
    b.plot(k, np.degrees(poses[:, 2]), "-o", ms=3, label="theta [deg]")
    for i in range(1, n):
        b.axvspan(i - 1, i, color=color[plan.pushers[i]], alpha=0.12, lw=0)
    b.set_xlabel("knot")
    b.legend(fontsize=8)
    b.grid(alpha=0.3)
    b.set_title("pose in the grasp (bands: pusher of each step)")
    steps = f"{n - 1} step" + ("" if n - 1 == 1 else "s")
    switches = f"{plan.switch_overs} switch-over" + ("" if plan.switch_overs == 1 else "s")
    fig.suptitle(f"{scene.name}: {'plan' if plan.found else 'best partial plan'} with {steps}, "
                 f"{switches}, found in {1e3 * plan.planning_time_s:.1f} ms ({plan.propagation})")
    return _save(fig, path)


def animate_plan(scene, plan, path, frames_per_step: int = 6, fps: int = 15) -> Path:
    """A GIF of the plan: the object moving in the grasp, the active pusher drawn in colour."""
    plt = pyplot()
    from matplotlib.animation import FuncAnimation, PillowWriter
    from matplotlib.patches import Circle, Polygon

    names = scene.pusher_names
    color = {n: PUSHER_COLORS[i % len(PUSHER_COLORS)] for i, n in enumerate(names)}
    plan = checked_plan(plan, scene)
    poses, pushers = plan.poses, plan.pushers
    frames = []
    for i in range(1, len(poses)):
        xi = body_twist(poses[i - 1], poses[i])
        for f in range(frames_per_step):
            frames.append((integrate_pose(poses[i - 1], xi, f / frames_per_step), pushers[i]))
    frames.append((poses[-1], pushers[-1]))
    fig, ax = animation_axes(scene, [q for q, _ in frames])
    obj = Polygon(_object_at(scene, frames[0][0]), closed=True, facecolor="0.8", edgecolor="k")
    ax.add_patch(obj)
    if scene.task is not None:
        ax.add_patch(Polygon(_object_at(scene, scene.task.goal), closed=True, fill=False, ls="--", edgecolor="0.4"))
    pad = scene.pad
    if pad is not None:
        ax.add_patch(Circle((0, 0), pad[1], color="0.2", zorder=5))
    (line,) = ax.plot([], [], "-", lw=5)
    title = ax.set_title("")

    def draw(k):
        q, pusher = frames[k]
        obj.set_xy(_object_at(scene, q))
        if pusher is None:
            line.set_data([], [])
        else:
            pts, nrm = _pusher_at(scene, q, pusher)
            if len(pts) == 1:
                pts = np.vstack([pts[0] - 0.004 * np.array([-nrm[1], nrm[0]]), pts[0] + 0.004 * np.array([-nrm[1], nrm[0]])])
            pts = pts - 0.0015 * nrm
            line.set_data(*pts.T)
            line.set_color(color[pusher])
        title.set_text(f"{scene.name}: pusher {pusher or '-'}")
        return obj, line, title

    anim = FuncAnimation(fig, draw, frames=len(frames), blit=False)
    return save_animation(anim, fig, path, PillowWriter(fps=fps))


def plot_control(scene, res, path, extra=None) -> Path:
    """Planned (reference) against executed poses of a controlled run, pokes and re-plans marked
    (like the thesis' Figs 5-8..5-11): x, z and θ over time, and the path in the X–Z plane."""
    plt = pyplot()

    fig, ax = plt.subplots(1, 3, figsize=(15, 4.2))
    _axes_pose(ax[:2], res.t, res.reference, "reference ", dict(ls="--", color="0.5"))
    _axes_pose(ax[:2], res.t, res.poses, f"{res.policy} ({res.engine}) ")
    for name, r in (extra or {}).items():
        _axes_pose(ax[:2], r.t, r.poses, f"{name} ", dict(ls=":"))
    for t, d in res.pokes:
        for a in ax[:2]:
            a.axvline(t, color="tab:red", lw=0.8, alpha=0.6)
        ax[0].annotate("poke", (t, ax[0].get_ylim()[1]), color="tab:red", fontsize=7, va="top")
    rp = [res.t[i] for i, s in enumerate(res.statuses) if s == "replanned"]
    for t in rp:
        for a in ax[:2]:
            a.axvline(t, color="tab:purple", lw=0.8, ls="-.", alpha=0.7)
    ax[0].set_ylabel("object position in the grasp [mm]")
    ax[1].set_ylabel("object angle in the grasp [deg]")
    for a in ax[:2]:
        a.set_xlabel("t [s]")
        a.grid(alpha=0.3)
        a.legend(fontsize=7)
    # the path in the X–Z plane
    a = ax[2]
    a.plot(1e3 * res.reference[:, 0], 1e3 * res.reference[:, 1], "--", color="0.5", label="reference")
    a.plot(1e3 * res.poses[:, 0], 1e3 * res.poses[:, 1], "-", color="tab:blue", label="executed")
    a.plot(1e3 * res.poses[0, 0], 1e3 * res.poses[0, 1], "o", color="tab:blue")
    if scene.task is not None:
        g, tol = scene.task.goal, scene.task.tolerance
        a.add_patch(plt.Rectangle((1e3 * (g[0] - tol[0]), 1e3 * (g[1] - tol[1])), 2e3 * tol[0], 2e3 * tol[1],
                                  color="tab:green", alpha=0.3, label="goal tolerance"))
    a.set_xlabel("x [mm]")
    a.set_ylabel("z [mm]")
    a.set_aspect("equal", adjustable="datalim")
    a.grid(alpha=0.3)
    a.legend(fontsize=7)
    fig.suptitle(f"{scene.name}: {res.policy} in {res.engine} — {'success' if res.success else 'failure'}, "
                 f"{res.replans} re-plans, {len(res.pokes)} pokes" + (f" ({res.failure})" if res.failure else ""))
    return _save(fig, path)
