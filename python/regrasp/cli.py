"""Command line: ``regrasp cone | approx-error | validate | simulate | push | bench | demo``.

Exit status: 0 success, 1 the task cannot be done (reason printed), 2 invalid input.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

from .errors import ArgumentError, GraspError, RegraspError, SceneError
from .scene import Scene

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


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
    scene = Scene.load(a.scene)
    pose = _floats(a.pose, 3, "--pose")
    twist = None if a.twist is None else _floats(a.twist, 3, "--twist")
    try:
        rep = cone_report(scene, pose, a.pusher, twist)
    except GraspError as e:
        hold = scene.hold_grip_force(pose)
        print(f"regrasp: {e} (holding needs at least {hold:.3f} N per finger)", file=sys.stderr)
        return 1
    if a.plot:
        from .plotting import plot_motion_cone

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
    from .report import approximation_report, format_report

    from .scene3d import is_3d

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
    from .bench import format_results, run

    n = 10_000 if a.quick else a.n
    res = run(n=n, reps=5 if a.quick else 11, baseline_reps=1 if a.quick else 3)
    print(json.dumps(res) if a.json else format_results(res))
    return 0


def cmd_demo(a) -> int:
    from .plotting import plot_motion_cone
    from .report import approximation_report, format_report

    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    path = EXAMPLES / "block-low-friction.toml"
    scene = Scene.load(path)
    start = scene.task.start
    print(f"demo: motion cones of every pusher of {path.name} at the start pose {start.tolist()}")
    reports = []
    for p in scene.pusher_names:
        rep = cone_report(scene, start, p)
        fig = plot_motion_cone(scene.motion_cone(start, p), out / f"cone-{p}.png")
        reports.append(rep)
        mn = rep["min_grip_force"]
        print(f"  {p:8s} {rep['pusher_kind']:5s} pusher: {len(rep['generators'])} generators, "
              f"central push sticks above {mn:.2f} N per finger -> {fig}")
    (out / "cones.json").write_text(json.dumps(reports, indent=1))
    rows = approximation_report([scene], (5.0, 20.0, 80.0), samples=5000)
    print("\npolyhedral approximation vs exact cone (share of random pushes misclassified):")
    print(format_report(rows))
    print(f"\nwrote {out / 'cones.json'} and {len(reports)} figures in {out}")
    return 0


def cmd_validate(a) -> int:
    from .quasistatic import format_confusion, validate

    scene = Scene.load(a.scene)
    engines = [e.strip() for e in a.engines.split(",")]
    for e in engines:
        if e not in ("quasistatic",):
            raise ArgumentError(f"invalid `--engines`: unknown engine {e!r} (available: quasistatic)", "--engines")
    res = validate(scene, a.pushes, a.seed, support=a.support)
    print(json.dumps(res) if a.json else format_confusion(res))
    return 0


def cmd_simulate(a) -> int:
    from .quasistatic import load_plan, replay_plan

    scene = Scene.load(a.scene)
    plan = load_plan(a.plan)
    if a.engine != "quasistatic":
        raise ArgumentError(f"invalid `--engine`: {a.engine!r} is not available (quasistatic)", "--engine")
    rep = replay_plan(scene, plan, dt=a.dt)
    if a.plot:
        from .plotting import plot_replay

        plot_replay(scene, rep, a.plot)
    out = rep.to_json()
    if a.json:
        print(json.dumps(out))
    else:
        print(f"{scene.name}: replayed {len(rep.steps)} pushes in the {rep.engine} simulator")
        for k, st in enumerate(rep.steps, 1):
            print(f"  {k:2d} {st['pusher']:12s} {st['duration']:6.2f} s  slip {1e3 * st['slip']:.3f} mm")
        print(f"  final pose {np.round(rep.final_pose, 5).tolist()}, error to goal {np.round(rep.goal_error, 5).tolist()}: "
              f"{'success' if rep.success else 'outside the tolerance'}; largest pusher slip {1e3 * rep.max_pusher_slip:.3f} mm")
    return 0 if rep.success else 1


def cmd_push3d(a) -> int:
    from .scene3d import Scene3D

    scene = Scene3D.load(a.scene)
    pose = _floats(a.pose, 7, "--pose")
    twist = _floats(a.twist, 6, "--twist")
    tr = scene.simulate_push(pose, a.pusher, twist, a.duration, a.dt)
    out = {
        "scene": scene.name, "pusher": a.pusher, "twist": twist.tolist(), "final_pose": tr["pose"][-1].tolist(),
        "max_pusher_slip_speed": float(tr["pusher_slip"].max()),
        "pusher_sticking_share": float(np.mean(tr["pusher_sticking"] == np.maximum(tr["pusher_contacts"], 1))),
        "max_residual": float(tr["residual"].max()),
    }
    if a.json:
        out["t"] = tr["t"].tolist()
        out["pose"] = tr["pose"].tolist()
        print(json.dumps(out))
    else:
        print(f"{scene.name}: pusher '{a.pusher}' with body twist {twist.tolist()} for {a.duration} s")
        print(f"  final pose {np.round(out['final_pose'], 5).tolist()}; pusher sticks in "
              f"{100 * out['pusher_sticking_share']:.0f}% of the steps; largest constraint residual {out['max_residual']:.1e}")
    return 0


def cmd_push(a) -> int:
    from .quasistatic import simulate_push
    from .scene3d import is_3d

    if is_3d(a.scene):
        return cmd_push3d(a)
    scene = Scene.load(a.scene)
    pose = _floats(a.pose, 3, "--pose")
    twist = _floats(a.twist, 3, "--twist")
    tr = simulate_push(scene, pose, a.pusher, twist, a.duration, a.dt)
    if a.plot:
        from .plotting import plot_push

        plot_push(scene, tr, a.pusher, twist, a.plot)
    out = {
        "scene": scene.name, "pusher": a.pusher, "twist": twist.tolist(),
        "final_pose": tr["pose"][-1].tolist(),
        "max_pusher_slip_speed": float(tr["pusher_slip"].max()),
        "pusher_sticking_share": float(np.mean(tr["pusher_sticking"] == np.maximum(tr["pusher_contacts"], 1))),
        "max_residual": float(tr["residual"].max()),
    }
    if a.json:
        out["t"] = tr["t"].tolist()
        out["pose"] = tr["pose"].tolist()
        out["pusher_wrench"] = tr["pusher_wrench"].tolist()
        print(json.dumps(out))
    else:
        print(f"{scene.name}: pusher '{a.pusher}' with twist {twist.tolist()} for {a.duration} s")
        print(f"  final pose {np.round(out['final_pose'], 5).tolist()}; pusher sticks in {100 * out['pusher_sticking_share']:.0f}% "
              f"of the steps; largest constraint residual {out['max_residual']:.1e}")
    return 0


def build_parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(prog="regrasp", description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="cmd", required=True)

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
    e.add_argument("--seed", type=int, default=0)
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
    v.add_argument("--engines", default="quasistatic")
    v.add_argument("--seed", type=int, default=0)
    v.add_argument("--support", default="points", choices=["points", "limit_surface"],
                   help="finger pads as point sets (default) or as the motion cones' limit surface")
    v.add_argument("--json", action="store_true")
    v.set_defaults(fn=cmd_validate)

    s = sub.add_parser("simulate", help="replay a plan in a simulator")
    s.add_argument("scene")
    s.add_argument("--plan", required=True)
    s.add_argument("--engine", default="quasistatic")
    s.add_argument("--dt", type=float, default=0.05)
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
