"""The regrasp actions by name (thesis §1.1.1): :data:`ACTIONS`, every action of the families
(:mod:`.gravity`, :mod:`.inertia`, :mod:`.table`, :mod:`.post`, :mod:`.repick`) in the order the
grasp graph measures them (:func:`~regrasp.dexterity.graph.edges_to_measure`), and :func:`action`,
one of them by name."""

from __future__ import annotations

from ...errors import ArgumentError
from .base import Action
from .gravity import DropCatch, GravityPivot, GravitySlide, GripPivot
from .inertia import InertialSlide, TossCatch
from .post import PostPush
from .repick import PlaceRepick, ToppleRepick
from .table import PushDown, TablePivot, TableSlide


ACTIONS = {a.name: a for a in (GravityPivot(), GravitySlide(), GripPivot(), DropCatch(), InertialSlide(), TossCatch(),
                                PushDown(), TableSlide(), PostPush(), TablePivot(), PlaceRepick(), ToppleRepick())}


def action(name: str) -> Action:
    """The action ``name`` (:data:`ACTIONS`), or an ArgumentError naming ``action``."""
    if name not in ACTIONS:
        raise ArgumentError(f"invalid `action`: unknown action {name!r} (known: {', '.join(ACTIONS)})", "action")
    return ACTIONS[name]
