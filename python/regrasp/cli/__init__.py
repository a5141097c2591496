"""Command line: ``regrasp plan | cone | approx-error | validate | simulate | control | push | bench | demo``.

Exit status: 0 success, 1 the task cannot be done (reason printed), 2 invalid input.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

from ..errors import ArgumentError, GraspError, RegraspError, SceneError
from ..scene.planar import Scene

EXAMPLES = Path(__file__).resolve().parents[3] / "examples"


def _seed(text: str) -> int:
    """argparse type of --seed: a whole number >= 0."""
    try:
        v = int(text)
    except ValueError:
        v = -1
    if not 0 <= v < 2**64:
        raise argparse.ArgumentTypeError(f"a whole number >= 0 (got {text!r})")
    return v


def _floats(text: str, n: int, name: str) -> np.ndarray:
    try:
        v = np.array([float(x) for x in text.split(",")])
    except ValueError:
        raise ArgumentError(f"invalid `{name}`: expected {n} comma-separated numbers, got {text!r}", name)
    if v.shape != (n,) or not np.all(np.isfinite(v)):
        raise ArgumentError(f"invalid `{name}`: expected {n} finite comma-separated numbers, got {text!r}", name)
    return v


def _json_float(x):
    return None if x is None or not np.isfinite(x) else float(x)


def cone_report(scene: Scene, pose, pusher: str, twist=None) -> dict:
    """Everything `regrasp cone --json` prints."""
    hold = scene.hold_grip_force(pose)
    probe = scene.motion_cone(pose, pusher, check_hold=False)
    cone = scene.motion_cone(pose, pusher)  # raises GraspError when it cannot hold
    if twist is None:
        twist = probe.central_twist()
        if not cone.is_line_pusher:
            # a point pusher imposes its contact point's velocity: report the twist it produces
            r = scene.pusher(pusher).points[0]
            u = twist[:2] + twist[2] * np.array([-r[1], r[0]])
            t = cone.point_pusher_twist(u)
            twist = twist if t is None else t
    twist = np.asarray(twist, float)
    rng = probe.grip_force_range(twist) if scene.grip_force is not None else None
    return {
        "scene": scene.name,
        "pusher": pusher,
        "pose": [float(x) for x in pose],
        "generators": cone.generators.tolist(),
        "gravity_free_generators": cone.gravity_free_generators.tolist(),
        "min_grip_force": None if rng is None else _json_float(rng[0]),
        "max_grip_force": None if rng is None else _json_float(rng[1]),
        "min_grip_force_twist": twist.tolist(),
        "grip_force": scene.grip_force,
        "hold_grip_force": hold,
        "hold_ratio": cone.hold_ratio,
        "pusher_kind": "line" if cone.is_line_pusher else "point",
        "twist_metric_length": scene.length,
    }


def cmd_cone(a) -> int:
    scene = _load_planar(a.scene, "cone")
    pose = _floats(a.pose, 3, "--pose")
    twist = None if a.twist is None else _floats(a.twist, 3, "--twist")
    try:
        rep = cone_report(scene, pose, a.pusher, twist)
    except GraspError as e:
        hold = scene.hold_grip_force(pose)
        print(f"regrasp: {e} (holding needs at least {hold:.3f} N per finger)", file=sys.stderr)
        return 1
    if a.plot:
        from ..viz.plotting import plot_motion_cone

        plot_motion_cone(scene.motion_cone(pose, a.pusher), a.plot)
    if a.json:
        print(json.dumps(rep))
    else:
        print(f"motion cone of pusher '{a.pusher}' in scene '{scene.name}' at pose {rep['pose']}")
        print(f"  ({rep['pusher_kind']} pusher; twists [vx, vz, omega] in the object frame, unit in diag(1,1,L^2), L = {scene.length:.4f} m)")
        print("  generators (polyhedral approximation):")
        for g in rep["generators"]:
            print("    [{:+.5f}, {:+.5f}, {:+.4f}]".format(*g))
        print("  gravity-free cone generators:")
        for g in rep["gravity_free_generators"]:
            print("    [{:+.5f}, {:+.5f}, {:+.4f}]".format(*g))
        mn, mx = rep["min_grip_force"], rep["max_grip_force"]
        rng = "none" if mn is None else f"[{mn:.3f}, {'inf' if mx is None else f'{mx:.3f}'}] N"
        print(f"  grip force {scene.grip_force} N per finger; holding needs {rep['hold_grip_force']:.3f} N")
        print(f"  grip forces at which the central gravity-free twist sticks: {rng}")
        if a.plot:
            print(f"  figure: {a.plot}")
    return 0


def cmd_approx_error(a) -> int:
    from ..reference.approx_error import approximation_report, format_report

    from ..scene.spatial import is_3d

    paths = a.scenes or [p for p in sorted(EXAMPLES.glob("*.toml")) if not is_3d(p)]
    scenes = [Scene.load(p) for p in paths]
    forces = _floats(a.forces, len(a.forces.split(",")), "--forces")
    if a.samples < 1:
        raise ArgumentError(f"invalid `--samples`: must be at least 1 (got {a.samples})", "--samples")
    if (forces <= 0).any():
        raise ArgumentError("invalid `--forces`: grip forces must be positive", "--forces")
    skipped = [s.name for s in scenes if s.kind != "grasp"]
    if skipped and not a.json:
        print(f"(skipped {', '.join(skipped)}: no grasp, so no grip force to vary)", file=sys.stderr)
    rows = approximation_report(scenes, tuple(forces), a.samples, a.seed)
    print(json.dumps(rows) if a.json else format_report(rows))
    return 0


def cmd_bench(a) -> int:
    from ..bench import format_results, run

    n = 10_000 if a.quick else a.n
    res = run(n=n, reps=5 if a.quick else 11, baseline_reps=1 if a.quick else 3)
    print(json.dumps(res) if a.json else format_results(res))
    return 0


def cmd_demo(a) -> int:
    from ..planning.plan import plan
    from ..viz.plotting import animate_plan, plot_motion_cone, plot_plan

    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    path = EXAMPLES / "t-shape.toml"
    scene = Scene.load(path)
    t = scene.task
    print(f"demo: regrasp of the T-shaped object ({path.name}) from {t.start.tolist()} to {t.goal.tolist()}")
    p = plan(scene, seed=a.seed)
    p.save(out / "t-shape-plan.json")
    plot_plan(scene, p, out / "t-shape-plan.png")
    animate_plan(scene, p, out / "t-shape-plan.gif")
    run, prev = [], None
    for k in p.path[1:]:
        if k["pusher"] != prev:
            run.append([k["pusher"], 0])
            prev = k["pusher"]
        run[-1][1] += 1
    print(f"  {'plan found' if p.found else 'NO plan found'} in {1e3 * p.planning_time_s:.2f} ms: {len(p.path) - 1} steps, "
          f"{p.switch_overs} switch-overs ({' -> '.join(f'{n} x{c}' for n, c in run)})")
    print(f"  every step sticks along its length by the exact motion-cone test: {p.valid}")
    # the motion cones the first push relies on
    first = p.path[1]["pusher"] if len(p.path) > 1 else scene.pusher_names[0]
    plot_motion_cone(scene.motion_cone(t.start, first), out / f"cone-{first}.png")
    # and the plan replayed in the quasi-static simulator
    from ..sim.quasistatic import replay_plan

    rep = replay_plan(scene, p.to_json())
    from ..viz.plotting import plot_replay

    plot_replay(scene, rep, out / "t-shape-replay.png")
    print(f"  replayed in the quasi-static simulator: final pose {np.round(rep.final_pose, 4).tolist()}, "
          f"error {np.round(1e3 * rep.goal_error[:2], 2).tolist()} mm / {np.degrees(rep.goal_error[2]):.2f} deg, "
          f"{'within' if rep.success else 'outside'} the tolerance")
    print(f"wrote {out}/t-shape-plan.json, t-shape-plan.png, t-shape-plan.gif, t-shape-replay.png, cone-{first}.png")
    return 0 if p.found else 1


def _check_factors(a) -> None:
    """--scale-friction/--scale-grip/--scale-mass must be positive finite factors."""
    for name in ("scale_friction", "scale_grip", "scale_mass"):
        v = getattr(a, name)
        if not (np.isfinite(v) and v > 0):
            raise ArgumentError(f"invalid `--{name.replace('_', '-')}`: must be a positive factor", name)


def _load_planar(path, cmd: str) -> Scene:
    """A planar scene for commands that have no 3-D counterpart (a clear error for a 3-D one)."""
    from ..scene.spatial import is_3d

    if is_3d(path):
        raise ArgumentError(f"invalid `scene`: `regrasp {cmd}` works on planar scenes; {path} is a 3-D scene "
                            "(3-D scenes: plan, simulate, push, control)", "scene")
    return Scene.load(path)


def cmd_validate(a) -> int:
    from ..sim.validation import format_validation, validate

    scene = _load_planar(a.scene, "validate")
    engines = tuple(e.strip() for e in a.engines.split(",") if e.strip())
    if a.workers is not None and a.workers < 1:
        raise ArgumentError("invalid `--workers`: must be at least 1", "--workers")
    res = validate(scene, a.pushes, a.seed, engines=engines, support=a.support, workers=a.workers,
                   ray_address=a.ray, progress=not a.json and a.pushes >= 500)
    print(json.dumps(res) if a.json else format_validation(res))
    return 0


def cmd_simulate(a) -> int:
    from ..sim.quasistatic import load_plan, replay_plan

    from ..scene.spatial import Scene3D, is_3d

    _check_factors(a)
    if a.dt is not None and not (np.isfinite(a.dt) and a.dt > 0):
        raise ArgumentError("invalid `--dt`: must be a positive time step [s]", "--dt")
    if is_3d(a.scene):
        if a.perturb or a.video or a.plot:
            raise ArgumentError("invalid flags for a 3-D scene: --perturb/--video/--plot are planar only "
                                "(3-D: --scale-*, --dt, --json; `regrasp plan --html` for a view)", "scene")
        s3 = Scene3D.load(a.scene)
        plan3 = _read_plan3d(a.plan)
        if a.engine == "mujoco":
            from ..mujoco.spatial import execute_plan3d

            r = execute_plan3d(s3, plan3, a.scale_friction, a.scale_grip, a.scale_mass)
        else:
            r = s3.replay(plan3, dt=0.25 if a.dt is None else a.dt)
        out = {k: r[k] for k in ("engine", "final_pose", "goal_error", "success")}
        out["max_pusher_slip"] = None
        print(json.dumps(out) if a.json else f"{s3.name}: {r['engine']}: {'success' if r['success'] else 'outside the tolerance'}, "
              f"error {np.round(r['goal_error'], 5).tolist()}")
        return 0 if r["success"] else 1
    scene = Scene.load(a.scene)
    plan = load_plan(a.plan)
    if a.engine == "quasistatic":
        rep = replay_plan(scene, plan, dt=0.05 if a.dt is None else a.dt)
    elif a.engine == "mujoco":
        from ..mujoco.planar import Perturbation, execute_plan

        if not (0 <= a.perturb < 1):
            raise ArgumentError("invalid `--perturb`: a spread in [0, 1)", "--perturb")
        base = Perturbation(a.scale_friction, a.scale_grip, a.scale_mass)
        pert = Perturbation.draw(a.perturb, np.random.default_rng(a.seed), base) if a.perturb > 0 else base
        rep = execute_plan(scene, plan, pert)
        if a.video:
            from ..mujoco.planar import animate_execution

            animate_execution(scene, rep, a.video)
    else:
        raise ArgumentError(f"invalid `--engine`: {a.engine!r} (quasistatic or mujoco)", "--engine")
    if a.plot:
        from ..viz.plotting import plot_replay

        plot_replay(scene, rep, a.plot)
    out = rep.to_json()
    if a.json:
        print(json.dumps(out))
    else:
        print(f"{scene.name}: replayed {len(rep.steps)} pushes in the {rep.engine} simulator")
        for k, st in enumerate(rep.steps, 1):
            print(f"  {k:2d} {st['pusher']:12s} slip {1e3 * st['slip']:.3f} mm")
        print(f"  final pose {np.round(rep.final_pose, 5).tolist()}, error to goal {np.round(rep.goal_error, 5).tolist()}: "
              f"{'success' if rep.success else 'outside the tolerance'}; largest pusher slip {1e3 * rep.max_pusher_slip:.3f} mm")
    return 0 if rep.success else 1


def cmd_push3d(a) -> int:
    from ..scene.spatial import Scene3D

    scene = Scene3D.load(a.scene)
    pose = _floats(a.pose, 7, "--pose")
    twist = _floats(a.twist, 6, "--twist")
    tr = scene.simulate_push(pose, a.pusher, twist, a.duration, a.dt)
    return _push_report(scene, a, twist, tr)


def _push_report(scene, a, twist, tr: dict) -> int:
    """What `regrasp push` prints for a simulated push (planar or 3-D)."""
    out = {
        "scene": scene.name, "pusher": a.pusher, "twist": twist.tolist(), "final_pose": tr["pose"][-1].tolist(),
        "max_pusher_slip_speed": float(tr["pusher_slip"].max()),
        "pusher_sticking_share": float(np.mean(tr["pusher_sticking"] == np.maximum(tr["pusher_contacts"], 1))),
        "max_residual": float(tr["residual"].max()),
    }
    if a.json:
        out["t"] = tr["t"].tolist()
        out["pose"] = tr["pose"].tolist()
        if "pusher_wrench" in tr:
            out["pusher_wrench"] = tr["pusher_wrench"].tolist()
        print(json.dumps(out))
    else:
        print(f"{scene.name}: pusher '{a.pusher}' with body twist {twist.tolist()} for {a.duration} s")
        print(f"  final pose {np.round(out['final_pose'], 5).tolist()}; pusher sticks in "
              f"{100 * out['pusher_sticking_share']:.0f}% of the steps; largest constraint residual {out['max_residual']:.1e}")
    return 0


def cmd_push(a) -> int:
    from ..sim.quasistatic import simulate_push
    from ..scene.spatial import is_3d

    if is_3d(a.scene):
        return cmd_push3d(a)
    scene = Scene.load(a.scene)
    pose = _floats(a.pose, 3, "--pose")
    twist = _floats(a.twist, 3, "--twist")
    tr = simulate_push(scene, pose, a.pusher, twist, a.duration, a.dt)
    if a.plot:
        from ..viz.plotting import plot_push

        plot_push(scene, tr, a.pusher, twist, a.plot)
    return _push_report(scene, a, twist, tr)


def _mode_scene(scene: Scene, a) -> Scene:
    """The scene in the cone mode the flags ask for (--robust, --uncertainty, --fixtureless)."""
    if getattr(a, "robust", False) and getattr(a, "fixtureless", False):
        raise ArgumentError("invalid `--robust`: choose --robust or --fixtureless, not both", "--robust")
    if getattr(a, "robust", False) or getattr(a, "uncertainty", None):
        u = None
        if getattr(a, "uncertainty", None):
            v = _floats(a.uncertainty, 4, "--uncertainty")
            u = dict(zip(("pusher_friction", "finger_friction", "grip_force", "mass"), v.tolist()))
        return scene.robust(u)
    if getattr(a, "fixtureless", False):
        return scene.fixtureless()
    return scene


def cmd_control(a) -> int:
    from ..control.loop import Poke, control
    from ..mujoco.planar import Perturbation
    from ..sim.quasistatic import load_plan

    from ..scene.spatial import is_3d

    _check_factors(a)
    if is_3d(a.scene):
        return _control3d(a)
    scene = _load_planar(a.scene, "control")
    plan = load_plan(a.plan)
    if a.horizon < 1:
        raise ArgumentError(f"invalid `--horizon`: must be at least 1 step (got {a.horizon})", "--horizon")
    if not (np.isfinite(a.dt) and a.dt > 0):
        raise ArgumentError("invalid `--dt`: must be a positive control period [s]", "--dt")
    if not (a.noise >= 0 and np.isfinite(a.noise)):
        raise ArgumentError("invalid `--noise`: must be a non-negative standard deviation", "--noise")
    pokes = [Poke.parse(t) for t in a.poke or []]
    start_error = np.zeros(3) if a.start_error is None else _floats(a.start_error, 3, "--start-error")
    ctrl_scene = _mode_scene(scene, a)
    res = control(scene, plan, engine=a.engine, policy="open_loop" if a.open_loop else "mpc", pokes=pokes,
                  start_error=start_error, perturb=Perturbation(a.scale_friction, a.scale_grip, a.scale_mass),
                  controller_scene=ctrl_scene, noise=a.noise, seed=a.seed, dt=a.dt, horizon=a.horizon)
    if a.plot:
        from ..viz.plotting import plot_control

        plot_control(scene, res, a.plot)
    out = res.to_json()
    if a.json:
        print(json.dumps(out))
    else:
        print(f"{scene.name}: {res.policy} in {res.engine}: {'success' if res.success else 'failure'} "
              f"after {res.t[-1]:.1f} s, {res.replans} re-plans, median MPC step {1e3 * res.mpc_step_median_s:.3f} ms; "
              f"final pose {np.round(res.final_pose, 5).tolist()}, error {np.round(res.goal_error, 5).tolist()}"
              + (f" ({res.failure})" if res.failure else ""))
    return 0 if res.success else 1


def _read_plan3d(path) -> dict:
    """A 3-D plan file (JSON), or an error naming --plan."""
    try:
        return json.loads(Path(path).read_text())
    except (OSError, ValueError) as e:
        raise ArgumentError(f"invalid `--plan`: cannot read {path}: {e}", "--plan") from e


def _control3d(a) -> int:
    """`regrasp control SCENE_3D`: the plan executed with feedback by re-planning (see
    :func:`regrasp.scene.spatial.run_plan3d`), or open loop with --open-loop."""
    from ..scene.spatial import Scene3D

    planar = [f for f in ("poke", "start_error", "robust", "uncertainty", "fixtureless", "plot") if getattr(a, f, None)]
    if a.dt != 0.1 or a.horizon != 5:  # the MPC's settings (their defaults): no meaning here
        planar.append("dt" if a.dt != 0.1 else "horizon")
    if planar or a.noise:
        raise ArgumentError("invalid flags for a 3-D scene: 3-D control re-plans from the measured pose "
                            f"(no --{', --'.join(f.replace('_', '-') for f in planar or ['noise'])})", "scene")
    s3 = Scene3D.load(a.scene)
    plan3 = _read_plan3d(a.plan)
    fb = not a.open_loop
    if a.engine == "quasistatic" and (a.scale_friction, a.scale_grip, a.scale_mass) != (1.0, 1.0, 1.0):
        raise ArgumentError("invalid `--scale-*`: the quasi-static 3-D world is the scene itself (MuJoCo only)", "--engine")
    if a.engine == "mujoco":
        from ..mujoco.spatial import execute_plan3d

        r = execute_plan3d(s3, plan3, a.scale_friction, a.scale_grip, a.scale_mass, feedback=fb, seed=a.seed)
    else:
        r = s3.replay(plan3, feedback=fb, seed=a.seed)
    out = {k: r[k] for k in ("engine", "final_pose", "goal_error", "success", "replans")}
    out["policy"] = "replan" if fb else "open_loop"
    if a.json:
        print(json.dumps(out))
    else:
        print(f"{s3.name}: {out['policy']} in {r['engine']}: {'success' if r['success'] else 'failure'}, "
              f"{r['replans']} re-plans; error {np.round(r['goal_error'], 5).tolist()}")
    return 0 if r["success"] else 1


def _plan3d(a) -> int:
    from ..scene.spatial import Scene3D

    if a.robust or a.fixtureless or a.uncertainty or a.propagation != "motion_cone" or a.plot or a.animate:
        raise ArgumentError("invalid flags for a 3-D scene: it plans with the inverse dynamics only "
                            "(no --robust/--fixtureless/--propagation/--plot/--animate; use --html)", "scene")
    scene = Scene3D.load(a.scene)
    start = None if a.start is None else _floats(a.start, 7, "--start")
    goal = None if a.goal is None else _floats(a.goal, 7, "--goal")
    p = scene.plan(start, goal, seed=a.seed, time_limit=a.time_limit)
    if a.out:
        Path(a.out).write_text(json.dumps(p, indent=1))
    if getattr(a, "html", None):
        from ..viz.viewer import write_html

        write_html(scene, p, a.html)
    if a.json:
        print(json.dumps(p))
    else:
        head = "plan found" if p["found"] else f"no plan found ({p['stop_reason']}); best partial plan"
        pushes = [k["pusher"] for k in p["path"][1:]]
        print(f"{scene.name}: {head}: {len(pushes)} steps, {p['switch_overs']} switch-overs, {p['nodes']} nodes, "
              f"{p['solves']} inverse/forward solves, {1e3 * p['planning_time_s']:.1f} ms (seed {p['seed']})")
        print("  pushes: " + " -> ".join(pushes))
    return 0 if p["found"] else 1


def cmd_plan(a) -> int:
    from ..planning.plan import plan
    from ..scene.spatial import is_3d

    if is_3d(a.scene):
        return _plan3d(a)
    scene = Scene.load(a.scene)
    start = None if a.start is None else _floats(a.start, 3, "--start")
    goal = None if a.goal is None else _floats(a.goal, 3, "--goal")
    if scene.task is None and (start is None or goal is None):
        raise ArgumentError("invalid `scene`: it has no [task]; give --start and --goal", "task")
    scene = _mode_scene(scene, a)
    p = plan(scene, start, goal, seed=a.seed, time_limit=a.time_limit, propagation=a.propagation)
    if a.out:
        p.save(a.out)
    if a.plot:
        from ..viz.plotting import plot_plan

        plot_plan(scene, p, a.plot)
    if a.animate:
        from ..viz.plotting import animate_plan

        animate_plan(scene, p, a.animate)
    if a.json:
        print(json.dumps(p.to_json()))
    else:
        head = "plan found" if p.found else f"no plan found ({p.stop_reason}); best partial plan"
        print(f"{scene.name}: {head}: {len(p.path) - 1} steps, {p.switch_overs} switch-overs, "
              f"{p.nodes} nodes, {1e3 * p.planning_time_s:.2f} ms ({p.propagation}, seed {p.seed})")
        run, prev = [], None
        for k in p.path[1:]:
            if k["pusher"] != prev:
                run.append([k["pusher"], 0])
                prev = k["pusher"]
            run[-1][1] += 1
        print("  pushes: " + " -> ".join(f"{n} x{c}" for n, c in run))
        print(f"  every step sticks along its length (exact test): {p.valid} (smallest margin "
              f"{min(p.step_margins, default=0):.3f})")
        if not p.found:
            print(f"  the best partial plan ends {1e3 * p.goal_distance:.2f} mm (metric) from the goal")
    if not p.found:
        print(f"regrasp: no plan found: {p.stop_reason}", file=sys.stderr)
        return 1
    return 0


def build_parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(prog="regrasp", description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="cmd", required=True)

    pl = sub.add_parser("plan", help="plan a regrasp (T-RRT* with motion-cone propagation)")
    pl.add_argument("scene")
    pl.add_argument("--out", metavar="PLAN.json")
    pl.add_argument("--seed", type=_seed, default=0)
    pl.add_argument("--time-limit", type=float, default=10.0)
    pl.add_argument("--propagation", default="motion_cone", choices=["motion_cone", "stable_check", "mncp"])
    pl.add_argument("--start", help="x,z,theta (default: the scene's task)")
    pl.add_argument("--goal", help="x,z,theta (default: the scene's task)")
    pl.add_argument("--plot", metavar="PNG")
    pl.add_argument("--animate", metavar="GIF")
    pl.add_argument("--json", action="store_true")
    pl.add_argument("--robust", action="store_true",
                    help="plan with robust motion cones for the scene's [uncertainty] (or --uncertainty)")
    pl.add_argument("--uncertainty", metavar="P,F,N,M",
                    help="relative spreads of pusher friction, finger friction, grip force, mass (implies --robust)")
    pl.add_argument("--fixtureless", action="store_true",
                    help="plan only with fixtureless-fixturing pushes (invariant to mass, grip force, finger friction)")
    pl.add_argument("--html", metavar="HTML", help="3-D scenes: an interactive 3-D view of the plan (self-contained page)")
    pl.set_defaults(fn=cmd_plan)

    k = sub.add_parser("control", help="track a plan with the MPC (closed loop) in a simulator "
                                          "(3-D scenes: feedback by re-planning from the measured pose)")
    k.add_argument("scene")
    k.add_argument("--plan", required=True)
    k.add_argument("--engine", default="quasistatic", choices=["quasistatic", "mujoco"])
    k.add_argument("--poke", action="append", metavar="T,dx,dz,dtheta",
                   help="displace the object in the grasp at time T [s] (repeatable)")
    k.add_argument("--start-error", metavar="dx,dz,dtheta", help="the object starts this far from the plan's start")
    k.add_argument("--scale-friction", type=float, default=1.0, help="factor on every friction coefficient of the world")
    k.add_argument("--scale-grip", type=float, default=1.0, help="factor on the world's grip force")
    k.add_argument("--scale-mass", type=float, default=1.0, help="factor on the object's mass in the world")
    k.add_argument("--robust", action="store_true", help="constrain the MPC with robust cones (scene's [uncertainty])")
    k.add_argument("--uncertainty", metavar="P,F,N,M", help="spreads for the robust cones (implies --robust)")
    k.add_argument("--fixtureless", action="store_true", help="constrain the MPC with fixtureless-fixturing cones")
    k.add_argument("--open-loop", action="store_true", help="execute the plan open loop instead (for comparison)")
    k.add_argument("--noise", type=float, default=0.0, help="pose measurement noise, standard deviation [m]")
    k.add_argument("--dt", type=float, default=0.1, help="control period [s]")
    k.add_argument("--horizon", type=int, default=5)
    k.add_argument("--seed", type=_seed, default=0)
    k.add_argument("--plot", metavar="PNG", help="planned against executed poses, pokes marked")
    k.add_argument("--json", action="store_true")
    k.set_defaults(fn=cmd_control)

    c = sub.add_parser("cone", help="motion cone of a pusher at a pose")
    c.add_argument("scene")
    c.add_argument("--pose", required=True, help="x,z,theta (m, m, rad)")
    c.add_argument("--pusher", required=True)
    c.add_argument("--twist", help="vx,vz,omega for min_grip_force (default: the central gravity-free twist)")
    c.add_argument("--json", action="store_true")
    c.add_argument("--plot", metavar="PNG")
    c.set_defaults(fn=cmd_cone)

    e = sub.add_parser("approx-error", help="polyhedral approximation vs exact cone, per scene and grip force")
    e.add_argument("scenes", nargs="*", help="scene files (default: every bundled example)")
    e.add_argument("--forces", default="5,20,80", help="grip forces per finger, N")
    e.add_argument("--samples", type=int, default=20000)
    e.add_argument("--seed", type=_seed, default=0)
    e.add_argument("--json", action="store_true")
    e.set_defaults(fn=cmd_approx_error)

    b = sub.add_parser("bench", help="speed probe against numpy baselines")
    b.add_argument("--json", action="store_true")
    b.add_argument("--quick", action="store_true", help="10,000 cones instead of 100,000")
    b.add_argument("-n", type=int, default=100_000)
    b.set_defaults(fn=cmd_bench)

    v = sub.add_parser("validate", help="motion-cone predictions against the simulators")
    v.add_argument("scene")
    v.add_argument("--pushes", type=int, default=2000)
    v.add_argument("--engines", default="quasistatic", help="comma-separated: quasistatic,mujoco")
    v.add_argument("--seed", type=_seed, default=0)
    v.add_argument("--workers", type=int, help="local processes for MuJoCo (default: all cores)")
    v.add_argument("--ray", metavar="ADDRESS", help="spread MuJoCo pushes over a Ray cluster ('local' starts one)")
    v.add_argument("--support", default="points", choices=["points", "limit_surface"],
                   help="quasi-static pads as point sets (default) or as the motion cones' limit surface")
    v.add_argument("--json", action="store_true")
    v.set_defaults(fn=cmd_validate)

    s = sub.add_parser("simulate", help="replay a plan in a simulator")
    s.add_argument("scene")
    s.add_argument("--plan", required=True)
    s.add_argument("--engine", default="quasistatic", choices=["quasistatic", "mujoco"])
    s.add_argument("--dt", type=float, help="quasi-static time step [s] (default 0.05 planar, 0.25 3-D)")
    s.add_argument("--scale-friction", type=float, default=1.0, help="MuJoCo: factor on every friction coefficient")
    s.add_argument("--scale-grip", type=float, default=1.0, help="MuJoCo: factor on the grip force")
    s.add_argument("--scale-mass", type=float, default=1.0, help="MuJoCo: factor on the object's mass")
    s.add_argument("--perturb", type=float, default=0.0,
                   help="MuJoCo: also draw each factor uniformly in [1-P, 1+P] from --seed")
    s.add_argument("--seed", type=_seed, default=0)
    s.add_argument("--video", metavar="GIF|MP4", help="MuJoCo: an animation of the execution")
    s.add_argument("--plot", metavar="PNG")
    s.add_argument("--json", action="store_true")
    s.set_defaults(fn=cmd_simulate)

    p = sub.add_parser("push", help="simulate one push and plot object motion and contact forces")
    p.add_argument("scene")
    p.add_argument("--pose", required=True, help="x,z,theta (3-D scenes: x,y,z,qw,qx,qy,qz)")
    p.add_argument("--pusher", required=True)
    p.add_argument("--twist", required=True,
                   help="pusher body twist vx,vz,omega, object frame at the start (3-D: vx,vy,vz,wx,wy,wz)")
    p.add_argument("--duration", type=float, default=1.0)
    p.add_argument("--dt", type=float, default=0.02)
    p.add_argument("--plot", metavar="PNG")
    p.add_argument("--json", action="store_true")
    p.set_defaults(fn=cmd_push)

    d = sub.add_parser("demo", help="the bundled example end to end, writing its figures")
    d.add_argument("--out", default="out/demo")
    d.add_argument("--seed", type=_seed, default=0)
    d.set_defaults(fn=cmd_demo)
    return ap


def main(argv=None) -> int:
    args = build_parser().parse_args(argv)
    try:
        return args.fn(args)
    except (SceneError, ArgumentError) as e:
        print(f"regrasp: {e}", file=sys.stderr)
        return 2
    except GraspError as e:
        print(f"regrasp: {e}", file=sys.stderr)
        return 1
    except RegraspError as e:
        print(f"regrasp: {e}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
