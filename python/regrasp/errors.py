"""The closed set of exceptions regrasp raises (the Rust core raises these too)."""

from __future__ import annotations


class RegraspError(Exception):
    """Base class. `field` names the scene field or argument at fault, when there is one."""

    def __init__(self, message: str, field: str | None = None):
        super().__init__(message)
        self.field = field


class SceneError(RegraspError, ValueError):
    """A scene value is missing or invalid (`field` is its dotted path, e.g. ``grasp.force``)."""


class ArgumentError(RegraspError, ValueError):
    """A call argument is invalid (`field` is the argument name, e.g. ``pose``)."""


class GraspError(RegraspError, RuntimeError):
    """The grasp cannot hold the object against gravity at the requested pose."""
