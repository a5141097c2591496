"""The trajectory file (docs/trajectory-file.md): a world motion written and read back equal,
the documented keys are the loader's, and bad content is refused naming the field."""

import json
import re
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import regrasp
from regrasp import ArgumentError, SceneError
from regrasp.execution import Trajectory, world_motion
from regrasp.execution.trajectory import ASSIGNMENT_KEYS, KEYS, SAMPLE_KEYS

DOC = Path(__file__).resolve().parents[1] / "docs" / "trajectory-file.md"
CACHE: dict = {}


def traj(name="block-low-friction"):
    if name not in CACHE:
        scene = regrasp.load_scene(regrasp.examples.path(name))
        m = world_motion(scene, regrasp.plan(scene, seed=0))
        CACHE[name] = (m, m.to_trajectory())
    return CACHE[name]


@pytest.mark.parametrize("name", ["block-low-friction", "pivot-3d"])
def test_a_world_motion_round_trips_through_the_file(name, tmp_path):
    m, t = traj(name)
    path = t.save(tmp_path / "t.json")
    u = Trajectory.load(path)
    assert u == t and len(u) == len(m.times) and u.robot is None and u.joint_names == [] and u.q.shape == (len(u), 0)
    # independent: the raw JSON holds the motion's numbers, null for no push
    raw = json.loads(Path(path).read_text())
    assert raw["format"] == "regrasp-trajectory" and raw["version"] == 1 and raw["scene"] == name
    assert np.array_equal([s["t"] for s in raw["samples"]], m.times)
    assert np.array_equal([s["gripper_pose"] for s in raw["samples"]], m.gripper)
    assert [s["push"] for s in raw["samples"]] == [None if p < 0 else int(p) for p in m.push]
    assert [a["feature"] for a in raw["assignments"]] == [a.feature for a in m.assignments]
    assert not list(tmp_path.glob(".*tmp*"))                        # written atomically, nothing left


def test_a_robot_trajectory_with_joints_round_trips():
    _, t = traj()
    d = t.to_dict()
    d["robot"], d["joint_names"] = "ur5e", [f"j{i}" for i in range(6)]
    for k, s in enumerate(d["samples"]):
        s["q"] = [0.01 * k + i for i in range(6)]
    u = Trajectory.from_dict(d)
    assert u.q.shape == (len(t), 6) and u.q[3, 2] == pytest.approx(2.03)
    assert Trajectory.from_json(u.to_json()) == u


def test_the_documented_keys_are_the_loaders():
    text = DOC.read_text()
    for keys in (KEYS, SAMPLE_KEYS, ASSIGNMENT_KEYS):
        for k in keys:
            assert re.search(rf"\| `{k}` \|", text), k


def mutate(d, where, value):
    d = json.loads(json.dumps(d))
    node = d
    parts = re.findall(r"[^.\[\]]+|\[\d+\]", where)
    for p in parts[:-1]:
        node = node[int(p[1:-1])] if p.startswith("[") else node[p]
    last = parts[-1]
    if value is KeyError:
        del node[last]
    else:
        node[int(last[1:-1]) if last.startswith("[") else last] = value
    return d


BAD = [
    ("format", "regrasp-plan"), ("version", 2), ("version", True), ("scene", ""), ("robot", 3),
    ("joint_names", ["a"]), ("samples", []), ("samples[3].t", float("nan")), ("samples[3].t", 0.0),
    ("samples[3].t", "1"), ("samples[2].q", [0.0]), ("samples[2].gripper_pose", [0, 0, 0, 1, 0, 0]),
    ("samples[2].gripper_pose", [0, 0, 0, 2, 0, 0, 0]), ("samples[2].gripper_pose", [0, 0, 0, 1, 0, 0, float("inf")]),
    ("samples[1].grip_force", -1.0), ("samples[1].label", "fly"), ("samples[1].push", 99), ("samples[1].push", 1.5),
    ("samples[1].t", KeyError), ("assignments[0].frame", [0, 0, 0, 0, 0, 0, 0]), ("assignments[0].last", 0),
    ("assignments[0].tilt", 4.0), ("assignments[0].penetration", -1e-3), ("assignments[0].pusher", None),
    ("samples[1].extra", 1), ("extra", 1),
]


@settings(max_examples=80, deadline=None)
@given(st.sampled_from(BAD), st.sampled_from(["dict", "json"]))
def test_bad_content_is_refused_naming_the_field(bad, how):
    where, value = bad
    _, t = traj()
    d = mutate(t.to_dict(), where, value)
    text = json.dumps(d)
    with pytest.raises(SceneError) as e:
        if how == "dict":
            Trajectory.from_dict(d)
        else:
            Trajectory.from_json(text)
    field, expected = e.value.field, where
    if how == "json" and ("NaN" in text or "Infinity" in text):
        expected = "(json)"                       # NaN and Infinity are not JSON
    assert field == expected or field.startswith(expected + "["), (where, value, field)


@settings(max_examples=40, deadline=None)
@given(st.lists(st.floats(0, 100), min_size=2, max_size=6))
def test_times_must_increase_strictly(ts):
    _, t = traj()
    d = t.to_dict()
    d["samples"] = [dict(d["samples"][0], t=x) for x in ts]
    ok = all(b > a for a, b in zip(ts, ts[1:]))
    if ok:
        assert np.array_equal(Trajectory.from_dict(d).times, ts)
    else:
        with pytest.raises(SceneError) as e:
            Trajectory.from_dict(d)
        i = next(i for i in range(1, len(ts)) if ts[i] <= ts[i - 1])
        assert e.value.field == f"samples[{i}].t"


def test_unreadable_and_non_json_files_are_refused(tmp_path):
    with pytest.raises(ArgumentError) as e:
        Trajectory.load(tmp_path / "missing.json")
    assert e.value.field == "path"
    (tmp_path / "x.json").write_text("{not json")
    with pytest.raises(SceneError) as e:
        Trajectory.load(tmp_path / "x.json")
    assert e.value.field == "(json)"
    with pytest.raises(SceneError) as e:
        Trajectory.from_json("[1, 2]")
    assert e.value.field == "(file)"
