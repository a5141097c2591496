"""The flat layout's module paths still import, with a DeprecationWarning, as the modules they
moved to; the package's own names are not shadowed."""

import importlib
import sys

import pytest

import regrasp
from regrasp._moved import MOVED


@pytest.mark.parametrize("old", sorted(MOVED))
def test_an_old_module_path_imports_the_moved_module_with_a_warning(old):
    sys.modules.pop(f"regrasp.{old}", None)
    with pytest.warns(DeprecationWarning, match=f"regrasp.{old}` moved to `regrasp.{MOVED[old]}"):
        mod = importlib.import_module(f"regrasp.{old}")
    assert mod is importlib.import_module(f"regrasp.{MOVED[old]}")


def test_new_paths_and_the_api_are_untouched():
    from regrasp.mujoco3d import execute_plan3d  # noqa: F401  (an old path in use)
    assert callable(regrasp.plan) and regrasp.plan.__module__ == "regrasp.planning.plan"
    assert importlib.import_module("regrasp.mujoco.spatial").__name__ == "regrasp.mujoco.spatial"
