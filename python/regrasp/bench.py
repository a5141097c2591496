"""End-to-end speed probe (``regrasp bench``): the Rust core through the Python API against
plain numpy implementations of the same equations, measured in the same run.

Each entry reports the median wall time of the regrasp call, the median of the baseline and
their ratio (baseline / regrasp), plus the largest difference between the two answers.
"""

from __future__ import annotations

import time

import numpy as np

from . import progress
from . import examples as bundled
from .errors import MissingExtraError
from .extras import have, need
from .reference import cones as reference
from .scene.planar import Scene


def _median_time(fn, reps: int) -> float:
    ts = []
    for _ in range(reps):
        t0 = time.perf_counter()
        fn()
        ts.append(time.perf_counter() - t0)
    return float(np.median(ts))


def _random_poses(scene: Scene, n: int, rng) -> np.ndarray:
    out = np.empty((0, 3))
    while len(out) < n:
        q = np.column_stack(
            [rng.uniform(-0.02, 0.02, 2 * n), rng.uniform(-0.035, 0.035, 2 * n), rng.uniform(-0.6, 0.6, 2 * n)]
        )
        out = np.vstack([out, q[scene.admissible(q)]])
    return out[:n]


#: cones per batch, repetitions of the timed regrasp calls and of the slow baselines (``regrasp bench``)
CONES, REPS, BASELINE_REPS = 100_000, 11, 3
#: the settings of :func:`run` for a quick look (``regrasp bench --quick``)
QUICK = {"n": 10_000, "reps": 5, "baseline_reps": 1}


def run(n: int = CONES, reps: int = REPS, baseline_reps: int = BASELINE_REPS, scene_path=None,
        pusher: str = "left") -> dict:
    """Every measurement (see the module notes): the cone batches on ``n`` random poses of the
    scene (default: the low-friction block), then the solver, planner, MuJoCo and MPC probes.
    A baseline that was skipped (its extra not installed) has None as its time and ratio."""
    # on the ellipsoidal limit surface: the numpy baselines implement that model
    scene = Scene.load(scene_path or bundled.path("block-low-friction")).with_limit_surface("ellipsoid")
    rng = np.random.default_rng(0)
    poses = _random_poses(scene, n, rng)
    params = reference.RefParams.from_scene(scene, pusher)
    twists = rng.normal(size=(n, 3)) * np.array([1.0, 1.0, 1.0 / scene.length])
    batch = scene.motion_cones(poses, pusher)
    benchmarks = [
        ("cone batch", lambda: _cone_batch(scene, pusher, params, poses, batch, reps, baseline_reps)),
        ("membership", lambda: _membership(params, poses, twists, batch, reps)),
        ("single cone", lambda: _single_cone(scene, pusher, params, poses[0], reps)),
        ("projection", lambda: _projection(scene, pusher, poses, twists, reps)),
        ("MNCP solver", lambda: _unless_missing("the MNCP solver against IPOPT", lambda: run_mncp(reps=reps))),
        ("MNCP scaling", lambda: _unless_missing("the MNCP solver's scaling against IPOPT", run_mncp_scaling)),
        ("planner", run_planner),
        ("hard plans", run_hard_plans),
        ("limit surfaces", run_limit_surface),
        ("MuJoCo", lambda: _unless_missing("MuJoCo's speed", run_mujoco)),
        ("MPC", lambda: _unless_missing("the MPC step against SciPy", run_mpc)),
        ("3-D planner", run_plan3d),
        ("world motion", run_world_motion),
        ("arm IK", lambda: _unless_missing("the arm's inverse kinematics", run_ik)),
        ("arm steps", lambda: _unless_missing("MuJoCo's speed with the arm", run_arm_steps)),
        ("grasp graph", lambda: _unless_missing("the grasp graph (MuJoCo, the arm)", run_grasp_graph)),
    ]
    results = {}
    with progress.bar(len(benchmarks), "bench", unit="benchmark") as bar:
        for name, measure in benchmarks:
            bar.set_postfix_str(name)
            results.update(measure())
            bar.update(1)
    return results


def _unless_missing(what: str, probe) -> dict:
    """``probe()``, or nothing when it needs an optional dependency that is not installed (said
    on stderr, with the extra that brings it)."""
    try:
        return probe()
    except MissingExtraError as e:
        progress.note(f"bench: {what} skipped: it needs {e.what} (pip install 'regrasp[{e.extra}]')")
        return {}


def _cone_batch(scene: Scene, pusher: str, params, poses, batch, reps: int, baseline_reps: int) -> dict:
    """One batch of n cones: Rust (threads) against a per-cone numpy loop and vectorized numpy."""
    n = len(poses)
    loop = np.array([reference.generators_numpy(params, q) for q in poses[: min(n, 2000)]])
    vec = reference.generators_numpy_batch(params, poses)
    diff = max(np.abs(batch.generators[: len(loop)] - loop).max(), np.abs(batch.generators - vec).max())
    t_rust = _median_time(lambda: scene.motion_cones(poses, pusher), reps)
    t_loop = _median_time(lambda: [reference.generators_numpy(params, q) for q in poses], baseline_reps)
    t_vec = _median_time(lambda: reference.generators_numpy_batch(params, poses), reps)
    return {
        f"cone_batch_{n}": {
            "median_s": t_rust,
            "baseline_median_s": t_loop,
            "ratio": t_loop / t_rust,
            "baseline": "numpy, one cone per call (thesis equations)",
            "n": n,
            "max_abs_diff": float(diff),
        },
        f"cone_batch_{n}_vs_vectorized_numpy": {
            "median_s": t_rust,
            "baseline_median_s": t_vec,
            "ratio": t_vec / t_rust,
            "baseline": "numpy, vectorized over poses (einsum)",
            "n": n,
            "max_abs_diff": float(np.abs(batch.generators - vec).max()),
        },
    }


def _membership(params, poses, twists, batch, reps: int) -> dict:
    """Exact membership of n twists (one per pose)."""
    n = len(poses)
    got = batch.contains(twists)
    ref = reference.classify_numpy_batch(params, poses, twists)
    t_rust = _median_time(lambda: batch.contains(twists), reps)
    t_vec = _median_time(lambda: reference.classify_numpy_batch(params, poses, twists), reps)
    return {f"membership_batch_{n}": {
        "median_s": t_rust,
        "baseline_median_s": t_vec,
        "ratio": t_vec / t_rust,
        "baseline": "numpy, vectorized over poses",
        "n": n,
        "disagreements": int((got != ref).sum()),
    }}


def _single_cone(scene: Scene, pusher: str, params, q0, reps: int, m: int = 2000) -> dict:
    """One cone from Python, call by call."""
    t_one = _median_time(lambda: [scene.motion_cone(q0, pusher).generators for _ in range(m)], reps) / m
    t_np = _median_time(lambda: [reference.generators_numpy(params, q0) for _ in range(m)], reps) / m
    return {"cone_single_call": {
        "median_s": t_one,
        "baseline_median_s": t_np,
        "ratio": t_np / t_one,
        "baseline": "numpy, one cone per call",
        "n": 1,
    }}


def _projection(scene: Scene, pusher: str, poses, twists, reps: int) -> dict:
    """Projection onto the exact cone (no numpy baseline: against the polyhedral projection
    called one by one)."""
    k = min(len(poses), 20_000)
    sub = scene.motion_cones(poses[:k], pusher)
    t_proj = _median_time(lambda: sub.project(twists[:k]), reps)
    t_poly = _median_time(
        lambda: [scene.motion_cone(q, pusher).project_polyhedral(t) for q, t in zip(poses[:500], twists[:500])], 1
    ) * (k / 500)
    return {f"project_exact_batch_{k}": {
        "median_s": t_proj,
        "baseline_median_s": t_poly,
        "ratio": t_poly / t_proj,
        "baseline": "polyhedral projection (NNLS) called one by one from Python",
        "n": k,
    }}


def run_mujoco(steps: int = 4000) -> dict:
    """MuJoCo's speed on the gripper scene (steps per second) beside the quasi-static
    simulator's time for the same push (10 mm at 10 mm/s)."""
    mujoco = need("mujoco", "mujoco")

    from .mujoco.push import PushRig
    from .sim.quasistatic import simulate_push

    scene = Scene.load(bundled.path("block-low-friction"))
    rig = PushRig(scene, "left")
    rig.reset([0.0, 0.0, 0.0])

    def run_steps():
        for _ in range(steps):
            mujoco.mj_step(rig.model, rig.data)

    t_steps = _median_time(run_steps, 3)
    duration = 1.0
    t_mj = _median_time(lambda: rig.push([0, 0, 0], [0.01, 0, 0], duration, settle=0.0, record_dt=duration), 3)
    t_qs = _median_time(lambda: simulate_push(scene, [0, 0, 0], "left", [0.01, 0, 0], duration, 0.05), 3)
    return {
        "mujoco_steps": {
            "median_s": t_steps / steps, "baseline_median_s": None, "ratio": None,
            "baseline": f"none: MuJoCo's own step (timestep {rig.contact.timestep} s: {steps / t_steps:.0f} steps/s)",
            "steps_per_s": steps / t_steps,
        },
        "push_10mm_quasistatic_vs_mujoco": {
            "median_s": t_qs, "baseline_median_s": t_mj, "ratio": t_mj / t_qs,
            "baseline": "the same push in MuJoCo (quasi-static: 20 steps of 50 ms)",
        },
    }


#: the examples whose seed-0 plans `run_world_motion` turns into world motions (default workcells)
WORLD_MOTION_EXAMPLES = ("block-low-friction", "t-shape", "block-xztheta", "pivot-3d", "offset-3d")


def run_world_motion(reps: int = 5, examples=WORLD_MOTION_EXAMPLES) -> dict:
    """Time to turn a plan into the gripper's world-frame motion in its default workcell
    (:func:`regrasp.execution.world_motion`: push assignment, knots, timed samples), per example:
    the median over ``reps`` [s]; issue 15's target is under 100 ms."""
    from .execution import world_motion
    from .planning.plan import plan
    from .scene import load_scene
    from .workcell import default_workcell

    out = {}
    for name in examples:
        scene = load_scene(bundled.path(name))
        p, cell = plan(scene, seed=0), default_workcell(scene)
        t = _median_time(lambda: world_motion(scene, p, cell), reps)
        out[f"world_motion_{name}"] = {"median_s": t, "baseline_median_s": None, "ratio": None,
                                       "baseline": f"none: target < 100 ms ({len(p.poses) - 1} plan steps)"}
    return out


def run_ik(poses: int = 40, reps: int = 3) -> dict:
    """The UR5e + 2F-85's inverse kinematics along a path (:func:`regrasp.robot.ik.ik_path`): the
    gripper from its home pose 1 mm per pose along world x and down; median time per pose [s]."""
    need("mujoco", "robot")  # before mink, which imports it
    need("mink", "robot")
    from .robot.ik import ik_path
    from .robot.model import build

    robot = build()
    q0 = robot.q
    home = robot.tcp_pose(q0)
    path = [np.r_[home[:3] + 1e-3 * k * np.array([1.0, 0.0, -0.5]), home[3:]] for k in range(1, poses + 1)]
    t = _median_time(lambda: ik_path(robot, path, q0), reps)
    return {"ik_path_per_pose": {"median_s": t / poses, "baseline_median_s": None, "ratio": None,
                                 "baseline": f"none: {poses} poses 1.1 mm apart (mink, DAQP; accept 1 mm / 0.01 rad)"}}


def run_arm_steps(steps: int = 1000, reps: int = 3, example: str = "block-3d") -> dict:
    """MuJoCo's speed with the arm (:mod:`regrasp.execution.arm`): the UR5e + 2F-85 holding the
    seed-0 plan's object of ``example`` at the world motion's start in its default workcell, the
    grip loop updated at its period, ``steps`` steps; against the free-flying gripper's model of
    the same motion (:mod:`regrasp.execution.free_gripper`) in the same run. Median time per step
    [s] (steps per second: its inverse)."""
    mujoco = need("mujoco", "robot")
    need("mink", "robot")
    from .execution import world_motion
    from .execution.arm import GRIP_PERIOD, build_robot, close_on
    from .execution.free_gripper import build as free_build
    from .mujoco.model import Contact, Rig
    from .planning.plan import plan
    from .robot.ik import solve_ik
    from .scene import load_scene
    from .pose import compose, inverse

    scene = load_scene(bundled.path(example))
    motion = world_motion(scene, plan(scene, seed=0))
    robot, body, geoms, tcp = build_robot(scene, motion)
    robot.set_q(solve_ik(robot, compose(motion.gripper[0], tcp), robot.kind.home))
    m, d = robot.model, robot.data
    jq = m.jnt_qposadr[m.body_jntadr[body]]
    d.qpos[jq:jq + 7] = compose(robot.tcp_pose(), inverse(tcp), motion.in_hand[0])
    mujoco.mj_forward(m, d)
    grip = close_on(robot, body, geoms, float(motion.grip_force[0]))
    grip.period = GRIP_PERIOD

    def arm():
        for _ in range(steps):
            grip.update()
            mujoco.mj_step(m, d)

    rig = Rig(free_build(scene, motion), Contact(), float(motion.grip_force[0]))

    def free():
        for _ in range(steps):
            rig.step()

    t, base = _median_time(arm, reps) / steps, _median_time(free, reps) / steps
    return {"arm_step": {"median_s": t, "baseline_median_s": base, "ratio": t / base,
                         "baseline": f"the free-flying gripper's model of the same motion ({example}); "
                                     f"{1 / t:,.0f} steps/s with the arm"}}


def _mpc_qp_scipy(scene: Scene, q, steps, targets, settings: dict):
    """The MPC's QP (see crates/regrasp-core/src/control/mpc.rs) solved by scipy's SLSQP: the
    baseline; ``settings`` the MPC's (``_core.mpc_defaults()``)."""
    minimize = need("scipy.optimize", "reference").minimize

    speed, dt = settings["speed"], settings["dt"]
    stage, terminal, effort = settings["stage_weight"], settings["terminal_weight"], settings["effort_weight"]
    L = scene.length
    ds = speed * dt
    gens = [np.asarray(st["generators"]) for st in steps]
    sizes = [len(g) for g in gens]
    n = sum(sizes)
    offs = np.cumsum([0] + sizes[:-1])
    B = np.zeros((3, n))
    T = []
    for i, g in enumerate(gens):
        th = q[2] if i == 0 else targets[i - 1][2]
        c, s_ = np.cos(th), np.sin(th)
        for k, v in enumerate(g):
            B[:, offs[i] + k] = [c * v[0] - s_ * v[1], s_ * v[0] + c * v[1], L * v[2]]
        T.append(scene.metric_twist(g) if len(g) else np.zeros((0, 3)))
    q0 = np.array([q[0], q[1], L * q[2]]) / ds
    P = 2 * effort * np.eye(n)
    c = np.zeros(n)
    for i, t in enumerate(targets[:len(gens)]):
        w = terminal if i + 1 == len(gens) else stage
        up = offs[i] + sizes[i]
        M = np.zeros((3, n))
        M[:, :up] = B[:, :up]
        e0 = q0 - np.array([t[0], t[1], L * t[2]]) / ds
        P += 2 * w * M.T @ M
        c += 2 * w * M.T @ e0
    cons = [{"type": "ineq", "fun": (lambda a, i=i: 1.0 - np.sum((a[offs[i]:offs[i] + sizes[i]] @ T[i]) ** 2))}
            for i in range(len(gens)) if sizes[i]]
    r = minimize(lambda a: 0.5 * a @ P @ a + c @ a, np.zeros(n), jac=lambda a: P @ a + c, bounds=[(0, 10)] * n,
                 constraints=cons, method="SLSQP", options={"ftol": 1e-10, "maxiter": 200})
    return r.x * speed


def run_mpc(reps: int = 200) -> dict:
    """One MPC step called from Python (Rust: closest knot, cones of the horizon, the QP with
    clarabel, the exact check; wall time of the call) against the same QP solved by scipy's SLSQP (the QP alone, generators given)."""
    from . import _core
    from .planning.plan import plan

    out = {}
    for name in ("block-high-friction", "t-shape"):
        scene = Scene.load(bundled.path(name))
        p = plan(scene, seed=0)
        poses = p.poses.tolist()
        q = (np.asarray(poses[0]) + [0.0005, -0.0005, 0.01]).tolist()
        times = []
        for _ in range(reps):
            m = _core.Mpc(scene._core, poses, p.pushers)
            t0 = time.perf_counter()  # wall time of the call from Python (bindings included)
            m.step(q)
            times.append(time.perf_counter() - t0)
        m = _core.Mpc(scene._core, poses, p.pushers)
        steps, _ = m.solve_qp(q, 0)
        knots = np.asarray(m.knots)
        targets = [knots[min(1 + i, len(knots) - 1)] for i in range(len(steps))]
        t_base = _median_time(lambda: _mpc_qp_scipy(scene, q, steps, targets, _core.mpc_defaults()), 5)
        t = float(np.median(times))
        out[f"mpc_step_{name}"] = {
            "median_s": t, "baseline_median_s": t_base, "ratio": t_base / t,
            "baseline": "the same QP alone (generators given) with scipy SLSQP",
        }
    return out


PLANNED_3D = ("offset-3d", "light-side-3d", "pivot-single-3d", "pivot-3d", "block-3d", "prism-3d", "ball-roll-3d",
              "pivot-90-3d", "offset-pivot-3d", "bracket-pivot-3d")


def run_plan3d(seeds: int = 10, examples=PLANNED_3D) -> dict:
    """3-D planning (T-RRT* over SE(3), inverse-dynamics steps): median planning time over
    ``seeds`` seeds per example, against the same search with each of its solves made by the
    IPOPT reference (the thesis' approach; estimated as solves x the median IPOPT time of the
    plan's first step solved forward, measured in the same run)."""
    from .reference import mncp as mncp_reference
    from .scene.spatial import Scene3D

    out = {}
    for name in examples:
        s = Scene3D.load(bundled.path(name))
        runs = [s.plan(seed=k, time_limit=60.0) for k in range(seeds)]
        t = float(np.median([first_time(r) for r in runs]))
        solves = float(np.median([r.solves for r in runs]))
        # the first step of the first plan, solved forward by IPOPT (the pusher moving with it)
        first = runs[0]
        p = s.quasistatic_problem(first.poses[0], first.pushers[1], 1.0)
        u = first.pusher_twists[1]
        times = []
        for _ in range(3 if have("casadi") else 0):  # the IPOPT baseline needs regrasp[reference]
            try:
                times.append(mncp_reference.solve(p, pusher_twist=u).solve_time_s)
            except Exception:  # noqa: BLE001 - a failed reference solve is left out
                pass
        t_ipopt = float(np.median(times)) if times else 0.0
        t_base = solves * t_ipopt if times else None  # None: skipped (valid JSON, not NaN)
        out[f"plan3d_{name}"] = {
            "median_s": t, "baseline_median_s": t_base, "ratio": None if t_base is None else t_base / max(t, 1e-9),
            "baseline": f"the same search with IPOPT solves ({solves:.0f} solves x {1e3 * t_ipopt:.1f} ms)"
                        if times else "IPOPT baseline skipped: " + ("every reference solve failed" if have("casadi")
                                                                    else "pip install 'regrasp[reference]'"),
            "found": sum(r.found for r in runs), "n": seeds, "median_solves": solves,
            "switch_overs": float(np.median([r.switch_overs for r in runs])),
        }
    return out


PLANNED = ("block-low-friction", "block-high-friction", "block-xztheta", "t-shape", "block-tilted-gripper")


def run_planner(seeds: int = 10, time_limit: float = 30.0, examples=PLANNED) -> dict:
    """The planner table (thesis Table 4.2): median planning time [s] over ``seeds`` seeds (each
    run stopped at ``time_limit`` [s]) for each
    example and each propagation, measured in the same run, with the baselines' ratios."""
    from .planning.plan import plan

    out = {}
    for name in examples:
        scene = Scene.load(bundled.path(name))
        stats = {}
        for prop in ("motion_cone", "stable_check", "mncp"):
            runs = [plan(scene, seed=k, propagation=prop, time_limit=time_limit) for k in range(seeds)]
            stats[prop] = {
                "median_s": float(np.median([first_time(r) for r in runs])),
                "found": sum(r.found for r in runs),
                "valid": sum(r.found and r.valid for r in runs),
                "switch_overs": float(np.median([r.switch_overs for r in runs])),
                "nodes": float(np.median([r.nodes for r in runs])),
            }
        mc = stats["motion_cone"]
        for prop in ("stable_check", "mncp"):
            b = stats[prop]
            out[f"plan_{name}_vs_{prop}"] = {
                "median_s": mc["median_s"],
                "baseline_median_s": b["median_s"],
                "ratio": b["median_s"] / max(mc["median_s"], 1e-9),
                "baseline": f"same T-RRT*, {prop} propagation",
                "n": seeds,
                "found": mc["found"], "baseline_found": b["found"],
                "valid": mc["valid"], "baseline_valid": b["valid"],
                "switch_overs": mc["switch_overs"], "baseline_switch_overs": b["switch_overs"],
            }
    return out


#: the examples whose plans :func:`run_limit_surface` times on each limit surface
LIMIT_SURFACE_PLANS = PLANNED + ("hard/u-shape", "hard/point-pushers", "hard/thin-bar")


def run_limit_surface(seeds: int = 100, time_limit: float = 30.0, examples=LIMIT_SURFACE_PLANS) -> dict:
    """The planner on the exact limit surface against the ellipsoid, measured in the same run:
    per example the median time to a first plan [s] over ``seeds`` seeds on each, and their
    ratio, baseline over regrasp as everywhere in the bench (issue 17's target: above 0.5).
    The time to a first plan is heavy-tailed (t-shape: p90 1.7x the median), so the median of
    10–20 seeds moves by ±15% with the seeds drawn: hence 100 (about a minute in all)."""
    from .planning.plan import plan

    out = {}
    for name in examples:
        scene = Scene.load(bundled.ROOT / f"{name}.toml")
        med = {}
        found = {}
        for model in ("true", "ellipsoid"):
            s = scene.with_limit_surface(model)
            runs = [plan(s, seed=k, time_limit=time_limit) for k in range(seeds)]
            med[model] = float(np.median([first_time(r) for r in runs]))
            found[model] = sum(r.found for r in runs)
        out[f"limit_surface_plan_{name.replace('/', '_')}"] = {
            "median_s": med["true"], "baseline_median_s": med["ellipsoid"],
            "ratio": med["ellipsoid"] / max(med["true"], 1e-9),
            "baseline": "the same planner on the ellipsoidal limit surface",
            "n": seeds, "found": found["true"], "baseline_found": found["ellipsoid"],
        }
    return out


#: issue 18's hard planar scenes (``regrasp/examples/hard/``, ``benches/scenes/`` in a clone)
HARD = tuple(sorted(p.stem for p in (bundled.ROOT / "hard").glob("*.toml")))
#: issue 18's targets for the hard scenes: the median and the 90th percentile of the time to a first plan [s]
HARD_TARGETS = (0.05, 0.2)


def first_time(r) -> float:
    """The time to the first plan [s] (before the anytime refinement), else the planning time."""
    return r.first_time_s if r.first_time_s is not None else r.planning_time_s


def run_hard_plans(seeds: int = 20, time_limit: float = 10.0, names=HARD) -> dict:
    """The hard planar scenes (:data:`HARD`): per scene, ``seeds`` plans (each stopped at
    ``time_limit`` [s]); the median and 90th percentile of the planning time (the time to the first
    plan, or to the answer "unreachable"), how many found a plan, how many of those pass the exact
    test along every step, how many were answered unreachable, the switch-overs (median, and the
    fewest over the seeds) of the final plans and (median) of the first ones, and the median time
    with the anytime refinement. No baseline: the targets are :data:`HARD_TARGETS`."""
    from .planning.plan import plan

    out = {}
    for name in names:
        scene = Scene.load(bundled.ROOT / "hard" / f"{name}.toml")
        runs = [plan(scene, seed=k, time_limit=time_limit) for k in range(seeds)]
        t = np.array([first_time(r) for r in runs])
        found = [r for r in runs if r.found]
        switch = [r.switch_overs for r in found]
        first_switch = [r.first_switch_overs for r in found]
        median, p90 = float(np.median(t)), float(np.percentile(t, 90))
        refused = sum(r.stop_reason == "unreachable" for r in runs)
        out[f"hard_{name}"] = {
            "median_s": median, "p90_s": p90, "n": seeds, "found": len(found),
            "valid": sum(bool(r.valid) for r in found), "unreachable": refused,
            "switch_overs": float(np.median(switch)) if switch else None, "best_switch_overs": min(switch, default=None),
            "first_switch_overs": float(np.median(first_switch)) if first_switch else None,
            "refined_median_s": float(np.median([r.planning_time_s for r in runs])),
            "baseline_median_s": None, "ratio": None,
            "baseline": f"found {len(found)}/{seeds}, unreachable {refused}, "
                        f"p90 {p90 * 1e3:.1f} ms (targets: median < {HARD_TARGETS[0] * 1e3:.0f} ms, p90 < "
                        f"{HARD_TARGETS[1] * 1e3:.0f} ms), switch-overs {np.median(switch) if switch else '-'} "
                        f"(best {min(switch, default='-')})",
        }
    return out


def run_mncp(reps: int = 11, ref_reps: int = 3) -> dict:
    """One instantaneous quasi-static solve (two finger patches of 4 points, a line pusher):
    the Rust solver against the IPOPT reference on the same problem, for a push that sticks, one
    that slides and one that separates."""
    from .reference import mncp as mncp_reference

    scene = Scene.load(bundled.path("block-low-friction"))
    p = scene.quasistatic_problem([0.0, 0.0, 0.0], "left", "points", 0, 4, False, None, None)
    out = {}
    for name, u in (("stick", [0.01, 0.0, 0.0]), ("slide", [0.002, 0.01, 0.0]), ("separate", [-0.01, 0.0, 0.2])):
        fast = p.solve_forward(u)
        ref = mncp_reference.solve(p, pusher_twist=u)
        m = 200
        t_fast = _median_time(lambda: [p.solve_forward(u) for _ in range(m)], reps) / m
        # IPOPT's own solve time (the casadi model is built outside it)
        t_ref = float(np.median([mncp_reference.solve(p, pusher_twist=u).solve_time_s for _ in range(ref_reps)]))
        out[f"mncp_forward_{name}"] = {
            "median_s": t_fast,
            "baseline_median_s": t_ref,
            "ratio": t_ref / t_fast,
            "baseline": "IPOPT solve (casadi), the thesis' NLP",
            "n": 1,
            "max_abs_twist_diff": float(np.abs(fast["twist"] - ref.twist).max()),
            "residual_fast": fast["max_residual"],
            "residual_reference": ref.max_residual,
        }
    return out


#: Finger contact points (both fingers together) of :func:`run_mncp_scaling`.
SCALING_POINTS = (8, 32, 128, 512, 1024)

#: The pusher twists of :func:`run_mncp_scaling` (the block's left line pusher): a push that
#: sticks, one that slides, one that separates.
SCALING_PUSHES = (("stick", [0.01, 0.0, 0.0]), ("slide", [0.002, 0.01, 0.0]), ("separate", [-0.01, 0.0, 0.2]))


def run_mncp_scaling(points=SCALING_POINTS, reps: int = 5) -> dict:
    """The forward complementarity solve as the finger pads get more contact points (the block of
    ``block-low-friction`` in two pads of ``points / 2`` points each, pushed by its left line
    pusher): the median time of a push that sticks, slides and separates, against IPOPT's own
    solve time (casadi's model build excluded) on the sliding one, in the same run; each row also
    gives the largest twist difference between the two. The entry's time is the sliding solve at
    512 points (or the largest size given)."""
    from .reference import mncp as mncp_reference

    scene = Scene.load(bundled.path("block-low-friction"))
    rows = []
    for n in points:
        p = scene.quasistatic_problem([0.0, 0.0, 0.0], "left", "points", 0, max(1, n // 2), False, None, None)
        row = {"points": int(n)}
        for name, u in SCALING_PUSHES:
            m = max(1, 200 // n)
            row[f"{name}_s"] = _median_time(lambda: [p.solve_forward(u) for _ in range(m)], reps) / m
        u = dict(SCALING_PUSHES)["slide"]
        ref = mncp_reference.solve(p, pusher_twist=u)
        row["ipopt_s"] = float(ref.solve_time_s)
        row["ratio_ipopt"] = row["ipopt_s"] / row["slide_s"]
        row["max_abs_twist_diff"] = float(np.abs(p.solve_forward(u)["twist"] - ref.twist).max())
        rows.append(row)
    at = next((r for r in rows if r["points"] == 512), rows[-1])
    return {"mncp_scaling": {
        "median_s": at["slide_s"], "baseline_median_s": at["ipopt_s"], "ratio": at["ratio_ipopt"],
        "baseline": f"IPOPT (casadi) on the sliding push at {at['points']} finger points; rows: "
                    + ", ".join(f"{r['points']}: {r['slide_s'] * 1e3:.3g} ms vs {r['ipopt_s'] * 1e3:.3g} ms" for r in rows),
        "rows": rows,
    }}


def run_grasp_graph(trials: int = 3, name: str = "prism", workers: int = 1) -> dict:
    """The grasp graph of bundled object ``name`` (:func:`regrasp.dexterity.graph.build_graph`)
    with ``trials`` runs per edge in ``workers`` processes (its time and throughput, in the
    baseline's note), and one trial of its first edge in the model compiled once per edge and
    reset (as the graph runs them) against the same trials each in a freshly compiled world (with
    its IK) in the same run: median time per trial [s]."""
    need("mujoco", "robot")
    need("mink", "robot")
    need("networkx", "robot")
    from .dexterity.actions import action
    from .dexterity.graph import Settings, _object, build_graph, edges_to_measure, fitting, perturbations
    from .dexterity.objects import object_path
    from .dexterity.trial import Runner

    path = str(object_path(name))
    t0 = time.perf_counter()
    g = build_graph(path, Settings(trials=trials), workers=workers)
    build = time.perf_counter() - t0
    n = sum(e.trials for e in g.edges)
    scene, tax, obj = _object(path)
    grasp, act, params = edges_to_measure(obj, Settings(trials=trials), fitting(scene, tax))[0]
    setup = action(act).setup(obj, tax.grasp(grasp), params)
    worlds = perturbations(Settings(trials=trials + 1), "bench")
    runner = Runner(scene, tax, tax.grasp(grasp), setup)
    runner.run(worlds[0])  # compiled and its path solved once
    reused = [runner.run(p).seconds for p in worlds[1:]]
    fresh = [Runner(scene, tax, tax.grasp(grasp), setup).run(p).seconds for p in worlds[1:]]
    t, base = float(np.median(reused)), float(np.median(fresh))
    return {"grasp_graph_trial": {"median_s": t, "baseline_median_s": base, "ratio": t / base,
                                  "baseline": f"a trial ({grasp} {act}) in a freshly compiled world with its IK; the "
                                              f"{name}'s whole graph: {len(g.edges)} edges, {n} trials in {build:.1f} s "
                                              f"with {workers} worker(s), {n / build:.2f} trials/s"}}


def format_results(res: dict) -> str:
    """The benchmark results of :func:`run` as a table: one row per benchmark, with regrasp's time,
    the baseline's and their ratio (``-`` for a skipped baseline, or a row without one)."""
    lines = [f"{'benchmark':42s} {'regrasp':>12s} {'baseline':>12s} {'ratio':>9s}  baseline"]
    for name, r in res.items():
        base, ratio = r["baseline_median_s"], r["ratio"]
        base_text = f"{'-':>12s}" if base is None else f"{base * 1e3:10.3f}ms"
        ratio_text = f"{'-':>9s}" if ratio is None else f"{ratio:8.1f}x"
        lines.append(f"{name:42s} {r['median_s'] * 1e3:10.3f}ms {base_text} {ratio_text}  {r['baseline']}")
    return "\n".join(lines)
