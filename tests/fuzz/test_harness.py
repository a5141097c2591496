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
