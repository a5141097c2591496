"""Validation of motion cones at scale (thesis Table 3.2): random pushes — a third drawn
uniformly among the twist directions inside the exact motion cone, a third within 5° of its
boundary, a third in random directions — at random poses where the grasp holds; the exact
motion-cone prediction (stick or slip at the pusher) against what the simulators do.

Engines: ``quasistatic`` (our complementarity simulator, point-set pads) and ``mujoco`` (an
independent engine: a 3 mm push at 10 mm/s; the pusher sticks when, at the contact, the object
moves relative to it by less than 2% of the push — a line pusher's slide or lift-off at either
end, a point pusher's slide — MuJoCo's sticking soft contacts creep by about 1% of a push).
MuJoCo pushes are spread over local processes
(``workers``) or over a Ray cluster (``ray_address``; ``"local"`` starts a local Ray instance).

Two outcomes. Where the support holds the object alone and no contact point of the pusher
moves into the object (each recedes or slides along the surface), the object can stay in the
grasp while the contact opens: a quasi-static outcome that needs no slip at the support. If
the push is also inside the motion cone (the object follows the pusher, the support slipping),
both outcomes solve the quasi-static problem, and a simulator picks one (the complementarity
solver mostly the first for a point pusher, the second for a line pusher's rotations). Such
pushes are counted as *ambiguous*; ``agreement_either`` counts them as agreeing whichever
outcome the simulator picks, ``agreement`` (strict) only when it picks the cone's.
"""

from __future__ import annotations

import multiprocessing
import os
import signal
import socket

import numpy as np

from .. import progress as bars
from ..errors import ArgumentError, RegraspError, check_seed
from ..extras import need
from ..interrupts import deferred
from ..sim.quasistatic import SPEED, support_kwargs
from ..scene.planar import Scene
from ..scene.settings import validation_rings
from ..fields import check_count

#: most random pushes one validation takes (a bound on its time: about 1 ms a push)
MAX_PUSHES = 1_000_000

def _random_pose(scene: Scene, rng, theta=np.pi / 6):
    out = scene.outline
    lo, hi = out.min(axis=0), out.max(axis=0)
    for _ in range(1000):
        c = rng.uniform(lo, hi)
        th = rng.uniform(-theta, theta)
        # pad centre at object point c: t = -R c
        R = np.array([[np.cos(th), -np.sin(th)], [np.sin(th), np.cos(th)]])
        q = np.r_[-(R @ c), th]
        if scene.admissible(q) and (scene.kind != "grasp" or scene.hold_ratio(q) < 0.95):
            return q
    raise ArgumentError("invalid `scene`: no admissible pose found where the grasp holds the object", "scene")


def _rotate_metric(v: np.ndarray, angle: float, rng) -> np.ndarray:
    """``v`` (unit) turned by ``angle`` towards a random perpendicular direction."""
    p = rng.normal(size=3)
    p -= (p @ v) * v
    p /= np.linalg.norm(p)
    return np.cos(angle) * v + np.sin(angle) * p


def sample_push(scene: Scene, pose, pusher: str, kind: str, rng):
    """A pusher motion (m/s, m/s, rad/s) at ``pose`` (m, m, rad) of the given kind ('inside',
    'near', 'random') for the validation."""
    cone = scene.motion_cone(pose, pusher)
    E = cone.pusher_edges
    if cone.is_line_pusher:
        if kind == "inside":
            # uniform over the twist directions inside the exact cone (rejection from a cap
            # around it)
            from ..reference.approx_error import _cap

            G = scene.metric_twist(cone.generators)
            axis = G.sum(axis=0)
            axis = axis / np.linalg.norm(axis)
            radius = min(np.pi, 1.2 * max(np.arccos(np.clip(G @ axis, -1, 1))))
            u = None
            for _ in range(50):
                cand = scene.metric_twist_inv(_cap(axis, radius, 64, rng))
                inside = np.asarray(cone.contains(cand))
                if inside.any():
                    u = cand[np.flatnonzero(inside)[0]]
                    break
            if u is None:
                u = cone.ray(rng.dirichlet(np.ones(len(E))) @ E)
        elif kind == "near":
            i, j = cone.boundary_segments[rng.integers(len(cone.boundary_segments))]
            t = rng.uniform()
            u = cone.ray((1 - t) * E[i] + t * E[j])
            m = scene.metric_twist(u)
            u = scene.metric_twist_inv(_rotate_metric(m / np.linalg.norm(m), np.radians(rng.uniform(0, 5)), rng))
        else:
            m = rng.normal(size=3)
            u = scene.metric_twist_inv(m / np.linalg.norm(m))
        u = u / np.linalg.norm(scene.metric_twist(u)) * SPEED
        return u, bool(cone.contains(u))
    # point pusher: its contact point's velocity
    r = scene.pusher(pusher).points[0]
    pv = lambda g: g[:2] + g[2] * np.array([-r[1], r[0]])  # noqa: E731
    a, b = pv(cone.generators[0]), pv(cone.generators[1])
    a, b = a / np.linalg.norm(a), b / np.linalg.norm(b)
    if kind == "inside":
        s = rng.uniform()
        v = (1 - s) * a + s * b
    elif kind == "near":
        base = a if rng.uniform() < 0.5 else b
        ang = np.radians(rng.uniform(-5, 5))
        v = np.array([[np.cos(ang), -np.sin(ang)], [np.sin(ang), np.cos(ang)]]) @ base
    else:
        ang = rng.uniform(0, 2 * np.pi)
        v = np.array([np.cos(ang), np.sin(ang)])
    v = v / np.linalg.norm(v) * SPEED
    t = cone.point_pusher_twist(v)
    stick = t is not None and bool(cone.contains(t))
    return np.array([v[0], v[1], 0.0]), stick


ENGINES = ("quasistatic", "mujoco", "drake")
#: The simulators measured by the slip at the pusher (:func:`~regrasp.mujoco.push.slip_fraction`),
#: by their names in print, and the share of the push below which a push sticks.
SIMULATORS = {"mujoco": "MuJoCo", "drake": "Drake"}
STICK_RATIO = 0.02
#: fewest quasi-static pushes solved in one call of the core (it solves a call's pushes in parallel)
QS_BATCH = 64
KINDS = ("inside", "near", "random")


def static_alternative(scene: Scene, pusher: str, pose, twist) -> bool:
    """Whether the object can also stay where it is in the grasp under this push (pusher
    motion ``twist`` (m/s, m/s, rad/s), object frame, at ``pose``): the support holds it alone
    and no contact point of the pusher moves into the object (``n·v ≤ 0`` at each, to 1e-9 of the
    speed), so that the contact opens or slides free (see the module notes)."""
    if scene.kind == "grasp" and not scene.hold_ratio(pose) < 1.0:
        return False
    p = scene.pusher(pusher)
    v = np.asarray(twist, float)
    pts = np.asarray(p.points, float).reshape(-1, 2)
    vel = v[:2] + v[2] * np.c_[-pts[:, 1], pts[:, 0]]
    tol = 1e-9 * (np.linalg.norm(v[:2]) + abs(v[2]) * scene.length)
    return bool(np.all(vel @ np.asarray(p.normal, float) <= tol))


def samples(scene: Scene, pushes: int, seed: int, progress: bool = False) -> list:
    """The random pushes: (pusher, kind, pose, twist, predicted stick, ambiguous: predicted
    stick while the object can also stay, :func:`static_alternative`)."""
    rng = np.random.default_rng(seed)
    out = []
    for k in bars.iterate(range(pushes), f"drawing pushes ({scene.name})", unit="push", show=progress):
        pusher = scene.pusher_names[rng.integers(len(scene.pusher_names))]
        pose = _random_pose(scene, rng)
        kind = KINDS[k % 3]
        u, pred = sample_push(scene, pose, pusher, kind, rng)
        out.append((pusher, kind, pose, u, pred, bool(pred) and static_alternative(scene, pusher, pose, u)))
    return out


def _rig(engine: str, scene: Scene, pusher: str):
    """The push rig of a simulator engine (``mujoco`` or ``drake``) for one pusher."""
    if engine == "drake":
        from ..drake.push import DrakePushRig

        return DrakePushRig(scene, pusher)
    from .push import PushRig

    return PushRig(scene, pusher)


def _engine_chunk(scene: Scene, chunk: list, engine: str = "mujoco") -> list:
    """A simulator's slip fractions (:func:`~regrasp.mujoco.push.slip_fraction`) of a chunk of
    (index, pusher, pose, twist); None where the run failed or diverged."""
    rigs, out = {}, []
    for i, pusher, pose, u in chunk:
        if pusher not in rigs:  # building the model: an error here is the caller's, never swallowed
            rigs[pusher] = _rig(engine, scene, pusher)
        try:
            f = rigs[pusher].slip_fraction(pose, u)
            out.append((i, f if np.isfinite(f) else None))
        except (RegraspError, FloatingPointError, ValueError, RuntimeError):  # unsolved, never an answer
            out.append((i, None))
    return out


def _engine_job(job: tuple) -> list:
    return _engine_chunk(*job)


def _ignore_sigint() -> None:
    """A pool worker's signals: Ctrl-C is the parent's to handle; SIGTERM (the pool's terminate)
    ends it at once (not the command's SIGTERM handler, inherited by a fork)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)


def _check_reachable(address: str, timeout: float = 5.0) -> None:
    """An ArgumentError naming ``--ray`` when a Ray head ``[ray://]HOST:PORT`` does not answer a
    TCP connection within ``timeout`` seconds (Ray itself would keep retrying)."""
    if address in ("local", "auto"):
        return
    host, _, port = address.removeprefix("ray://").rpartition(":")
    try:
        socket.create_connection((host, int(port)), timeout=timeout).close()
    except (OSError, ValueError) as e:
        raise ArgumentError(f"invalid `--ray`: no Ray cluster answers at {address!r} ({e})", "--ray") from e


def ray_init(address: str, workers: int):
    """The ``ray`` module, connected to the cluster at ``address`` (``local``: a cluster of
    ``workers`` CPUs started here) unless it is already; an ArgumentError naming ``--ray`` when
    no cluster answers there."""
    ray = need("ray", "ray")
    if not ray.is_initialized():
        _check_reachable(address)
        with deferred():  # a Ctrl-C half-way through would leave the cluster's agents running
            ray.init(address=None if address == "local" else address, include_dashboard=False,
                     log_to_driver=False, num_cpus=workers if address == "local" else None)
    return ray


def _each_chunk(scene: Scene, chunks: list, workers: int, ray_address, take, engine: str = "mujoco") -> None:
    """``take(outcomes)`` of every chunk in ``engine``, run on Ray (``ray_address``), here (one
    worker) or in a process pool."""
    if ray_address is not None:
        ray = ray_init(ray_address, workers)
        try:
            remote = ray.remote(_engine_chunk)
            pending = [remote.remote(scene, c, engine) for c in chunks]
            while pending:
                done, pending = ray.wait(pending, num_returns=1)
                take(ray.get(done[0]))
        except BaseException:
            # stopped (Ctrl-C) or failed: the driver leaves the cluster now, so that Ray's own
            # messages as its tasks are cancelled come before ours, not after
            with deferred():
                ray.shutdown()
            raise
    elif workers <= 1:
        for c in chunks:
            take(_engine_chunk(scene, c, engine))
    else:
        # a Pool's exit terminates its workers at once (Ctrl-C does not wait for running chunks);
        # the workers ignore SIGINT, the parent ends them. Spawned, not forked: a fork copies the
        # caller's whole address space (a large one fails with ENOMEM) and its threads' locks
        with multiprocessing.get_context("spawn").Pool(workers, initializer=_ignore_sigint) as pool:
            for part in pool.imap_unordered(_engine_job, [(scene, c, engine) for c in chunks]):
                take(part)


def _run_engine(scene: Scene, rows: list, workers: int, ray_address, progress: bool, engine: str = "mujoco") -> np.ndarray:
    """Each push's slip fraction in a simulator ``engine`` (NaN: unsolved)."""
    jobs = [(i, r[0], r[2], r[3]) for i, r in enumerate(rows)]
    size = max(1, min(50, len(jobs) // max(4 * workers, 1) or 1))
    chunks = [jobs[k:k + size] for k in range(0, len(jobs), size)]
    result = np.full(len(rows), np.nan)
    # the bar ends before any message (Ctrl-C included)
    with bars.bar(len(jobs), f"{SIMULATORS[engine]} pushes ({scene.name})", unit="push", show=progress) as bar:
        def take(part):
            for i, f in part:
                result[i] = np.nan if f is None else float(f)
            bar.update(len(part))

        _each_chunk(scene, chunks, workers, ray_address, take, engine)
    return result


def _run_quasistatic(scene: Scene, rows: list, support: dict, progress: bool) -> tuple[np.ndarray, np.ndarray]:
    """Whether each push sticks in the quasi-static simulator and whether it was solved: the
    pushes of each pusher in batches (of at least :data:`QS_BATCH`, for the progress bar);
    ``support`` the pad model (:func:`~regrasp.sim.quasistatic.support_kwargs`)."""
    sim, ok = np.zeros(len(rows), bool), np.zeros(len(rows), bool)
    by: dict = {}
    for i, r in enumerate(rows):
        by.setdefault(r[0], []).append(i)
    size = max(QS_BATCH, len(rows) // 50)
    with bars.bar(len(rows), f"quasi-static pushes ({scene.name})", unit="push", show=progress) as bar:
        for p, idx in by.items():
            for k in range(0, len(idx), size):
                part = idx[k:k + size]
                st, _, _, err = scene.push_outcomes(np.array([rows[i][2] for i in part]), p,
                                                         np.array([rows[i][3] for i in part]), support["support"],
                                                         support["rings"], support["points"], support["merge_fingers"])
                sim[part] = st
                ok[part] = [e is None for e in err]
                bar.update(len(part))
    return sim, ok


def _table(pred, sim, ok, mask) -> dict:
    m = mask & ok
    return {
        "predicted_stick_simulated_stick": int((pred & sim & m).sum()),
        "predicted_stick_simulated_slip": int((pred & ~sim & m).sum()),
        "predicted_slip_simulated_stick": int((~pred & sim & m).sum()),
        "predicted_slip_simulated_slip": int((~pred & ~sim & m).sum()),
    }


def validate(scene: Scene, pushes: int = 2000, seed: int = 0, engines=("quasistatic",), support: str | None = None,
             workers: int | None = None, ray_address=None, progress: bool = False, rings: int | None = None) -> dict:
    """Agreement of the exact motion-cone prediction (on the scene's limit surface,
    ``scene.limit_surface``) with each engine (see the module notes); ``support`` the quasi-static
    pad model, "points" or "limit_surface" (default: the core's), ``rings`` the point-set pads'
    rings (default: the core's ``validation_rings``, finer than the simulator's everyday pads)."""
    pushes, seed = check_count(pushes, "pushes", 1, MAX_PUSHES), check_seed(seed)
    if isinstance(engines, str) or not isinstance(engines, (list, tuple)) or not engines:
        raise ArgumentError(f"invalid `engines`: a list of engine names (got {engines!r:.60})", "engines")
    support = support_kwargs(support, rings=validation_rings() if rings is None else rings)
    if workers is not None:
        workers = check_count(workers, "workers", 1, 4096)
    for e in engines:
        if e not in ENGINES:
            raise ArgumentError(f"invalid `engines`: unknown engine {e!r} (available: {', '.join(ENGINES)})", "engines")
    for e in SIMULATORS:
        if e in engines and scene.kind != "grasp":
            raise ArgumentError(f"invalid `engines`: the {SIMULATORS[e]} model is a parallel-jaw grasp; scene "
                                f"{scene.name!r} is a {scene.kind!r} scene (use quasistatic)", "engines")
    if "mujoco" in engines:  # before any work
        need("mujoco", "mujoco")
    if "drake" in engines:
        need("pydrake", "drake")
    if ray_address is not None and set(engines) & set(SIMULATORS):
        need("ray", "ray")
    workers = workers or os.cpu_count() or 1
    rows = samples(scene, pushes, seed, progress)
    pred = np.array([r[4] for r in rows])
    amb = np.array([r[5] for r in rows], bool)
    kind = np.array([r[1] for r in rows])
    out = {"scene": scene.name, "pushes": pushes, "seed": seed, "limit_surface": scene.limit_surface}
    slips: dict = {}
    for engine in engines:
        if engine == "quasistatic":
            sim, ok = _run_quasistatic(scene, rows, support, progress)
            out["support_model"] = support["support"]
            if support["support"] == "points":
                out["rings"] = support["rings"]
        else:
            slips[engine] = _run_engine(scene, rows, workers, ray_address, progress, engine)
            ok = ~np.isnan(slips[engine])
            sim = np.nan_to_num(slips[engine], nan=1.0) < STICK_RATIO
            out[f"slip_{engine}"] = [None if np.isnan(f) else round(float(f), 6) for f in slips[engine]]
        n = int(ok.sum())
        out[f"solved_{engine}"] = n
        out[f"agreement_{engine}"] = float(((pred == sim) & ok).sum() / max(n, 1))
        out[f"ambiguous_{engine}"] = int((amb & ok).sum())
        out[f"agreement_either_{engine}"] = float((((pred == sim) | amb) & ok).sum() / max(n, 1))
        out[f"confusion_{engine}"] = _table(pred, sim, ok, np.ones(pushes, bool))
        out[f"by_sample_kind_{engine}"] = {
            k: {"pushes": int((kind == k).sum()),
                "agreement": float(((pred == sim) & ok & (kind == k)).sum() / max(((kind == k) & ok).sum(), 1))}
            for k in KINDS}
    if len(slips) == 2:
        out["slip_comparison"] = compare_slips(*slips.values(), kind)
    # the names of the first version, for the quasi-static engine
    if "quasistatic" in engines:
        out["solved"] = out["solved_quasistatic"]
        out["by_sample_kind"] = out["by_sample_kind_quasistatic"]
    return out


def compare_slips(a: np.ndarray, b: np.ndarray, kind=None) -> dict:
    """Two simulators' slip fractions of the same pushes (NaN: unsolved) compared: the pushes
    both solved, how often their verdicts agree (:data:`STICK_RATIO`), the median and 90th
    percentile of the difference of their slips (in shares of the push), the rank correlation
    of the slips (Spearman's ρ), and, where one calls the push a stick and the other a slip, the
    median of the larger slip (a small one is a threshold case: both engines barely slip)."""
    ok = ~(np.isnan(a) | np.isnan(b))
    a, b = a[ok], b[ok]
    if len(a) == 0:
        return {"pushes": 0}
    diff = np.abs(a - b)
    va, vb = a < STICK_RATIO, b < STICK_RATIO
    split = va != vb
    rank = lambda x: np.argsort(np.argsort(x, kind="stable"), kind="stable").astype(float)  # noqa: E731
    ra, rb = rank(a), rank(b)
    rho = float(np.corrcoef(ra, rb)[0, 1]) if len(a) > 2 and ra.std() > 0 and rb.std() > 0 else float("nan")
    out = {"pushes": int(len(a)), "verdict_agreement": float((va == vb).mean()),
           "median_abs_difference": float(np.median(diff)), "p90_abs_difference": float(np.percentile(diff, 90)),
           "spearman": rho, "disagreements": int(split.sum()),
           "disagreement_median_larger_slip": float(np.median(np.maximum(a, b)[split])) if split.any() else 0.0}
    if kind is not None:
        k = np.asarray(kind)[ok]
        out["verdict_agreement_by_kind"] = {x: float((va == vb)[k == x].mean()) for x in KINDS if (k == x).any()}
    return out


def format_validation(res: dict) -> str:
    """The validation results of :func:`validate` as text: per engine, the agreement of the
    motion-cone prediction with the simulator."""
    lines = [f"{res['scene']}: {res['pushes']} random pushes, motion cones on the {res['limit_surface']} limit surface"]
    for engine in ENGINES:
        if f"agreement_{engine}" not in res:
            continue
        c = res[f"confusion_{engine}"]
        lines += [
            f"  {engine}: agreement of the motion-cone prediction {100 * res[f'agreement_{engine}']:.1f}% "
            f"({res[f'solved_{engine}']} pushes simulated)",
            f"  {res[f'ambiguous_{engine}']} ambiguous pushes (in the cone, and the object can also stay: no pusher "
            f"point moves into it); either outcome counted as agreeing: {100 * res[f'agreement_either_{engine}']:.1f}%",
            "                         simulated stick   simulated slip",
            f"  predicted stick        {c['predicted_stick_simulated_stick']:15d}   {c['predicted_stick_simulated_slip']:14d}",
            f"  predicted slip         {c['predicted_slip_simulated_stick']:15d}   {c['predicted_slip_simulated_slip']:14d}",
            "  by kind of push: " + ", ".join(f"{k} {100 * v['agreement']:.1f}% of {v['pushes']}"
                                             for k, v in res[f"by_sample_kind_{engine}"].items()),
        ]
    c = res.get("slip_comparison")
    if c and c["pushes"]:
        a, b = [SIMULATORS[e] for e in ENGINES if f"slip_{e}" in res]
        lines += [f"  {a} against {b}, {c['pushes']} pushes both solved: verdicts agree on "
                  f"{100 * c['verdict_agreement']:.1f}%; slip difference median {100 * c['median_abs_difference']:.2f}% "
                  f"(90th percentile {100 * c['p90_abs_difference']:.2f}%) of the push, rank correlation "
                  f"{c['spearman']:.3f}; where they disagree the larger slip is {100 * c['disagreement_median_larger_slip']:.1f}% "
                  f"of the push (median)"]
    return "\n".join(lines)
