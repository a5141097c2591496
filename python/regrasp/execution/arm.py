"""A world motion (:func:`~regrasp.execution.world_motion`) executed by a real arm and gripper
in MuJoCo (:mod:`regrasp.robot`: the UR5e + Robotiq 2F-85): the joint-space trajectory by
inverse kinematics, then the arm under joint position control, the fingers force-controlled,
holding the object against the workcell's fixed features.

The model: the robot (its base at the workcell's ``robot.base``, no table of its own), the
table and every feature as fixed geoms colliding with the object and the robot
(:func:`~regrasp.mujoco.world.add_workcell_geoms`), and the object on a free joint
(:func:`regrasp.mujoco.model.add_object`: the planar scene's lamina, 12 mm thick; a 3-D scene's
mesh). The pads are the 2F-85's, a grid of point contacts of the scene's pad shape
(:meth:`~regrasp.robot.pads.Pads.of_scene`) with the scene's finger friction; the limit surface
comes from MuJoCo's contacts. The TCP is midway between the pads, which close on the object's
extreme points across the grasp (its width sets the TCP, :func:`grasp_of`); the regrasp gripper
frame is the TCP shifted by the grasp's centre.

The joint trajectory: the TCP's world poses along the motion (every sample) by
:func:`~regrasp.robot.ik.ik_path` from the arm's solution for the first pose (from its home
joints), clear of the table and the features; when that path hits a joint limit, the same path
with that joint wound 2π the other way from where it stopped (the same arm shape); when it hits a
collision, a joint limit or a branch flip, from up to :data:`~regrasp.robot.branches.MAX_BRANCHES` other branches of the arm at the first pose
(:func:`~regrasp.robot.ik.ik_solutions`: a UR5e's wrist_1 clear of a feature with the elbow the
other way). A pose the arm cannot reach on any of them (its reach, a joint
limit, a collision, a branch flip) fails the execution with an :class:`~regrasp.errors.ExecutionError`
naming the push (or the transfer before it) and why. The object starts in the hand: held at the
motion's first in-hand pose while the fingers close, then let go."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import pose as P
from ..errors import ArgumentError, ExecutionError
from ..extras import need
from ..scene.perturbation import ArmScales, Perturbation
from .world_motion import WorldMotion

#: The object's colour in the arm's model (red, green, blue, alpha): seen in videos.
OBJECT_RGBA = (0.95, 0.55, 0.1, 1.0)
#: Time [s] the fingers close on the object held in place (at least, at most, until both pads
#: press within :data:`SETTLED` of the grip force).
CLOSE_TIME = (0.3, 1.5)
SETTLED = 0.05
#: Period [s] of the grip force loop during an execution (1 kHz; the fingers' loop of
#: :class:`~regrasp.robot.grip.GripController` is 2 kHz by default: half the cost per step,
#: the same holding within 0.01 N).
GRIP_PERIOD = 0.001
#: Clearance [m] the arm and gripper keep from the table and the features while in contact
#: (approach, push, retreat: the fingers hold the object against a feature); elsewhere the IK's
#: ``MIN_DISTANCE``.
CONTACT_CLEARANCE = 0.001
#: Depth [m] beyond which the object, at a planned in-hand pose, is inside the gripper's own body
#: (its housing, the fingers' linkage; the pads excepted): the plan cannot be done in this hand.
HAND_TOUCH = 1e-6
#: How many choices of contacts :func:`arm_motion` tries before giving up.
MAX_TRIES = 6
#: Time [s] the arm holds still after the motion before the object's pose is measured.
SETTLE = 0.3


#: The old name (deprecated): ``regrasp.Perturbation`` (the features at their nominal friction by default, as there).
Scales = ArmScales


@dataclass
class ArmTrajectory:
    """The arm's joint-space trajectory of a world motion: ``robot`` (registry name),
    ``joint_names``, per motion sample ``times`` (n,) [s] (time-parametrised within the robot's
    joint limits, never faster than the motion: :func:`~regrasp.execution.retime.retime`),
    ``q`` (n, 6) [rad], ``qd`` (n, 6) [rad/s] and ``qdd`` (n, 6) [rad/s²]; ``tcp`` (7,) the TCP's
    pose in regrasp's gripper frame (m, unit quaternion); ``grasp_width`` [m]; ``holding``: the
    pads' :class:`~regrasp.execution.holding.Holding` along it (None: not tested, a 3-D scene)."""
    robot: str
    joint_names: list
    times: np.ndarray
    q: np.ndarray
    tcp: np.ndarray
    grasp_width: float
    qd: np.ndarray | None = None
    qdd: np.ndarray | None = None
    holding: object = None


@dataclass
class ArmResult:
    """An arm execution: ``success`` (the object's final in-hand pose within the scene's goal
    tolerance of the plan's goal); ``goal_error`` (planar ``[x, z, theta]`` (m, m, rad) or 3-D
    ``[position, angle]`` (m, rad)); ``max_creep`` [m] / ``max_creep_angle`` [rad]: the most the
    object moved in the gripper frame within a run of non-push samples; ``duration`` [s]
    simulated; ``tracking`` (:class:`~regrasp.robot.tracking.Tracking`); ``trajectory`` (the
    :class:`ArmTrajectory` sent); ``times`` (n,) [s], ``in_hand`` (n, 7) the object's measured
    pose in the gripper frame per motion sample, ``planned`` (n, 7) the motion's; ``q`` (n, 6)
    [rad] the arm's measured joints."""
    success: bool
    goal_error: np.ndarray
    max_creep: float
    max_creep_angle: float
    duration: float
    tracking: object
    trajectory: ArmTrajectory
    times: np.ndarray
    in_hand: np.ndarray
    planned: np.ndarray
    q: np.ndarray


def grasp_of(scene, in_hand) -> tuple[float, float]:
    """(width [m], centre [m]) of the grasp at in-hand pose ``in_hand`` (m, unit quaternion):
    the distance between the object's extreme points along the gripper's y (the pads' faces) and
    their midpoint's y. Planar: the lamina (:data:`regrasp.mujoco.model.THICKNESS`), centred."""
    from ..mujoco.model import THICKNESS

    if scene.dimension == 2:
        return THICKNESS, 0.0
    R = scene.sphere
    if R:
        return 2 * R, float(in_hand[1])
    v = np.asarray(scene.mesh()[0], float)
    y = P.transform(in_hand, v)[:, 1]
    return float(y.max() - y.min()), float((y.max() + y.min()) / 2)


def _pad_friction(scene) -> float:
    return scene.pad_friction


def build_robot(scene, motion: WorldMotion, robot: str | None = None, scales: Perturbation = Perturbation(), pads=None,
                noslip: bool = True):
    """The robot (:func:`regrasp.robot.model.build`) in ``motion``'s workcell with the object on
    a free joint at the motion's first world pose, the fingers closed at its width
    (:func:`~regrasp.robot.grip.close_fingers`), the pads of the scene's pad shape and finger
    friction (``pads``: another :class:`~regrasp.robot.pads.Pads`, e.g. the old single-contact
    model :func:`~regrasp.robot.pads.single_contact`); ``noslip``: MuJoCo's no-slip
    post-processing as :class:`~regrasp.mujoco.model.Contact` sets it (False: none, MuJoCo's soft
    contacts alone, which let a held object creep); returns (robot, the object's body id, its
    geom ids, the TCP in the gripper frame)."""
    from dataclasses import replace

    from ..mujoco.model import Contact
    from ..mujoco.world import Layout, build as build_world
    from ..robot.grip import close_fingers
    from ..robot.model import build
    from ..robot.robot_file import robot_name
    from ..robot.pads import Pads

    wc = motion.workcell
    name = robot_name(robot if robot is not None else wc.robot.name)
    width, centre = grasp_of(scene, motion.in_hand[0])
    start = np.zeros(3) if scene.dimension == 2 else motion.object[0]
    world = Layout(scene, start, "robot", workcell=wc, perturbation=scales, object_rgba=OBJECT_RGBA)

    def add(spec):  # the world around the robot: the workcell's features at their (perturbed) friction, the object
        build_world(world, spec=spec)

    try:
        r = build(name, base_pose=wc.robot.base, table=None, pads=Pads.of_scene(scene) if pads is None else pads,
                  pad_friction=_pad_friction(scene) * scales.finger_friction, grasp_width=width, add=add,
                  contact=Contact() if noslip else replace(Contact(), noslip_iterations=0))
    except ArgumentError as e:
        if e.field == "grasp_width":
            raise ExecutionError(f"the object is {width * 1e3:.1f} mm wide across the grasp: the 2F-85 opens "
                                 f"85 mm", "grasp_width") from None
        raise
    close_fingers(r)  # as they will hold the object, so that the IK checks the closed linkage's clearance
    m = r.model
    body = m.body("object").id
    geoms = [g for g in range(m.ngeom) if m.geom_bodyid[g] == body]
    return r, body, geoms, np.array([0.0, centre, 0.0, 1.0, 0.0, 0.0, 0.0])


def where(motion: WorldMotion, i: int) -> str:
    """Names sample ``i`` of ``motion`` for a message: the push it belongs to (its pusher and
    feature) or the transfer before push k (or after the last)."""
    k = int(motion.push[i])
    t = f"t = {motion.times[i]:.2f} s"
    if k >= 0:
        a = motion.assignments[k]
        return f"push {k} ({motion.labels[i]}, pusher {a.pusher} on {a.feature}, {t})"
    nxt = [int(p) for p in motion.push[i:] if p >= 0]
    return f"the transfer before push {nxt[0]} ({t})" if nxt else f"the final transfer ({t})"


def first_solution(robot, target, avoid):
    """Arm joints [rad] reaching TCP pose ``target`` clear of ``avoid``: the differential IK from
    the arm's home, else from home with the wrist's last joint or the base turned by ±π/2 or π
    (a large turn of the TCP from home can stall it); the home's IKError when none reaches it."""
    from ..robot.ik import IKError, IKSolver

    solver, home = IKSolver(robot, avoid), np.asarray(robot.kind.home, float)
    first = None
    for j, turn in [(None, 0.0), (5, np.pi), (5, -np.pi), (5, np.pi / 2), (5, -np.pi / 2), (0, np.pi / 2),
                    (0, -np.pi / 2)]:
        q = home.copy()
        if j is not None:
            q[j] += turn
        try:
            return solver.solve(target, q, field="poses[0]")
        except IKError as e:
            first = first or e
    raise first


#: How far [m] :func:`hand_clearance` looks: beyond it the object is clear of the hand (inf).
HAND_REACH = 0.01


def hand_clearance(robot, motion: WorldMotion, tcp) -> tuple[float, int, str]:
    """(m, sample, body): the smallest signed distance (MuJoCo's ``mj_geomDistance``, negative
    inside) from the object at each in-hand pose of ``motion`` to the gripper's body (every
    colliding geom of the gripper but the pads'), the fingers as :func:`build_robot` closed
    them, the sample where it is smallest and the gripper body it is to; (inf, 0, "") when the
    object stays farther than :data:`HAND_REACH`. The planner sees only the pads: a regrasp that
    raises the object far enough towards the palm runs it into the housing (pivot-3d's lift),
    which no feature and no arm motion can avoid. (The arm's wrist, behind the gripper's base,
    is not checked: an object would meet the base first.)"""
    return clearance(robot, P.compose(robot.tcp_pose(), P.inverse(tcp)), motion.in_hand)


def clearance(robot, frame, in_hand) -> tuple[float, int, str]:
    """(m, index, body): the smallest signed distance (``mj_geomDistance``, negative inside) from
    the object (body ``object``) at each of the poses ``in_hand`` (n, 7) in the world frame
    ``frame`` (7,) to the gripper's body (its colliding geoms but the pads'), the fingers as they
    are in ``robot``'s data; the pose where it is smallest and the gripper body; (inf, 0, "")
    when farther than :data:`HAND_REACH` (:func:`hand_clearance`)."""
    mujoco = need("mujoco", "robot")
    from ..robot.model import GRIPPER_PREFIX

    m = robot.model
    d = mujoco.MjData(m)
    d.qpos[:] = robot.data.qpos
    body = m.body("object").id
    jq = m.jnt_qposadr[m.body_jntadr[body]]
    pads = {int(m.geom_bodyid[g]) for side in robot.pad_geoms for g in side}
    obj = [g for g in range(m.ngeom) if m.geom_bodyid[g] == body]
    hand = [g for g in robot.robot_geoms if m.geom_bodyid[g] not in pads
            and mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, int(m.geom_bodyid[g])).startswith(GRIPPER_PREFIX)]
    best, at, part, last = np.inf, 0, "", None
    for i, h in enumerate(np.asarray(in_hand, float)):
        if last is not None and np.max(np.abs(h - last)) < 1e-7:
            continue  # the object still in the hand where it was last checked
        last = h
        d.qpos[jq:jq + 7] = P.compose(frame, h)
        mujoco.mj_kinematics(m, d)
        for g in hand:
            for o in obj:
                dist = mujoco.mj_geomDistance(m, d, o, g, HAND_REACH, None)
                if dist < min(best, HAND_REACH):
                    best, at, part = dist, i, mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, int(m.geom_bodyid[g]))
    return float(best), at, part


def check_hand(robot, motion: WorldMotion, tcp) -> None:
    """Raises ExecutionError when the object, at a planned in-hand pose, goes more than
    :data:`HAND_TOUCH` into the gripper's body (:func:`hand_clearance`); its field names the
    plan's pusher of the push (``plan.path[i].pusher``), or, outside a push, the plan's pose
    the object is held at (``plan.path[i].pose``: ``path[0]``, the start, before the first push)."""
    dist, i, part = hand_clearance(robot, motion, tcp)
    if dist >= -HAND_TOUCH:
        return
    k = int(motion.push[i])
    if k >= 0:
        field_ = f"plan.path[{motion.assignments[k].first + 1}].pusher"
    else:  # held between pushes: at the end of the last push before it
        done = [int(p) for p in motion.push[:i] if p >= 0]
        field_ = f"plan.path[{motion.assignments[done[-1]].last if done else 0}].pose"
    raise ExecutionError(f"the plan cannot be done in this hand: at {where(motion, i)} the object goes "
                         f"{-dist * 1e3:.2f} mm into the gripper's `{part.split('/')[-1]}` (the planner sees only "
                         f"the pads)", field_)


def solve_arm(robot, motion: WorldMotion, tcp, load=None, boost: bool = False) -> ArmTrajectory:
    """The arm's :class:`ArmTrajectory` putting the TCP at ``motion.gripper ∘ tcp`` at every
    sample, clear of the table and the workcell's features (by :data:`CONTACT_CLEARANCE` in
    contact, else the IK's ``MIN_DISTANCE``); from the solution for the first pose
    found from the arm's home, else from another branch (see the module's doc); timed so that
    the pads hold the object's ``load`` (an :class:`~regrasp.execution.holding.ObjectLoad`,
    :func:`timed`; with ``boost``, the grip raised between pushes where gravity takes more than
    :func:`~regrasp.execution.holding.transfer_share` of the pads' friction, written into
    ``motion.grip_force``). Raises ExecutionError naming the push (see the module's doc), or
    when the plan puts the object into the gripper's body (:func:`check_hand`)."""
    from ..robot.branches import other_branch
    from ..robot.ik import MIN_DISTANCE, IKError, fixed_geoms, ik_path

    check_hand(robot, motion, tcp)
    avoid = fixed_geoms(robot)
    targets = P.compose_rows(motion.gripper, np.broadcast_to(tcp, motion.gripper.shape))
    gaps = [CONTACT_CLEARANCE if lab in ("approach", "push", "retreat") else MIN_DISTANCE for lab in motion.labels]
    q0 = None
    try:
        q0 = first_solution(robot, targets[0], avoid)
        q = ik_path(robot, targets, q0, avoid=avoid, min_distance=gaps)
    except IKError as e:
        q = other_branch(robot, targets, avoid, gaps, q0, e)
        if q is None:
            raise _arm_error(motion, e) from None
    if load is not None and boost:
        _boost(robot, motion, load, q)
    return timed(robot, motion, tcp, q, load)


def grip_ceiling(robot) -> float:
    """The most per-finger grip force [N] the grip is raised to between pushes:
    :data:`~regrasp.execution.holding.MAX_GRIP_SHARE` of the gripper's force range."""
    from ..robot.grip import robot_pad_state
    from ..robot.kinds import GRIP_RANGE
    from .holding import MAX_GRIP_SHARE

    gain, bias, _ = robot_pad_state(robot)
    return MAX_GRIP_SHARE * (GRIP_RANGE * gain + bias)


def _boost(robot, motion: WorldMotion, load, q) -> None:
    """The grip raised between pushes (:meth:`~regrasp.execution.holding.ObjectLoad.boost`),
    within :func:`grip_ceiling`: ``motion.grip_force`` per sample."""
    f = np.asarray(motion.grip_force, float)
    base = float(np.max(f)) if np.any(f > 0) else 0.0
    if base <= 0:
        return
    scale = load.boost(q, grip_ceiling(robot) / base)
    motion.grip_force = np.where(f > 0, f * scale, f)


def timed(robot, motion: WorldMotion, tcp, q, load=None) -> ArmTrajectory:
    """The :class:`ArmTrajectory` of joint path ``q`` (one row per sample of ``motion``), time-
    parametrised within the robot's joint limits (:func:`~regrasp.execution.retime.retime`) and,
    with ``load``, slowed where the pads could not hold the object's load with the scene's
    required margin (:mod:`.holding`). ExecutionError naming where (and the push it serves or
    leads to, ``push``) when gravity alone leaves less than that margin, or no timing holds."""
    from .holding import required_margin
    from .retime import HoldError, retime

    hold = None
    if load is not None:
        allowed = 1.0 - required_margin(load.scene)
        still = load.at_rest(q)
        if np.nanmax(still, initial=0.0) > allowed:
            i = int(np.nanargmax(still))
            raise _hold_error(motion, i, f"gravity alone takes {still[i]:.1%} of the pads' friction there, where at "
                                         f"most {allowed:.1%} may be (the required margin {1 - allowed:.1%}: "
                                         "the scene's uncertainty and HOLD_MARGIN)")
        hold = lambda idx, qq, qd, qdd: load.ratios(idx, qq, qd, qdd) / allowed  # noqa: E731
    try:
        t = retime(motion.times, q, robot.kind.velocity_limit, robot.kind.acceleration_limit, hold)
    except HoldError as e:
        raise _hold_error(motion, e.sample, f"its load takes {e.excess:.2f} of the allowed share of the pads' "
                                            "friction however slowly the arm moves") from None
    holding = None if load is None else load.holding(q, t.qd, t.qdd, lambda i: where(motion, i))
    return ArmTrajectory(robot.name, list(robot.kind.arm_joints), motion.times[0] + t.times, q,
                         np.asarray(tcp, float), robot.grasp_width, t.qd, t.qdd, holding)


def _hold_error(motion: WorldMotion, i: int, why: str) -> ExecutionError:
    """The ExecutionError of the pads unable to hold the object at sample ``i``: where, why, and
    the push it serves or leads to (``push``: another contact may need less tilt)."""
    err = ExecutionError(f"the pads cannot hold the object in {where(motion, i)}: {why}", "robot")
    err.push = _push_of(motion, i)
    return err


def _push_of(motion: WorldMotion, i: int) -> int:
    """The push sample ``i`` serves or leads to (the final transfer: the last push's)."""
    return next((int(p) for p in motion.push[i:] if p >= 0), int(motion.push.max()))


def object_load(scene, robot, body: int, tcp, motion: WorldMotion):
    """The :class:`~regrasp.execution.holding.ObjectLoad` of a planar ``scene``'s object held
    through ``motion`` (None for a 3-D scene: not tested)."""
    from .holding import ObjectLoad

    return ObjectLoad(scene, robot, body, tcp, motion) if scene.dimension == 2 else None


def _arm_error(motion: WorldMotion, e) -> ExecutionError:
    """The ExecutionError of a path's IKError ``e``: where in ``motion`` and why, with the push it
    serves or leads to (``push``; the final transfer: the last push's)."""
    i = int(e.field.split("[")[1].rstrip("]")) if "[" in (e.field or "") else 0
    why = str(e).split(": ", 1)[1] if ": " in str(e) else str(e)
    err = ExecutionError(f"the arm cannot execute {where(motion, i)}: {why}", "robot")
    err.push = _push_of(motion, i)
    return err


@dataclass
class ArmMotion:
    """A plan made executable by the arm (:func:`arm_motion`): the world ``motion``, the
    ``robot`` built for it, the object's ``body`` id and ``geoms``, the ``tcp`` in the gripper
    frame (m, unit quaternion), the joint ``trajectory``; ``refused``: the (push, contact, why)
    the arm could not follow, each replaced by the next contact that serves the push."""
    motion: WorldMotion
    robot: object
    body: int
    geoms: list
    tcp: np.ndarray
    trajectory: ArmTrajectory
    refused: list


def arm_motion(scene, plan, workcell=None, robot: str | None = None, scales: Perturbation = Perturbation(), timing=None,
               max_tries: int = MAX_TRIES) -> ArmMotion:
    """The world motion of ``plan`` in ``workcell`` (default: the scene's default workcell) that the
    arm ``robot`` (default: the workcell's) can follow, and its joint trajectory: when the arm
    cannot follow a push with the contact :func:`~regrasp.execution.world_motion` chose (its
    reach, a joint limit, the fingers against the feature), the push goes to the next contact
    that serves it, at most ``max_tries`` times. ExecutionError naming the push when none is left."""
    from .world_motion import Timing, world_motion

    refused, exclude = [], set()
    for _ in range(max_tries):
        try:
            motion = world_motion(scene, plan, workcell, Timing() if timing is None else timing, exclude=exclude)
        except ExecutionError as e:
            if not refused:
                raise
            raise ExecutionError(f"{e}; where the arm could not follow: "
                                 + "; ".join(f"push {k} on {f}: {why}" for k, f, why in refused), "robot") from None
        r, body, geoms, tcp = build_robot(scene, motion, robot, scales)
        try:
            load = object_load(scene, r, body, tcp, motion)
            return ArmMotion(motion, r, body, geoms, tcp, solve_arm(r, motion, tcp, load, boost=True), refused)
        except ExecutionError as e:
            k = getattr(e, "push", -1)
            if k < 0:
                raise
            a = motion.assignments[k]
            refused.append((k, a.feature, str(e)))
            exclude.add((k, a.feature))
    raise ExecutionError(f"the arm cannot follow the plan with {max_tries} choices of contacts: "
                         + "; ".join(f"push {k} on {f}: {why}" for k, f, why in refused), "robot")


def grip_sensing(robot, sensing=None):
    """What ``robot``'s grip loop measures: ``sensing`` (a
    :class:`~regrasp.robot.sensing.GripSensing`) when given, else its gripper's default
    (``robot.kind.sensing``, :data:`~regrasp.robot.kinds.GRIPPER_SENSING`)."""
    from ..robot.sensing import GripSensing

    return GripSensing.parse(robot.kind.sensing, "robot.sensing") if sensing is None else sensing


def close_on(robot, body: int, geoms, grip_force: float, sensing=None):
    """Closes the fingers on the object (held in place) until both pads press within
    :data:`SETTLED` of ``grip_force`` [N] (:data:`CLOSE_TIME`), the arm's servo holding the
    joints where they are (so the hand does not sag against the held object: 0.54 mm on
    offset-3d with the joints left free); returns the grip controller, its loop measuring as
    ``sensing`` says (:class:`~regrasp.robot.sensing.GripSensing`; None: the robot's gripper's
    default, :func:`grip_sensing`)."""
    mujoco = need("mujoco", "robot")
    from ..robot.grip import GripController, pad_forces
    from ..robot.tracking import Servo

    sensing = grip_sensing(robot, sensing)
    m, d = robot.model, robot.data
    jq, jv = m.jnt_qposadr[m.body_jntadr[body]], m.jnt_dofadr[m.body_jntadr[body]]
    hold, q = d.qpos[jq:jq + 7].copy(), robot.q.copy()
    grip = GripController(robot, grip_force, geoms, period=GRIP_PERIOD, sensing=sensing)
    servo = Servo(robot)
    t0 = d.time
    while d.time - t0 < CLOSE_TIME[1]:
        if d.time - t0 >= CLOSE_TIME[0] and np.all(np.abs(pad_forces(robot, geoms) - grip_force) <= SETTLED * grip_force):
            break
        servo.command(q)
        for _ in range(servo.steps):
            d.qpos[jq:jq + 7], d.qvel[jv:jv + 6] = hold, 0.0
            grip.update()
            mujoco.mj_step(m, d)
    return grip


def execute_arm(scene, plan, motion: WorldMotion, robot: str | None = None, scales: Perturbation = Perturbation(),
                observe=None, trajectory: ArmTrajectory | None = None, pads=None, start=None, sensing=None,
                noslip: bool = True) -> ArmResult:
    """Executes ``motion`` (the :class:`WorldMotion` of ``plan`` for ``scene``) with the arm
    ``robot`` (default: the workcell's) in MuJoCo, in a world perturbed by ``scales``, and
    measures it (:class:`ArmResult`). ``observe(robot)``: called after every control period
    (e.g. a video recorder). ``trajectory``: the arm's joint trajectory when already solved
    (:func:`solve_arm`, e.g. for repeated runs in perturbed worlds). Raises ExecutionError when
    the arm cannot follow the motion. ``pads``: as :func:`build_robot`'s. ``start``: where the
    object really starts in the hand (planar ``[x, z, theta]`` or ``[x, y, z, qw, qx, qy, qz]``;
    default the motion's first in-hand pose), the motion left as planned. ``sensing``: what the
    grip loop measures (:class:`~regrasp.robot.sensing.GripSensing`; None: the gripper's default,
    :func:`~regrasp.execution.arm.grip_sensing`); ``noslip``: as :func:`build_robot`'s."""
    mujoco = need("mujoco", "robot")
    from ..robot.grip import body_pose
    from ..robot.tracking import track
    from .free_gripper import _tolerance_error

    if not isinstance(motion, WorldMotion):
        raise ArgumentError(f"invalid `motion`: a WorldMotion (got {type(motion).__name__})", "motion")
    start = np.asarray(_start(scene, motion, start), float)
    r, body, geoms, tcp = build_robot(scene, motion, robot if trajectory is None else trajectory.robot, scales, pads,
                                      noslip)
    if trajectory is not None:
        check_hand(r, motion, tcp)  # solve_arm checks it otherwise
    traj = solve_arm(r, motion, tcp, object_load(scene, r, body, tcp, motion), boost=True) if trajectory is None \
        else trajectory
    m, d = r.model, r.data
    r.set_q(traj.q[0])
    jq = m.jnt_qposadr[m.body_jntadr[body]]
    d.qpos[jq:jq + 7] = P.compose(P.compose(r.tcp_pose(), P.inverse(tcp)), start)
    mujoco.mj_forward(m, d)
    grip = close_on(r, body, geoms, float(motion.grip_force[0]) * scales.grip, sensing)
    untcp = P.inverse(tcp)
    samples, qs, k = [], [], [0]

    def in_hand() -> np.ndarray:
        return P.compose(P.inverse(P.compose(r.tcp_pose(), untcp)), body_pose(d, body))

    def record(t: float) -> None:
        while k[0] < len(traj.times) and t >= traj.times[k[0]] - 1e-9:
            samples.append(in_hand())
            qs.append(r.q)
            k[0] += 1
            if k[0] < len(traj.times) and motion.grip_force[k[0]] != motion.grip_force[k[0] - 1]:
                grip.set_force(float(motion.grip_force[k[0]]) * scales.grip)  # raised between pushes
        if observe is not None:
            observe(r)

    tracking = track(r, traj.times, traj.q, settle=SETTLE, grip=grip, ease=False, observe=record)
    while len(samples) < len(motion.times):
        record(np.inf)
    H = np.array(samples)
    H[-1] = in_hand()  # after settling
    creep, turn = _creep(motion, H)
    err, ok = _tolerance_error(scene, plan, H[-1])
    return ArmResult(ok, err, creep, turn, float(d.time), tracking, traj, np.array(traj.times, float), H,
                     motion.in_hand.copy(), np.array(qs))


def _start(scene, motion: WorldMotion, start) -> np.ndarray:
    """The object's in-hand start pose (m, unit quaternion): ``start`` (planar ``[x, z, theta]``,
    admissible: the pad on the object; or 3-D) or the motion's; else an ArgumentError naming ``start``."""
    if start is None:
        return motion.in_hand[0]
    if scene.dimension != 2:
        from ..robot.model import check_pose

        return check_pose(start, "start")
    try:
        s = np.asarray(start, float)
    except (TypeError, ValueError):
        s = np.zeros(0)
    if s.shape != (3,) or not np.all(np.isfinite(s)):
        raise ArgumentError(f"invalid `start`: the object's in-hand start pose [x, z, theta] (m, m, rad) "
                            f"(got {start!r})", "start")
    if not scene.admissible(s):
        raise ArgumentError("invalid `start`: the object's start pose puts the pad off the object", "start")
    return np.asarray(P.planar_to_spatial(s), float)


def _creep(motion: WorldMotion, H) -> tuple[float, float]:
    """(m, rad): the most the object moved in the gripper frame within a run of non-push samples."""
    creep, turn, start = 0.0, 0.0, None
    for i, lab in enumerate(motion.labels):
        if lab == "push":
            start = None
            continue
        start = i if start is None else start
        creep = max(creep, float(np.linalg.norm(H[i, :3] - H[start, :3])))
        turn = max(turn, P.quat_angle(H[i, 3:], H[start, 3:]))
    return creep, turn
