"""The bundled examples (``regrasp.examples``, ``regrasp examples``) and a 3-D scene whose mesh
is missing."""

from __future__ import annotations

import subprocess
import sys
import tomllib

import pytest

import regrasp
from regrasp import examples


#: the bundled examples (README, "Example scenes"): planar, then 3-D
PLANAR_NAMES = ["block-fixtureless", "block-high-friction", "block-low-friction", "block-on-incline",
                "block-tilted-gripper", "block-xztheta", "small-block-xztheta", "t-shape"]
SPATIAL_NAMES = ["ball-roll-3d", "block-3d", "bracket-pivot-3d", "light-side-3d", "offset-3d", "offset-pivot-3d", "pivot-3d", "pivot-90-3d",
                 "pivot-single-3d", "prism-3d"]


def test_names_paths_and_dimensions():
    assert examples.names() == sorted(PLANAR_NAMES + SPATIAL_NAMES)
    assert examples.path("t-shape") == examples.path("t-shape.toml")
    assert examples.path("t-shape").name == "t-shape.toml" and examples.path("t-shape").is_file()
    assert [p.stem for p in examples.planar()] == PLANAR_NAMES
    assert [p.stem for p in examples.spatial()] == SPATIAL_NAMES
    for name in PLANAR_NAMES + SPATIAL_NAMES:
        declared = tomllib.loads(examples.path(name).read_text()).get("dimension", 2)  # planar files have no key
        assert declared == (3 if name in SPATIAL_NAMES else 2), name
        assert examples.dimension(name) == declared == regrasp.load_scene(examples.path(name)).dimension, name
        assert examples.description(name), name


def test_an_unknown_name_lists_the_names():
    with pytest.raises(regrasp.ArgumentError) as e:
        examples.path("t-shap")
    assert e.value.field == "name" and "t-shape" in str(e.value) and "prism-3d" in str(e.value)


def test_a_copied_3d_example_loads_with_its_mesh_and_is_not_overwritten(tmp_path):
    p = examples.copy("prism-3d", tmp_path / "mine")
    assert (tmp_path / "mine" / "meshes" / "prism.obj").read_bytes() == (examples.ROOT / "meshes" / "prism.obj").read_bytes()
    assert regrasp.load_scene(p).dimension == 3
    p.write_text(p.read_text() + "\n# edited\n")
    with pytest.raises(regrasp.ArgumentError) as e:
        examples.copy("prism-3d", tmp_path / "mine")
    assert e.value.field == "dest_folder"
    assert p.read_text().endswith("# edited\n")  # untouched


def test_a_missing_mesh_names_the_field_the_path_and_its_folder(tmp_path):
    (tmp_path / "prism-3d.toml").write_text(examples.path("prism-3d").read_text())
    with pytest.raises(regrasp.SceneError) as e:
        regrasp.load_scene(tmp_path / "prism-3d.toml")
    msg = str(e.value)
    assert e.value.field == "object.mesh" and "meshes/prism.obj" in msg and str(tmp_path) in msg, msg


def test_cli_lists_and_copies(tmp_path):
    def cli(*args):
        return subprocess.run([sys.executable, "-m", "regrasp.cli", *args], capture_output=True, text=True, cwd=tmp_path)

    r = cli("examples")
    assert r.returncode == 0, r.stderr
    lines = r.stdout.splitlines()
    assert [ln.split()[0] for ln in lines] == examples.names()
    assert any(ln.split()[:2] == ["prism-3d", "3-D"] for ln in lines) and any(ln.split()[:2] == ["t-shape", "2-D"] for ln in lines)
    r = cli("examples", "prism-3d", "--copy", "out")
    assert r.returncode == 0 and (tmp_path / "out" / "meshes" / "prism.obj").exists(), r.stderr
    again, nameless, unknown = cli("examples", "prism-3d", "--copy", "out"), cli("examples", "--copy", "x"), cli("examples", "nope")
    for bad, opt in ((again, "--copy"), (nameless, "--copy"), (unknown, "name")):
        assert bad.returncode == 2 and f"`{opt}`" in bad.stderr and "Traceback" not in bad.stderr, bad.stderr


def test_a_failed_copy_leaves_no_files_and_no_new_folders(tmp_path, monkeypatch):
    """All or none: the mesh cannot be copied, so neither the scene file nor the folders the
    copy made are left."""
    real = examples.shutil.copyfile

    def copyfile(src, dst):
        if str(src).endswith(".obj"):
            raise OSError(28, "No space left on device", str(dst))
        return real(src, dst)

    monkeypatch.setattr(examples.shutil, "copyfile", copyfile)
    with pytest.raises(OSError):
        examples.copy("prism-3d", tmp_path / "new" / "mine")
    assert list(tmp_path.iterdir()) == []


def test_copy_names_the_callers_option():
    dest = examples.path("t-shape").parent  # the file exists there
    with pytest.raises(regrasp.ArgumentError) as e:
        examples.copy("t-shape", dest, field="--copy")
    assert e.value.field == "--copy" and str(e.value).startswith("invalid `--copy`:"), str(e.value)
