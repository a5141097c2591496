"""The Franka Hand built with ``mujoco.MjSpec`` from the model the ``example-robot-data`` package
ships (``pip install 'regrasp[panda]'``; nothing is downloaded): the hand's collision mesh
(``meshes/collision/hand.stl``) and each finger's four collision boxes of ``panda.urdf`` (screw
mount, carriage sledge, diagonal finger, rubber tip), the fingers on the hand's prismatic joints
(0–40 mm each, an 80 mm stroke), their frames 58.4 mm above the hand's base, the rubber tips'
faces (17.5 mm across, 18.5 mm along the finger) centred 103.65 mm above it (Franka's TCP:
103.4 mm).

The model keeps the names and frames of the parametric gripper (:mod:`.parallel_gripper`): the
root ``base_mount``, and ``base`` turned −90° about z from it, its +y towards the right finger
(Franka's ``panda_rightfinger``): the hand's own frame is ``base`` turned 180° about z, i.e. the
mount turned +90°, so that on Franka's flange (the hand turned −45° about z, as the Panda's
``panda_hand_joint``) the mount stands at −135° (``arm.flange_pose`` of
``examples/robots/panda-hand.toml``); pad bodies ``left_pad``, ``right_pad`` with the face at
``y = FACE_Y``, the tendon ``split`` and the force-driven grip of
:func:`regrasp.robot.kinds.gripper_spec`. The
rubber tip's box stands ``RECESS`` behind the pad's face: regrasp's distributed-contact pads are
the tip's surface. The hand's own joint damping (0.3 N·s/m) is replaced by the parametric
gripper's: the grip is force-controlled here, as the thesis assumes (Franka's hand holds a set
force too, through its own controller)."""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..errors import MissingExtraError
from ..extras import need
from .pads import FACE_Y
from .parallel_gripper import add_base, add_finger, add_pad_body, couple

#: Where ``example-robot-data`` keeps the Panda's description (under its distribution's files).
DESCRIPTION = "cmeel.prefix/share/example-robot-data/robots/panda_description"
#: The fingers' frames above the hand's base [m] (``panda_finger_joint1``'s origin).
FINGER_Z = 0.0584
#: Each finger's travel [m] (``panda_finger_joint1``'s upper limit).
TRAVEL = 0.04
#: The rubber tip's face in the finger's frame: y of the face [m], centre z [m], half-width
#: across [m], half-length along the finger [m] (the URDF's box at y 7.58 mm, size 15.2 mm).
TIP_FACE_Y, TIP_Z, TIP_HALF_WIDTH, TIP_HALF_LENGTH = 7.58e-3 - 7.6e-3, 45.25e-3, 17.5e-3 / 2, 18.5e-3 / 2
#: A finger's collision boxes in its own frame, its +y away from the other finger (Franka's
#: ``panda_leftfinger``'s; ``panda_rightfinger``'s are the same turned 180° about z): (name,
#: centre [m], rotation about x [rad], size [m]).
BOXES = (
    ("screw_mount", (0.0, 18.5e-3, 11e-3), 0.0, (22e-3, 15e-3, 20e-3)),
    ("sledge", (0.0, 6.8e-3, 2.2e-3), 0.0, (22e-3, 8.8e-3, 3.8e-3)),
    ("diagonal", (0.0, 15.9e-3, 28.35e-3), math.pi / 6, (17.5e-3, 7e-3, 23.5e-3)),
    ("tip", (0.0, 7.58e-3, 45.25e-3), 0.0, (17.5e-3, 15.2e-3, 18.5e-3)),
)
#: The rubber tip's box behind the pads' face [m] (only the pads touch a held object).
RECESS = 0.001
#: Masses [kg]: the hand (its URDF inertial) and each finger.
HAND_MASS, FINGER_MASS = 0.73, 0.015
#: Each finger joint's damping [N·s/m] (the parametric gripper's: a steady force-driven grip).
DAMPING = 40.0


def mesh_path() -> str:
    """The hand's collision mesh shipped by ``example-robot-data``; MissingExtraError naming the
    ``panda`` extra when the package is not installed."""
    import importlib.metadata

    try:
        dist = importlib.metadata.distribution("example-robot-data")
    except importlib.metadata.PackageNotFoundError:
        raise MissingExtraError("the Franka Hand needs the `example-robot-data` package: "
                                "pip install 'regrasp[panda]'", "example-robot-data") from None
    return str(dist.locate_file(f"{DESCRIPTION}/meshes/collision/hand.stl"))


@dataclass(frozen=True)
class FrankaHand:
    """The Franka Hand (no parameters: its shape is Franka's). The properties the robot model
    reads of a gripper, as :class:`~regrasp.robot.parallel_gripper.ParallelGripper`'s."""

    @property
    def stroke(self) -> float:
        """The widest opening between the tips' faces [m]."""
        return 2 * TRAVEL

    @property
    def pad_height(self) -> float:
        """Height [m] of the tips' centres above the hand's base, along the fingers."""
        return FINGER_Z + TIP_Z

    @property
    def face(self) -> tuple:
        """The rubber tip's face: (half-width, half-length) [m]."""
        return (TIP_HALF_WIDTH, TIP_HALF_LENGTH)

    def spec(self):
        """The hand's ``mujoco.MjSpec`` (no actuator, no pads: :func:`regrasp.robot.kinds.gripper_spec`
        adds them)."""
        mujoco = need("mujoco", "robot")
        s = mujoco.MjSpec()
        s.add_mesh(name="hand", file=mesh_path())
        base = add_base(s)  # the hand's frame: base turned 180° about z
        base.add_geom(name="hand", type=mujoco.mjtGeom.mjGEOM_MESH, meshname="hand", quat=[0, 0, 0, 1],
                      mass=HAND_MASS, rgba=[0.92, 0.92, 0.92, 1])
        shift = FACE_Y - TIP_FACE_Y + RECESS  # the URDF's finger frame to ours: its tip RECESS behind the pads
        for side in ("right", "left"):
            finger = add_finger(base, side, TRAVEL, TRAVEL - 0.001, DAMPING)
            for name, (x, y, z), rx, size in BOXES:
                finger.add_geom(name=f"{side}_{name}", type=mujoco.mjtGeom.mjGEOM_BOX, size=[v / 2 for v in size],
                                pos=[x, y + shift, FINGER_Z + z], quat=[math.cos(rx / 2), math.sin(rx / 2), 0, 0],
                                mass=FINGER_MASS / len(BOXES), rgba=[0.3, 0.3, 0.32, 1])
            add_pad_body(finger, side, self.pad_height, self.face)
            # the finger runs in the hand's slot, inside the mesh's convex hull
            s.add_exclude(bodyname1="base", bodyname2=f"{side}_finger")
        couple(s)
        return s
