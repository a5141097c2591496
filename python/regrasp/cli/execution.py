"""`regrasp execute`: a plan executed in a workcell by a real arm (or a free-flying gripper) in
MuJoCo, its timed joint trajectory exported."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from ..errors import ArgumentError
from ..execution.trajectory_formats import FORMATS as TRAJECTORY_FORMATS, format_of
from ..planning.plan import Plan
from . import (CANNOT, OK, add_command, add_scale_options, add_verbose, check_outputs, floats, load, refuse_flags,
               rounded, scales)

#: `--robot` of the free-flying gripper (the baseline rig, no arm)
FREE_GRIPPER = "free-gripper"


def _robots() -> list[str]:
    from ..robot.model import ALIASES, ROBOTS
    from ..robot.robot_file import bundled

    return [*ROBOTS, *ALIASES, *(n for n in bundled() if n not in ROBOTS), FREE_GRIPPER]


def _check(a) -> None:
    """The options of `regrasp execute`, before any work."""
    from ..robot.robot_file import bundled, robot_name

    if a.robot is not None and (a.robot.lower().endswith(".toml") or a.robot in bundled()):
        a.robot = robot_name(a.robot)  # the robot file read and checked, its robot registered
    elif a.robot is not None and a.robot not in _robots():
        raise ArgumentError(f"invalid `--robot`: unknown robot {a.robot!r} (known: {', '.join(_robots())}; or a "
                            "robot file, docs/robot-file.md)", "--robot")
    scales(a)
    if a.video and a.robot == FREE_GRIPPER:
        raise ArgumentError("invalid `--video`: the video shows the arm (not --robot free-gripper)", "--video")
    if a.plan_only:
        refuse_flags(a, ("video", "closed_loop", "scale_friction", "scale_grip", "scale_mass", "start_error",
                         "grip_sensing"), "with --plan-only", "nothing is simulated (leave out --plan-only to run it in MuJoCo)")
    if a.grip_sensing is not None:
        from ..robot.sensing import GripSensing

        if a.robot == FREE_GRIPPER:
            raise ArgumentError("invalid `--grip-sensing`: the arm's grip loop (not --robot free-gripper)", "--grip-sensing")
        a.grip_sensing = GripSensing.parse(a.grip_sensing)
    if a.format is not None and not a.trajectory:
        raise ArgumentError("invalid `--format`: the format of --trajectory, which is not given", "--format")
    if a.trajectory and a.robot == FREE_GRIPPER and format_of(a.trajectory, a.format) != "json":
        raise ArgumentError(f"invalid `--trajectory`: {format_of(a.trajectory, a.format)} carries a robot's joints (a "
                            "free gripper's trajectory is .json)", "--trajectory")
    suffixes = None if a.format else tuple(e for exts in TRAJECTORY_FORMATS.values() for e in exts)
    check_outputs(a, {"trajectory": suffixes, "video": (".gif", ".mp4"), "html": (".html", ".htm")},
                  [a.scene, a.plan, a.workcell])


def goal_text(scene, err) -> str:
    """A goal error for people (``Scene.goal_error``'s): planar ``[x, z, theta]`` (m, m, rad),
    3-D ``[dx, dy, dz, angle]`` as a distance and an angle (m, rad)."""
    if scene.dimension == 2:
        return f"{rounded(err)} (m, m, rad)"
    return f"{float(np.linalg.norm(err[:3])) * 1e3:.2f} mm, {float(err[3]):.4f} rad"


def _workcell(a):
    from ..workcell.file import load as load_workcell

    return load_workcell(a.workcell) if a.workcell else None


def _start_error(scene, a, plan=None):
    """``--start-error`` as a planar ``[dx, dz, dtheta]`` (m, m, rad), None when not given;
    with ``plan``, it must keep the pad on the object at the plan's start."""
    if a.start_error is None:
        return None
    if scene.dimension != 2:
        raise ArgumentError("invalid `--start-error`: planar scenes only", "--start-error")
    se = floats(a.start_error, 3, "--start-error")
    if np.max(np.abs(se[:2])) > 1.0 or abs(se[2]) > np.pi:
        raise ArgumentError(f"invalid `--start-error`: a perturbation of the start, at most 1 m and pi rad (got "
                            f"{a.start_error})", "--start-error")
    if plan is not None and not scene.admissible(np.asarray(plan.poses[0], float) + se):
        raise ArgumentError("invalid `--start-error`: from the plan's start it puts the pad off the object",
                            "--start-error")
    return se


def _free(scene, plan, a):
    """The free-flying gripper: (result dict, motion, None)."""
    from ..execution.execute import World, execute

    refuse_flags(a, ("scale_friction", "scale_grip", "scale_mass", "start_error"), "with --robot free-gripper",
                 "the free-gripper rig is not perturbed (use the arm)")
    run = execute(World(scene, rig="free-gripper", workcell=_workcell(a)), plan)
    r = run.detail
    return dict(success=run.success, goal_error=r.goal_error, max_creep=r.max_creep, max_creep_angle=r.max_creep_angle,
                duration_s=r.duration, robot=FREE_GRIPPER, task_error=run.goal_error), run.motion, None


def _arm(scene, plan, a):
    """The arm: (result dict, motion, (result, recorder or None))."""
    from ..execution.execute import World, execute

    holder: dict = {}
    observe = None
    if a.video:
        from ..robot.video import Recorder

        def observe(robot):  # the recorder is made on the first call, once the model exists
            if "r" not in holder:
                holder["r"] = Recorder(robot.model, robot.data)
            holder["r"].capture()
    run = execute(World(scene, rig="arm", workcell=_workcell(a), robot=a.robot, grip_sensing=a.grip_sensing), plan,
                  perturbation=_perturbation(scene, a), observe=observe)
    r = run.detail
    out = dict(success=run.success, goal_error=r.goal_error, max_creep=r.max_creep, max_creep_angle=r.max_creep_angle,
               duration_s=r.duration, robot=r.trajectory.robot,
               tracking=dict(max_joint_error=r.tracking.max_error, rms_joint_error=r.tracking.rms_error,
                             max_tcp_error=r.tracking.tcp_error),
               refused=[dict(push=k, feature=f_, why=why) for k, f_, why in run.refused],
               task_error=run.goal_error)
    if r.trajectory.holding is not None:
        out["holding"] = r.trajectory.holding.to_json()
    from ..robot.kinds import ROBOTS
    from ..robot.sensing import GripSensing

    out["grip_sensing"] = (a.grip_sensing or GripSensing.parse(ROBOTS[r.trajectory.robot].sensing)).kind
    return out, run.motion, (r, holder.get("r"))


def _perturbation(scene, a):
    """The world of --scale-* (--scale-friction on the fingers and the features) and --start-error
    (a planar ``[dx, dz, dθ]``: a shift in x-z and a turn of −dθ about the grasp axis)."""
    from ..scene.perturbation import Perturbation

    f, g, m = scales(a)
    se = _start_error(scene, a)
    if se is None:
        return Perturbation(f, g, m, f)
    return Perturbation(f, g, m, f, shift=(float(se[0]), 0.0, float(se[1])), turn=-float(se[2]))


def _closed_loop(scene, plan, a) -> int:
    """`--closed-loop`: the arm in the loop (docs/robot.md, "Closed loop with the arm")."""
    from ..execution.execute import World, execute

    for opt in ("trajectory", "video", "html"):
        if getattr(a, opt):
            raise ArgumentError(f"invalid `--{opt}`: not with --closed-loop (the motion is decided as it runs)",
                                f"--{opt}")
    if a.robot == FREE_GRIPPER:
        raise ArgumentError("invalid `--robot`: --closed-loop runs the arm (not the free gripper)", "--robot")
    world = World(scene, rig="arm", workcell=_workcell(a), robot=a.robot, grip_sensing=a.grip_sensing)
    run = execute(world, plan, loop="closed", perturbation=_perturbation(scene, a))
    r = run.detail
    out = dict(success=run.success, goal_error=r.goal_error, task_error=run.goal_error, replans=r.replans, switch_overs=r.switch_overs,
               duration_s=r.duration, failure=r.failure, closed_loop=True)
    if a.json:
        print(json.dumps({k: (rounded(v) if isinstance(v, np.ndarray) else v) for k, v in out.items()}, allow_nan=False))
    else:
        err = goal_text(scene, run.goal_error)
        print(f"{scene.name}: closed loop with the arm, {r.duration:.1f} s, {r.replans} re-plans, {r.switch_overs} "
              f"switch-overs: {'success' if run.success else 'outside the tolerance'}, error to goal {err}"
              + (f" ({r.failure})" if r.failure else ""))
    return OK if run.success else CANNOT


def _write_html(path, scene, motion, arm) -> Path:
    """The world view of ``motion`` at ``path``, with the robot's bodies along the joint
    trajectory ``arm`` (an ArmTrajectory; None: the gripper alone)."""
    from ..viz.viewer import write_motion_html

    view = None
    if arm is not None:
        from ..robot.shapes import trajectory_view

        view = trajectory_view(arm.robot, motion.workcell.robot.base, arm.q)
    return write_motion_html(path, scene, motion, view)


def _plan_only(scene, plan, a) -> int:
    """`--plan-only`: the world motion and, with the arm, its IK and time parametrisation; no
    simulation. Prints the trajectory's length, duration and joint rates against the limits."""
    from ..execution.arm import arm_motion
    from ..execution.world_motion import world_motion

    if a.robot == FREE_GRIPPER:
        motion, arm, refused = world_motion(scene, plan, _workcell(a)), None, []
    else:
        am = arm_motion(scene, plan, _workcell(a), a.robot)
        motion, arm, refused = am.motion, am.trajectory, am.refused
    tr = motion.to_trajectory(arm)
    written = [tr.save(a.trajectory, a.format)] if a.trajectory else []
    if a.html:
        written.append(_write_html(a.html, scene, motion, arm))
    out = dict(plan_only=True, robot=tr.robot or FREE_GRIPPER, workcell=motion.workcell.name, samples=len(tr),
               duration_s=tr.duration, pushes=[{"pusher": p.pusher, "feature": p.feature, "tilt": p.tilt}
                                               for p in motion.assignments],
               refused=[dict(push=k, feature=f_, why=why) for k, f_, why in refused])
    if arm is not None:
        from ..robot.kinds import ROBOTS

        kind = ROBOTS[arm.robot]
        out["max_velocity_ratio"] = float(np.max(np.abs(arm.qd) / np.asarray(kind.velocity_limit)))
        out["max_acceleration_ratio"] = float(np.max(np.abs(arm.qdd) / np.asarray(kind.acceleration_limit)))
        if arm.holding is not None:
            out["holding"] = arm.holding.to_json()
    if a.json:
        print(json.dumps(out, allow_nan=False))
    else:
        rates = (f"; joint speeds up to {out['max_velocity_ratio']:.0%} and accelerations up to "
                 f"{out['max_acceleration_ratio']:.0%} of the limits") if arm is not None else ""
        if "holding" in out:
            h = out["holding"]
            rates += f"; the pads keep {h['smallest_margin']:.0%} of their friction unused at least ({h['where']})"
        print(f"{scene.name}: {out['robot']} in workcell {out['workcell']}, {len(motion.assignments)} pushes "
              f"({', '.join(f'{p.pusher} on {p.feature}' for p in motion.assignments)}): a trajectory of "
              f"{len(tr)} samples, {tr.duration:.1f} s{rates} (not simulated)")
        for p in written:
            print(f"wrote {p}")
    return OK


def cmd_execute(a) -> int:
    _check(a)
    scene = load(a.scene, a)
    _start_error(scene, a)  # before any work
    plan = Plan.load(a.plan, scene)
    _start_error(scene, a, plan)
    if a.closed_loop:
        return _closed_loop(scene, plan, a)
    if a.plan_only:
        return _plan_only(scene, plan, a)
    out, motion, extra = (_free if a.robot == FREE_GRIPPER else _arm)(scene, plan, a)
    written = []
    if a.trajectory:
        arm = extra[0].trajectory if extra else None
        written.append(motion.to_trajectory(arm).save(a.trajectory, a.format))
    if a.video and extra and extra[1] is not None:
        written.append(extra[1].save(a.video))
    if a.html:
        written.append(_write_html(a.html, scene, motion, extra[0].trajectory if extra else None))
    out = {**out, "workcell": motion.workcell.name, "pushes": [
        {"pusher": p.pusher, "feature": p.feature, "tilt": p.tilt} for p in motion.assignments]}
    if a.json:
        print(json.dumps({k: (rounded(v) if isinstance(v, np.ndarray) else v) for k, v in out.items()},
                         allow_nan=False))
    else:
        err = goal_text(scene, out["task_error"])
        print(f"{scene.name}: {out['robot']} in workcell {out['workcell']}, {len(motion.assignments)} pushes "
              f"({', '.join(f'{p.pusher} on {p.feature}' for p in motion.assignments)}), {out['duration_s']:.1f} s: "
              f"{'success' if out['success'] else 'outside the tolerance'}, error to goal {err}; "
              f"largest creep {out['max_creep'] * 1e3:.2f} mm")
        for p in written:
            print(f"wrote {p}")
    return OK if out["success"] else CANNOT


def add_parsers(sub) -> None:
    e = add_command(sub, "execute", "execute a plan with a real arm in a workcell (MuJoCo) and export its joint "
                    "trajectory", "regrasp execute block-xztheta.toml --plan plan.json --trajectory traj.json --json",
                    cmd_execute)
    e.add_argument("scene", help="the scene file the plan is for")
    e.add_argument("--plan", required=True, metavar="PLAN.json", help="the plan file")
    e.add_argument("--workcell", metavar="W.toml", help="the workcell file (docs/workcell-file.md; default: one "
                   "generated for the scene)")
    e.add_argument("--robot", metavar="NAME|ROBOT.toml", help=f"the robot: one of {', '.join(_robots())}, or a robot "
                   "file (docs/robot-file.md; default: the workcell's)")
    e.add_argument("--trajectory", metavar="TRAJ", help="write the timed joint trajectory, within the robot's "
                   "joint limits: .json (ours), .yaml (a ROS 2 JointTrajectory) or .csv (docs/trajectory-file.md)")
    e.add_argument("--format", choices=list(TRAJECTORY_FORMATS), help="the format of --trajectory (default: by "
                   "its extension)")
    e.add_argument("--plan-only", action="store_true", help="stop after the world motion, the IK and the time "
                   "parametrisation: write the trajectory without simulating it")
    e.add_argument("--video", metavar="GIF|MP4", help="a video of the arm doing it (MuJoCo's renderer)")
    e.add_argument("--html", metavar="HTML", help="a browser view of the workcell and the world motion")
    add_scale_options(e, "the arm's world: ")
    e.add_argument("--closed-loop", action="store_true", help="closed loop with the arm: the MPC (planar) or "
                   "re-planning (3-D) from the object's pose measured in MuJoCo")
    e.add_argument("--start-error", metavar="dx,dz,dtheta", help="planar: the object starts this far from the "
                   "plan's start in the grasp (m, m, rad)")
    e.add_argument("--grip-sensing", metavar="KIND", help="what the arm's grip loop measures: ideal "
                   "(MuJoCo's contact forces), open-loop (none: the calibrated feed-forward), sensor or "
                   "sensor:NOISE,DELAY,BANDWIDTH (a force sensor per finger; N, s, Hz) (default: the gripper's: "
                   "open-loop for the 2F-85 and the Franka Hand, sensor for the parametric parallel gripper)")
    e.add_argument("--json", action="store_true", help="print the result as JSON")
    add_verbose(e)
