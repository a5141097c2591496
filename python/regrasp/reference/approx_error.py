"""How far the polyhedral approximation is from the exact motion cone.

For each pusher, random pusher motions are classified by the exact test and by the polyhedral
approximation (its generators); the report gives the share misclassified each way:

* ``false_inside``: the approximation admits the motion but the pusher would slip (the dangerous
  error a planner inherits from the thesis' approximation);
* ``false_outside``: the approximation rejects a motion that sticks.

Line pushers impose a whole twist: twist directions in the metric space ``[v_com, L omega]``
are drawn uniformly over a spherical cap around the cone (its axis is the mean of the exact
generators, its radius 1.5 times the widest generator's angle from the axis, at most the whole
sphere), so that thin cones are sampled as finely as wide ones. A point pusher imposes only its contact point's velocity:
directions of that velocity are drawn uniformly, the exact outcome follows from the rotation
that balances the moments (``MotionCone.point_pusher_twist``), and the approximation admits the
velocity when it lies between the generators' contact-point velocities.
"""

from __future__ import annotations

import numpy as np

from ..errors import ArgumentError, GraspError, check_seed
from ..scene.planar import Scene
from ..fields import check_count, check_name, check_vector

#: most random pushes one row takes (a bound on its time)
MAX_SAMPLES = 1_000_000


def _point_velocity(g: np.ndarray, r: np.ndarray) -> np.ndarray:
    return np.array([g[0] - g[2] * r[1], g[1] + g[2] * r[0]])


def _cap(axis: np.ndarray, radius: float, n: int, rng) -> np.ndarray:
    """Uniform unit vectors within angle ``radius`` of ``axis``."""
    z = rng.uniform(np.cos(radius), 1.0, n)
    phi = rng.uniform(0, 2 * np.pi, n)
    r = np.sqrt(1 - z * z)
    e1 = np.cross(axis, [1.0, 0.0, 0.0] if abs(axis[0]) < 0.9 else [0.0, 1.0, 0.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(axis, e1)
    return z[:, None] * axis + (r * np.cos(phi))[:, None] * e1 + (r * np.sin(phi))[:, None] * e2


def approximation_error(scene: Scene, pusher: str, pose=None, samples: int = 20000, seed: int = 0) -> dict:
    """Misclassification shares of the polyhedral approximation for one pusher at one ``pose``
    ``[x, z, theta]`` (m, m, rad; default: the task's start)."""
    if pose is None and scene.task is None:
        raise ArgumentError("invalid `pose`: the scene has no [task]; give the pose", "pose")
    pose = scene.task.start if pose is None else check_vector(pose, 3, "pose")
    samples, pusher = check_count(samples, "samples", 1, MAX_SAMPLES), check_name(pusher, "pusher")
    rng = np.random.default_rng(check_seed(seed))
    try:
        cone = scene.motion_cone(pose, pusher)
    except GraspError as e:
        return {"pusher": pusher, "error": str(e)}
    if cone.is_line_pusher:
        G = scene.metric_twist(cone.generators)
        axis = G.sum(axis=0)
        axis = axis / np.linalg.norm(axis) if np.linalg.norm(axis) > 1e-9 else G[0]
        radius = min(np.pi, 1.5 * max(np.arccos(np.clip(G @ axis, -1, 1))))
        d = _cap(axis, radius, samples, rng)
        tw = scene.metric_twist_inv(d)
        exact = np.asarray(cone.contains(tw))
        poly = np.asarray(cone.contains_polyhedral(tw))
        kind = "line"
        cap = float(np.degrees(radius))
    else:
        r = scene.pusher(pusher).points[0]
        gens = cone.generators
        a, b = (_point_velocity(g, r) for g in gens)
        ang = rng.uniform(0, 2 * np.pi, samples)
        U = np.column_stack([np.cos(ang), np.sin(ang)])
        exact = np.zeros(samples, bool)
        for k, u in enumerate(U):
            t = cone.point_pusher_twist(u)
            exact[k] = t is not None and bool(cone.contains(t))
        cr = lambda x, y: x[..., 0] * y[..., 1] - x[..., 1] * y[..., 0]  # noqa: E731
        s = np.sign(cr(a, b)) or 1.0
        poly = (s * cr(a, U) >= 0) & (s * cr(U, b) >= 0)
        kind = "point"
        cap = 180.0
    n_in = int(exact.sum())
    fi = int((poly & ~exact).sum())
    fo = int((~poly & exact).sum())
    return {
        "pusher": pusher,
        "kind": kind,
        "samples": samples,
        "cap_radius_deg": cap,
        "exact_inside": n_in,
        "false_inside": fi / samples,
        "false_outside": fo / samples,
        "false_inside_of_cone": fi / max(n_in, 1),
        "false_outside_of_cone": fo / max(n_in, 1),
        "hold_ratio": cone.hold_ratio,
    }


def approximation_report(scenes: list[Scene], forces=(5.0, 20.0, 80.0), samples: int = 20000, seed: int = 0) -> list[dict]:
    """The approximation error of every pusher of each grasp scene, at its task's start pose, for
    each grip force in ``forces`` [N]: one dict a row (see :func:`format_report`)."""
    rows = []
    for sc in scenes:
        if sc.kind != "grasp":
            continue
        for f in forces:
            s = sc.with_grip_force(f)
            for p in s.pusher_names:
                r = approximation_error(s, p, samples=samples, seed=seed)
                r.update(scene=sc.name, grip_force=f)
                rows.append(r)
    return rows


def format_report(rows: list[dict]) -> str:
    """The rows of :func:`approximation_report` as a text table."""
    lines = [
        f"{'scene':22s} {'grip N':>6s} {'pusher':12s} {'kind':5s} {'cap deg':>7s} {'in cone':>8s} "
        f"{'false in':>9s} {'false out':>9s} {'(of cone)':>10s}"
    ]
    for r in rows:
        if "error" in r:
            lines.append(f"{r['scene']:22s} {r['grip_force']:6.0f} {r['pusher']:12s} cannot hold: {r['error'][:60]}")
            continue
        lines.append(
            f"{r['scene']:22s} {r['grip_force']:6.0f} {r['pusher']:12s} {r['kind']:5s} {r['cap_radius_deg']:7.1f} "
            f"{r['exact_inside'] / r['samples']:8.2%} {r['false_inside']:9.3%} {r['false_outside']:9.3%} "
            f"{r['false_inside_of_cone'] + r['false_outside_of_cone']:10.2%}"
        )
    return "\n".join(lines)
