"""The gripper's release, shared by the two catches (thesis §1.1.1): ``drop-catch``
(:mod:`.gravity`) and ``toss-catch`` (:mod:`.inertia`) open the fingers for a moment and close
them again; :func:`release` measures how the object comes loose and is caught, once per object
and grasp."""

from __future__ import annotations

import weakref
from typing import Optional

import numpy as np

from ...errors import ArgumentError, SceneError
from ..world import hand_pose
from .base import ObjectModel
from .geometry import _offset_step


_RELEASE: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()  # scene -> {grasp pose: Release or why none}


def release(obj: ObjectModel, grasp):
    """The gripper's :class:`~regrasp.dexterity.world.Release` of ``grasp``'s object: measured
    once per object and grasp in a :class:`~regrasp.dexterity.world.HandWorld`, fingers down
    (:func:`~regrasp.dexterity.world.release_timing`; the object then moves towards the fingertips when loose, as in both catches — the timing is
    the gripper's: fingers up it is the same within 2 ms). An ArgumentError naming ``grasp``
    when the gripper cannot let go and catch it."""
    from ..world import HandWorld, release_timing

    cache = _RELEASE.setdefault(obj.scene, {})
    key = tuple(np.round(np.asarray(grasp.pose, float), 6))
    if key not in cache:
        try:
            cache[key] = release_timing(HandWorld(obj.scene, grasp.pose, hand_pose(0.0)))
        except SceneError as e:
            cache[key] = str(e)
    if isinstance(cache[key], str):
        raise ArgumentError(f"invalid `grasp`: {grasp.name}: {cache[key]}", "grasp")
    return cache[key]


def _catch_applies(obj: ObjectModel, grasp) -> Optional[str]:
    """Why a catch does not apply to ``grasp`` (None when it does)."""
    if _offset_step(obj, grasp, -1) is None:
        return "no grasp further towards the fingertips"
    try:
        release(obj, grasp)
    except ArgumentError as e:
        return str(e)
    return None


def _released(force: float, t0: float, delta: float):
    """The grip schedule: ``force`` [N], the fingers open for ``delta`` [s] from ``t0`` [s]."""
    return lambda t: None if t0 <= t < t0 + delta else force
