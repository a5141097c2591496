"""The arm's ``mujoco.MjSpec`` from its model file, MJCF or URDF (MuJoCo compiles both), made
ready for the robot model (:func:`regrasp.robot.model.robot_spec`):

- a URDF's ``package://NAME/…`` mesh paths resolved against the nearest folder ``NAME`` above
  the file (a ROS package's share folder, as a package that ships URDFs lays them out), its visual
  elements dropped (MuJoCo reads STL, OBJ and MSH meshes, not the DAE of many visuals), and its
  fixed links kept as bodies (``fusestatic`` off: the flange is often one);
- the ``remove`` bodies deleted with their subtrees (e.g. the arm's own hand);
- a site ``attachment_site`` on the ``flange_body`` at ``flange_pose``, where the gripper mounts
  (Menagerie's arms have it already);
- a position actuator per arm joint with gains ``kp``, ``kv`` and the joint's range as its
  control range, when the model has none (a URDF), and the arm joints' ``armature``."""

from __future__ import annotations

import re
from pathlib import Path

from ..errors import ArgumentError
from ..extras import need

#: The site where the gripper mounts (the flange), as Menagerie's arms name it.
FLANGE_SITE = "attachment_site"
#: MuJoCo's URDF extension: fixed links kept as bodies, visuals dropped, mesh paths kept whole.
URDF_COMPILER = '<mujoco><compiler fusestatic="false" discardvisual="true" strippath="false"/></mujoco>'


def arm_spec(kind, model_path: str):
    """The arm of robot kind ``kind`` (:class:`~regrasp.robot.kinds.RobotKind`) from its model file
    ``model_path``, prepared as the module says. ArgumentError naming ``arm.*`` when a named
    body or joint is not in the model."""
    mujoco = need("mujoco", "robot")
    path = Path(model_path)
    if path.suffix.lower() == ".urdf":
        s = mujoco.MjSpec.from_string(urdf_text(path))
    else:
        s = mujoco.MjSpec.from_file(str(path))
    _body(s, kind.arm_root, "arm.root")  # the body the robot model attaches
    for b in kind.remove:
        body = _body(s, b, "arm.remove")
        s.delete(body)
    if kind.flange_body:  # the robot file's flange replaces the model's own
        if s.site(FLANGE_SITE) is not None:
            s.delete(s.site(FLANGE_SITE))
        q = kind.flange_pose or (0, 0, 0, 1, 0, 0, 0)
        _body(s, kind.flange_body, "arm.flange").add_site(name=FLANGE_SITE, pos=list(q[:3]), quat=list(q[3:]))
    joints = [_joint(s, j) for j in kind.arm_joints]
    if kind.armature:
        for j in joints:
            j.armature = kind.armature
    if not list(s.actuators):
        for i, j in enumerate(joints):
            kp, kv = kind.kp[i], kind.kv[i]
            s.add_actuator(name=j.name, trntype=mujoco.mjtTrn.mjTRN_JOINT, target=j.name,
                           gaintype=mujoco.mjtGain.mjGAIN_FIXED, biastype=mujoco.mjtBias.mjBIAS_AFFINE,
                           gainprm=[kp] + [0] * 9, biasprm=[0, -kp, -kv] + [0] * 7,
                           ctrlrange=list(j.range), ctrllimited=True)
    return s


def urdf_text(path: Path) -> str:
    """The URDF at ``path`` as MuJoCo should read it (see the module's doc)."""
    from ..files import read_text

    text = read_text(path, "arm.model")
    text = re.sub(r"<visual\b.*?</visual>", "", text, flags=re.S)

    def package(m):
        name, rest = m.group(1), m.group(2)
        for folder in path.resolve().parents:
            if folder.name == name:
                return str(folder / rest)
        raise ArgumentError(f"invalid `arm.model`: {path} names `package://{name}/…` but no folder {name!r} "
                            "holds it", "arm.model")

    text = re.sub(r"package://([^/\"']+)/([^\"']*)", package, text)
    text = re.sub(r'filename="(?!/)([^"]+)"', lambda m: f'filename="{(path.parent / m.group(1)).resolve()}"', text)
    text, n = re.subn(r"(<robot\b[^>]*>)", lambda m: m.group(1) + URDF_COMPILER, text, count=1)
    if not n:
        raise ArgumentError(f"invalid `arm.model`: {path} has no <robot> element (a URDF)", "arm.model")
    return text


def _body(s, name: str, field: str):
    b = s.body(name)
    if b is None:
        raise ArgumentError(f"invalid `{field}`: the arm's model has no body {name!r}", field)
    return b


def _joint(s, name: str):
    j = s.joint(name)
    if j is None:
        raise ArgumentError(f"invalid `arm.joints`: the arm's model has no joint {name!r}", "arm.joints")
    return j
