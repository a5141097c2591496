"""Progress bars: drawn on stderr when it is a terminal (a pseudo-terminal here), never with
-q/--quiet or without a terminal, never on stdout."""

from __future__ import annotations

import json
import os
import pty
import re
import select
import subprocess
import sys
from pathlib import Path

import pytest

from regrasp import progress

ROOT = Path(__file__).resolve().parents[1]
BLOCK = ROOT / "examples" / "block-low-friction.toml"
#: what a tqdm bar draws: a carriage return, a percentage before the bar, the count against the total
BAR = ("\r", "%|")
COUNT = re.compile(r"[\d.]+/[\d.]+ (\[|s)")

pytestmark = pytest.mark.skipif(not sys.platform.startswith(("linux", "darwin")), reason="needs a pseudo-terminal")


def env(delay: float = 0.0) -> dict:
    e = {**os.environ, "REGRASP_PROGRESS_DELAY": str(delay)}
    e["PYTHONPATH"] = os.pathsep.join([str(ROOT / "python"), *filter(None, [e.get("PYTHONPATH")])])
    return e


def run_tty(*args, delay: float = 0.0, timeout: float = 120) -> tuple[int, str, str]:
    """`regrasp ARGS` with stderr on a pseudo-terminal and stdout on a pipe: (status, stdout, stderr)."""
    master, slave = pty.openpty()
    p = subprocess.Popen([sys.executable, "-m", "regrasp.cli", *map(str, args)], stdout=subprocess.PIPE,
                         stderr=slave, stdin=subprocess.DEVNULL, env=env(delay))
    os.close(slave)
    err = b""
    try:
        while True:  # read the terminal while the command runs (it blocks on a full terminal)
            ready, _, _ = select.select([master], [], [], timeout)
            if not ready:
                p.kill()
                raise TimeoutError(f"regrasp {args} did not end")
            try:
                chunk = os.read(master, 65536)
            except OSError:  # the command ended: the terminal is closed
                break
            if not chunk:
                break
            err += chunk
        out = p.stdout.read().decode()
        p.wait(timeout)
    finally:
        p.stdout.close()
        os.close(master)
    return p.returncode, out, err.decode(errors="replace")


def has_bar(text: str) -> bool:
    return all(mark in text for mark in BAR) and COUNT.search(text) is not None


VALIDATE = ["validate", BLOCK, "--pushes", "150", "--json"]


def test_validate_draws_a_bar_on_a_terminal_and_never_on_stdout():
    status, out, err = run_tty(*VALIDATE)
    assert status == 0, err
    assert has_bar(err) and "quasi-static pushes (block-low-friction)" in err, err
    assert not any(mark in out for mark in BAR), out
    assert json.loads(out)["pushes"] == 150


@pytest.mark.parametrize("quiet", [["-q"], ["--quiet"], ["after"]])
def test_quiet_before_or_after_the_command_draws_no_bar(quiet):
    args = [*VALIDATE, "--quiet"] if quiet == ["after"] else [*quiet, *VALIDATE]
    status, out, err = run_tty(*args)
    assert status == 0, err
    assert not has_bar(err) and "pushes (" not in err, err
    assert json.loads(out)["pushes"] == 150


def test_no_bar_when_stderr_is_not_a_terminal():
    r = subprocess.run([sys.executable, "-m", "regrasp.cli", *map(str, VALIDATE)], capture_output=True, text=True,
                       env=env(), timeout=120)
    assert r.returncode == 0, r.stderr
    assert r.stderr == "" and json.loads(r.stdout)["pushes"] == 150


def test_a_long_plan_shows_the_time_against_its_limit(tmp_path):
    # a scene that can only push down while the goal is up and turned 2.8 rad: not decided
    # unreachable (over such turns gravity pulls every way in the object's frame), not found
    # either: the planner runs for its time limit
    parts = BLOCK.read_text().split("[[pushers]]")
    top = [p for p in parts[1:] if 'name = "top"' in p][0]
    scene = tmp_path / "top-only.toml"
    scene.write_text(parts[0] + "[[pushers]]" + top)
    status, out, err = run_tty("plan", scene, "--goal", "0,0.03,2.8", "--time-limit", "1.5", "--json", delay=0.3)
    assert status == 1, err
    assert has_bar(err) and "planning block-low-friction" in err and "/1.5 s" in err, err
    assert not any(mark in out for mark in BAR)
    assert json.loads(out)["found"] is False


def test_a_short_plan_shows_no_bar():
    status, out, err = run_tty("plan", ROOT / "examples" / "t-shape.toml", "--json", delay=1.0)
    assert status == 0 and not has_bar(err), err


def test_the_bars_do_nothing_when_quiet_or_without_a_terminal(capsys):
    progress.set_quiet(True)
    try:
        assert not progress.enabled()
        assert list(progress.iterate(range(5), "x")) == list(range(5))
        with progress.bar(3, "x") as b:
            b.update(3)
        with progress.elapsed(1.0, "x"):
            pass
    finally:
        progress.set_quiet(False)
    assert not progress.enabled()  # pytest's stderr is not a terminal
    assert capsys.readouterr().err == ""


def test_an_animation_counts_its_frames(tmp_path):
    status, out, err = run_tty("plan", BLOCK, "--animate", tmp_path / "plan.gif", "--json")
    assert status == 0, err
    assert has_bar(err) and "animation frames" in err, err
    assert (tmp_path / "plan.gif").read_bytes()[:4] == b"GIF8" and json.loads(out)["found"] is True


def run_tty_python(code: str, timeout: float = 60) -> str:
    """Python ``code`` with stderr on a pseudo-terminal: what it wrote there."""
    master, slave = pty.openpty()
    p = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.DEVNULL, stderr=slave,
                         stdin=subprocess.DEVNULL, env=env(0.0))
    os.close(slave)
    err = b""
    try:
        while select.select([master], [], [], timeout)[0]:
            try:
                chunk = os.read(master, 65536)
            except OSError:
                break
            if not chunk:
                break
            err += chunk
        p.wait(timeout)
    finally:
        os.close(master)
    assert p.returncode == 0, err
    return err.decode(errors="replace")


def test_a_note_during_a_bar_gets_its_own_line():
    """A message printed while a bar is drawn (e.g. bench's skip notices) is not glued onto it."""
    code = ("import time; from regrasp import progress\n"
            "with progress.bar(4, 'bench', unit='benchmark') as b:\n"
            "    b.update(1); b.refresh(); time.sleep(0.1)\n"
            "    progress.note('bench: the MNCP solver against IPOPT skipped: test')\n"
            "    b.update(1)\n")
    err = run_tty_python(code)
    assert has_bar(err), err
    segments = [s.strip() for s in re.split(r"[\r\n]", err)]
    assert "bench: the MNCP solver against IPOPT skipped: test" in segments, err


def test_bench_prints_its_notices_through_progress_note(monkeypatch, capsys):
    from regrasp import bench
    from regrasp.errors import MissingExtraError

    said = []
    monkeypatch.setattr(progress, "note", said.append)

    def missing():
        raise MissingExtraError("casadi", "reference")

    assert bench._unless_missing("the MNCP solver against IPOPT", missing) == {}
    assert said and "skipped" in said[0] and "regrasp[reference]" in said[0]
    assert capsys.readouterr().err == ""
