"""The package's shape (issue "One world", DEVELOPERS.md "Shape"): no import circle in
python/regrasp, counting imports written inside functions; no module outside scene/ and planning/
reaches into the compiled core (the scene is the one door to it); the goal tolerance's default stated once. The graph is read from the source with ``ast``, so the
check needs no import of the package."""

import ast
import re
from pathlib import Path

import pytest

PKG = Path(__file__).resolve().parents[1] / "python" / "regrasp"
DOORS = ("regrasp.scene", "regrasp.planning")
#: the base modules under every stage that may import the core too: the version, pose algebra, the bound on numbers
BASE = ("regrasp", "regrasp.pose", "regrasp.fields")


def _name(path: Path, root: Path = PKG) -> str:
    parts = list(path.relative_to(root.parent).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def modules(root: Path = PKG) -> dict:
    """{module name: parsed tree} of every .py file under ``root``."""
    return {_name(p, root): ast.parse(p.read_text(), str(p)) for p in sorted(root.rglob("*.py"))}


def imports(name: str, tree: ast.AST, known: set) -> set:
    """The package's modules that module ``name`` imports anywhere in its text (functions too)."""
    pkg = name if name in known and _is_pkg(name) else name.rpartition(".")[0]
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            targets = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = pkg.split(".")[: len(pkg.split(".")) - (node.level - 1)] if node.level else []
            mod = ".".join(base + ([node.module] if node.module else [])) if node.level else node.module or ""
            targets = [mod] + [f"{mod}.{a.name}" for a in node.names]
        else:
            continue
        for t in targets:
            while t and t not in known:
                t = t.rpartition(".")[0]
            if t and t != name and not name.startswith(t + "."):
                out.add(t)
    return out


_PACKAGES: set = set()


def _is_pkg(name: str) -> bool:
    return name in _PACKAGES


def graph(root: Path = PKG) -> dict:
    mods = modules(root)
    _PACKAGES.clear()
    _PACKAGES.update(_name(p, root) for p in root.rglob("__init__.py"))
    known = set(mods)
    return {m: imports(m, t, known) for m, t in mods.items()}


def circles(g: dict) -> list:
    """The strongly connected components of ``g`` with more than one module (Tarjan)."""
    index, low, stack, on, out = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in g.get(v, ()):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in sorted(g):
        if v not in index:
            visit(v)
    return out


def test_no_import_circle():
    assert circles(graph()) == []


def package(root: Path, files: dict) -> Path:
    """A package ``regrasp`` under ``root`` of ``files`` (path → text), with its ``__init__``s."""
    pkg = root / "regrasp"
    for rel, text in {"__init__.py": "", **files}.items():
        (pkg / rel).parent.mkdir(parents=True, exist_ok=True)
        (pkg / rel).parent.joinpath("__init__.py").touch()
        (pkg / rel).write_text(text)
    return pkg


def test_the_circle_check_finds_a_circle(tmp_path):
    """Not vacuous: a circle through an import written inside a function is found."""
    pkg = package(tmp_path, {"a/x.py": "from .y import f\n", "a/y.py": "def f():\n    from ..b import g\n",
                             "b.py": "def g():\n    from .a.x import f\n"})
    assert circles(graph(pkg)) == [["regrasp.a.x", "regrasp.a.y", "regrasp.b"]]


#: The folders of python/regrasp from the bottom up (README "What is where"); a module imports
#: only from its own stage or one below. The base modules are under every stage; drawing code
#: takes data (it imports no stage); ``planning`` is the Plan (the plan file's type) and
#: ``plan()``, which the scenes' ``plan``/``replay`` return and read.
STAGES = (
    ("errors", "fields", "files", "pose", "polygon", "extras", "progress", "interrupts", "_moved", "_core"),
    ("viz",),
    ("planning",),
    ("scene", "examples"),
    ("reference",),
    ("sim",),
    ("workcell",),
    ("mujoco", "drake"),
    ("control",),
    ("robot",),
    ("execution",),
    ("dexterity",),
    ("bench",),
    ("cli", "__main__"),
)


def _stage(module: str) -> int:
    parts = module.split(".")
    if len(parts) == 1:  # the package's face re-exports every stage
        return len(STAGES)
    return next(i for i, s in enumerate(STAGES) if parts[1] in s)


def upward(g: dict) -> list:
    """(importer, imported) of every import of a later stage."""
    return sorted((a, b) for a, bs in g.items() for b in bs if _stage(b) > _stage(a))


def test_imports_only_go_down_the_pipeline():
    folders = {p.name for p in PKG.iterdir() if p.is_dir() and p.name != "__pycache__"}
    folders |= {p.stem for p in PKG.glob("*.py") if p.stem != "__init__"}
    folders |= {p.name.split(".")[0] for p in PKG.glob("_core*")}
    staged = {f for s in STAGES for f in s}
    assert folders - staged == set(), "a folder or module of no stage: add it to STAGES (and README)"
    assert upward(graph()) == []


def test_the_order_check_finds_an_upward_import():
    """Not vacuous: a scene importing the executor (inside a function) is found."""
    g = {"regrasp.scene.planar": {"regrasp.pose", "regrasp.execution.execute"}, "regrasp.execution.execute":
         {"regrasp.scene.planar"}}
    assert upward(g) == [("regrasp.scene.planar", "regrasp.execution.execute")]


def core_reach(root: Path = PKG) -> list:
    """(module, line) of every reach into the compiled core outside the doors: an attribute
    ``x._core`` (a scene's or a cone's core object), or an import of ``_core`` (outside the base
    modules too)."""
    out = []
    for name, tree in modules(root).items():
        if name.startswith(DOORS) or name == "regrasp._core":
            continue
        for node in ast.walk(tree):
            if isinstance(node, ast.Attribute) and node.attr == "_core":
                out.append((name, node.lineno))
            elif name not in BASE and isinstance(node, (ast.Import, ast.ImportFrom)):
                mod = getattr(node, "module", None) or ""
                if "_core" in mod.split(".") or any(a.name.split(".")[-1] == "_core" for a in node.names):
                    out.append((name, node.lineno))
    return out


def test_the_scene_is_the_one_door_to_the_core():
    assert core_reach() == []


def test_the_door_check_finds_a_reach(tmp_path):
    pkg = package(tmp_path, {"execution/arm.py": "def f(scene):\n    return scene._core.grip_force\n",
                             "execution/loop.py": "from .. import _core\n\ndef g():\n    from .._core import Mpc\n",
                             "pose.py": "from . import _core\n"})  # a base module may
    assert sorted(core_reach(pkg)) == [("regrasp.execution.arm", 2), ("regrasp.execution.loop", 1),
                                       ("regrasp.execution.loop", 4)]


def test_the_goal_tolerance_default_is_stated_once():
    """[1e-3, 1e-3, 0.0175] in the core's scene module only; every "is it at the goal?" asks the
    core (``Scene.goal_error``)."""
    root = PKG.parents[1]
    pattern = re.compile(r"\[1e-3,\s*1e-3,\s*0\.0175\]")
    hits = [str(p.relative_to(root)) for p in [*root.joinpath("crates").glob("*/src/**/*.rs"), *PKG.rglob("*.py")]
            if pattern.search(p.read_text())]
    assert hits == ["crates/regrasp-core/src/scene/planar.rs"]


@pytest.mark.parametrize("kind", ["planar", "spatial"])
def test_goal_error_wraps_the_angle_and_uses_the_tolerance(kind):
    """The core's answer against a direct computation: planar θ wrapped into [−π, π), 3-D the
    relative rotation's angle; within means every component within the task's tolerance."""
    import numpy as np

    import regrasp
    from regrasp.examples import path

    if kind == "planar":
        s = regrasp.Scene.load(path("t-shape"))
        goal, tol = s.task.goal, s.task.tolerance
        for d in ([0, 0, 2 * np.pi], [0.5e-3, -0.5e-3, -2 * np.pi + 0.01], [2e-3, 0, 0], [0, 0, np.pi - 1e-9]):
            e, ok = s.goal_error(goal + np.array(d))
            want = np.array(d, float)
            want[2] = (want[2] + np.pi) % (2 * np.pi) - np.pi
            assert np.allclose(e, want, atol=1e-12) and ok == bool(np.all(np.abs(want) <= tol))
        e, ok = s.goal_error([0.0, 0.0, 0.0], [0.0, 0.0, 4 * np.pi])
        assert np.allclose(e, 0, atol=1e-12) and ok
    else:
        s = regrasp.Scene3D.load(path("pivot-3d"))
        goal, tol = s.task.goal, s.task.tolerance
        turn = 0.01
        q = goal.copy()
        q[:3] += [0.5e-3, 0, -0.2e-3]
        c, n = np.cos(turn / 2), np.sin(turn / 2)
        w, x, y, z = goal[3:]
        q[3:] = [c * w - n * x, c * x + n * w, c * y + n * z, c * z - n * y]  # goal ∘ turn about x
        e, ok = s.goal_error(q)
        assert np.allclose(e[:3], [0.5e-3, 0, -0.2e-3], atol=1e-12) and abs(e[3] - turn) < 1e-9
        assert ok == (turn <= tol[3])
        q[0] += 2 * tol[0]
        assert not s.goal_error(q)[1]


#: The longest a module may be, in lines: read at once (DEVELOPERS.md "Style").
MAX_LINES = 600


def test_every_module_reads_at_once():
    long = {str(p.relative_to(PKG)): n for p in PKG.rglob("*.py")
            if (n := len(p.read_text(encoding="utf-8").splitlines())) > MAX_LINES}
    assert long == {}, f"modules over {MAX_LINES} lines: {long}"


def test_one_perturbation_type():
    """One class describes a perturbed world; the old names are shims that make it."""
    classes = [(name, node.name) for name, tree in modules().items() for node in ast.walk(tree)
               if isinstance(node, ast.ClassDef) and ("Perturbation" in node.name or "Scales" in node.name)]
    assert sorted(c for _, c in classes) == ["ArmScales", "HandPerturbation", "Perturbation", "PlanarEnginePerturbation"]
    assert {m for m, _ in classes} == {"regrasp.scene.perturbation"}
