"""`regrasp validate`, `regrasp simulate` and `regrasp push`: the simulators."""

from __future__ import annotations

import json

import numpy as np

from .. import progress
from ..scene.settings import DT, quasistatic_defaults, validation_rings
from ..errors import ArgumentError
from ..files import Outputs
from ..planning.plan import POSE_SIZE, Plan
from . import (CANNOT, FIGURE_SUFFIXES, MAX_DURATION, MAX_PUSHES, MAX_STEPS, MAX_WORKERS, OK, pusher_help, VIDEO_SUFFIXES,
               add_command, add_limit_surface, add_scale_options, api_default, add_verbose, check_count, check_number, check_outputs, check_positive,
               check_pusher, execute3d, floats, given, load, load_planar, plural, refuse_flags, runs, rounded, scales, every_friction, seed_arg, error3d)


def cmd_validate(a) -> int:
    from ..mujoco.validation import format_validation, validate

    check_count(a, "pushes", 1, MAX_PUSHES)
    check_count(a, "workers", 1, MAX_WORKERS)
    engines = tuple(e.strip() for e in a.engines.split(",") if e.strip())
    if not {"mujoco", "drake"} & set(engines):
        refuse_flags(a, ("workers", "ray"), "without the MuJoCo or Drake engine", "only their pushes run in "
                     "processes (add --engines mujoco or drake)")
    if "quasistatic" not in engines:
        refuse_flags(a, ("support", "rings"), "without the quasi-static engine", "it is the quasi-static simulator's pad model")
    if a.rings is not None and a.support == "limit_surface":
        refuse_flags(a, ("rings",), "with --support limit_surface", "rings are the point-set pads' (--support points)")
    scene = load_planar(a.scene, "validate", a)
    res = validate(scene, a.pushes, a.seed, engines=engines, workers=a.workers, ray_address=a.ray, progress=True,
                   support=a.support, rings=a.rings)
    print(json.dumps(res) if a.json else format_validation(res))
    return OK


# --- simulate ----------------------------------------------------------------------------------

def _check_engine_flags(a) -> None:
    """The flags of `regrasp simulate` that only one engine uses."""
    if a.engine == "quasistatic":
        refuse_flags(a, ("scale_friction", "scale_grip", "scale_mass", "perturb", "video"), "with --engine quasistatic",
                     "they change or show the MuJoCo or Drake world (add --engine mujoco or drake)")
    else:
        refuse_flags(a, ("dt",), f"with --engine {a.engine}", "it is the quasi-static simulator's time step")
    if a.engine == "drake":
        refuse_flags(a, ("video",), "with --engine drake", "the video is MuJoCo's renderer (use --plot)")
    if not a.perturb:
        refuse_flags(a, ("seed",), "without --perturb", "it seeds the factors --perturb draws")


def _simulate3d(scene, plan: Plan, a) -> int:
    refuse_flags(a, ("perturb", "video", "plot"), "for a 3-D scene", "they are planar only "
                 "(3-D: --scale-*, --dt, --json; `regrasp plan --html` for a view)")
    _check_engine_flags(a)
    r = execute3d(scene, plan, a, **given(a, "dt"))
    out = {k: r[k] for k in ("engine", "final_pose", "goal_error", "success", "plan_end_error")}
    out["max_pusher_slip"] = None
    print(json.dumps(out) if a.json else f"{scene.name}: {r['engine']}: "
          f"{'success' if r['success'] else 'outside the tolerance'}, error {error3d(r['goal_error'])}")
    return OK if r["success"] else CANNOT


#: the seed of the factors `regrasp simulate --perturb` draws when --seed is not given
PERTURB_SEED = 0


def _replay_planar(scene, plan: Plan, a):
    """The planar plan run open loop (:func:`~regrasp.execution.execute`) in the planner's-view
    world of --engine, perturbed by the --scale-* factors and --perturb's draw."""
    from ..execution.execute import World, execute
    from ..scene.perturbation import Perturbation

    base = Perturbation(*every_friction(scales(a)))
    seed = PERTURB_SEED if a.seed is None else a.seed
    pert = Perturbation.draw(np.random.default_rng(seed), a.perturb, features="finger", base=base) if a.perturb else base
    return execute(World(scene, engine=a.engine, options=given(a, "dt")), plan, perturbation=pert)


def _print_replay(scene, plan: Plan, rep) -> None:
    """The replay's summary: the plan's steps and pusher runs (the same in both engines), then one
    line per step (quasi-static) or per pusher run (MuJoCo executes a run as one push)."""
    steps = len(plan.pushers) - 1
    print(f"{scene.name}: replayed {plural(steps, 'step')} in {plural(len(runs(plan.pushers)), 'pusher run')} in the {rep.engine} "
          f"simulator; slip per {'step' if rep.engine == 'quasistatic' else 'pusher run'}:")
    for k, st in enumerate(rep.steps, 1):
        print(f"  {k:2d} {st['pusher']:12s} slip {1e3 * st['slip']:.3f} mm")
    print(f"  final pose {rounded(rep.final_pose)}, error to goal {rounded(rep.goal_error)} (m, m, rad): "
          f"{'success' if rep.success else 'outside the tolerance'}; largest pusher slip {1e3 * rep.max_pusher_slip:.3f} mm")


def _check_simulate(a) -> None:
    """The options of `regrasp simulate`, before any work."""
    scales(a)
    check_positive(a, "dt", "time step [s]")
    if a.perturb is not None and not (0 <= a.perturb < 1):
        raise ArgumentError("invalid `--perturb`: a spread in [0, 1)", "--perturb")
    check_outputs(a, {"plot": FIGURE_SUFFIXES, "video": VIDEO_SUFFIXES}, [a.scene, a.plan])


def _write_figures(scene, rep, a) -> None:
    """--video (MuJoCo) and --plot of a planar replay, all or none."""
    with Outputs() as outs:
        if a.video and a.engine == "mujoco":
            from ..mujoco.planar import animate_execution

            outs.write(a.video, lambda tmp: animate_execution(scene, rep, tmp))
        if a.plot:
            from ..viz.plotting import plot_replay

            outs.write(a.plot, lambda tmp: plot_replay(scene, rep, tmp))


def cmd_simulate(a) -> int:
    _check_simulate(a)
    scene = load(a.scene, a)
    plan = Plan.load(a.plan, scene)
    if scene.dimension == 3:
        return _simulate3d(scene, plan, a)
    _check_engine_flags(a)
    run = _replay_planar(scene, plan, a)
    rep = run.detail
    _write_figures(scene, rep, a)
    if a.json:
        print(json.dumps({**rep.to_json(), "success": run.success, "plan_end_error": run.plan_end_error.tolist()}))
    else:
        _print_replay(scene, plan, rep)
    return OK if run.success else CANNOT


# --- push --------------------------------------------------------------------------------------

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
        print(f"  final pose {rounded(out['final_pose'])}; pusher sticks in "
              f"{100 * out['pusher_sticking_share']:.0f}% of the steps; largest constraint residual {out['max_residual']:.1e}")
    return OK


def _check_push(a) -> None:
    """--duration, --dt (positive, at most MAX_STEPS steps) and --plot, before any work."""
    from ..scene.settings import push_dt

    check_number(a, "duration", 0.0, MAX_DURATION, what="duration [s]", lo_open=True)
    a.dt = push_dt(a.duration, a.dt)
    check_number(a, "dt", 0.0, a.duration, what="time step [s] (at most --duration)", lo_open=True)
    if a.duration / a.dt > MAX_STEPS:
        raise ArgumentError(f"invalid `--dt`: --duration / --dt is at most {MAX_STEPS} steps "
                            f"(got {a.duration / a.dt:.3g})", "--dt")
    check_outputs(a, {"plot": FIGURE_SUFFIXES}, [a.scene])


def cmd_push(a) -> int:
    _check_push(a)
    scene = load(a.scene, a)
    pose = floats(a.pose, POSE_SIZE[scene.dimension], "--pose")
    twist = floats(a.twist, 6 if scene.dimension == 3 else 3, "--twist")
    check_pusher(scene, a.pusher)
    if scene.dimension == 3:
        refuse_flags(a, ("plot",), "for a 3-D scene", "it draws planar pushes only")
        with progress.elapsed(None, "push"):
            tr = scene.simulate_push(pose, a.pusher, twist, a.duration, a.dt)
    else:
        from ..sim.quasistatic import simulate_push

        with progress.elapsed(None, "push"):
            tr = simulate_push(scene, pose, a.pusher, twist, a.duration, a.dt)
        if a.plot:
            from ..viz.plotting import plot_push

            plot_push(scene, tr, a.pusher, twist, a.plot)
    return _push_report(scene, a, twist, tr)


def add_parsers(sub) -> None:
    from ..scene.spatial import Scene3D
    from ..sim import quasistatic
    from ..mujoco.validation import validate

    v = add_command(sub, "validate", "motion-cone predictions against the simulators (planar scenes)",
                    "regrasp validate block-low-friction.toml --pushes 500 --engines quasistatic,mujoco",
                    cmd_validate)
    v.add_argument("scene", help="a planar scene file")
    v.add_argument("--pushes", type=int, default=api_default(validate, "pushes"), help=f"random pushes, 1 to {MAX_PUSHES}")
    v.add_argument("--engines", default="quasistatic", help="comma-separated: quasistatic,mujoco,drake (drake: "
                   "pip install 'regrasp[drake]')")
    v.add_argument("--seed", type=seed_arg, default=api_default(validate, "seed"), help="random seed, a whole number >= 0")
    v.add_argument("--workers", type=int, help=f"local processes for MuJoCo and Drake, 1 to {MAX_WORKERS} (default: all cores)")
    v.add_argument("--ray", metavar="ADDRESS", help="spread MuJoCo and Drake pushes over a Ray cluster ('local' starts one)")
    v.add_argument("--support", choices=["points", "limit_surface"],
                   help="quasi-static pads as point sets or as one patch on the ellipsoidal limit surface (eq 3.7) "
                   f"(default: {quasistatic_defaults()['support']})")
    v.add_argument("--rings", type=int, help="quasi-static point-set pads: rings of points per circular pad, 1 to 64 "
                   f"(6, 12, 18... points; default: {validation_rings()})")
    v.add_argument("--json", action="store_true", help="print the result as JSON")
    add_limit_surface(v)
    add_verbose(v)

    s = add_command(sub, "simulate", "replay a plan in a simulator (planar or 3-D)",
                    "regrasp simulate t-shape.toml --plan plan.json --engine mujoco --video replay.gif",
                    cmd_simulate)
    s.add_argument("scene", help="the scene file the plan is for")
    s.add_argument("--plan", required=True, metavar="PLAN.json", help="the plan file")
    s.add_argument("--engine", default="quasistatic", choices=["quasistatic", "mujoco", "drake"],
                   help="our quasi-static simulator, MuJoCo or Drake (planar; pip install 'regrasp[drake]')")
    s.add_argument("--dt", type=float, help=f"quasi-static time step [s] (default: {api_default(quasistatic.replay_plan, 'dt')} "
                   f"planar, {api_default(Scene3D.replay, 'dt')} 3-D)")
    add_scale_options(s, "MuJoCo and Drake: ")
    s.add_argument("--perturb", type=float,
                   help="MuJoCo and Drake, planar: also draw each factor uniformly in [1-P, 1+P] from --seed (default: 0, none)")
    s.add_argument("--seed", type=seed_arg, help=f"random seed of --perturb (default: {PERTURB_SEED})")
    s.add_argument("--video", metavar="GIF|MP4", help="MuJoCo, planar: an animation of the execution")
    s.add_argument("--plot", metavar="PNG", help="planar: planned against simulated poses")
    s.add_argument("--json", action="store_true", help="print the result as JSON")
    add_verbose(s)

    p = add_command(sub, "push", "simulate one push in the quasi-static simulator (planar or 3-D)",
                    "regrasp push t-shape.toml --pose 0,0,0 --pusher top --twist 0,-0.01,0 --plot push.png",
                    cmd_push)
    p.add_argument("scene", help="the scene file")
    p.add_argument("--pose", required=True, help="x,z,theta (3-D scenes: x,y,z,qw,qx,qy,qz)")
    p.add_argument("--pusher", required=True, help=pusher_help("push"))
    p.add_argument("--twist", required=True,
                   help="pusher body twist vx,vz,omega, object frame at the start (3-D: vx,vy,vz,wx,wy,wz)")
    p.add_argument("--duration", type=float, default=1.0, help="duration of the push [s]")
    p.add_argument("--dt", type=float, help=f"time step [s], at most --duration (default: min({DT}, --duration))")
    p.add_argument("--plot", metavar="PNG", help="planar: object motion and contact forces")
    p.add_argument("--json", action="store_true", help="print the result as JSON")
    add_verbose(p)
