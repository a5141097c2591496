"""The fuzz harness itself can fail: each bad outcome it is meant to catch is caught."""

from __future__ import annotations

import math
import time

import numpy as np
import pytest

import regrasp

from . import harness


@pytest.fixture
def fresh(monkeypatch):
    """A recorder of its own, failing on the first bad outcome (whatever the profile)."""
    rec = harness.Recorder()
    monkeypatch.setattr(harness, "RECORDER", rec)
    monkeypatch.setattr(harness, "LONG", False)
    return rec


@pytest.mark.parametrize("fn,kind", [
    (lambda: {"a": [1.0, np.array([0.0, math.nan])]}, "nan"),
    (lambda: regrasp.Plan.from_json({"path": [{"pose": [0.0, 0.0, 0.0], "pusher": None}]}) and math.inf, "nan"),
    (lambda: [1, 2][5], "out_of_set"),
    (lambda: (_ for _ in ()).throw(regrasp.ArgumentError("bad", None)), "no_field"),
    (lambda: 1.0, "accepted"),
])
def test_bad_outcomes_fail(fresh, fn, kind):
    reject = ["grasp.force"] if kind == "accepted" else None
    with pytest.raises(AssertionError, match=rf"\[{kind}\]"):
        harness.run("self", "case", fn, reject=reject)
    assert fresh.bad[kind] == 1


def test_a_hang_is_interrupted(fresh):
    def spin():
        while True:
            time.sleep(0.01)

    t0 = time.monotonic()
    with pytest.raises(AssertionError, match=r"\[hang\]"):
        harness.run("self", "spin", spin, timeout=0.3)
    assert time.monotonic() - t0 < 5


def test_a_rejection_must_name_the_field(fresh):
    def wrong():
        raise regrasp.SceneError("bad", "object.mass")

    with pytest.raises(AssertionError, match=r"\[wrong_field\]"):
        harness.run("self", "case", wrong, reject=["grasp.force"])
    harness.run("self", "case", lambda: (_ for _ in ()).throw(regrasp.SceneError("bad", "grasp.force")),
                reject=["grasp.force"])
    assert fresh.cases["self"] == 2


def test_good_outcomes_pass(fresh):
    assert harness.run("self", "ok", lambda: {"x": np.zeros(3), "y": [1, 2.0, None, "s"]}) is not None
    assert harness.run("self", "err", lambda: regrasp.plan(regrasp.load_scene(
        harness_example()), max_nodes=-1)) is None
    assert not any(fresh.bad.values())


def harness_example():
    from .strategies import EXAMPLES

    return EXAMPLES / "block-low-friction.toml"


# --- the checks added for the world side (issue 44): each catches its kind -----------------------

def _judge(argv, result, must=None, outputs=()):
    from .test_fuzz_cli import judge

    judge("self", argv, result, must, None, outputs)


@pytest.mark.parametrize("result,argv,kind", [
    ((1, "", "regrasp: internal error (please report): ValueError: x"), ["cone"], "internal"),
    ((2, '{"x": NaN}', "regrasp: invalid `pose`"), ["cone", "--json"], "nan"),  # NaN printed by a failed run
    ((0, '{"x": [1.0, Infinity]}', ""), ["cone", "--json"], "nan"),
    ((1, "", "Traceback (most recent call last):\n  ValueError"), ["cone"], "traceback"),
    ((0, "", ""), ["cone", "--pose=nan,0,0"], "accepted"),
])
def test_the_cli_checks_catch_their_kind(fresh, result, argv, kind):
    must = "pose" if kind == "accepted" else None
    with pytest.raises(AssertionError, match=rf"\[{kind}\]"):
        _judge(argv, result, must)


def test_nan_in_a_written_file_is_caught(fresh, tmp_path):
    f = tmp_path / "traj.json"
    f.write_text('{"samples": [{"t": NaN}]}')
    with pytest.raises(AssertionError, match=r"\[nan\]"):
        _judge(["execute"], (0, "", ""), outputs=[str(f)])


def test_a_temporary_file_left_behind_is_caught(fresh, tmp_path):
    from .test_fuzz_world import _no_temporary_files

    _no_temporary_files("self", "case", str(tmp_path))
    (tmp_path / ".out.tmp1234abcd.json").write_text("{")
    with pytest.raises(AssertionError, match=r"\[temp_left\]"):
        _no_temporary_files("self", "case", str(tmp_path))


def test_an_unbounded_read_fails_the_case_not_the_machine(fresh, monkeypatch):
    monkeypatch.setattr(harness, "MEMORY", 256 * 2**20)
    with pytest.raises(AssertionError, match=r"\[memory\]"):
        harness.run("self", "read /dev/zero", lambda: open("/dev/zero", "rb").read(2 * 2**30))


def test_a_subprocess_runs_under_the_memory_limit(monkeypatch):
    import subprocess
    import sys

    monkeypatch.setattr(harness, "MEMORY", 256 * 2**20)
    p = subprocess.run([sys.executable, "-c", "b = bytearray(1 << 30)"], preexec_fn=harness.limit_child,
                       capture_output=True, text=True)
    assert p.returncode != 0 and "MemoryError" in p.stderr


def test_accepted_nonsense_in_a_world_file_is_caught(fresh, monkeypatch, tmp_path):
    from regrasp.workcell import Workcell

    from . import test_fuzz_world as world

    p = tmp_path / "w.toml"
    p.write_text('name = "w"\n[table]\nheight = nan\n')
    monkeypatch.setattr(Workcell, "load", staticmethod(lambda path: "accepted"))  # a reader that checks nothing
    with pytest.raises(AssertionError, match=r"\[accepted\]"):
        harness.run("self", "nan height", lambda: world._load("workcell", p), reject=["table"])
