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


class ExecutionError(RegraspError, RuntimeError):
    """A valid plan cannot be executed in the world: no feature of the workcell serves a push, or
    the arm cannot follow the motion (its reach, a joint limit, a collision). The message names
    the push and why; ``field`` the part of the world at fault (``workcell``, ``robot``)."""


class InternalError(RegraspError, RuntimeError):
    """A bug in regrasp: please report it with the input. (A Rust panic caught at the boundary;
    the message carries the panic's message and location.)"""


class MissingExtraError(RegraspError, ImportError):
    """An optional dependency is not installed: ``module`` (e.g. ``mujoco``) comes with the
    package's extra ``extra`` (``pip install 'regrasp[mujoco]'``); ``what`` names it for people."""

    def __init__(self, module: str, extra: str, what: str | None = None):
        self.module, self.extra, self.what = module, extra, what or module
        super().__init__(f"{self.what} is not installed (module `{module}`): pip install 'regrasp[{extra}]'")
        ImportError.__init__(self, str(self), name=module)
        self.field = None

    def __reduce__(self):  # picklable (worker processes)
        return type(self), (self.module, self.extra, self.what)


def check_seed(seed) -> int:
    """A random seed: a whole number >= 0 (the core's generators take an unsigned 64-bit seed)."""
    import numbers

    if isinstance(seed, bool) or not isinstance(seed, numbers.Integral) or not 0 <= int(seed) < 2**64:
        raise ArgumentError(f"invalid `seed`: a whole number in [0, 2^64) (got {seed!r})", "seed")
    return int(seed)
