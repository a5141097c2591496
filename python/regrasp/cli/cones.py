"""`regrasp cone` and `regrasp approx-error`: motion cones of planar scenes."""

from __future__ import annotations

import json

import numpy as np

from ..errors import ArgumentError, GraspError
from ..scene.planar import Scene
from .. import progress
from . import (CANNOT, FIGURE_SUFFIXES, MAX_FORCE, MAX_SAMPLES, OK, pusher_help, add_command, add_limit_surface, add_verbose, api_default,
               check_count, check_outputs, check_pusher, floats, load_planar, seed_arg)


def _json_float(x):
    return None if x is None or not np.isfinite(x) else float(x)


def _report_twist(scene: Scene, probe, cone, pusher: str, twist):
    """The twist `regrasp cone` reports the grip forces of: the given one, else the central
    gravity-free twist (a point pusher: the twist its contact-point motion produces)."""
    if twist is not None:
        return np.asarray(twist, float)
    twist = probe.central_twist()
    if not cone.is_line_pusher:
        # a point pusher imposes its contact point's velocity: report the twist it produces
        r = scene.pusher(pusher).points[0]
        u = twist[:2] + twist[2] * np.array([-r[1], r[0]])
        t = cone.point_pusher_twist(u)
        twist = twist if t is None else t
    return np.asarray(twist, float)


def cone_report(scene: Scene, pose, pusher: str, twist=None) -> dict:
    """Everything `regrasp cone --json` prints."""
    hold = scene.hold_grip_force(pose)
    probe = scene.motion_cone(pose, pusher, check_hold=False)
    cone = scene.motion_cone(pose, pusher)  # raises GraspError when it cannot hold
    twist = _report_twist(scene, probe, cone, pusher, twist)
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
        "limit_surface": scene.limit_surface,
    }


def _print_cone(scene: Scene, rep: dict, plot) -> None:
    print(f"motion cone of pusher '{rep['pusher']}' in scene '{scene.name}' at pose {rep['pose']}")
    print(f"  ({rep['pusher_kind']} pusher on the {rep['limit_surface']} limit surface; twists [vx, vz, omega] in the "
          f"object frame, unit in diag(1,1,L^2), L = {scene.length:.4f} m)")
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
    if plot:
        print(f"  figure: {plot}")


def cmd_cone(a) -> int:
    check_outputs(a, {"plot": FIGURE_SUFFIXES}, [a.scene])
    scene = load_planar(a.scene, "cone", a)
    pose = floats(a.pose, 3, "--pose")
    check_pusher(scene, a.pusher)
    twist = None if a.twist is None else floats(a.twist, 3, "--twist")
    try:
        rep = cone_report(scene, pose, a.pusher, twist)
    except GraspError as e:
        hold = scene.hold_grip_force(pose)
        progress.note(f"regrasp: {e} (holding needs at least {hold:.3f} N per finger)")
        return CANNOT
    if a.plot:
        from ..viz.plotting import plot_motion_cone

        plot_motion_cone(scene.motion_cone(pose, a.pusher), a.plot)
    if a.json:
        print(json.dumps(rep))
    else:
        _print_cone(scene, rep, a.plot)
    return OK


def _bundled_planar_examples() -> list:
    from .. import examples

    return examples.planar()


def cmd_approx_error(a) -> int:
    from ..reference.approx_error import approximation_report, format_report

    check_count(a, "samples", 1, MAX_SAMPLES)
    forces = floats(a.forces, len(a.forces.split(",")), "--forces")
    if (forces <= 0).any() or (forces > MAX_FORCE).any():
        raise ArgumentError(f"invalid `--forces`: grip forces must be positive, at most {MAX_FORCE:g} N", "--forces")
    scenes = [load_planar(p, "approx-error", a) for p in a.scenes or _bundled_planar_examples()]
    skipped = [s.name for s in scenes if s.kind != "grasp"]
    if len(skipped) == len(scenes):
        raise ArgumentError(f"invalid `scene`: {', '.join(skipped)} {'has' if len(skipped) == 1 else 'have'} no grasp, "
                            "so no grip force to vary (approx-error compares cones per grip force)", "scene")
    if skipped and not a.json:
        progress.note(f"(skipped {', '.join(skipped)}: no grasp, so no grip force to vary)")
    rows = approximation_report(scenes, tuple(forces), a.samples, a.seed)
    print(json.dumps(rows) if a.json else format_report(rows))
    return OK


def add_parsers(sub) -> None:
    from ..reference.approx_error import approximation_report

    c = add_command(sub, "cone", "motion cone of a pusher at a pose (planar scenes)",
                    "regrasp cone t-shape.toml --pose 0,0,0 --pusher top --plot cone.png", cmd_cone)
    c.add_argument("scene", help="a planar scene file")
    c.add_argument("--pose", required=True, help="the object's pose in the gripper frame: x,z,theta [m, m, rad]")
    c.add_argument("--pusher", required=True, help=pusher_help("cone"))
    c.add_argument("--twist", help="vx,vz,omega whose grip-force range is reported (default: the central "
                   "gravity-free twist)")
    c.add_argument("--json", action="store_true", help="print the report as JSON")
    c.add_argument("--plot", metavar="PNG", help="draw the cone in wrench and twist space")
    add_limit_surface(c)
    add_verbose(c)

    e = add_command(sub, "approx-error", "polyhedral approximation vs exact cone, per scene and grip force",
                    "regrasp approx-error t-shape.toml --forces 5,20 --samples 2000", cmd_approx_error)
    e.add_argument("scenes", nargs="*", help="planar scene files (default: every bundled planar example)")
    e.add_argument("--forces", default=",".join(f"{f:g}" for f in api_default(approximation_report, "forces")),
                   help="grip forces per finger [N], comma-separated")
    e.add_argument("--samples", type=int, default=api_default(approximation_report, "samples"),
                   help=f"random pushes per row, 1 to {MAX_SAMPLES}")
    e.add_argument("--seed", type=seed_arg, default=api_default(approximation_report, "seed"),
                   help="random seed, a whole number >= 0")
    e.add_argument("--json", action="store_true", help="print the rows as a JSON array")
    add_verbose(e)
