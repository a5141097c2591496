"""One executor (issue "One world"): :func:`regrasp.execution.execute` runs a plan in any rig and
engine with one result, judged against the task; each run checked against the rig's own function
called directly, and a cut plan shows success is the task's, not the plan's end."""

import numpy as np
import pytest

import regrasp
from regrasp import ArgumentError, Perturbation
from regrasp.examples import path as example
from regrasp.execution import Execution, World, execute

pytest.importorskip("mujoco")


@pytest.fixture(scope="module")
def planar():
    scene = regrasp.Scene.load(example("block-high-friction"))
    return scene, regrasp.plan(scene, seed=0)


@pytest.fixture(scope="module")
def spatial():
    scene = regrasp.load_scene(example("offset-3d"))
    return scene, regrasp.plan(scene, seed=0)


@pytest.fixture(scope="module")
def arm_world(planar):
    """The arm's world of ``planar``: its arm motion solved once for the tests that share it."""
    pytest.importorskip("mink")
    return World(planar[0], rig="arm")


def cut(plan, n: int):
    """The plan's first ``n`` poses: a plan that ends off the task's goal."""
    return regrasp.Plan.from_json({"path": plan.to_json()["path"][:n]})


def test_quasistatic_replay(planar):
    from regrasp.sim.quasistatic import replay_plan

    scene, plan = planar
    run = execute(World(scene, engine="quasistatic"), plan)
    ref = replay_plan(scene, plan)
    assert isinstance(run, Execution) and np.allclose(run.final_pose, ref.final_pose)
    err, ok = scene.goal_error(ref.final_pose)
    assert run.success == ok and np.allclose(run.goal_error, err)
    from regrasp.cli import runs

    assert [p["pusher"] for p in run.pushes] == [n for n, _ in runs(plan.pushers)]
    assert run.to_json()["rig"] == "planner"


def test_success_is_the_tasks_not_the_plans_end(planar):
    scene, plan = planar
    half = cut(plan, max(2, len(plan.poses) // 2))
    run = execute(World(scene, engine="quasistatic"), half)
    assert run.at_plan_end and not run.success  # it did what the plan said, which is not the task
    assert np.abs(run.plan_end_error).max() < np.abs(run.goal_error).max()


def test_mujoco_in_a_perturbed_world(planar):
    from regrasp.mujoco.planar import execute_plan

    scene, plan = planar
    pert = Perturbation(0.9, 1.1, 1.05, 0.95)
    run = execute(World(scene, options={"speed": 0.02}), plan, perturbation=pert)
    ref = execute_plan(scene, plan, pert, speed=0.02)
    assert np.allclose(run.final_pose, ref.final_pose, atol=1e-9) and run.perturbation == pert


def test_closed_loop_from_a_moved_start(planar):
    from regrasp.control.loop import control

    scene, plan = planar
    pert = Perturbation(shift=(0.001, 0.0, -0.001), turn=0.02)
    run = execute(World(scene, engine="quasistatic"), plan, loop="closed", perturbation=pert)
    ref = control(scene, plan, "quasistatic", start_error=(0.001, -0.001, -0.02))
    assert np.allclose(run.final_pose, ref.final_pose) and run.success == ref.success and run.replans == ref.replans


def test_3d_replay_and_mujoco(spatial):
    from regrasp.mujoco.spatial import execute_plan3d

    scene, plan = spatial
    q = execute(World(scene, engine="quasistatic"), plan)
    assert np.allclose(q.final_pose, scene.replay(plan)["final_pose"]) and q.goal_error.shape == (4,)
    m = execute(World(scene), plan, perturbation=Perturbation(1.1, 1.0, 1.0, 1.0))
    ref = execute_plan3d(scene, plan, 1.1, feature_scale=1.0)
    assert np.allclose(m.final_pose, ref["final_pose"], atol=1e-9)
    assert m.success == scene.goal_error(m.final_pose)[1]


def test_free_gripper(planar):
    scene, plan = planar
    run = execute(World(scene, rig="free-gripper"), plan)
    assert run.max_creep is not None and run.duration > 0 and all(p["feature"] for p in run.pushes)
    assert run.success == scene.goal_error(run.final_pose)[1]
    assert run.trajectory.to_trajectory() is not None  # the world motion a controller can load


@pytest.mark.parametrize("world, kw, field", [
    (dict(rig="hand"), {}, "world.rig"),
    (dict(engine="bullet"), {}, "world.engine"),
    (dict(rig="arm", engine="quasistatic"), {}, "world.engine"),
    (dict(robot="ur5e"), {}, "world.robot"),
    (dict(options={"sped": 0.1}), {}, "world.options.sped"),
    ({}, dict(loop="half"), "loop"),
    ({}, dict(perturbation=(1.0, 1.0)), "perturbation"),
    ({}, dict(perturbation=Perturbation(turn=0.1)), "perturbation.shift"),
    (dict(rig="free-gripper"), dict(perturbation=Perturbation(grip=0.9)), "perturbation"),
    (dict(rig="free-gripper"), dict(loop="closed"), "loop"),
    (dict(noslip=False), {}, "world.noslip"),
    (dict(rig="arm", noslip=0), {}, "world.noslip"),
    (dict(rig="arm", noslip=False), dict(loop="closed"), "world.noslip"),
])
def test_what_a_rig_cannot_do_is_named(planar, world, kw, field):
    scene, plan = planar
    with pytest.raises(ArgumentError) as e:
        execute(World(scene, **world), plan, **kw)
    assert e.value.field == field


def test_the_arm_open_and_closed_loop(planar, arm_world):
    pytest.importorskip("mink")
    from regrasp.execution.arm import arm_motion, execute_arm
    from regrasp.execution.arm_loop import ArmLoopResult
    from regrasp.execution.execute import arm_motion_of

    scene, plan = planar
    pert = Perturbation(0.95, 1.05, 1.0, 1.0)
    world = arm_world
    run = execute(world, plan, perturbation=pert)
    am = arm_motion_of(world, plan)  # the robot is sent the nominal world's trajectory: the perturbation is unknown to it
    assert am is arm_motion_of(world, plan) and len(world._motions) == 1  # solved once
    assert np.array_equal(am.trajectory.q, arm_motion(scene, plan).trajectory.q)  # the arm's own motion
    ref = execute_arm(scene, plan, am.motion, scales=pert, trajectory=am.trajectory)
    assert np.allclose(run.detail.in_hand, ref.in_hand, atol=1e-9) and run.tracking is not None
    assert run.trajectory.robot == ref.trajectory.robot and run.max_creep == ref.max_creep
    assert run.success == scene.goal_error(run.final_pose)[1]
    c = execute(world, plan, loop="closed", perturbation=Perturbation(shift=(0.0005, 0.0, 0.0)))
    assert isinstance(c.detail, ArmLoopResult) and np.allclose(c.final_pose, c.detail.final)
    assert c.success == scene.goal_error(c.final_pose)[1] and c.loop == "closed"


def test_the_arm_without_no_slip(planar, arm_world):
    """``World(noslip=False)``: the arm's world without MuJoCo's no-slip post-processing (the
    model's option, nothing else changed); the run differs from the one with it."""
    pytest.importorskip("mink")
    from regrasp.execution.arm import build_robot
    from regrasp.execution.execute import arm_motion_of

    scene, plan = planar
    world = arm_world
    motion = arm_motion_of(world, plan).motion
    on, off = build_robot(scene, motion)[0], build_robot(scene, motion, noslip=False)[0]
    assert on.model.opt.noslip_iterations == 20 and off.model.opt.noslip_iterations == 0
    assert off.contact.noslip_iterations == 0 and off.model.nbody == on.model.nbody
    soft = execute(World(scene, rig="arm", noslip=False), plan)
    hard = execute(world, plan)
    assert not np.allclose(soft.detail.in_hand, hard.detail.in_hand, atol=1e-9)
    assert soft.success == scene.goal_error(soft.final_pose)[1] and soft.max_creep is not None
