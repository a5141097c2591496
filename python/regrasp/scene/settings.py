"""The core's defaults, read where they are stated once: the Rust settings structs
(``quasistatic::Options``, ``control::mpc::Settings``, the validation's ring count, the default
limit-surface model). Every Python default and every CLI help text reads them from here."""

from __future__ import annotations

from pathlib import Path

from .. import _core


def quasistatic_defaults() -> dict:
    """The quasi-static simulator's defaults (``support``, ``rings``, ``points``,
    ``merge_fingers``, ``h`` [s], ...)."""
    return dict(_core.quasistatic_defaults())


def mpc_defaults() -> dict:
    """The MPC's defaults (``dt`` [s], ``horizon``, ``speed`` [m/s], the weights, ``margin``,
    ``seed``, ...)."""
    return dict(_core.mpc_defaults())


def validation_rings() -> int:
    """Rings of support points the cone validation simulates with (6, 12, 18... points)."""
    return int(_core.validation_rings())


def limit_surface_default() -> str:
    """The limit-surface model a scene file gets when it names none."""
    return str(_core.limit_surface_default())


#: Time step of simulated pushes and plan replays [s] (``regrasp push --dt``, ``regrasp simulate --dt``).
DT = 0.05


def push_dt(duration: float, dt: float | None = None) -> float:
    """The time step [s] of a push of ``duration`` [s]: ``dt`` when given, else min(:data:`DT`,
    ``duration``) (a short push is one step)."""
    return min(DT, duration) if dt is None else dt


def core_build() -> tuple[str, str]:
    """The core's version and the file name of its compiled extension."""
    return str(_core.__version__), Path(_core.__file__).name
