"""The robot file (docs/robot-file.md): your arm and gripper as data. A TOML file names the arm's
model (MJCF or URDF, which MuJoCo compiles; paths relative to the file), its joints, home, joint
velocity and acceleration limits, where the gripper mounts, and the gripper: a bundled one by
name or the parametric parallel gripper with its parameters. :func:`load` reads and checks it
(a SceneError naming the field, ``arm.home[2]``; a model a Python package ships is
``dist://DISTRIBUTION/PATH``) into a :class:`~regrasp.robot.kinds.RobotKind`;
:func:`robot_name` takes a registry name or a robot file's path and registers the file's robot
under its ``name``, so every part of regrasp that takes a robot by name takes it."""

from __future__ import annotations

import math
from dataclasses import fields
from pathlib import Path

from ..errors import ArgumentError, SceneError
from ..fields import FieldCheck
from . import kinds
from .kinds import GRIPPER_SENSING, ROBOTS, RobotKind
from .franka_hand import FrankaHand
from .parallel_gripper import ParallelGripper

_CHECK = FieldCheck("robot file")
_fail, _number, _name, _vector, _keys = _CHECK.fail, _CHECK.number, _CHECK.name, _CHECK.vector, _CHECK.keys
KEYS = ("name", "arm", "gripper")
ARM_REQUIRED = ("model", "root", "flange", "joints", "home", "velocity_limit", "acceleration_limit", "shoulder", "reach")
ARM_OPTIONAL = ("flange_pose", "remove", "mounted", "kp", "kv", "armature")
#: The bundled grippers by ``gripper.kind`` (the parametric one takes its parameters beside it).
GRIPPERS = ("robotiq-2f85", "parallel", "franka-hand")
MAX_JOINTS = 16
#: The prefix of a model path inside an installed Python distribution.
DIST = "dist://"
#: The position gains [N·m/rad, N·m·s/rad] of arm joints a model gives no actuator, by default.
KP, KV = 2000.0, 400.0
_LOADED: dict = {}


def load(path) -> RobotKind:
    """The robot file at ``path`` as a :class:`~regrasp.robot.kinds.RobotKind` (its ``name``:
    :func:`name_of`). SceneError naming the field; ArgumentError (``path``) when it cannot be read."""
    from ..files import parse_toml, read_text

    path = Path(path)
    d = parse_toml(read_text(path, "path"), "(toml)", lambda why: SceneError(f"robot file: {why}", "(toml)"))
    return from_dict(d, path.resolve().parent, str(path))


def from_dict(d, folder: Path, source: str = "") -> RobotKind:
    """The robot of a dict laid out as the file; model paths relative to ``folder``."""
    _keys_subset(d, KEYS, KEYS[:2], "")
    name = _name(d["name"], "name")
    a = d["arm"]
    _keys_subset(a, ARM_REQUIRED + ARM_OPTIONAL, ARM_REQUIRED, "arm")
    model = model_path(_name(a["model"], "arm.model"), folder)
    if model.suffix.lower() not in (".xml", ".urdf") or not model.is_file():
        raise _fail("arm.model", "must be an MJCF (.xml) or URDF (.urdf) file that exists", str(model))
    joints = _names(a["joints"], "arm.joints")
    n = len(joints)
    per_joint = lambda k, lo, hi, unit: tuple(float(x) for x in _vector(a[k], n, f"arm.{k}", lo, hi, unit))  # noqa: E731
    home = per_joint("home", -2 * math.pi, 2 * math.pi, "rad")
    vel = per_joint("velocity_limit", 1e-3, 100.0, "rad/s")
    acc = per_joint("acceleration_limit", 1e-3, 1e3, "rad/s²")
    kp = per_joint("kp", 1.0, 1e6, "N·m/rad") if "kp" in a else (KP,) * n
    kv = per_joint("kv", 0.0, 1e5, "N·m·s/rad") if "kv" in a else (KV,) * n
    flange_pose = tuple(float(x) for x in _vector(a["flange_pose"], 7, "arm.flange_pose", -10, 10)) \
        if "flange_pose" in a else (0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0)
    if abs(math.hypot(*flange_pose[3:]) - 1) > 1e-6:
        raise _fail("arm.flange_pose", "its quaternion [qw, qx, qy, qz] must have unit norm", list(flange_pose))
    root, flange = _name(a["root"], "arm.root"), _name(a["flange"], "arm.flange")
    kind = RobotKind(arm_file=str(model), gripper_file="", arm_joints=joints, home=home, pad_bodies=("left_pad", "right_pad"),
                     driver="split", driver_joints=(), gripper_base="base", reach=_number(a["reach"], "arm.reach", 0.05, 10, "m"),
                     shoulder=_name(a["shoulder"], "arm.shoulder"),
                     mounted=_names(a.get("mounted", [root]), "arm.mounted"), velocity_limit=vel, acceleration_limit=acc,
                     arm_root=root, flange_body=flange, flange_pose=flange_pose,
                     remove=_names(a.get("remove", []), "arm.remove", empty=True), kp=kp, kv=kv,
                     armature=_number(a.get("armature", 0.1), "arm.armature", 0.0, 100.0, "kg·m²"), source=source,
                     name=name)
    return _with_gripper(kind, d.get("gripper", {"kind": "parallel"}))


def model_path(text: str, folder: Path) -> Path:
    """A robot file's model path: ``dist://DISTRIBUTION/PATH`` (a file an installed Python
    distribution ships, e.g. ``dist://example-robot-data/cmeel.prefix/…/panda.urdf``), or a path,
    relative to the file's ``folder``."""
    if not text.startswith(DIST):
        return folder / text
    import importlib.metadata

    dist, _, rest = text[len(DIST):].partition("/")
    try:
        return Path(importlib.metadata.distribution(dist).locate_file(rest))
    except importlib.metadata.PackageNotFoundError:
        raise _fail("arm.model", f"names the Python distribution {dist!r}, which is not installed", text) from None


def _with_gripper(kind: RobotKind, g) -> RobotKind:
    if not isinstance(g, dict):
        raise _fail("gripper", "must be a table", g)
    params = [f.name for f in fields(ParallelGripper)]
    _keys_subset(g, ("kind", "sensing", *params), ("kind",), "gripper")
    if g["kind"] not in GRIPPERS:
        raise _fail("gripper.kind", f"must be one of {', '.join(GRIPPERS)}", g["kind"])
    sensing = _sensing(g.get("sensing", GRIPPER_SENSING[g["kind"]]))
    g = {k: v for k, v in g.items() if k != "sensing"}
    kind = RobotKind(**{**kind.__dict__, "sensing": sensing})
    if g["kind"] in ("robotiq-2f85", "franka-hand") and len(g) > 1:
        raise _fail(f"gripper.{next(k for k in g if k != 'kind')}", f"the {g['kind']} gripper takes no parameters", g)
    if g["kind"] == "robotiq-2f85":
        base = ROBOTS["ur5e-2f85"]
        return RobotKind(**{**kind.__dict__, "gripper_file": base.gripper_file, "pad_bodies": base.pad_bodies,
                            "driver_joints": base.driver_joints, "opening": base.opening,
                            "calibration_height": base.calibration_height})
    try:
        p = FrankaHand() if g["kind"] == "franka-hand" else ParallelGripper(**{k: v for k, v in g.items() if k != "kind"})
    except ArgumentError as e:
        raise SceneError(f"robot file field `{e.field}`: {str(e).split(': ', 1)[-1]}", e.field) from None
    return RobotKind(**{**kind.__dict__, "gripper": p, "opening": p.stroke, "calibration_height": p.pad_height,
                        "driver_joints": ("right_finger_joint", "left_finger_joint")})


def _sensing(text) -> str:
    """``gripper.sensing`` checked (:meth:`~regrasp.robot.sensing.GripSensing.parse`)."""
    from .sensing import GripSensing

    if not isinstance(text, str):
        raise _fail("gripper.sensing", "must be a string: ideal, open-loop, sensor or sensor:NOISE,DELAY,BANDWIDTH", text)
    try:
        GripSensing.parse(text, "gripper.sensing")
    except ArgumentError as e:
        raise SceneError(f"robot file field `gripper.sensing`: {str(e).split(': ', 1)[-1]}", "gripper.sensing") from None
    return text


def _keys_subset(d, allowed, required, where: str) -> None:
    if not isinstance(d, dict):
        raise _fail(where or "(file)", "must be a table", type(d).__name__)
    pre = f"{where}." if where else ""
    for k in d:
        if k not in allowed:
            raise _fail(f"{pre}{k}", f"unknown key (the keys: {', '.join(allowed)})", k)
    for k in required:
        if k not in d:
            raise _fail(f"{pre}{k}", "is required", None)


def _names(x, where: str, empty: bool = False) -> tuple:
    if not isinstance(x, list) or (not x and not empty) or len(x) > MAX_JOINTS * 4:
        raise _fail(where, "must be a list of names" + ("" if empty else " (at least one)"), x)
    out = tuple(_name(v, f"{where}[{i}]") for i, v in enumerate(x))
    if len(set(out)) != len(out):
        raise _fail(where, "must not repeat a name", x)
    return out


def robot_name(name) -> str:
    """The registry name of robot ``name``: a bundled robot's name or alias
    (:func:`regrasp.robot.kinds.robot_name`), a bundled robot file's name (:func:`bundled`), or
    the path of a robot file (``.toml``), whose robot is then registered under its ``name`` (a
    bundled robot's name is refused)."""
    if isinstance(name, (str, Path)) and str(name).lower().endswith(".toml"):
        return register(load(name))
    if isinstance(name, str) and name not in ROBOTS and name in bundled():
        return register(load(bundled()[name]))
    try:
        return kinds.robot_name(name)
    except ArgumentError as e:
        raise ArgumentError(f"{e}, the bundled robot files ({', '.join(bundled())}) or a robot file's path "
                            "(ROBOT.toml, docs/robot-file.md)", "robot") from None


def bundled() -> dict:
    """The bundled robot files (``regrasp/examples/robots``) by their robot's name (the file's
    stem is its ``name``)."""
    folder = Path(__file__).resolve().parents[1] / "examples" / "robots"
    return {p.stem: p for p in sorted(folder.glob("*.toml"))}


def register(kind: RobotKind) -> str:
    """Adds a robot file's robot ``kind`` to the registry under its ``name``; returns the name."""
    from .grip import _low_force_curve, _pad_state

    name = kind.name
    if name in kinds.ALIASES or (name in ROBOTS and not ROBOTS[name].source):
        raise SceneError(f"robot file field `name`: {name!r} is a bundled robot's name; give yours another", "name")
    if ROBOTS.get(name) != kind:
        if name in ROBOTS:  # the file changed: measure its gripper again
            _pad_state.cache_clear()
            _low_force_curve.cache_clear()
        ROBOTS[name] = kind
    return name
