"""Closed standard streams (issue "Hardening, second round"): a command started with its standard
output or error closed (``>&-``) runs, discards what would go there, and exits with its own status
— never a traceback."""

import shlex
import subprocess
import sys

import pytest

import regrasp

SCENE = str(regrasp.examples.path("block-low-friction"))
CMD = f"{shlex.quote(sys.executable)} -m regrasp"


def sh(line: str, tmp_path):
    return subprocess.run(["sh", "-c", line], capture_output=True, text=True, timeout=120, cwd=tmp_path)


@pytest.mark.parametrize("args, status", [
    (f"cone {SCENE} --pose 0,0,0 --pusher left --json", 0),
    (f"plan {SCENE} --out plan.json", 0),
    (f"cone {SCENE} --pose 0,0,0 --pusher nobody", 2),
    ("--version", 0),
])
def test_a_closed_stdout_discards_the_output_and_keeps_the_status(args, status, tmp_path):
    r = sh(f"{CMD} {args} >&-", tmp_path)
    assert r.returncode == status and "Traceback" not in r.stderr, r.stderr
    if status == 2:
        assert "`--pusher`" in r.stderr  # the error still reaches stderr
    if "--out" in args:
        assert regrasp.Plan.load(tmp_path / "plan.json").found  # its files are written


def test_closed_stdout_and_stderr_keep_the_status(tmp_path):
    assert sh(f"{CMD} cone {SCENE} --pose 0,0,0 --pusher left >&- 2>&-", tmp_path).returncode == 0
    assert sh(f"{CMD} cone {SCENE} --pose 0,0,0 --pusher nobody >&- 2>&-", tmp_path).returncode == 2
    r = sh(f"{CMD} cone {SCENE} --pose 0,0,0 --pusher left 2>&-", tmp_path)
    assert r.returncode == 0 and "motion cone" in r.stdout
