"""A parametric parallel-jaw gripper built with ``mujoco.MjSpec``: a palm and two straight
fingers on prismatic joints, coupled symmetric (a rack and pinion), driven by one force actuator,
with regrasp's distributed-contact pads at the fingertips. Its defaults follow the thesis' rig
(Chavan-Dafle 2020, §2.5: a WSG-style gripper with long, thin fingers that reach past an
object's outline, so that a lamina held at its edge clears the palm): 100 mm fingers, 8 mm
thick, 24 mm wide, with 20 mm square pads at their tips, a 110 mm stroke.

The model keeps the names and frames the robot model expects of a gripper (those of Menagerie's
Robotiq 2F-85, :mod:`.kinds`): a root body ``base_mount`` (on the arm's flange) and under it
``base`` turned −90° about z, its z along the fingers and its +y towards the right finger; pad
bodies ``left_pad`` and ``right_pad`` whose frames put the contact face at ``y = FACE_Y``
looking at the other finger, centred at ``z = LENGTH / 2`` (:mod:`.pads`; the grid spans this
gripper's own pad, :attr:`ParallelGripper.face`) and flush with the fingertip; a fixed tendon
``split`` (the fingers' mean closing [m] times ``GEAR``) that the grip actuator pulls. Each
finger's inner face stands :attr:`ParallelGripper.recess` behind its pad's face, so only the pads
touch a held object."""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

from ..errors import ArgumentError
from ..extras import need
from .pads import FACE_Y, HALF_WIDTH, LENGTH

#: The tendon's gear: joint force [N] per N of the grip actuator (20 N of actuator ≈ 100 N a pad).
GEAR = 5.0


#: The largest value and the unit of the parameters that are not lengths (at most 1 m).
BOUNDS = {"palm_mass": (100.0, "kg"), "finger_mass": (100.0, "kg"), "damping": (1e4, "N·s/m")}


@dataclass(frozen=True)
class ParallelGripper:
    """The gripper's shape [m]: ``finger_length`` (palm to fingertip), ``finger_width`` (across
    the fingers, at least the pad's width), ``finger_thickness`` (along the grasp axis), the
    pads' ``pad_width`` (across) and ``pad_length`` (along the finger, ending at its tip),
    ``stroke`` (the widest opening between the pads' faces), ``palm_height`` (along the fingers),
    ``recess`` (the finger's inner face behind the pad's face); masses [kg] ``palm_mass``,
    ``finger_mass``; ``damping`` [N·s/m] of each finger's joint."""

    finger_length: float = 0.10
    finger_width: float = 0.024
    finger_thickness: float = 0.008
    pad_width: float = 0.02
    pad_length: float = 0.02
    stroke: float = 0.11
    palm_height: float = 0.04
    recess: float = 0.001
    palm_mass: float = 0.6
    finger_mass: float = 0.05
    damping: float = 40.0

    def __post_init__(self):
        for f in fields(self):
            v, (most, unit) = getattr(self, f.name), BOUNDS.get(f.name, (1.0, "m"))
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or not 0 < v <= most:
                raise ArgumentError(f"invalid `gripper.{f.name}`: a number in (0, {most:g}] {unit} (got {v!r:.40})",
                                    f"gripper.{f.name}")
        for pad, finger, most in (("pad_width", "finger_width", 2 * HALF_WIDTH), ("pad_length", "finger_length", LENGTH)):
            if getattr(self, pad) > most:
                raise ArgumentError(f"invalid `gripper.{pad}`: at most {most * 1e3:.1f} mm (got {getattr(self, pad)})",
                                    f"gripper.{pad}")
            if getattr(self, finger) < getattr(self, pad):
                raise ArgumentError(f"invalid `gripper.{finger}`: at least the pad's {getattr(self, pad) * 1e3:.1f} mm "
                                    f"(got {getattr(self, finger)})", f"gripper.{finger}")

    @property
    def pad_height(self) -> float:
        """Height [m] of the pads' centres above the base, along the fingers."""
        return self.palm_height + self.finger_length - self.pad_length / 2

    @property
    def face(self) -> tuple:
        """The pad's face: (half-width, half-length) [m] (:meth:`regrasp.robot.pads.Pads.points`)."""
        return (self.pad_width / 2, self.pad_length / 2)

    def spec(self):
        """The gripper's ``mujoco.MjSpec`` (:func:`spec`)."""
        return spec(self)


def spec(g: ParallelGripper):
    """The gripper's ``mujoco.MjSpec`` (no actuator: :func:`regrasp.robot.kinds.gripper_spec`
    adds the grip's; no pads: :func:`regrasp.robot.pads.add_pads` adds them)."""
    mujoco = need("mujoco", "robot")
    s = mujoco.MjSpec()
    box = mujoco.mjtGeom.mjGEOM_BOX
    base = add_base(s)
    half_palm_y = g.stroke / 2 + g.recess + g.finger_thickness + 0.01
    base.add_geom(name="palm", type=box, size=[0.03, half_palm_y, g.palm_height / 2], pos=[0, 0, g.palm_height / 2],
                  mass=g.palm_mass, rgba=[0.25, 0.25, 0.28, 1])
    for side in ("right", "left"):
        finger = add_finger(base, side, g.stroke / 2, max(g.stroke / 2 - 0.001, 0.0), g.damping)
        finger.add_geom(name=f"{side}_finger_geom", type=box,
                        size=[g.finger_width / 2, g.finger_thickness / 2, g.finger_length / 2],
                        pos=[0, FACE_Y + g.recess + g.finger_thickness / 2, g.palm_height + g.finger_length / 2],
                        mass=g.finger_mass, rgba=[0.55, 0.57, 0.6, 1])
        add_pad_body(finger, side, g.pad_height, g.face)
    couple(s)
    return s


def add_base(s):
    """The gripper's root ``base_mount`` and, turned −90° about z from it, ``base`` (returned)."""
    mount = s.worldbody.add_body(name="base_mount")
    return mount.add_body(name="base", quat=[math.sqrt(0.5), 0, 0, -math.sqrt(0.5)])


def add_finger(base, side: str, half_open: float, travel: float, damping: float):
    """Finger ``side`` ("right" at +y of ``base``, "left" turned 180° about z at −y) on a prismatic
    joint ``{side}_finger_joint`` closing by up to ``travel`` [m], its frame putting the pad's
    face at ``y = FACE_Y`` and ``half_open`` [m] from the grasp axis when open."""
    mujoco = need("mujoco", "robot")
    sign = 1.0 if side == "right" else -1.0
    quat = [1, 0, 0, 0] if sign > 0 else [0, 0, 0, 1]  # the left finger turned 180° about z: its face looks at +y
    finger = base.add_body(name=f"{side}_finger", pos=[0, sign * (half_open - FACE_Y), 0], quat=quat)
    finger.add_joint(name=f"{side}_finger_joint", type=mujoco.mjtJoint.mjJNT_SLIDE, axis=[0, -1, 0],
                     range=[0, travel], limited=mujoco.mjtLimited.mjLIMITED_TRUE, damping=damping, armature=0.01)
    return finger


def add_pad_body(finger, side: str, height: float, face: tuple) -> None:
    """The pad body ``{side}_pad`` of ``finger``, its face's centre ``height`` [m] above the base
    (:mod:`.pads`' frame), drawn as a thin plate of ``face`` (half-width, half-length) [m]."""
    mujoco = need("mujoco", "robot")
    pad = finger.add_body(name=f"{side}_pad", pos=[0, 0, height - LENGTH / 2])
    pad.add_geom(type=mujoco.mjtGeom.mjGEOM_BOX, size=[face[0], 0.0005, face[1]], pos=[0, FACE_Y + 0.0005, LENGTH / 2],
                 contype=0, conaffinity=0, mass=0, rgba=[0.1, 0.1, 0.1, 1], group=1)


def couple(s) -> None:
    """The fingers' drive: the tendon ``split`` over both joints with gear :data:`GEAR` (the grip
    actuator pulls it) and a joint equality that moves them together (a rack and pinion)."""
    mujoco = need("mujoco", "robot")
    split = s.add_tendon(name="split")
    for side in ("right", "left"):
        split.wrap_joint(f"{side}_finger_joint", GEAR)
    s.add_equality(type=mujoco.mjtEq.mjEQ_JOINT, name1="right_finger_joint", name2="left_finger_joint",
                   data=[0, 1, 0, 0, 0] + [0] * 7, solref=[0.005, 1], solimp=[0.95, 0.99, 0.001, 0.5, 2])
