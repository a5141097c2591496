"""The module paths of regrasp 0.1's flat layout, kept importable (with a DeprecationWarning)
after the package became folders by pipeline stage: ``import regrasp.mujoco3d`` gives
``regrasp.mujoco.spatial``, and so on. To be removed in a later release."""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.util
import sys
import warnings

#: old module → new module (both under ``regrasp``); not ``plan`` (``regrasp.plan`` is the
#: function) nor ``reference``/``control``/``cli`` (now packages of their own)
MOVED = {
    "scene3d": "scene.spatial",
    "quasistatic": "sim.quasistatic",
    "validation": "mujoco.validation",
    "sim.validation": "mujoco.validation",
    "workcell.default": "execution.layout",
    "mncp_reference": "reference.mncp",
    "report": "reference.approx_error",
    "mujoco_model": "mujoco.model",
    "mujoco_sim": "mujoco.push",
    "mujoco_exec": "mujoco.planar",
    "mujoco3d": "mujoco.spatial",
    "plotting": "viz.plotting",
    "viewer": "viz.viewer",
}


class _Alias(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    """Finds ``regrasp.<old>`` and loads it as the module it moved to."""

    def find_spec(self, fullname, path=None, target=None):
        old = fullname.removeprefix("regrasp.")
        if fullname.startswith("regrasp.") and old in MOVED:
            return importlib.util.spec_from_loader(fullname, self)
        return None

    def create_module(self, spec):
        new = "regrasp." + MOVED[spec.name.removeprefix("regrasp.")]
        warnings.warn(f"`{spec.name}` moved to `{new}`; the old path will be removed", DeprecationWarning, stacklevel=3)
        return importlib.import_module(new)

    def exec_module(self, module):
        pass


def attribute_aliases(package: str, moved: dict):
    """A module ``__getattr__`` for ``package``'s names that moved: name → module (under
    ``regrasp``) that holds it now; each use warns."""

    def __getattr__(name: str):
        if name not in moved:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        new = "regrasp." + moved[name]
        warnings.warn(f"`{package}.{name}` moved to `{new}.{name}`; the old path will be removed", DeprecationWarning,
                      stacklevel=2)
        return getattr(importlib.import_module(new), name)

    return __getattr__


def install() -> None:
    """Puts the alias finder after the regular ones (a real module always wins)."""
    if not any(isinstance(f, _Alias) for f in sys.meta_path):
        sys.meta_path.append(_Alias())
