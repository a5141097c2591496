"""Drake as a second engine (``regrasp.drake``; issue "Plans that survive the world", item 5): the
real engine, checked against the physics it must show (the pads' grip, a push inside the motion
cone sticking and one far outside slipping, as MuJoCo and the cones say), against MuJoCo (the
same pushes end within a fraction of a millimetre), through ``validate`` and ``simulate``."""

import json

import numpy as np
import pytest

import regrasp
from regrasp import ArgumentError
from regrasp.examples import path as example

from .conftest import run_cli

pytest.importorskip("pydrake")
pytest.importorskip("mujoco")


@pytest.fixture(scope="module")
def block():
    return regrasp.Scene.load(example("block-low-friction"))


def test_the_pads_press_with_the_grip_force_and_hold_the_object(block):
    from regrasp.drake.push import SETTINGS, DrakeRig

    assert SETTINGS["near_rigid_threshold"] == 0.0 and SETTINGS["contact_model"] == "hydroelastic_with_fallback"
    rig = DrakeRig(block, ("left",))
    rig.reset(np.zeros(3))
    rig.idle(0.3)
    pc = rig.plant_context
    cr = rig.plant.get_contact_results_output_port().Eval(pc)
    normals = sorted(abs(cr.hydroelastic_contact_info(i).F_Ac_W().translational()[1])
                     for i in range(cr.num_hydroelastic_contacts()))
    assert len(normals) == 2 and np.allclose(normals, block.grip_force, rtol=0.01)
    # gravity alone (the grasp holds at 0.3 of its limit there): the object stays put in the pads
    assert np.all(np.abs(rig.object_pose()[:2]) < 2e-5) and abs(rig.object_pose()[2]) < 1e-3


def test_a_push_ends_where_mujocos_does(block):
    """A sliding push and a turning one: Drake and MuJoCo (which share no contact model) put the
    object within 0.25 mm and 0.3° of each other after 3 mm (0.01 mm and 0.14 mm measured)."""
    from regrasp.drake.push import DrakePushRig
    from regrasp.mujoco.push import PushRig

    for pusher, tw in (("left", [0.01, 0.0, 0.0]), ("right", [-0.01, 0.002, -0.3])):
        d = DrakePushRig(block, pusher).push(np.zeros(3), tw, 0.3)["pose"][-1]
        m = PushRig(block, pusher).push(np.zeros(3), tw, 0.3)["pose"][-1]
        assert np.linalg.norm(d[:2] - m[:2]) < 2.5e-4 and abs(d[2] - m[2]) < np.radians(0.3), (pusher, d, m)
        assert np.linalg.norm(d[:2]) > 2.5e-3  # the push moved the object in the grasp


def test_the_slip_at_the_pusher_inside_and_far_outside_the_cone(block):
    """The motion cone's central ray sticks (slip well under 2 % of the push); a push along the
    contact slides (the object stays in the pads, the pusher slides past: slip near 100 %)."""
    from regrasp.drake.push import DrakePushRig

    cone = block.motion_cone(np.zeros(3), "left")
    inside = cone.ray(np.mean(cone.pusher_edges, axis=0))
    rig = DrakePushRig(block, "left")
    assert bool(cone.contains(inside)) and rig.slip_fraction(np.zeros(3), inside) < 0.015
    along = np.array([0.0, 0.01, 0.0])  # the left pusher's line is along z: a slide along it
    assert not bool(cone.contains(along)) and rig.slip_fraction(np.zeros(3), along) > 0.5


def test_validate_compares_the_engines_slips(block, tmp_path):
    code, out, err = run_cli("validate", example("block-low-friction"), "--pushes", "6", "--engines",
                             "mujoco,drake", "--workers", "1", "--json", "-q")
    assert code == 0, err
    r = json.loads(out)
    assert r["solved_drake"] == 6 and len(r["slip_drake"]) == 6 and len(r["slip_mujoco"]) == 6
    c = r["slip_comparison"]
    assert c["pushes"] == 6 and 0 <= c["verdict_agreement"] <= 1
    a, b = np.array(r["slip_mujoco"]), np.array(r["slip_drake"])
    assert c["median_abs_difference"] == pytest.approx(float(np.median(np.abs(a - b))), abs=1e-5)
    assert r["agreement_drake"] == pytest.approx(np.mean((b < 0.02) == np.array(
        [r_ for r_ in _predicted(block, 6)])), abs=1e-9)


def _predicted(scene, n):
    from regrasp.mujoco.validation import samples

    return [s[4] for s in samples(scene, n, 0)]


def test_simulate_with_drake_replays_the_plan(tmp_path):
    scene = example("block-low-friction")
    plan = tmp_path / "plan.json"
    assert run_cli("plan", scene, "--out", plan)[0] == 0
    code, out, err = run_cli("simulate", scene, "--plan", plan, "--engine", "drake", "--json")
    assert code == 0, err
    r = json.loads(out)
    assert r["engine"] == "drake" and r["success"] is True and r["max_pusher_slip"] < 1e-3
    # what Drake does not do is refused before any work, naming the flag
    for extra in (["--video", tmp_path / "v.gif"], ["--dt", "0.01"]):
        code, _, err = run_cli("simulate", scene, "--plan", plan, "--engine", "drake", *extra)
        assert code == 2 and "Traceback" not in err, err
    p3 = tmp_path / "p3.json"
    assert run_cli("plan", example("offset-3d"), "--out", p3)[0] == 0
    code, _, err = run_cli("simulate", example("offset-3d"), "--plan", p3, "--engine", "drake")
    assert code == 2 and "drake" in err.lower() and "Traceback" not in err, err


def test_execute_in_drake_is_the_replay(block):
    from regrasp.drake.replay import replay_plan
    from regrasp.execution import World, execute

    plan = regrasp.plan(block, seed=0)
    run = execute(World(block, engine="drake"), plan)
    ref = replay_plan(block, plan)
    assert np.allclose(run.final_pose, ref.final_pose, atol=1e-12) and run.success == ref.success
    with pytest.raises(ArgumentError) as e:
        execute(World(block, engine="drake"), plan, loop="closed")
    assert e.value.field == "world.engine"


def test_what_drake_cannot_take_is_refused_naming_it(block):
    from regrasp.drake.push import DrakeRig
    from regrasp.drake.replay import replay_plan

    with pytest.raises(ArgumentError) as e:
        DrakeRig(regrasp.load_scene(example("offset-3d")), ("left",))
    assert e.value.field == "scene"
    with pytest.raises(ArgumentError) as e:
        replay_plan(block, regrasp.plan(block, seed=0), perturb=(1.0, 1.0))
    assert e.value.field == "perturb"
