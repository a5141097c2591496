"""The Franka Hand (regrasp.robot.franka_hand, robot `panda-hand`) with the real engine, checked
against the model it is built from: the Panda's URDF compiled by MuJoCo with its own hand, at the
same joints, puts the hand's mesh and every finger box where ours are (the rubber tips `RECESS`
behind our pads); the TCP midway between the pads' faces; the grip's measured force map is the
geared tendon's; the hand takes no parameters; the T, which the thesis' long fingers hold, is
refused by this hand naming its body."""

import importlib.metadata
from pathlib import Path

import numpy as np
import pytest

import regrasp
from regrasp.robot.parallel_gripper import GEAR

from .conftest import pad_faces, rotation_matrix, run_cli

pytest.importorskip("mink")
try:
    importlib.metadata.distribution("example-robot-data")
except importlib.metadata.PackageNotFoundError:
    pytest.skip("needs example-robot-data (regrasp[panda])", allow_module_level=True)
ROBOT = "panda-hand"
FILE = Path(regrasp.examples.path("block-xztheta")).parent / "robots" / "panda-hand.toml"


def urdf_model(kind):
    """The Panda's URDF with its own hand, as MuJoCo compiles it (the reference)."""
    import mujoco

    from regrasp.robot.arm_model import urdf_text

    return mujoco.MjModel.from_xml_string(urdf_text(Path(kind.arm_file)))


def frame(d, g):
    return d.geom_xpos[g].copy(), d.geom_xmat[g].reshape(3, 3).copy()


@pytest.mark.parametrize("width", [0.01, 0.05])
def test_the_hand_is_where_the_urdf_puts_it(width):
    import mujoco

    from regrasp.robot.franka_hand import BOXES, RECESS
    from regrasp.robot.grip import close_fingers
    from regrasp.robot.kinds import ROBOTS
    from regrasp.robot.model import build

    r = build(ROBOT, grasp_width=width)
    close_fingers(r)
    mujoco.mj_forward(r.model, r.data)
    kind = ROBOTS[ROBOT]
    ref = urdf_model(kind)
    rd = mujoco.MjData(ref)
    for j in kind.arm_joints:  # the same arm joints
        rd.qpos[ref.jnt_qposadr[ref.joint(j).id]] = r.data.qpos[r.model.jnt_qposadr[r.model.joint("arm/" + j).id]]
    for j in ("panda_finger_joint1", "panda_finger_joint2"):
        rd.qpos[ref.jnt_qposadr[ref.joint(j).id]] = width / 2
    mujoco.mj_forward(ref, rd)
    hand = [g for g in range(ref.ngeom) if ref.geom_bodyid[g] == ref.body("panda_hand").id]
    p, R = frame(r.data, r.model.geom("gripper/hand").id)
    q, S = frame(rd, hand[0])
    assert np.allclose(p, q, atol=1e-9) and np.allclose(R, S, atol=1e-9), "the hand's mesh"
    # each finger's boxes (the URDF's collision boxes in its order): the same orientation and
    # place, but across the grasp, where ours stand RECESS behind the pads (which touch the
    # object at the grasp width, sinking a little into it)
    axis = rotation_matrix(r.tcp_pose()[3:])[:, 1]
    for ours, theirs in (("right", "panda_rightfinger"), ("left", "panda_leftfinger")):
        boxes = [g for g in range(ref.ngeom) if ref.geom_bodyid[g] == ref.body(theirs).id]
        assert len(boxes) == len(BOXES)
        for g, (name, *_rest) in zip(boxes, BOXES):
            p, R = frame(r.data, r.model.geom(f"gripper/{ours}_{name}").id)
            q, S = frame(rd, g)
            assert np.allclose(np.abs(R.T @ S), np.eye(3), atol=1e-9), (ours, name)
            d = p - q
            along = d @ axis
            assert np.linalg.norm(d - along * axis) < 1e-9, (ours, name)
            assert abs(abs(along) - RECESS) < 1e-3, (ours, name, along)


@pytest.mark.parametrize("width", [0.006, 0.04, 0.075])
def test_the_tcp_is_midway_between_the_pads_faces(width):
    from regrasp.robot.grip import close_fingers
    from regrasp.robot.model import build

    r = build(ROBOT, grasp_width=width)
    close_fingers(r)
    left, right = pad_faces(r)
    assert left.mean() + right.mean() == pytest.approx(0.0, abs=1e-6)
    # the pads sink into a box as wide as the grasp at the calibration's 25 N a pad: 0.67 mm each
    # (MuJoCo's contact impedance scales with the 15 g finger's mass; the parametric's 50 g: < 0.5)
    assert 0.6e-3 < (width - (left.mean() - right.mean())) / 2 < 0.75e-3


def test_the_housing_is_37_6_mm_below_the_tips_centre():
    """The figure docs/robot.md gives: the hand mesh's highest point along the fingers (its
    convex hull, as MuJoCo collides it), measured in the compiled model, below the pads' centre."""
    import mujoco

    from regrasp.robot.franka_hand import FrankaHand
    from regrasp.robot.model import build

    r = build(ROBOT, grasp_width=0.03)
    m, d = r.model, r.data
    mujoco.mj_forward(m, d)
    g = m.geom("gripper/hand").id
    v = m.mesh_vert[m.mesh_vertadr[m.geom_dataid[g]]:][:m.mesh_vertnum[m.geom_dataid[g]]]
    world = v @ d.geom_xmat[g].reshape(3, 3).T + d.geom_xpos[g]
    base = m.body("gripper/base").id
    up = world @ d.xmat[base].reshape(3, 3)[:, 2] - d.xpos[base] @ d.xmat[base].reshape(3, 3)[:, 2]
    assert FrankaHand().pad_height - up.max() == pytest.approx(0.0376, abs=1e-4)


def test_the_grip_map_is_the_tendons_gear():
    from regrasp.robot.franka_hand import FrankaHand
    from regrasp.robot.grip import least_force, pad_state

    gain, bias, height = pad_state(0.03, ROBOT)
    assert gain == pytest.approx(GEAR, rel=1e-6) and abs(bias) < 1e-6
    assert height == pytest.approx(FrankaHand().pad_height, abs=1e-9)
    assert least_force(0.03, ROBOT) == pytest.approx(0.0, abs=1e-6)


def test_the_hand_takes_no_parameters(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text(FILE.read_text().replace('kind = "franka-hand"', 'kind = "franka-hand"\nstroke = 0.1'))
    scene = regrasp.examples.path("block-xztheta")
    regrasp.plan(regrasp.load_scene(scene), seed=0).save(tmp_path / "p.json")
    code, _, err = run_cli("execute", scene, "--plan", tmp_path / "p.json", "--robot", bad, "--plan-only")
    assert code == 2 and "gripper.stroke" in err and "takes no parameters" in err and "Traceback" not in err


def test_the_t_is_refused_in_this_hand_naming_its_body(tmp_path):
    """The T held at its tips reaches the hand's housing (its fingers are 54 mm; the thesis'
    rig's 100 mm): refused before the arm moves, naming the hand's body."""
    scene = regrasp.examples.path("t-shape")
    regrasp.plan(regrasp.load_scene(scene), seed=0).save(tmp_path / "p.json")
    code, _, err = run_cli("execute", scene, "--plan", tmp_path / "p.json", "--robot", ROBOT, "--plan-only")
    assert code == 1 and "the plan cannot be done in this hand" in err and "into the gripper's `base`" in err, err
    assert "Traceback" not in err
