"""The wheel as a user gets it: ``maturin build --release`` (abi3, examples, meshes, LICENSE, the
stubs when the source has them), installed into bare virtual environments (the dependencies from
the package index), used from a temporary folder: the lean core without extras (the demo, a plan
of a bundled example, `regrasp examples`, a command that needs MuJoCo names `regrasp[mujoco]`),
then with ``[mujoco]`` one MuJoCo simulation. Prints the installed sizes.

Reuses the cargo target folder (``target/`` or ``$CARGO_TARGET_DIR``), so the build is
incremental after ``make build``. Skipped only where maturin (or cargo) is missing.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

from .conftest import ROOT

pytestmark = pytest.mark.wheel

PACKAGE = ROOT / "python" / "regrasp"
MATURIN = shutil.which("maturin", path=os.pathsep.join([str(Path(sys.executable).parent), os.environ.get("PATH", "")]))


def sh(args: list, cwd=None, timeout: float = 300, env=None) -> subprocess.CompletedProcess:
    """``args`` run to the end (output captured)."""
    return subprocess.run([str(a) for a in args], capture_output=True, text=True, cwd=cwd, timeout=timeout, env=env)


def bare_env() -> dict:
    """The environment of a user's shell: nothing of this checkout on the import path."""
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV", "PYTHONHOME", "REGRASP_TRACEBACK")}
    env["PIP_DISABLE_PIP_VERSION_CHECK"] = "1"
    return env


@pytest.fixture(scope="module")
def wheel(tmp_path_factory) -> Path:
    if MATURIN is None or shutil.which("cargo") is None:
        pytest.skip("maturin or cargo is not installed: the wheel cannot be built here")
    out = tmp_path_factory.mktemp("wheel")
    # this interpreter and make's profile (release-fast), as `maturin develop` (make build) uses:
    # the same build configuration, so the target folder's artifacts are reused (a wheel in
    # seconds after make build; the published wheel's `--release` adds link-time optimisation only)
    # and make's environment (its virtual environment named, its bin first on PATH, its `python`
    # named as `maturin develop` finds it, not pytest's `python3`): pyo3's build configuration is
    # rerun, and pyo3 and the extension recompiled, when these differ
    env, python = dict(os.environ), sys.executable
    if sys.prefix != sys.base_prefix and (Path(sys.prefix) / "bin" / "python").exists():
        python = str(Path(sys.prefix) / "bin" / "python")
        env["VIRTUAL_ENV"] = sys.prefix
        env["PATH"] = os.pathsep.join([str(Path(sys.prefix) / "bin"), env.get("PATH", "")])
    r = sh([MATURIN, "build", "--profile", "release-fast", "-q", "-i", python, "-o", out], cwd=ROOT, timeout=900,
           env=env)
    assert r.returncode == 0, r.stderr[-3000:]
    wheels = list(out.glob("regrasp-*.whl"))
    assert len(wheels) == 1, wheels
    return wheels[0]


def venv(path: Path) -> Path:
    """A bare virtual environment at ``path``; its bin folder."""
    r = sh([sys.executable, "-m", "venv", path], timeout=120)
    assert r.returncode == 0, r.stderr
    return path / "bin"


def install(bin_: Path, spec: str) -> None:
    r = sh([bin_ / "python", "-m", "pip", "install", "-q", spec], timeout=600, env=bare_env())
    assert r.returncode == 0, r.stderr[-3000:]


def site_size_mb(bin_: Path) -> float:
    """The size of the environment's site-packages [MB]."""
    r = sh([bin_ / "python", "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"], env=bare_env())
    site = Path(r.stdout.strip())
    return sum(f.stat().st_size for f in site.rglob("*") if f.is_file() and not f.is_symlink()) / 1e6


def test_wheel_is_abi3_and_carries_the_examples_and_license(wheel):
    assert "-abi3-" in wheel.name, wheel.name
    names = set(zipfile.ZipFile(wheel).namelist())
    bundled = {f"regrasp/examples/{p.relative_to(PACKAGE / 'examples').as_posix()}"
               for p in (PACKAGE / "examples").rglob("*") if p.suffix in (".toml", ".obj")}
    assert "regrasp/examples/t-shape.toml" in bundled and "regrasp/examples/meshes/prism.obj" in bundled
    assert bundled <= names, sorted(bundled - names)
    assert "regrasp/examples/__init__.py" in names
    assert any(n.endswith(".dist-info/licenses/LICENSE") for n in names), sorted(names)
    assert any(n.startswith("regrasp/_core.") and n.endswith(".so") or n.endswith(".pyd") for n in names)
    for typed in ("py.typed", "_core.pyi"):  # the type information
        assert f"regrasp/{typed}" in names, typed
    meta = zipfile.ZipFile(wheel).read(next(n for n in names if n.endswith(".dist-info/METADATA"))).decode()
    requires = [line.split(":", 1)[1].strip() for line in meta.splitlines() if line.startswith("Requires-Dist:")]
    core = sorted(r.split(">")[0].split("=")[0].split("<")[0].strip() for r in requires if "extra ==" not in r)
    assert core == ["numpy", "tqdm"], core


def test_core_wheel_in_a_bare_venv(wheel, tmp_path):
    bin_ = venv(tmp_path / "venv")
    install(bin_, str(wheel))
    work = tmp_path / "work"  # a folder with nothing of the checkout in it
    work.mkdir()
    env = bare_env()

    def regrasp(*args, ok=True):
        r = sh([bin_ / "regrasp", *args], cwd=work, env=env)
        if ok:
            assert r.returncode == 0, (args, r.stdout[-2000:], r.stderr[-2000:])
        return r

    r = sh([bin_ / "python", "-c", "import regrasp, sys; print(regrasp.__version__); print(regrasp.__file__)"], cwd=work, env=env)
    assert r.returncode == 0, r.stderr
    version, where = r.stdout.split()
    assert str(tmp_path / "venv") in where, where  # the installed copy, not the checkout
    assert version in regrasp("--version").stdout
    # the demo (no matplotlib: the plan and its report, the figures skipped)
    r = regrasp("demo", "--out", "demo")
    assert "figures skipped: pip install 'regrasp[plot]'" in r.stdout, r.stdout
    assert json.loads((work / "demo" / "t-shape-plan.json").read_text())["found"] is True
    # a bundled planar example, by its installed path
    r = sh([bin_ / "python", "-c", "from regrasp import examples; print(examples.path('block-low-friction'))"], cwd=work, env=env)
    example = r.stdout.strip()
    assert str(tmp_path / "venv") in example, example
    regrasp("plan", example, "--out", "plan.json")
    assert json.loads((work / "plan.json").read_text())["found"] is True
    # the examples: listed, and a 3-D one with its mesh copied out and planned
    listing = regrasp("examples").stdout
    assert "t-shape" in listing and "prism-3d" in listing, listing
    regrasp("examples", "prism-3d", "--copy", "mine")
    regrasp("plan", "mine/prism-3d.toml", "--out", "prism.json")
    # approx-error with no argument: every bundled planar example (a row each)
    r = regrasp("approx-error", "--samples", "200", "--forces", "20", "--json")
    assert len({row["scene"] for row in json.loads(r.stdout)}) >= 5, r.stdout[:500]
    # a command that needs MuJoCo: exit 1, one line naming the extra
    r = regrasp("validate", example, "--engines", "mujoco", "--pushes", "2", ok=False)
    assert r.returncode == 1 and "pip install 'regrasp[mujoco]'" in r.stderr and "Traceback" not in r.stderr, r.stderr
    print(f"\ninstalled size, core only: {site_size_mb(bin_):.0f} MB (site-packages)")


def test_mujoco_extra_runs_a_simulation(wheel, tmp_path):
    bin_ = venv(tmp_path / "venv")
    install(bin_, f"{wheel}[mujoco]")
    example = PACKAGE / "examples" / "block-low-friction.toml"
    r = sh([bin_ / "regrasp", "validate", example, "--engines", "mujoco", "--pushes", "2", "--workers", "1", "--json"],
           cwd=tmp_path, env=bare_env())
    assert r.returncode == 0, (r.stdout[-2000:], r.stderr[-2000:])
    res = json.loads(r.stdout)
    assert res["solved_mujoco"] == 2 and 0 <= res["agreement_mujoco"] <= 1, r.stdout[:500]
    print(f"\ninstalled size with [mujoco]: {site_size_mb(bin_):.0f} MB (site-packages)")
