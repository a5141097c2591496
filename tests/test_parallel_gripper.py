"""The parametric parallel-jaw gripper (regrasp.robot.parallel_gripper, robot `ur5e-parallel`)
with the real engine: the TCP midway between the pads' faces (the pads' contact spheres read from
the compiled model), the grip's measured force map against the geared tendon's statics, the
fingers behind the pads, bad parameters named; the thesis' tasks that the 2F-85 refuses
(the object in its housing) fit this hand and execute."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import regrasp
from regrasp import ArgumentError, ExecutionError
from regrasp.robot.parallel_gripper import GEAR, ParallelGripper

from .conftest import pad_faces, rotation_matrix

pytest.importorskip("mink")
ROBOT = "ur5e-parallel"


@pytest.mark.parametrize("width", [0.006, 0.04, 0.1])
def test_the_tcp_is_midway_between_the_pads_faces(width):
    import mujoco

    from regrasp.robot.model import build

    r = build(ROBOT, grasp_width=width)
    from regrasp.robot.grip import close_fingers

    close_fingers(r)
    m, d = r.model, r.data
    tcp = r.tcp_pose()
    R = rotation_matrix(tcp[3:])
    left, right = pad_faces(r)
    assert left.mean() + right.mean() == pytest.approx(0.0, abs=1e-6), "midway"
    # the fingers as they close on a box as wide as the grasp (the calibration's 25 N a pad): the
    # compliant pads' spheres sink a little into it
    assert 0.0 <= width - (left.mean() - right.mean()) < 1e-3
    centre = np.mean([d.geom_xpos[g] for side in r.pad_geoms for g in side], axis=0)
    assert np.linalg.norm((centre - tcp[:3]) - ((centre - tcp[:3]) @ R[:, 1]) * R[:, 1]) < 1e-9  # on the grasp axis
    mujoco.mj_forward(m, d)


@pytest.mark.parametrize("width", [0.004, 0.03, 0.1])
def test_the_grip_map_is_the_tendons_gear(width):
    """Statics of the geared tendon: each finger's joint gets GEAR times the actuator's force,
    and a frictionless slide puts all of it on the pad: gain GEAR, no bias."""
    from regrasp.robot.grip import least_force, pad_state

    gain, bias, height = pad_state(width, ROBOT)
    assert gain == pytest.approx(GEAR, rel=1e-6) and abs(bias) < 1e-6
    assert height == pytest.approx(ParallelGripper().pad_height, abs=1e-9)
    assert least_force(width, ROBOT) == pytest.approx(0.0, abs=1e-6)


@settings(max_examples=40, deadline=None)
@given(name=st.sampled_from(["finger_length", "finger_width", "finger_thickness", "pad_width", "pad_length", "stroke",
                             "palm_height", "recess", "palm_mass", "finger_mass", "damping"]),
       bad=st.sampled_from([0.0, -0.01, float("nan"), float("inf"), True, "long", 1e6]))
def test_bad_parameters_name_the_field(name, bad):
    with pytest.raises(ArgumentError) as e:
        ParallelGripper(**{name: bad})
    assert e.value.field == f"gripper.{name}"


def test_a_pad_wider_than_its_finger_is_refused():
    with pytest.raises(ArgumentError) as e:
        ParallelGripper(finger_width=0.015, pad_width=0.02)
    assert e.value.field == "gripper.finger_width"


@pytest.mark.parametrize("name", ["t-shape", "pivot-3d"])
def test_the_thesis_tasks_fit_this_hand_and_not_the_2f85(name):
    from regrasp.execution import world_motion
    from regrasp.execution.arm import build_robot, check_hand

    scene = regrasp.load_scene(regrasp.examples.path(name))
    motion = world_motion(scene, regrasp.plan(scene, seed=0))
    r, _, _, tcp = build_robot(scene, motion, "ur5e-2f85")
    with pytest.raises(ExecutionError, match="into the gripper"):
        check_hand(r, motion, tcp)
    r, _, _, tcp = build_robot(scene, motion, ROBOT)
    check_hand(r, motion, tcp)


@pytest.mark.parametrize("name", ["pivot-3d", "prism-3d"])
def test_the_thesis_tasks_execute_with_the_long_fingers(name):
    from regrasp.execution import World, execute

    scene = regrasp.load_scene(regrasp.examples.path(name))
    run = execute(World(scene, rig="arm", robot=ROBOT), regrasp.plan(scene, seed=0))
    assert run.success, run.goal_error
