"""Regrasp actions (thesis §1.1.1, ICRA 2014 "Extrinsic dexterity"): open-loop, parameterised
motions of the arm and grip-force schedules that change the grasp on an object with resources
outside the hand — gravity, the inertia of the arm's motion, contacts with the table. Each
action (:class:`Action`) says which grasps it applies to (:meth:`Action.applies`), and
turns a grasp into a :class:`Setup`: the hand's start pose, its timed path, the grip schedule
and the model's prediction of the in-hand pose at the end (:mod:`~regrasp.dexterity.slip` for the
gravity and inertial actions, the kinematics of sticking contact for the table's), whose nearest grasp of
the taxonomy is the grasp it is meant to reach. Geometry in the hand frame (x, z: the plane of
the pads, y the grasp axis); every action here keeps the grasp axis horizontal along the
world's y, so that the hand frame's x-z plane is the world's x-z plane turned by the hand's
angle α (the hand's x from the world's x towards its z; α = 0: the fingers point down).
Parameters are SI; their defaults are physically grounded (the holding force m g / 2 μ, the
taxonomy's offset and turn steps) and stated in :data:`DEFAULTS`.

The actions, one module per family: gravity (:mod:`.gravity`: ``gravity-pivot``,
``gravity-slide``, ``grip-pivot``, ``drop-catch``), the arm's inertia (:mod:`.inertia`:
``inertial-slide``, ``toss-catch``), contacts with the table (:mod:`.table`: ``push-down``,
``table-slide``, ``table-pivot``), with the post (:mod:`.post`: ``post-push``) and setting the
object down to pick it again (:mod:`.repick`: ``place-repick``, ``topple-repick``); what they
share in :mod:`.base`, :mod:`.geometry` and :mod:`.catch`; :data:`ACTIONS` and :func:`action`
in :mod:`.registry`. Every name is importable from here."""

from __future__ import annotations

from ..world import WORK_POINT, hand_pose
from .base import DEFAULTS, RAMP, WHOLE, G, Action, ObjectModel, Setup
from .catch import release
from .geometry import (FINGER_ROOM, TURNS, _angle, body, com_in_hand, contact_centre, lowest, moved, plane_inertia,
                       turn_target)
from .gravity import DropCatch, GravityPivot, GravitySlide, GripPivot
from .inertia import ARM_LAG, InertialSlide, TossCatch
from .post import PLAN_TIME_CAP, POST_HOLDS, POST_ROOM, PostPush, post_scene
from .registry import ACTIONS, action
from .repick import MAX_PICK_TILT, MAX_PLACE_TILT, TARGETS, TOPPLE_TILTS, PlaceRepick, ToppleRepick, _topple, pad_height
from .table import PushDown, TablePivot, TableSlide

__all__ = ["ACTIONS", "ARM_LAG", "DEFAULTS", "FINGER_ROOM", "G", "MAX_PICK_TILT", "MAX_PLACE_TILT", "PLAN_TIME_CAP",
           "POST_HOLDS", "POST_ROOM", "RAMP", "TARGETS", "TOPPLE_TILTS", "TURNS", "WHOLE", "WORK_POINT", "Action",
           "DropCatch", "GravityPivot", "GravitySlide", "GripPivot", "InertialSlide", "ObjectModel", "PlaceRepick",
           "PostPush", "PushDown", "Setup", "TablePivot", "TableSlide", "TossCatch", "ToppleRepick", "action", "body",
           "com_in_hand", "contact_centre", "hand_pose", "lowest", "moved", "pad_height", "plane_inertia",
           "post_scene", "release", "turn_target"]
