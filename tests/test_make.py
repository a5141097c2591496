"""The two commands' plumbing: scripts/stage (one line per stage with its time, the whole output
in a log, the log's end and the status on failure) and the Makefile's dry run."""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
STAGE = ROOT / "scripts" / "stage"


def _stage(tmp_path, *cmd: str):
    log = tmp_path / "logs" / "x.log"
    r = subprocess.run([str(STAGE), "compile things", str(log), *cmd], capture_output=True, text=True, timeout=60,
                       env={**os.environ, "STAGE_PLAIN": "1"})
    return r, log


def test_a_stage_prints_one_line_and_keeps_the_output(tmp_path):
    r, log = _stage(tmp_path, "bash", "-c", "for i in 1 2 3; do echo line $i; done")
    assert r.returncode == 0 and r.stdout == ""
    lines = r.stderr.strip().splitlines()
    assert lines[0] == "compile things ..." and lines[-1].startswith("compile things: done in ") and len(lines) == 2, r.stderr
    assert log.read_text().split() == ["line", "1", "line", "2", "line", "3"]


def test_a_failed_stage_shows_its_end_and_keeps_its_status(tmp_path):
    r, log = _stage(tmp_path, "bash", "-c", "seq 1 100; echo 'error: it broke' >&2; exit 7")
    assert r.returncode == 7
    assert "error: it broke" in r.stderr and "\n60\n" not in r.stderr and "\n99\n" in r.stderr  # the last 40 lines
    assert "compile things: FAILED (exit 7)" in r.stderr and str(log) in r.stderr


def test_the_makefile_dry_run_runs_nothing():
    """`make -n` prints the commands without running any (no recursive $(MAKE) in a recipe, which
    make runs even then)."""
    r = subprocess.run(["make", "-n", "test", "demo"], cwd=ROOT, capture_output=True, text=True, timeout=60)
    assert r.returncode == 0, r.stderr
    assert "pytest -q" in r.stdout and "cargo test --profile" in r.stdout and "regrasp demo" in r.stdout
    assert "passed" not in r.stdout and "test result" not in r.stdout
