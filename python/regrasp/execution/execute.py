"""One world, one executor: a plan run in a :class:`World` (the planner's view, the free-flying
gripper or the arm, in a workcell, in MuJoCo or the quasi-static simulator), open or closed
loop, in a perturbed world (:class:`~regrasp.Perturbation`), with one result,
:class:`Execution`, whatever the rig::

    from regrasp.execution import World, execute
    run = execute(World(scene, rig="arm"), plan, perturbation=Perturbation(0.9, 1.1, 1.0, 1.0))
    run.success, run.goal_error, run.plan_end_error, run.max_creep, run.trajectory
    run = execute(World(scene, rig="arm"), pick_place(scene))   # a pick-regrasp-place: its task is the place

Success is judged against the **task** (the scene's goal and tolerance, :meth:`Scene.goal_error`);
the error to the plan's last pose is reported beside it (a plan may end off the task's goal when
it was made for another start). The rigs' own functions (:func:`~regrasp.sim.quasistatic.replay_plan`,
:func:`~regrasp.mujoco.planar.execute_plan`, :func:`~regrasp.mujoco.spatial.execute_plan3d`,
:func:`~regrasp.control.loop.control`, :func:`~regrasp.execution.free_gripper.execute_free_gripper`,
:func:`~regrasp.execution.arm.execute_arm`, :func:`~regrasp.execution.arm_loop.control_arm`) do
the work; ``Execution.detail`` is their result."""

from __future__ import annotations

import inspect
from dataclasses import dataclass, field

import numpy as np

from .. import pose as P
from ..errors import ArgumentError, InternalError
from ..planning.plan import Plan, as_plan
from ..scene.perturbation import Perturbation
from ..workcell.description import Workcell

#: Who moves the object: the planner's view (the object alone in the fixed grasp, the pushers
#: moved as planned), a free-flying gripper in a workcell, or the arm holding the gripper.
RIGS = ("planner", "free-gripper", "arm")
#: The physics: the quasi-static model the plans are made with, or MuJoCo (shares none of it).
ENGINES = ("quasistatic", "mujoco", "drake")
LOOPS = ("open", "closed")


@dataclass(frozen=True)
class World:
    """Where a plan runs: ``scene`` (planar or 3-D), ``rig`` (:data:`RIGS`), ``engine``
    (:data:`ENGINES`; the gripper rigs are MuJoCo's), ``workcell`` (the gripper rigs'; default:
    the scene's default workcell), ``robot`` (the arm's registry name; default: the workcell's),
    ``options``: settings of the rig's function (e.g. ``speed`` [m/s], ``dt`` [s],
    ``view``, ``timing``, ``seed``), each checked against it, and ``grip_sensing``: what the
    arm's grip loop measures (:class:`~regrasp.robot.sensing.GripSensing`; None: the robot's
    gripper's default, :data:`~regrasp.robot.kinds.GRIPPER_SENSING`); ``noslip``: MuJoCo's
    no-slip post-processing in the arm's world (False: none; open loop only)."""

    scene: object
    rig: str = "planner"
    engine: str = "mujoco"
    workcell: Workcell | None = None
    robot: str | None = None
    options: dict = field(default_factory=dict)
    grip_sensing: object = None
    noslip: bool = True
    #: the arm's world motion and joint trajectory of each plan run here (:func:`arm_motion_of`)
    _motions: dict = field(default_factory=dict, init=False, repr=False, compare=False)

    def __post_init__(self):
        if getattr(self.scene, "dimension", None) not in (2, 3):
            raise ArgumentError(f"invalid `world.scene`: a Scene or Scene3D (got {type(self.scene).__name__})",
                                "world.scene")
        for k, allowed in (("rig", RIGS), ("engine", ENGINES)):
            if getattr(self, k) not in allowed:
                raise ArgumentError(f"invalid `world.{k}`: one of {', '.join(allowed)} (got {getattr(self, k)!r:.60})",
                                    f"world.{k}")
        if self.rig != "planner" and self.engine != "mujoco":
            raise ArgumentError(f"invalid `world.engine`: the {self.rig} runs in MuJoCo", "world.engine")
        if self.workcell is not None and (self.rig == "planner" or not isinstance(self.workcell, Workcell)):
            raise ArgumentError("invalid `world.workcell`: a Workcell, for the free-gripper or arm rig", "world.workcell")
        if self.robot is not None and (self.rig != "arm" or not isinstance(self.robot, str)):
            raise ArgumentError("invalid `world.robot`: a robot's name, for the arm rig", "world.robot")
        if not isinstance(self.options, dict) or not all(isinstance(k, str) for k in self.options):
            raise ArgumentError("invalid `world.options`: a dict of settings by name", "world.options")
        if self.grip_sensing is not None:
            from ..robot.sensing import GripSensing

            if self.rig != "arm" or not isinstance(self.grip_sensing, GripSensing):
                raise ArgumentError("invalid `world.grip_sensing`: a GripSensing, for the arm rig", "world.grip_sensing")
        if not isinstance(self.noslip, bool) or (not self.noslip and self.rig != "arm"):
            raise ArgumentError("invalid `world.noslip`: True or False (False: the arm rig only)", "world.noslip")


@dataclass
class Execution:
    """The outcome of :func:`execute`, the same for every rig.

    ``success``: the final pose within the task's tolerance of the task's goal (no task: of the
    plan's last pose); ``goal_error``: :meth:`Scene.goal_error` of the final pose (planar
    ``[dx, dz, dθ]`` (m, m, rad), 3-D ``[dx, dy, dz, angle]`` (m, m, m, rad)); ``plan_end_error``
    and ``at_plan_end``: the same against the plan's last pose; ``final_pose`` the object's pose
    in the grasp (the scene's form); ``poses`` along the run where recorded; ``duration`` [s]
    simulated; ``max_creep`` [m] / ``max_creep_angle`` [rad] in the grasp between pushes (the
    gripper rigs); ``tracking`` (the arm's joint tracking); ``replans``; ``pushes``: per push,
    its pusher, plan steps and (the gripper rigs) the feature that renders it; ``trajectory``
    (the arm's joint trajectory, the free gripper's world motion); ``motion``: the gripper rigs'
    :class:`~regrasp.execution.world_motion.WorldMotion`; ``refused``: ``(push, feature, why)``
    of each contact the arm could not follow (another served the push); ``detail``: the rig's
    own result; ``steps``: a sequence of regrasp actions' per-step records (action, from, to,
    the grasp reached)."""

    success: bool
    goal_error: np.ndarray
    plan_end_error: np.ndarray
    at_plan_end: bool
    final_pose: np.ndarray
    world: World
    loop: str
    perturbation: Perturbation
    duration: float | None = None
    max_creep: float | None = None
    max_creep_angle: float | None = None
    tracking: object = None
    replans: int = 0
    pushes: list = field(default_factory=list)
    poses: np.ndarray | None = field(default=None, repr=False)
    trajectory: object = field(default=None, repr=False)
    motion: object = field(default=None, repr=False)
    refused: list = field(default_factory=list)
    detail: object = field(default=None, repr=False)
    steps: list = field(default_factory=list)

    def to_json(self) -> dict:
        """The run's numbers as a JSON-ready dict."""
        out = {"rig": self.world.rig, "engine": self.world.engine, "loop": self.loop, "success": bool(self.success),
               "goal_error": self.goal_error.tolist(), "plan_end_error": self.plan_end_error.tolist(),
               "at_plan_end": bool(self.at_plan_end), "final_pose": self.final_pose.tolist(), "replans": self.replans,
               "pushes": self.pushes}
        if self.steps:
            out["steps"] = self.steps
        for k in ("duration", "max_creep", "max_creep_angle"):
            if getattr(self, k) is not None:
                out[k] = float(getattr(self, k))
        holding = getattr(self.trajectory, "holding", None)  # the arm's (execution.holding)
        if holding is not None:
            out["holding"] = holding.to_json()
        return out


def execute(world: World, plan, *, loop: str = "open", perturbation: Perturbation | None = None,
            observe=None) -> Execution:
    """Runs ``plan`` (a :class:`~regrasp.Plan` or its dict; with the arm also a planned
    pick-regrasp-place, :func:`_pick_place`, or regrasp actions: a
    :class:`~regrasp.dexterity.sequence.Sequence` or one action's
    :class:`~regrasp.dexterity.trial.Runner`, which run themselves: ``plan.run_in``) in ``world``, ``loop`` open (the plan
    as made) or closed (the planar MPC of thesis §5.2, or re-planning from the measured pose in
    3-D), in the world ``perturbation`` (default: nominal). ``observe(robot)``: called every
    control period of the arm (e.g. a video recorder). ArgumentError naming the field when the
    rig cannot run the request (e.g. a moved start in an open-loop planner's-view replay)."""
    if not isinstance(world, World):
        raise ArgumentError(f"invalid `world`: a regrasp.execution.World (got {type(world).__name__})", "world")
    if loop not in LOOPS:
        raise ArgumentError(f"invalid `loop`: 'open' or 'closed' (got {loop!r:.60})", "loop")
    pert = Perturbation() if perturbation is None else perturbation
    if not isinstance(pert, Perturbation):
        raise ArgumentError(f"invalid `perturbation`: a regrasp.Perturbation (got {type(pert).__name__})", "perturbation")
    scene = world.scene
    from .pick_place import PickPlace

    if isinstance(plan, PickPlace):
        return _pick_place(world, scene, plan, loop, pert, observe)
    run_in = getattr(plan, "run_in", None)
    if callable(run_in):  # a plan of a later stage (regrasp actions: regrasp.dexterity) runs itself here
        out = run_in(world, loop, pert, observe)
        if not isinstance(out, Execution):
            raise InternalError(f"{type(plan).__name__}.run_in returned {type(out).__name__}, not an Execution")
        return out
    plan = as_plan(plan, scene)
    run = _RUNNERS[world.rig](world, scene, plan, loop, pert, observe)
    return _judged(world, scene, plan, loop, pert, run)


def _options(world: World, fn, fixed: dict) -> dict:
    """``fixed`` and the world's options for ``fn``, each option checked against its signature."""
    params = inspect.signature(fn).parameters
    for k in world.options:
        if k not in params or k in fixed:
            names = sorted(p for p in params if p not in fixed and p not in ("scene", "plan", "motion"))
            raise ArgumentError(f"invalid `world.options.{k}`: not a setting of this rig (its settings: "
                                f"{', '.join(names)})", f"world.options.{k}")
    return {**fixed, **world.options}


def _start_offset(scene, plan: Plan, pert: Perturbation):
    """The perturbation's moved start as a planar ``[dx, dz, dθ]`` (m, m, rad) from the plan's
    start (a turn about +y is −θ), None when the start is not moved; 3-D: refused."""
    if pert.pose is None and not any(pert.shift) and not pert.turn:
        return None
    if scene.dimension != 2:
        raise ArgumentError("invalid `perturbation`: a moved start (shift, turn, pose) is planar only here "
                            "(the 3-D rigs start at the plan's start)", "perturbation.shift")
    start = np.asarray(plan.poses[0], float) if pert.pose is None else P.spatial_to_planar(pert.pose)
    moved = start + np.array([pert.shift[0], pert.shift[2], -pert.turn])
    return moved - np.asarray(plan.poses[0], float)


def _refuse_start(scene, plan, pert, what: str) -> None:
    if _start_offset(scene, plan, pert) is not None:
        raise ArgumentError(f"invalid `perturbation`: {what} starts at the plan's start (no shift, turn or pose)",
                            "perturbation.shift")


def _planner(world, scene, plan, loop, pert, observe) -> dict:
    """The planner's view: quasi-static replay, MuJoCo, Drake (planar, open loop), or (closed)
    the MPC / re-planning."""
    if world.engine == "drake" and (scene.dimension == 3 or loop == "closed"):
        raise ArgumentError("invalid `world.engine`: Drake replays planar plans open loop (3-D and closed loop: "
                            "quasistatic or mujoco)", "world.engine")
    if scene.dimension == 3:
        _refuse_start(scene, plan, pert, "a 3-D run")
        if world.engine == "quasistatic":
            if not pert.nominal:
                raise ArgumentError("invalid `perturbation`: the 3-D quasi-static replay runs in the scene's own "
                                    "physics (use engine 'mujoco')", "perturbation")
            d = scene.replay(plan, **_options(world, scene.replay, {"feedback": loop == "closed"}))
        else:
            from ..mujoco.spatial import execute_plan3d

            d = execute_plan3d(scene, plan, **_options(world, execute_plan3d, {
                "friction_scale": pert.finger_friction, "grip_scale": pert.grip, "mass_scale": pert.mass,
                "feature_scale": pert.feature_friction, "feedback": loop == "closed"}))
        return {"final": d["final_pose"], "poses": d.get("poses"), "replans": int(d.get("replans", 0)), "detail": d}
    if loop == "closed":
        from ..control.loop import control

        se = _start_offset(scene, plan, pert)
        r = control(scene, plan, **_options(world, control, {
            "engine": world.engine, "policy": "mpc", "perturb": pert,
            "start_error": (0.0, 0.0, 0.0) if se is None else tuple(se)}))
        return {"final": r.final_pose, "poses": r.poses, "replans": r.replans, "detail": r,
                "duration": float(r.t[-1]) if r.t is not None and len(r.t) else None}
    _refuse_start(scene, plan, pert, "an open-loop planner's-view run")
    if world.engine == "quasistatic":
        from ..sim.quasistatic import replay_plan

        r = replay_plan(pert.scene(scene), plan, **_options(world, replay_plan, {}))
    elif world.engine == "drake":
        from ..drake.replay import replay_plan

        r = replay_plan(scene, plan, **_options(world, replay_plan, {"perturb": pert}))
    else:
        from ..mujoco.planar import execute_plan

        r = execute_plan(scene, plan, **_options(world, execute_plan, {"perturb": pert}))
    return {"final": r.final_pose, "poses": r.poses, "detail": r,
            "duration": float(r.t[-1]) if r.t is not None and len(r.t) else None}


def _free_gripper(world, scene, plan, loop, pert, observe) -> dict:
    """The free-flying gripper in the workcell (open loop, the scene's physics)."""
    from .free_gripper import execute_free_gripper
    from .world_motion import world_motion

    if loop != "open":
        raise ArgumentError("invalid `loop`: the free gripper runs open loop (the arm closes the loop)", "loop")
    if not pert.nominal:
        raise ArgumentError("invalid `perturbation`: the free-gripper rig runs in the scene's own physics "
                            "(use the arm)", "perturbation")
    motion = world_motion(scene, plan, **_options(world, world_motion, {"workcell": world.workcell}))
    r = execute_free_gripper(scene, plan, motion)
    return {"final": r.in_hand[-1], "poses": r.in_hand, "detail": r, "duration": r.duration,
            "creep": (r.max_creep, r.max_creep_angle), "motion": motion, "trajectory": motion}


def _arm(world, scene, plan, loop, pert, observe) -> dict:
    """The arm in the workcell: the joint trajectory open loop, or the arm in the MPC's loop."""
    se = _start_offset(scene, plan, pert)
    if loop == "closed":
        from .arm_loop import control_arm

        if not world.noslip:
            raise ArgumentError("invalid `world.noslip`: False is for the open loop only", "world.noslip")
        r = control_arm(scene, plan, **_options(world, control_arm, {
            "workcell": world.workcell, "scales": pert, "robot": world.robot,
            "start_error": np.zeros(3) if se is None else se, "sensing": world.grip_sensing}))
        return {"final": r.final, "detail": r, "duration": r.duration, "replans": r.replans}
    from .arm import execute_arm

    am = arm_motion_of(world, plan)
    start = None if se is None else np.asarray(plan.poses[0], float) + se
    r = execute_arm(scene, plan, am.motion, world.robot, pert, observe=observe, trajectory=am.trajectory, start=start,
                    sensing=world.grip_sensing, noslip=world.noslip)
    return {"final": r.in_hand[-1], "poses": r.in_hand, "detail": r, "duration": r.duration,
            "creep": (r.max_creep, r.max_creep_angle), "tracking": r.tracking, "motion": am.motion,
            "trajectory": r.trajectory, "refused": list(am.refused)}


def check_hand_world(world: World, loop: str, pert: Perturbation, what: str) -> None:
    """What a run of regrasp actions (the arm holding the object by its hand, thesis §1.1.1)
    needs: the arm rig, open loop and its own world (the table and the post: no workcell, no
    options; the perturbation's shift, turn or pose move the object in the hand at the start);
    an ArgumentError naming the field otherwise."""
    if world.rig != "arm":
        raise ArgumentError(f"invalid `world.rig`: {what} runs with the arm", "world.rig")
    if loop != "open":
        raise ArgumentError(f"invalid `loop`: {what} runs open loop", "loop")
    if world.workcell is not None or world.options:
        raise ArgumentError(f"invalid `world.workcell`: {what} runs in its object's own world (the table and the "
                            "post; no workcell or options)", "world.workcell")


def _pick_place(world, scene, r, loop, pert, observe) -> Execution:
    """A planned pick-regrasp-place (:class:`~regrasp.execution.pick_place.PickPlace`) executed by
    the arm in its own workcell; its task is the place: ``goal_error`` = ``plan_end_error`` =
    ``[position (m), angle (rad)]`` of the object's final world pose from the place pose, success
    within :data:`~regrasp.execution.pick_place.PLACE_TOLERANCE`."""
    from .pick_place import execute_pick_place

    if world.rig != "arm":
        raise ArgumentError("invalid `world.rig`: a pick-regrasp-place runs with the arm", "world.rig")
    if loop != "open":
        raise ArgumentError("invalid `loop`: a pick-regrasp-place runs open loop", "loop")
    for k in ("options", "robot"):
        if getattr(world, k):
            raise ArgumentError(f"invalid `world.{k}`: a pick-regrasp-place takes its settings from its planning "
                                "(pick_place)", f"world.{k}")
    if world.workcell is not None and world.workcell is not r.motion.workcell:
        raise ArgumentError("invalid `world.workcell`: a pick-regrasp-place runs in the workcell it was planned "
                            "in (leave it out)", "world.workcell")
    if r.scene != scene.name:
        raise ArgumentError(f"invalid `plan`: a pick-regrasp-place of {r.scene!r}, not of {scene.name!r}", "plan")
    if pert.pose is not None or any(pert.shift) or pert.turn:
        raise ArgumentError("invalid `perturbation`: a pick-regrasp-place starts from its pick pose (no shift, "
                            "turn or pose)", "perturbation.shift")
    x = execute_pick_place(scene, r, pert, observe=observe, sensing=world.grip_sensing)
    err = np.asarray(x.place_error, float)
    return Execution(bool(x.success), err, err.copy(), bool(x.success), np.asarray(x.final_pose, float), world, loop,
                     pert, x.duration, tracking=x.tracking, motion=r.motion, trajectory=r.arm, detail=x)


def arm_motion_of(world: World, plan):
    """The arm's :class:`~regrasp.execution.arm.ArmMotion` of ``plan`` in ``world`` (its world
    motion in the workcell and joint trajectory, IK solved in the nominal world: the robot is
    sent one trajectory, a perturbation is the world's, unknown to it), solved once per world and
    plan; an ExecutionError when the arm cannot do the plan."""
    from .arm import arm_motion

    plan = as_plan(plan, world.scene)
    hit = world._motions.get(id(plan))
    if hit is None or hit[0] is not plan:  # the plan is kept with it: its id stays its own
        am = arm_motion(world.scene, plan, **_options(world, arm_motion, {
            "workcell": world.workcell, "robot": world.robot, "scales": Perturbation()}))
        world._motions[id(plan)] = hit = (plan, am)
    return hit[1]


_RUNNERS = {"planner": _planner, "free-gripper": _free_gripper, "arm": _arm}


def _pushes(plan: Plan, motion) -> list:
    """Per push: its pusher, first and last plan step and (with a world motion) its feature."""
    if motion is not None:
        return [{"pusher": a.pusher, "first": int(a.first), "last": int(a.last), "feature": a.feature}
                for a in motion.assignments]
    out, pushers = [], list(plan.pushers)
    for i in range(1, len(pushers)):
        if out and out[-1]["pusher"] == pushers[i] and out[-1]["last"] == i - 1:
            out[-1]["last"] = i
        else:
            out.append({"pusher": pushers[i], "first": i - 1, "last": i, "feature": None})
    return out


def _judged(world, scene, plan: Plan, loop, pert, run: dict) -> Execution:
    """The rig's run judged against the task and the plan's end, in the scene's pose form."""
    final = np.asarray(run["final"], float)
    if scene.dimension == 2 and final.shape == (7,):
        final = P.spatial_to_planar(final)
    end = np.asarray(plan.poses[-1], float)
    err, ok = scene.goal_error(final, None if scene.task is not None else end)
    end_err, at_end = scene.goal_error(final, end)
    creep = run.get("creep", (None, None))
    poses = run.get("poses")
    return Execution(bool(ok), np.asarray(err, float), np.asarray(end_err, float), bool(at_end), final, world, loop,
                     pert, run.get("duration"), creep[0], creep[1], run.get("tracking"), int(run.get("replans", 0)),
                     _pushes(plan, run.get("motion")), None if poses is None else np.asarray(poses, float),
                     run.get("trajectory"), run.get("motion"), run.get("refused", []), run["detail"])
