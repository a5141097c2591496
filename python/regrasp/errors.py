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


class InternalError(RegraspError, RuntimeError):
    """A bug in regrasp: please report it with the input. (A Rust panic caught at the boundary;
    the message carries the panic's message and location.)"""


def check_seed(seed) -> int:
    """A random seed: a whole number >= 0 (the core's generators take an unsigned 64-bit seed)."""
    import numbers

    if isinstance(seed, bool) or not isinstance(seed, numbers.Integral) or not 0 <= int(seed) < 2**64:
        raise ArgumentError(f"invalid `seed`: a whole number in [0, 2^64) (got {seed!r})", "seed")
    return int(seed)
