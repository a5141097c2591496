"""Files the package writes and the command line's handling of bad invocations (issue 13):
atomic writes (also under SIGKILL), outputs never onto inputs, existing outputs kept on failure,
unwritable outputs and non-object plan files as invalid input, broken pipes, count and number
bounds, Ctrl-C and internal errors without a traceback, --verbose notes."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

import regrasp
from regrasp import cli
from regrasp.errors import ArgumentError
from regrasp.files import Outputs, atomic_write, refuse_overwrite_input, write_text

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
BLOCK = EXAMPLES / "block-low-friction.toml"
SCENE_3D = EXAMPLES / "offset-3d.toml"


def run_cli(*args, timeout: float = 120, **kw) -> subprocess.CompletedProcess:
    """`python -m regrasp.cli ARGS` in a subprocess."""
    return subprocess.run([sys.executable, "-m", "regrasp.cli", *map(str, args)], capture_output=True, text=True,
                          timeout=timeout, cwd=kw.pop("cwd", ROOT), **kw)


def main(capsys, *args) -> tuple[int, str, str]:
    """`regrasp ARGS` in this process: (status, stdout, stderr)."""
    status = cli.main([str(a) for a in args])
    out, err = capsys.readouterr()
    return status, out, err


def assert_clean(err: str) -> None:
    assert "Traceback" not in err and "Exception ignored" not in err, err


def temp_files(folder: Path) -> list:
    return [p.name for p in folder.iterdir() if ".tmp" in p.name]


@pytest.fixture(scope="module")
def top_only(tmp_path_factory) -> Path:
    """A planar scene whose only pusher pushes down while the goal is up: no plan is ever found."""
    parts = BLOCK.read_text().split("[[pushers]]")
    top = [p for p in parts[1:] if 'name = "top"' in p][0]
    f = tmp_path_factory.mktemp("scenes") / "top-only.toml"
    f.write_text(parts[0] + "[[pushers]]" + top)
    return f


@pytest.fixture(scope="module")
def block_plan(tmp_path_factory) -> Path:
    f = tmp_path_factory.mktemp("plans") / "block.json"
    regrasp.plan(regrasp.Scene.load(BLOCK)).save(f)
    return f


# --- regrasp.files -------------------------------------------------------------------------------

def test_atomic_write_replaces_the_output_whole_and_leaves_no_temporary_file(tmp_path):
    out = tmp_path / "a.json"
    out.write_text("old")
    seen = []

    def write(tmp):
        seen.append(Path(tmp))
        assert Path(tmp).parent == tmp_path and Path(tmp).suffix == ".json" and Path(tmp) != out
        assert out.read_text() == "old"  # not touched while the new content is written
        Path(tmp).write_text("new")

    assert atomic_write(out, write) == out
    assert out.read_text() == "new" and not seen[0].exists() and temp_files(tmp_path) == []


@pytest.mark.parametrize("error", [RuntimeError("boom"), KeyboardInterrupt()])
def test_a_failing_write_leaves_the_existing_output_untouched(tmp_path, error):
    out = tmp_path / "a.png"
    out.write_bytes(b"old")

    def write(tmp):
        Path(tmp).write_bytes(b"half")
        raise error

    with pytest.raises(type(error)):
        atomic_write(out, write)
    assert out.read_bytes() == b"old" and temp_files(tmp_path) == []


def test_outputs_are_written_all_or_none(tmp_path):
    a, b = tmp_path / "a.txt", tmp_path / "b.txt"
    a.write_text("old a")
    with pytest.raises(RuntimeError):
        with Outputs() as outs:
            outs.write(a, lambda tmp: Path(tmp).write_text("new a"))
            outs.write(b, lambda tmp: (_ for _ in ()).throw(RuntimeError("b fails")))
    assert a.read_text() == "old a" and not b.exists() and temp_files(tmp_path) == []
    with Outputs() as outs:
        outs.write(a, lambda tmp: Path(tmp).write_text("new a"))
        outs.write(b, lambda tmp: Path(tmp).write_text("new b"))
        assert a.read_text() == "old a" and not b.exists()  # nothing renamed before the end
    assert (a.read_text(), b.read_text()) == ("new a", "new b")


def test_ctrl_c_while_outputs_are_renamed_waits_until_all_are(tmp_path, monkeypatch):
    import regrasp.files as files

    real = os.replace

    def replace_then_ctrl_c(src, dst):
        real(src, dst)
        os.kill(os.getpid(), signal.SIGINT)

    a, b = tmp_path / "a.txt", tmp_path / "b.txt"
    outs = Outputs()
    outs.write(a, lambda tmp: Path(tmp).write_text("a"))
    outs.write(b, lambda tmp: Path(tmp).write_text("b"))
    monkeypatch.setattr(files.os, "replace", replace_then_ctrl_c)
    with pytest.raises(KeyboardInterrupt):
        outs.commit()
    assert (a.read_text(), b.read_text()) == ("a", "b") and temp_files(tmp_path) == []


def test_an_output_onto_an_input_or_onto_another_output_is_refused(tmp_path, monkeypatch):
    scene = tmp_path / "s.toml"
    scene.write_text("x")
    monkeypatch.chdir(tmp_path)
    with pytest.raises(ArgumentError) as e:
        refuse_overwrite_input({"--out": "./s.toml"}, [scene])
    assert e.value.field == "--out"
    with pytest.raises(ArgumentError) as e:
        refuse_overwrite_input({"--out": "p.json", "--plot": tmp_path / "p.json"}, [scene])
    assert e.value.field == "--plot"
    refuse_overwrite_input({"--out": "p.json", "--plot": "p.png", "--html": None}, [scene])


def test_a_symlinked_output_is_written_through_and_a_pipe_in_place(tmp_path):
    import threading

    target = tmp_path / "real.txt"
    target.write_text("old")
    link = tmp_path / "link.txt"
    link.symlink_to(target)
    write_text(link, "new")
    assert link.is_symlink() and target.read_text() == "new" and temp_files(tmp_path) == []
    fifo = tmp_path / "pipe.txt"
    os.mkfifo(fifo)
    got = []
    reader = threading.Thread(target=lambda: got.append(fifo.read_text()))
    reader.start()
    with Outputs() as outs:
        outs.write(fifo, lambda p: Path(p).write_text("streamed"))
    reader.join(timeout=10)
    assert got == ["streamed"] and fifo.exists() and not fifo.is_file()


KILLED_WRITER = r"""
import sys, time
from pathlib import Path
from regrasp.files import atomic_write

def write(tmp):
    with open(tmp, "wb") as f:
        for i in range(10_000):
            f.write(b"x" * 65536)
            f.flush()
            if i == 20:
                print("writing", flush=True)
            time.sleep(0.01)

atomic_write(Path(sys.argv[1]), write)
"""


def test_an_output_keeps_its_old_content_when_the_writer_is_killed_mid_write(tmp_path):
    out = tmp_path / "plan.json"
    out.write_text('{"old": true}')
    p = subprocess.Popen([sys.executable, "-c", KILLED_WRITER, str(out)], stdout=subprocess.PIPE, text=True)
    try:
        assert p.stdout.readline().strip() == "writing"
        temps = temp_files(tmp_path)
        assert len(temps) == 1 and (tmp_path / temps[0]).stat().st_size > 0  # it is writing, beside the output
    finally:
        p.send_signal(signal.SIGKILL)
        p.wait(timeout=10)
    assert p.returncode == -signal.SIGKILL
    assert out.read_text() == '{"old": true}'  # a leftover temporary file never replaces the output
    assert json.loads(out.read_text()) == {"old": True}


def test_a_figure_written_through_a_temporary_name_keeps_its_format(tmp_path):
    from regrasp.viz.plotting import plot_plan

    scene = regrasp.Scene.load(BLOCK)
    p = regrasp.plan(scene)
    pdf = plot_plan(scene, p, tmp_path / "plan.pdf")
    png = plot_plan(scene, p, tmp_path / "plan.png")
    assert pdf.read_bytes()[:4] == b"%PDF" and png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert temp_files(tmp_path) == []


def test_write_text_and_plan_save_are_atomic(tmp_path, monkeypatch):
    out = tmp_path / "p.json"
    write_text(out, "old")
    p = regrasp.plan(regrasp.Scene.load(BLOCK))
    monkeypatch.setattr(json, "dumps", lambda *a, **k: (_ for _ in ()).throw(KeyboardInterrupt()))
    with pytest.raises(KeyboardInterrupt):
        p.save(out)
    assert out.read_text() == "old" and temp_files(tmp_path) == []


# --- outputs onto inputs -------------------------------------------------------------------------

@pytest.mark.parametrize("option", ["--out", "--plot", "--animate"])
def test_plan_refuses_to_write_onto_its_scene(tmp_path, capsys, option):
    scene = tmp_path / "self.toml"
    scene.write_text(BLOCK.read_text())
    if option != "--out":
        scene = scene.rename(tmp_path / ("self.png" if option == "--plot" else "self.gif"))
    status, _, err = main(capsys, "plan", scene, option, scene)
    assert status == 2 and f"`{option}`" in err and "input" in err, err
    assert scene.read_text() == BLOCK.read_text()


def test_plan_html_onto_the_3d_scene_and_two_equal_outputs_are_refused(tmp_path, capsys):
    scene = tmp_path / "s.html"
    scene.write_text(SCENE_3D.read_text().replace('"meshes/', f'"{EXAMPLES}/meshes/'))
    status, _, err = main(capsys, "plan", scene, "--html", scene)
    assert status == 2 and "`--html`" in err and scene.read_text().startswith(SCENE_3D.read_text()[:20])
    status, _, err = main(capsys, "plan", BLOCK, "--out", tmp_path / "x.png", "--plot", tmp_path / "x.png")
    assert status == 2 and "`--plot`" in err and not (tmp_path / "x.png").exists()


def test_simulate_and_control_refuse_to_plot_onto_the_plan_file(tmp_path, capsys, block_plan):
    plan = tmp_path / "p.png"
    plan.write_text(block_plan.read_text())
    for cmd in ("simulate", "control"):
        status, _, err = main(capsys, cmd, BLOCK, "--plan", plan, "--plot", plan)
        assert status == 2 and "`--plot`" in err, err
        assert plan.read_text() == block_plan.read_text()


def test_cone_and_push_refuse_to_plot_onto_the_scene(tmp_path, capsys):
    scene = tmp_path / "s.png"
    scene.write_text(BLOCK.read_text())
    for args in (["cone", scene, "--pose", "0,0,0", "--pusher", "left"],
                 ["push", scene, "--pose", "0,0,0", "--pusher", "left", "--twist", "0.01,0,0"]):
        status, _, err = main(capsys, *args, "--plot", scene)
        assert status == 2 and "`--plot`" in err, err
    assert scene.read_text() == BLOCK.read_text()


# --- unwritable outputs --------------------------------------------------------------------------

def test_unwritable_outputs_are_invalid_input_naming_the_option_before_any_work(tmp_path, capsys, monkeypatch):
    afile = tmp_path / "file"
    afile.write_text("x")
    import regrasp.cli.planning as planning

    monkeypatch.setattr(planning, "plan", lambda *a, **k: pytest.fail("planned although an output is unwritable"))
    for option, path in (("--out", afile / "p.json"), ("--out", tmp_path), ("--plot", afile / "p.png"),
                         ("--animate", tmp_path / "p.txt"), ("--plot", tmp_path / "p.unknown"),
                         ("--partial-out", afile / "p.json")):
        status, _, err = main(capsys, "plan", BLOCK, option, path)
        assert status == 2 and f"`{option}`" in err and "cannot write" in err and str(path) in err, (option, err)
    status, _, err = main(capsys, "plan", SCENE_3D, "--html", afile / "v.html")
    assert status == 2 and "`--html`" in err and "cannot write" in err


def test_unwritable_outputs_of_the_other_commands(tmp_path, capsys, block_plan):
    afile = tmp_path / "file"
    afile.write_text("x")
    bad = afile / "x.png"
    for args in (["cone", BLOCK, "--pose", "0,0,0", "--pusher", "left", "--plot", bad],
                 ["push", BLOCK, "--pose", "0,0,0", "--pusher", "left", "--twist", "0.01,0,0", "--plot", bad],
                 ["simulate", BLOCK, "--plan", block_plan, "--plot", bad],
                 ["simulate", BLOCK, "--plan", block_plan, "--engine", "mujoco", "--video", tmp_path / "v.txt"],
                 ["control", BLOCK, "--plan", block_plan, "--plot", bad],
                 ["demo", "--out", afile]):
        status, _, err = main(capsys, *args)
        assert status == 2 and "cannot write" in err, (args, err)


def test_unwritable_output_in_a_subprocess_exits_2_without_a_traceback(tmp_path):
    afile = tmp_path / "file"
    afile.write_text("x")
    r = run_cli("plan", BLOCK, "--out", afile / "p.json", "--plot", tmp_path / "p.png")
    assert r.returncode == 2 and "regrasp: invalid `--out`: cannot write" in r.stderr, r.stderr
    assert_clean(r.stderr)
    assert not (tmp_path / "p.png").exists()


# --- failures keep existing outputs ----------------------------------------------------------------

def test_a_failed_plan_leaves_an_existing_out_untouched(tmp_path, capsys, top_only):
    out = tmp_path / "p.json"
    out.write_text("OLD")
    status, _, err = main(capsys, "plan", top_only, "--time-limit", "0.2", "--out", out)
    assert status == 1 and "no plan found" in err and "left unchanged" in err and str(out) in err, err
    assert out.read_text() == "OLD" and temp_files(tmp_path) == []


def test_a_failed_plan_goes_to_partial_out_and_says_where(tmp_path, capsys, top_only):
    out, partial = tmp_path / "p.json", tmp_path / "partial.json"
    out.write_text("OLD")
    status, _, err = main(capsys, "plan", top_only, "--time-limit", "0.2", "--out", out, "--partial-out", partial)
    assert status == 1 and f"wrote the best partial plan to {partial}" in err, err
    assert out.read_text() == "OLD"
    d = json.loads(partial.read_text())
    assert d["found"] is False and len(d["path"]) >= 1


def test_a_found_plan_does_not_write_partial_out(tmp_path, capsys):
    out, partial = tmp_path / "p.json", tmp_path / "partial.json"
    status, _, _ = main(capsys, "plan", BLOCK, "--out", out, "--partial-out", partial)
    assert status == 0 and json.loads(out.read_text())["found"] and not partial.exists()


def test_when_the_figure_fails_the_plan_file_is_not_written(tmp_path, capsys, monkeypatch):
    import regrasp.viz.plotting as plotting

    out, png = tmp_path / "p.json", tmp_path / "p.png"
    out.write_text("OLD")

    def boom(scene, plan, path):
        Path(path).write_bytes(b"half a figure")
        raise RuntimeError("the figure failed")

    monkeypatch.setattr(plotting, "plot_plan", boom)
    status, _, err = main(capsys, "plan", BLOCK, "--out", out, "--plot", png)
    assert status == 1 and "internal error (please report)" in err and "the figure failed" in err, err
    assert out.read_text() == "OLD" and not png.exists() and temp_files(tmp_path) == []


# --- plan files --------------------------------------------------------------------------------

@pytest.mark.parametrize("text", ["[1, 2]", "3", '"x"', "null", "true", "[[[[[]]]]]"])
def test_a_plan_file_that_is_json_but_not_an_object_is_invalid_input_naming_it(tmp_path, capsys, text):
    f = tmp_path / "plan.json"
    f.write_text(text)
    with pytest.raises(ArgumentError) as e:
        regrasp.Plan.load(f)
    assert e.value.field == "plan" and str(f) in str(e.value)
    for cmd in ("simulate", "control"):
        status, _, err = main(capsys, cmd, BLOCK, "--plan", f)
        assert status == 2 and "`plan`" in err and str(f) in err, err


def test_a_plan_file_that_is_not_json_or_missing_is_invalid_input(tmp_path, capsys):
    f = tmp_path / "plan.json"
    f.write_bytes(b"\xff\xfe{")
    for path in (f, tmp_path / "missing.json", tmp_path):
        status, _, err = main(capsys, "simulate", BLOCK, "--plan", path)
        assert status == 2 and "`plan`" in err, err


# --- numbers and counts ------------------------------------------------------------------------

def test_time_limit_inf_means_no_limit_and_nan_or_negative_are_invalid(capsys):
    status, out, err = main(capsys, "plan", BLOCK, "--time-limit", "inf")
    assert status == 0 and "plan found" in out, err
    for bad in ("nan", "-1", "-inf"):
        status, _, err = main(capsys, "plan", BLOCK, f"--time-limit={bad}")
        assert status == 2 and "`--time-limit`" in err, (bad, err)


@pytest.mark.parametrize("args,option", [
    (["validate", BLOCK, "--pushes", "100000000"], "--pushes"),
    (["validate", BLOCK, "--pushes", "0"], "--pushes"),
    (["validate", BLOCK, "--workers", "0"], "--workers"),
    (["validate", BLOCK, "--workers", "100000"], "--workers"),
    (["approx-error", BLOCK, "--samples", "0"], "--samples"),
    (["approx-error", BLOCK, "--samples", "100000000000"], "--samples"),
    (["approx-error", BLOCK, "--forces", "nan"], "--forces"),
    (["approx-error", BLOCK, "--forces", "5,-1"], "--forces"),
    (["approx-error", BLOCK, "--forces", "1e300"], "--forces"),
    (["control", BLOCK, "--plan", "PLAN", "--scale-grip", "1e300"], "--scale-grip"),
    (["bench", "-n", "0"], "-n"),
    (["bench", "-n", "1000000000000"], "-n"),
    (["push", BLOCK, "--pose", "0,0,0", "--pusher", "left", "--twist", "0.01,0,0", "--duration", "0"], "--duration"),
    (["push", BLOCK, "--pose", "0,0,0", "--pusher", "left", "--twist", "0.01,0,0", "--duration", "nan"], "--duration"),
    (["push", BLOCK, "--pose", "0,0,0", "--pusher", "left", "--twist", "0.01,0,0", "--duration", "inf"], "--duration"),
    (["push", BLOCK, "--pose", "0,0,0", "--pusher", "left", "--twist", "0.01,0,0", "--dt", "0"], "--dt"),
    (["push", BLOCK, "--pose", "0,0,0", "--pusher", "left", "--twist", "0.01,0,0", "--dt", "1e-12"], "--dt"),
    (["push", BLOCK, "--pose", "0,0,0", "--pusher", "left", "--twist", "0.01,0,0", "--dt", "2"], "--dt"),
    (["push", BLOCK, "--pose", "0,0,0", "--pusher", "left", "--twist", "0.01,0,0", "--duration", "1e300",
      "--dt", "1e299"], "--duration"),
    (["push", SCENE_3D, "--pose", "0,0,0,1,0,0,0", "--pusher", "x", "--twist", "0,0,0,0,0,0", "--duration", "0"],
     "--duration"),
    (["simulate", BLOCK, "--plan", "PLAN", "--dt", "nan"], "--dt"),
    (["simulate", BLOCK, "--plan", "PLAN", "--engine", "mujoco", "--perturb", "1"], "--perturb"),
    (["simulate", BLOCK, "--plan", "PLAN", "--scale-mass", "inf"], "--scale-mass"),
    (["control", BLOCK, "--plan", "PLAN", "--horizon", "0"], "--horizon"),
    (["control", BLOCK, "--plan", "PLAN", "--horizon", "1000000"], "--horizon"),
    (["control", BLOCK, "--plan", "PLAN", "--noise", "nan"], "--noise"),
    (["control", BLOCK, "--plan", "PLAN", "--dt", "-1"], "--dt"),
])
def test_numeric_options_out_of_range_are_invalid_input_naming_them(capsys, block_plan, args, option):
    args = [block_plan if a == "PLAN" else a for a in args]
    t0 = time.perf_counter()
    status, _, err = main(capsys, *args)
    assert status == 2 and f"`{option}`" in err, err
    assert time.perf_counter() - t0 < 20  # refused before the work


# --- signals, pipes, internal errors -------------------------------------------------------------

def test_ctrl_c_in_process_exits_130_and_writes_nothing(tmp_path, capsys, monkeypatch):
    import regrasp.cli.planning as planning

    def interrupted(*a, **k):
        raise KeyboardInterrupt

    monkeypatch.setattr(planning, "plan", interrupted)
    out = tmp_path / "p.json"
    status, _, err = main(capsys, "plan", BLOCK, "--out", out)
    assert status == 130 and err.strip() == "regrasp: interrupted" and not out.exists()


def test_an_internal_error_is_one_line_with_status_1(capsys, monkeypatch):
    import regrasp.cli.planning as planning

    internal = getattr(regrasp.errors, "InternalError", None)
    for error in [IndexError("list index out of range")] + ([internal("a panic in the core")] if internal else []):
        monkeypatch.setattr(planning, "plan", lambda *a, **k: (_ for _ in ()).throw(error))
        status, _, err = main(capsys, "plan", BLOCK)
        assert status == 1 and err.startswith("regrasp: internal error (please report): ") and err.count("\n") == 1
        assert_clean(err)


def test_a_closed_stdout_ends_quietly_with_141():
    p = subprocess.Popen([sys.executable, "-m", "regrasp.cli", "plan", str(BLOCK), "--json"], cwd=ROOT,
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    p.stdout.close()  # like `| head` that has read enough
    err = p.stderr.read()
    assert p.wait(timeout=120) == 141 and err == "", err


def test_output_piped_into_head_has_no_traceback(tmp_path):
    r = subprocess.run(f"{sys.executable} -m regrasp.cli approx-error {BLOCK} --samples 200 --json | head -c 10; "
                       f"{sys.executable} -m regrasp.cli --help | head -n 1",
                       shell=True, capture_output=True, text=True, timeout=120, cwd=ROOT)
    assert r.returncode == 0 and r.stdout.startswith("[") and "usage" in r.stdout, r.stdout
    assert_clean(r.stderr)


def test_bad_invocations_in_a_subprocess_exit_2_without_a_traceback(tmp_path):
    f = tmp_path / "plan.json"
    f.write_text("[1, 2]")
    for args in (["simulate", BLOCK, "--plan", f], ["validate", BLOCK, "--pushes", "100000000"],
                 ["plan", BLOCK, "--time-limit", "nan"], ["plan", BLOCK, "--out", BLOCK]):
        r = run_cli(*args)
        assert r.returncode == 2 and r.stderr.startswith("regrasp: "), (args, r.stderr)
        assert_clean(r.stderr)


# --- verbose -----------------------------------------------------------------------------------

def test_verbose_prints_the_scenes_notes(capsys, monkeypatch):
    import regrasp.cli as cli_module

    real = cli_module.load_scene

    def with_notes(path):
        scene = real(path)
        monkeypatch.setattr(type(scene), "notes", ["pushers[0].points[1]: snapped 8 µm onto the outline"],
                            raising=False)
        return scene

    monkeypatch.setattr(cli_module, "load_scene", with_notes)
    for args in (["-v", "cone", BLOCK], ["cone", BLOCK, "--verbose"]):
        status, _, err = main(capsys, *args, "--pose", "0,0,0", "--pusher", "left")
        assert status == 0 and f"regrasp: {BLOCK}: pushers[0].points[1]: snapped 8 µm onto the outline" in err, err
    status, _, err = main(capsys, "cone", BLOCK, "--pose", "0,0,0", "--pusher", "left")
    assert status == 0 and "snapped" not in err
