"""Every public name of the package has a docstring, and those of functions with physical
parameters state their units.

Public: each module of ``regrasp`` (and ``regrasp._core``, the compiled module) whose dotted name
has no part starting with ``_``, and in each its members not starting with ``_`` that are defined
in ``regrasp`` (classes, functions, and the methods and properties of those classes). The members
of ``regrasp.cli.*`` are the command-line program, documented by its ``--help`` and docs/cli.md;
only those modules' docstrings are required here.
"""

from __future__ import annotations

import importlib
import inspect
import pkgutil
import re

import regrasp

#: The compiled module: its classes and functions are public through the package's modules.
CORE = "regrasp._core"
#: Modules whose members are not API (the command-line program: ``regrasp --help``).
MEMBERS_EXEMPT = ("regrasp.cli",)
#: A parameter is physical when its name contains one of these (e.g. ``grip_force``, ``poses``).
PHYSICAL = ("force", "pose", "twist", "duration", "dt", "time_limit")
#: A unit stated in brackets or parentheses: ``[m]``, ``(m, m, rad)``, ``[N]``, ``(s)``, ``[m/s²]``.
UNIT = re.compile(r"[\[(][^\])]*(?<![\w/])(m|rad|N|s|kg|m/s|rad/s|N·m|m/s²|N m|Hz)(?![\w])[^\])]*[\])]")


def public_modules() -> list[str]:
    """The dotted names of the package's public modules, the package and ``_core`` included."""
    names = ["regrasp", CORE]
    for m in pkgutil.walk_packages(regrasp.__path__, "regrasp."):
        if not any(part.startswith("_") for part in m.name.split(".")[1:]):
            names.append(m.name)
    return names


def is_ours(obj) -> bool:
    """Whether ``obj`` (a class or function) is defined in the package."""
    return (getattr(obj, "__module__", None) or "").startswith("regrasp")


def documented(obj) -> bool:
    """Whether ``obj`` has a docstring of its own (not a dataclass's generated signature)."""
    doc = inspect.getdoc(obj)
    if not doc or not doc.strip():
        return False
    return not (inspect.isclass(obj) and doc.startswith(f"{obj.__name__}("))


def class_members(cls) -> list[tuple[str, object]]:
    """The public methods and properties ``cls`` defines (not the dataclass fields' values)."""
    out = []
    for name, raw in vars(cls).items():
        if name.startswith("_"):
            continue
        if isinstance(raw, (staticmethod, classmethod)):
            out.append((name, raw.__func__))
        elif isinstance(raw, property) or inspect.isfunction(raw) or inspect.ismethoddescriptor(raw) \
                or inspect.isdatadescriptor(raw) or inspect.isbuiltin(raw):
            out.append((name, getattr(cls, name)))
    return out


def module_members(mod) -> list[tuple[str, object]]:
    """The public classes and functions of ``mod`` defined in the package."""
    exported = getattr(mod, "__all__", None)
    out = []
    for n in exported or [n for n in vars(mod) if not n.startswith("_")]:
        obj = getattr(mod, n)
        kind = inspect.isclass(obj) or inspect.isfunction(obj) or inspect.isbuiltin(obj)
        if kind and is_ours(obj) and (exported or obj.__module__ == mod.__name__):
            out.append((n, obj))
    return out


def public_api() -> list[tuple[str, object]]:
    """(dotted name, object) of every public module, class, function, method and property, each
    object once (under the first name the walk meets it by: ``regrasp.Scene`` before
    ``regrasp.scene.planar.Scene``)."""
    out, seen = [], set()
    for name in public_modules():
        mod = importlib.import_module(name)
        out.append((name, mod))
        if name.startswith(MEMBERS_EXEMPT):
            continue
        for n, obj in module_members(mod):
            if id(obj) in seen:
                continue
            seen.add(id(obj))
            out.append((f"{name}.{n}", obj))
            if inspect.isclass(obj):
                out += [(f"{name}.{n}.{m}", v) for m, v in class_members(obj)]
    return out


def physical_parameters(obj) -> list[str]:
    """The parameters of a function or method whose names make them physical quantities."""
    fn = obj.fget if isinstance(obj, property) else obj
    try:
        params = inspect.signature(fn).parameters
    except (TypeError, ValueError):
        return []
    return [p for p in params if any(w in p for w in PHYSICAL)]


def test_the_walk_sees_the_api():
    """The walk finds the names it must (else the checks below would pass vacuously)."""
    names = {n for n, _ in public_api()}
    for n in ("regrasp.Scene.motion_cone", "regrasp.Scene.com", "regrasp.Plan.save", "regrasp.control.Poke",
              "regrasp.plan", "regrasp.files", "regrasp._core.Scene.motion_cone",
              "regrasp._core.se3_log", "regrasp.sim.quasistatic", "regrasp.mujoco.planar"):
        assert n in names, n
    assert len(names) > 250


def test_every_public_name_has_a_docstring():
    missing = sorted({n for n, obj in public_api() if not documented(obj)})
    assert not missing, f"{len(missing)} public names without a docstring:\n" + "\n".join(missing)


def test_physical_parameters_have_units():
    """A docstring of a function with a physical parameter (force, pose, twist, duration, dt,
    time_limit) states a unit."""
    bad = sorted({f"{n}({', '.join(ps)})" for n, obj in public_api() if (ps := physical_parameters(obj))
                  and documented(obj) and not UNIT.search(inspect.getdoc(obj))})
    assert not bad, f"{len(bad)} docstrings without units:\n" + "\n".join(bad)


def test_the_unit_check_can_fail():
    assert UNIT.search("``pose`` ``[x, z, theta]`` (m, m, rad)")
    assert UNIT.search("for ``duration`` [s] > 0")
    assert not UNIT.search("The pose of the object (see the docs).")
    assert not UNIT.search("Moves the object [somewhat].")


def test_a_dataclass_signature_is_not_a_docstring():
    from dataclasses import dataclass

    @dataclass
    class Bare:
        x: float

    assert not documented(Bare)
