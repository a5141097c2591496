"""`regrasp pick-place`: pick the object from the table with the grasp whose regrasp to a
placing grasp is cheapest, regrasp it against the workcell, place it (docs/cli.md)."""

from __future__ import annotations

import json
import math

import numpy as np

from ..errors import ArgumentError
from . import CANNOT, OK, add_command, add_verbose, api_default, check_outputs, load, rounded, seed_arg


def pose_arg(text: str, option: str) -> list:
    """A pose option ``x,y,z,qw,qx,qy,qz`` (m, quaternion): 7 finite numbers, a non-zero
    quaternion; ArgumentError naming ``option`` otherwise."""
    try:
        v = [float(x) for x in text.split(",")]
    except ValueError:
        v = []
    if len(v) != 7 or not all(math.isfinite(x) for x in v) or math.hypot(*v[3:]) < 1e-6:
        raise ArgumentError(f"invalid `{option}`: a pose x,y,z,qw,qx,qy,qz (m, quaternion), 7 comma-separated "
                            f"numbers (got {text!r:.80})", option)
    return v


def cmd_pick_place(a) -> int:
    from ..execution.pick_place import pick_place, place_error
    from ..workcell.file import load as load_workcell

    place = pose_arg(a.place, "--place") if a.place is not None else None
    pick = pose_arg(a.pick, "--pick") if a.pick is not None else None
    if not (0 <= a.depth < 1):
        raise ArgumentError(f"invalid `--depth`: a height in [0, 1) m (got {a.depth})", "--depth")
    check_outputs(a, {"trajectory": (".json",)}, [a.scene, a.workcell])
    scene = load(a.scene, a)
    workcell = load_workcell(a.workcell) if a.workcell else None
    r = pick_place(scene, workcell, place=place, pick=pick, depth=a.depth, seed=a.seed)
    final = r.motion.object[-1]
    err = place_error(final, r.place_pose)
    success = True
    executed = None
    if not a.plan_only:
        from ..execution.execute import World, execute

        executed = execute(World(scene, rig="arm"), r)
        err, success = tuple(executed.goal_error), executed.success
    out = {"success": bool(success), "pick_grasp": rounded(r.pick.in_hand), "place_grasp": rounded(r.place.in_hand),
           "place_error": rounded(err), "switch_overs": int(r.switch_overs),
           "planning_time_s": round(r.planning_time, 4), "executed": executed is not None,
           "pick_pose": rounded(r.pick_pose), "place_pose": rounded(r.place_pose),
           "duration_s": round(float(r.motion.duration), 3), "workcell": r.motion.workcell.name}
    written = []
    if a.trajectory:
        written.append(r.motion.to_trajectory(r.arm).save(a.trajectory))
    if a.json:
        print(json.dumps(out, allow_nan=False))
    else:
        print(f"{scene.name}: pick at in-hand {out['pick_grasp']}, regrasp with {r.switch_overs} switch-overs to "
              f"{out['place_grasp']}, place at {out['place_pose'][:3]} in workcell {out['workcell']} "
              f"({out['duration_s']:.1f} s; chosen in {r.planning_time:.2f} s): "
              + ("planned (not executed)" if executed is None else
                 f"{'placed' if success else 'missed the place'}, error {err[0] * 1e3:.1f} mm, "
                 f"{np.degrees(err[1]):.1f}°"))
        for p in written:
            print(f"wrote {p}")
    return OK if success else CANNOT


def add_parsers(sub) -> None:
    from ..execution.pick_place import DEFAULT_PICK, DEFAULT_SHIFT, pick_place

    e = add_command(sub, "pick-place", "pick the object from the table, regrasp it against the workcell and place "
                    "it (the pick grasp chosen for the cheapest regrasp)",
                    "regrasp pick-place t-shape.toml --place 0.55,-0.1,0.79,1,0,0,0 --json", cmd_pick_place)
    e.add_argument("scene", help="the scene file (planar; the pick grasp at its task start, the place grasp at its "
                   "goal)")
    e.add_argument("--workcell", metavar="W.toml", help="the workcell file (docs/workcell-file.md; default: one "
                   "generated for the scene); its object pose on the table is the pick pose")
    e.add_argument("--place", metavar="x,y,z,qw,qx,qy,qz", help="the object's world pose to place it at (m, "
                   f"quaternion; default: the pick pose moved by {list(DEFAULT_SHIFT)} m in x, y)")
    e.add_argument("--pick", metavar="x,y,z,qw,qx,qy,qz", help="the object's world pose on the table (default: the "
                   f"workcell's, else upright at x, y = {list(DEFAULT_PICK)} m)")
    e.add_argument("--depth", type=float, default=api_default(pick_place, "depth"), metavar="M",
                   help="how much higher the fingers must stay above the table at the place (a pocket) [m]")
    e.add_argument("--seed", type=seed_arg, default=api_default(pick_place, "seed"),
                   help="the planner's random seed, a whole number >= 0")
    e.add_argument("--plan-only", action="store_true", help="plan (grasps, regrasp, world motion, joint "
                   "trajectory) without executing in MuJoCo")
    e.add_argument("--trajectory", metavar="TRAJ.json", help="write the timed joint trajectory "
                   "(docs/trajectory-file.md)")
    e.add_argument("--json", action="store_true", help="print the result as JSON")
    add_verbose(e)
