"""Closed-loop control of a regrasp (thesis §5.2): the MPC loop in a simulated world."""

from .loop import ControlResult, Poke, control

__all__ = ["ControlResult", "Poke", "control"]
