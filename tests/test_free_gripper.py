"""World motions executed in MuJoCo by a free-flying gripper in the workcell
(regrasp.execution.free_gripper), with the real engine; checked independently with 4 x 4
matrices, the plan's goal and the scene's tolerance, and by removing the feature that pushes."""

import numpy as np
import pytest

import regrasp
from regrasp import ArgumentError
from regrasp.execution import world_motion
from regrasp.execution.free_gripper import FEATURE_RADIUS, build, execute_free_gripper
from regrasp.workcell import Workcell

from .conftest import rotation_matrix as rot, pose_matrix as T

pytest.importorskip("mujoco")
RUNS: dict = {}


def run(name, drop=None):
    if (name, drop) not in RUNS:
        scene = regrasp.load_scene(regrasp.examples.path(name))
        plan = regrasp.plan(scene, seed=0)
        m = world_motion(scene, plan)
        w = m.workcell if drop is None else Workcell(
            "without", m.workcell.table, tuple(f for f in m.workcell.features if f.name != drop), m.workcell.robot)
        RUNS[name, drop] = (scene, plan, m, execute_free_gripper(scene, plan, m, w))
    return RUNS[name, drop]


@pytest.mark.parametrize("name", ["block-low-friction", "t-shape", "offset-3d"])
def test_the_plan_executes_in_the_workcell(name):
    scene, plan, m, r = run(name)
    # independent: the in-hand pose is the measured gripper's inverse times the object's
    for i in range(0, len(r.times), 50):
        assert np.abs(np.linalg.inv(T(r.gripper[i])) @ T(r.object[i]) - T(r.in_hand[i])).max() < 1e-9
    # the gripper followed the motion
    assert np.abs(r.gripper[:, :3] - m.gripper[:, :3]).max() < 1e-6
    final = np.linalg.inv(T(r.gripper[-1])) @ T(r.object[-1])
    goal = np.asarray(plan.poses[-1], float)
    if scene.dimension == 2:
        got = np.array([final[0, 3], final[2, 3], np.arctan2(final[2, 0], final[0, 0])])
        assert np.all(np.abs(got - goal) <= scene.task.tolerance), (got, goal)
        assert abs(final[1, 3]) < 1e-3                          # still between the pads
    else:
        _, _, tol = scene.task
        assert np.all(np.abs(final[:3, 3] - goal[:3]) <= tol[:3])
        cos = (np.trace(rot(goal[3:]).T @ final[:3, :3]) - 1) / 2
        assert np.arccos(np.clip(cos, -1, 1)) <= tol[3]
    assert r.success and r.duration >= m.duration
    assert r.max_creep < 1e-3                                   # the grasp holds in transfers
    if name == "t-shape":                                       # `top` is pushed down by the ledge
        a = m.assignments[0]
        assert (a.pusher, a.feature) == ("top", "ledge")
        js = np.flatnonzero((m.push == 0) & (np.array(m.labels) == "push"))
        moved = np.linalg.norm(r.in_hand[js[-1], :3] - r.in_hand[js[0], :3])
        planned = np.linalg.norm(m.in_hand[js[-1], :3] - m.in_hand[js[0], :3])
        assert planned > 5e-3 and moved == pytest.approx(planned, rel=0.2)


def test_without_the_feature_the_push_does_not_move_the_object():
    """block-low-friction's `left` push is made by the fixture block's edge: with the block gone,
    the gripper makes the same motion but the object stays where it was in the hand."""
    scene, plan, m, r = run("block-low-friction")
    _, _, _, bare = run("block-low-friction", drop="fixture")
    a = next(a for a in m.assignments if a.pusher == "left")
    assert a.feature.startswith("fixture.")
    js = np.flatnonzero((m.push == a.index) & (np.array(m.labels) == "push"))
    planned = np.linalg.norm(m.in_hand[js[-1], :3] - m.in_hand[js[0], :3])
    moved = np.linalg.norm(r.in_hand[js[-1], :3] - r.in_hand[js[0], :3])
    stayed = np.linalg.norm(bare.in_hand[js[-1], :3] - bare.in_hand[js[0], :3])
    assert planned > 5e-3 and moved == pytest.approx(planned, rel=0.2)
    assert stayed < 0.1 * planned
    assert r.success and not bare.success


def test_the_workcell_is_in_the_model_where_the_file_says():
    mujoco = pytest.importorskip("mujoco")
    scene = regrasp.load_scene(regrasp.examples.path("t-shape"))
    plan = regrasp.plan(scene, seed=0)
    m = world_motion(scene, plan)
    model = build(scene, m).compile()
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    w = m.workcell
    table = model.geom("table")
    assert data.geom_xpos[table.id][2] + model.geom_size[table.id][2] == pytest.approx(w.table.height)
    assert model.geom_friction[table.id][0] == pytest.approx(w.table.friction)
    block = w.feature("fixture")
    assert np.allclose(data.geom_xpos[model.geom("fixture").id], block.pose[:3])
    assert np.allclose(model.geom_size[model.geom("fixture").id], np.asarray(block.size) / 2)
    ledge = w.feature("ledge")                                  # the capsule's surface touches the edge line
    g = model.geom("ledge").id
    axis = data.geom_xmat[g].reshape(3, 3)[:, 2]
    off = ledge.pose[:3] - data.geom_xpos[g]
    dist = np.linalg.norm(off - (off @ axis) * axis)
    assert dist == pytest.approx(FEATURE_RADIUS, abs=1e-9) and model.geom_size[g][1] == pytest.approx(ledge.length / 2)
    assert np.isclose(abs(axis @ rot(ledge.pose[3:])[:, 0]), 1)
    assert model.opt.gravity[2] < 0 and np.allclose(model.opt.gravity[:2], 0)
    # the block edge that renders `bar-right` has a capsule whose surface touches the contact point
    a = next(a for a in m.assignments if a.pusher == "bar-right")
    g = model.geom(f"{a.feature}-push{a.index}").id
    axis = data.geom_xmat[g].reshape(3, 3)[:, 2]
    off = a.frame[:3] - data.geom_xpos[g]
    assert np.linalg.norm(off - (off @ axis) * axis) == pytest.approx(FEATURE_RADIUS, abs=1e-9)
    assert np.isclose(abs(axis @ rot(a.frame[3:])[:, 0]), 1)
    assert (off / np.linalg.norm(off)) @ rot(a.frame[3:])[:, 2] == pytest.approx(1)   # behind it


def test_bad_arguments_are_refused_naming_them():
    scene, plan, m, _ = run("block-low-friction")
    with pytest.raises(ArgumentError) as e:
        execute_free_gripper(scene, plan, "motion")
    assert e.value.field == "motion"
    with pytest.raises(ArgumentError) as e:
        execute_free_gripper(scene, plan, m, workcell=3)
    assert e.value.field == "workcell"
