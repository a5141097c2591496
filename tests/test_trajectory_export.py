"""A trajectory a controller can load (`regrasp execute --plan-only`, docs/trajectory-file.md,
"Formats"): the arm's joint trajectory without simulation, every sample within the robot's joint
velocity and acceleration limits (and the positions' divided differences too), the ROS 2
document checked against `trajectory_msgs/msg/JointTrajectory`'s fields and types, the CSV read
back to the same numbers; bad requests refused before any work."""

import json

import numpy as np
import pytest

import regrasp
from regrasp.execution import Trajectory
from regrasp.execution.trajectory_formats import parse_csv, read_csv, stamp
from regrasp.robot.kinds import ROBOTS

from .conftest import run_cli

pytest.importorskip("mink")
pytest.importorskip("toppra")
yaml = pytest.importorskip("yaml")
NAME = "block-xztheta"
INT32, UINT32 = (-2**31, 2**31 - 1), (0, 2**32 - 1)

# trajectory_msgs/msg/JointTrajectory (ROS 2 Humble/Jazzy), its nested messages by field
DURATION = {"sec": ("int", INT32), "nanosec": ("int", (0, 999_999_999))}
SCHEMA = {
    "header": {"stamp": {"sec": ("int", INT32), "nanosec": ("int", UINT32)}, "frame_id": ("str", None)},
    "joint_names": ("str[]", None),
    "points": [{"positions": ("float[]", None), "velocities": ("float[]", None), "accelerations": ("float[]", None),
                "effort": ("float[]", None), "time_from_start": DURATION}],
}


def conforms(doc, schema, where="msg"):
    """``doc`` has exactly the fields of ``schema`` with their types (YAML as ROS 2 parses it)."""
    if isinstance(schema, dict):
        assert isinstance(doc, dict) and set(doc) == set(schema), (where, doc if not isinstance(doc, dict) else set(doc))
        for k, s in schema.items():
            conforms(doc[k], s, f"{where}.{k}")
    elif isinstance(schema, list):
        assert isinstance(doc, list), where
        for i, d in enumerate(doc):
            conforms(d, schema[0], f"{where}[{i}]")
    else:
        kind, bounds = schema
        if kind == "int":
            assert type(doc) is int and bounds[0] <= doc <= bounds[1], (where, doc)
        elif kind == "str":
            assert isinstance(doc, str), (where, doc)
        elif kind == "str[]":
            assert isinstance(doc, list) and all(isinstance(x, str) for x in doc), (where, doc)
        else:  # float64[]: YAML floats (an integer literal would be refused by the message's type check)
            assert isinstance(doc, list) and all(type(x) is float for x in doc), (where, doc)


@pytest.fixture(scope="module")
def exported(tmp_path_factory):
    d = tmp_path_factory.mktemp("export")
    scene = regrasp.load_scene(regrasp.examples.path(NAME))
    regrasp.plan(scene, seed=0).save(d / "plan.json")
    runs = {}
    for ext in ("json", "yaml", "csv"):
        runs[ext] = run_cli("execute", regrasp.examples.path(NAME), "--plan", d / "plan.json", "--plan-only",
                            "--trajectory", d / f"t.{ext}", *(["--json"] if ext == "json" else []))
    return d, runs


def test_plan_only_writes_the_trajectory_without_simulating(exported):
    d, runs = exported
    for ext, (code, out, err) in runs.items():
        assert code == 0, (ext, err)
    out = json.loads(runs["json"][1])
    tr = Trajectory.load(d / "t.json")
    assert out["plan_only"] and out["samples"] == len(tr) and out["duration_s"] == pytest.approx(tr.duration)
    assert 0 < out["max_velocity_ratio"] <= 1 + 1e-6 and 0 < out["max_acceleration_ratio"] <= 1 + 1e-6
    h = out["holding"]  # the pads' hold along it (execution.holding): the smallest margin and where
    assert h["holds"] and 1 > h["smallest_margin"] >= h["required_margin"] > 0 and "t = " in h["where"]
    assert "not simulated" in runs["yaml"][1] and "of their friction unused at least" in runs["yaml"][1]


def test_every_sample_is_within_the_robot_limits(exported):
    d, _ = exported
    tr = Trajectory.load(d / "t.json")
    kind = ROBOTS[tr.robot]
    vmax, amax = np.array(kind.velocity_limit), np.array(kind.acceleration_limit)
    assert tr.joint_names == list(kind.arm_joints) and tr.qd.shape == tr.q.shape == tr.qdd.shape
    assert np.all(np.abs(tr.qd) <= vmax * (1 + 1e-6)) and np.all(np.abs(tr.qdd) <= amax * (1 + 1e-6))
    dt = np.diff(tr.times)
    v = np.diff(tr.q, axis=0) / dt[:, None]                       # independent of the reported rates
    a = 2 * np.diff(v, axis=0) / (dt[1:] + dt[:-1])[:, None]
    assert np.all(np.abs(v) <= vmax * (1 + 1e-3)) and np.all(np.abs(a) <= amax * (1 + 1e-3)), np.abs(a).max()
    assert np.all(tr.qd[[0, -1]] == 0)                             # from rest to rest


def test_the_ros2_document_is_a_joint_trajectory(exported):
    d, _ = exported
    tr = Trajectory.load(d / "t.json")
    doc = yaml.safe_load((d / "t.yaml").read_text())
    conforms(doc, SCHEMA)
    assert doc["joint_names"] == tr.joint_names and len(doc["points"]) == len(tr)
    n = len(tr.joint_names)
    for i, p in enumerate(doc["points"]):
        assert len(p["positions"]) == len(p["velocities"]) == len(p["accelerations"]) == n and p["effort"] == []
        t = p["time_from_start"]["sec"] + p["time_from_start"]["nanosec"] * 1e-9
        assert t == pytest.approx(tr.times[i], abs=1e-9)
    assert np.array_equal([p["positions"] for p in doc["points"]], tr.q)
    assert np.array_equal([p["accelerations"] for p in doc["points"]], tr.qdd)


def test_the_csv_reads_back_to_the_same_numbers(exported):
    d, _ = exported
    tr, c = Trajectory.load(d / "t.json"), read_csv(d / "t.csv")
    assert c.joint_names == tr.joint_names
    for k in ("times", "q", "qd", "qdd", "grip_force"):
        assert np.array_equal(getattr(c, k), getattr(tr, k)), k
    raw = np.loadtxt(d / "t.csv", delimiter=",", skiprows=1)        # independent: numpy's reader
    assert np.array_equal(raw[:, 0], tr.times) and np.array_equal(raw[:, -1], tr.grip_force)


def test_stamps_carry_whole_seconds():
    assert stamp(0.0) == (0, 0) and stamp(1.5) == (1, 500_000_000) and stamp(2.9999999999) == (3, 0)


@pytest.mark.parametrize("text, field", [
    ("", "(file)"),
    ("t,a,a.vel,a.acc\n0,0,0,0\n", "(header)"),
    ("t,a,a.vel,a.acc,grip_force\n0,0,0,0\n", "rows[0]"),
    ("t,a,a.vel,a.acc,grip_force\n0,0,x,0,1\n", "rows[0]"),
    ("t,a,a.vel,a.acc,grip_force\n0,0,nan,0,1\n", "rows[0].a.vel"),
    ("t,a,a.vel,a.acc,grip_force\n1,0,0,0,1\n1,0,0,0,1\n", "rows[1].t"),
    ("t,a,a.vel,a.acc,grip_force\n", "rows"),
])
def test_a_bad_csv_names_the_field(text, field):
    with pytest.raises(regrasp.SceneError) as e:
        parse_csv(text)
    assert e.value.field == field


def test_bad_requests_are_refused_before_any_work(tmp_path):
    scene = regrasp.examples.path(NAME)
    plan = tmp_path / "p.json"
    plan.write_text("{}")  # never read: the options fail first
    for extra, opt in [(["--trajectory", tmp_path / "t.txt"], "--trajectory"),
                       (["--format", "ros2"], "--format"),
                       (["--robot", "free-gripper", "--trajectory", tmp_path / "t.csv"], "--trajectory"),
                       (["--robot", "free-gripper", "--trajectory", tmp_path / "t.json", "--format", "ros2"], "--trajectory"),
                       (["--plan-only", "--video", tmp_path / "v.gif"], "--video"),
                       (["--plan-only", "--scale-mass", "1.1"], "--scale-mass")]:
        code, _, err = run_cli("execute", scene, "--plan", plan, *extra)
        assert code == 2 and opt in err and "Traceback" not in err, (extra, err)


def test_the_documented_python_snippet_writes_a_joint_trajectory(tmp_path, monkeypatch):
    import re
    from pathlib import Path

    doc = (Path(__file__).resolve().parents[1] / "docs" / "trajectory-file.md").read_text()
    code = re.findall(r"```python\n(.*?)```", doc.split("## Formats")[1], re.S)[0]
    assert len(code.strip().splitlines()) <= 10
    monkeypatch.chdir(tmp_path)
    exec(compile(code, "trajectory-file.md", "exec"), {})
    doc = yaml.safe_load((tmp_path / "block-xztheta.yaml").read_text())
    conforms(doc, SCHEMA)
    assert len(doc["points"]) > 100
