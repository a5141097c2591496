"""Types: the stubs of the compiled module agree with it (mypy's stubtest), the README's Python
examples type-check against the package (its ``py.typed`` and ``_core.pyi``) with ``mypy
--strict``, a wrong call in such an example is an error, and the planning and scene packages
type-check.

mypy runs with ``MYPYPATH=python`` (this checkout's package) and ``--follow-imports=silent``
(the package's own modules are checked by ``test_package_type_checks``, not once per snippet).
Skipped when mypy is not installed (``pip install mypy``; it is in the ``dev`` extra).
"""

from __future__ import annotations

import ast
import inspect
import os
import re
import subprocess
import sys

import pytest

import regrasp._core as core

from .conftest import ROOT

pytest.importorskip("mypy", reason="mypy is not installed (pip install mypy)")

STUB = ROOT / "python" / "regrasp" / "_core.pyi"
ALLOWLIST = ROOT / "tests" / "stubtest-allowlist.txt"
#: The flags every snippet is checked with; numpy's and the package's types come from their stubs.
SNIPPET_FLAGS = ["--strict", "--follow-imports=silent", "--ignore-missing-imports", "--no-incremental"]


def mypy(*args: str, cwd=ROOT) -> subprocess.CompletedProcess:
    """``python -m mypy ARGS`` against this checkout's package."""
    env = {**os.environ, "MYPYPATH": str(ROOT / "python")}
    return subprocess.run([sys.executable, "-m", "mypy", *args], cwd=cwd, env=env, capture_output=True, text=True,
                          timeout=600)


def readme_snippets() -> list[str]:
    """The README's ```python blocks (as tests/test_readme.py finds them)."""
    blocks = re.findall(r"```python\n(.*?)```", (ROOT / "README.md").read_text(), re.S)
    assert blocks
    return blocks


def check_snippets(tmp_path, snippets: list[str]) -> subprocess.CompletedProcess:
    """mypy on each snippet as its own module."""
    files = []
    for i, s in enumerate(snippets):
        f = tmp_path / f"readme_snippet_{i}.py"
        f.write_text(s)
        files.append(str(f))
    return mypy(*SNIPPET_FLAGS, *files)


def test_stubs_match_the_compiled_module():
    """stubtest: every name, signature and default of the stub is the runtime's (the few
    unavoidable differences are in tests/stubtest-allowlist.txt, each with its reason)."""
    r = subprocess.run([sys.executable, "-m", "mypy.stubtest", "regrasp._core", "--allowlist", str(ALLOWLIST)],
                       cwd=ROOT, env={**os.environ, "MYPYPATH": str(ROOT / "python")}, capture_output=True, text=True,
                       timeout=600)
    assert r.returncode == 0, r.stdout + r.stderr


def test_the_package_ships_its_types():
    assert (ROOT / "python" / "regrasp" / "py.typed").exists()
    assert STUB.exists()


def stub_docstrings() -> dict[str, str]:
    """Dotted name (``Scene.motion_cone``) -> docstring of each class and function in the stub."""
    out = {}

    def walk(body, prefix):
        for node in body:
            if isinstance(node, (ast.ClassDef, ast.FunctionDef)):
                doc = ast.get_docstring(node)
                if doc is not None:
                    out[prefix + node.name] = doc
                if isinstance(node, ast.ClassDef):
                    walk(node.body, f"{prefix}{node.name}.")

    walk(ast.parse(STUB.read_text()).body, "")
    return out


def test_stub_docstrings_are_the_bindings_doc_comments():
    """The .pyi says what ``help()`` says: each docstring of the stub is the runtime ``__doc__``
    (the bindings' /// comments), and every documented runtime name has its docstring there."""
    docs = stub_docstrings()
    assert len(docs) > 100
    differ = []
    for name, doc in docs.items():
        obj = core
        for part in name.split("."):
            obj = inspect.getattr_static(obj, part) if inspect.isclass(obj) else getattr(obj, part)
        obj = obj.__func__ if isinstance(obj, staticmethod) else obj
        if inspect.cleandoc(obj.__doc__ or "") != doc:
            differ.append(f"{name}:\n  stub:    {doc!r}\n  runtime: {obj.__doc__!r}")
    assert not differ, "\n".join(differ)


def test_readme_examples_type_check(tmp_path):
    r = check_snippets(tmp_path, readme_snippets())
    assert r.returncode == 0, r.stdout + r.stderr


def test_a_wrong_call_is_a_type_error(tmp_path):
    """The check is not vacuous: a README-like snippet that passes a number as a pusher name (the
    Python API) and as the scene text (the compiled module) fails, naming both lines."""
    bad = (
        "import regrasp\n"
        "from regrasp import _core\n"
        "scene = regrasp.Scene.load('examples/block-low-friction.toml')\n"
        "cone = scene.motion_cone([0.0, 0.0, 0.0], 3)\n"
        "core = _core.Scene.from_toml(42)\n"
    )
    r = check_snippets(tmp_path, [bad])
    assert r.returncode == 1, r.stdout + r.stderr
    assert "readme_snippet_0.py:4: error" in r.stdout and "readme_snippet_0.py:5: error" in r.stdout, r.stdout


def test_package_type_checks():
    """The planning and scene packages (and what they import) type-check; scipy has no stubs."""
    r = mypy("--ignore-missing-imports", "--warn-unused-ignores", "--no-incremental", "-p", "regrasp.planning",
             "-p", "regrasp.scene")
    assert r.returncode == 0, r.stdout + r.stderr
