"""Execution in MuJoCo (the real engine): the grasp holds without creep under our contact
settings, pushes stick or slip as the motion cones say, plans execute, validation runs over
processes and over a local Ray instance."""

import json
import subprocess
import sys

import numpy as np
import pytest

import regrasp
from regrasp import Perturbation
from regrasp.mujoco.planar import execute_plan
from regrasp.mujoco.model import SOFT, convex_pieces
from regrasp.mujoco.world import creep
from regrasp.mujoco.push import PushRig
from regrasp.mujoco.validation import validate

from .conftest import EXAMPLES

mujoco = pytest.importorskip("mujoco")


def test_a_held_object_does_not_creep_with_our_settings():
    s = regrasp.Scene.load(EXAMPLES / "block-low-friction.toml")
    ours, soft = creep(s, duration=1.0), creep(s, duration=1.0, contact=SOFT)
    assert ours < 1e-5, ours  # rigid Coulomb friction holds it: a few micrometres at most
    assert soft > 1e-3, soft  # soft, pyramidal contact without no-slip lets it slide down


def test_non_convex_outline_is_a_union_of_convex_pieces():
    t = regrasp.Scene.load(EXAMPLES / "t-shape.toml")
    pieces = convex_pieces(t.outline)
    area = lambda p: 0.5 * abs(np.sum(p[:, 0] * np.roll(p[:, 1], -1) - np.roll(p[:, 0], -1) * p[:, 1]))  # noqa: E731
    assert len(pieces) >= 2 and sum(area(p) for p in pieces) == pytest.approx(area(t.outline))
    assert creep(t, duration=0.5) < 1e-5


def test_pushes_stick_inside_the_cone_and_slip_outside():
    s = regrasp.Scene.load(EXAMPLES / "block-low-friction.toml")
    rig = PushRig(s, "left")
    # along the normal: inside the motion cone; straight up with a side pusher: far outside
    assert s.motion_cone([0, 0, 0], "left").contains([0.01, 0, 0])
    assert rig.slip_fraction([0, 0, 0], [0.01, 0, 0]) < 0.02
    assert rig.slip_fraction([0, 0, 0], [0.0, 0.01, 0]) > 0.5


def test_plans_execute_in_mujoco_with_perturbed_physics():
    for name in ("block-low-friction", "t-shape"):
        s = regrasp.Scene.load(EXAMPLES / f"{name}.toml")
        p = regrasp.plan(s, seed=1).to_json()
        rng = np.random.default_rng(7)
        rep = execute_plan(s, p, Perturbation.draw(rng, 0.1, features="finger"))
        assert rep.success, (name, rep.goal_error)
        assert rep.poses.shape[1] == 3 and len(rep.t) == len(rep.poses)


def test_simulate_cli_mujoco(tmp_path):
    s = regrasp.Scene.load(EXAMPLES / "block-high-friction.toml")
    f = tmp_path / "plan.json"
    regrasp.plan(s, seed=0).save(f)
    gif = tmp_path / "run.gif"
    r = subprocess.run([sys.executable, "-m", "regrasp.cli", "simulate", str(EXAMPLES / "block-high-friction.toml"),
                        "--plan", str(f), "--engine", "mujoco", "--json", "--perturb", "0.1", "--seed", "2",
                        "--video", str(gif)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    out = json.loads(r.stdout)
    assert set(out) >= {"engine", "final_pose", "goal_error", "success", "max_pusher_slip"} and out["engine"] == "mujoco"
    assert gif.stat().st_size > 10_000
    # a plan that asks the side pusher to lift the block fails, exit 1
    bad = {"path": [{"pose": [0, 0, 0], "pusher": None}, {"pose": [0.0, 0.008, 0.0], "pusher": "left"}]}
    f.write_text(json.dumps(bad))
    r = subprocess.run([sys.executable, "-m", "regrasp.cli", "simulate", str(EXAMPLES / "block-high-friction.toml"),
                        "--plan", str(f), "--engine", "mujoco", "--json"], capture_output=True, text=True)
    assert r.returncode == 1 and not json.loads(r.stdout)["success"]


def test_validation_over_processes_and_ray():
    s = regrasp.Scene.load(EXAMPLES / "block-high-friction.toml")
    a = validate(s, 30, seed=3, engines=("quasistatic", "mujoco"), workers=2)
    assert a["solved_mujoco"] == 30 and {"agreement_mujoco", "confusion_mujoco", "agreement_quasistatic"} <= set(a)
    assert a["agreement_mujoco"] >= 0.7
    pytest.importorskip("ray")
    b = validate(s, 30, seed=3, engines=("mujoco",), workers=2, ray_address="local")
    # the same pushes, the same outcomes, wherever they run
    assert b["confusion_mujoco"] == a["confusion_mujoco"]


def test_point_pusher_sticks_while_the_object_turns_about_it():
    # a point pusher (the corner of a fixture) turns the block about the pad: its contact does
    # not slide on the object although the pusher–object relative pose changes a lot
    s = regrasp.Scene.load(EXAMPLES / "block-xztheta.toml")
    rig = PushRig(s, "corner")
    cone = s.motion_cone([0, 0, 0], "corner")
    r = s.pusher("corner").points[0]
    a, b = (g[:2] + g[2] * np.array([-r[1], r[0]]) for g in cone.generators[:2])
    u = a / np.linalg.norm(a) + b / np.linalg.norm(b)  # the middle of the contact-velocity wedge
    u = np.r_[0.01 * u / np.linalg.norm(u), 0.0]
    assert cone.contains(cone.point_pusher_twist(u[:2]))
    assert rig.slip_fraction([0, 0, 0], u) < 0.05
    # pulled along the face, it slides
    assert rig.slip_fraction([0, 0, 0], [0.01, 0.0, 0.0]) > 0.2


def test_models_carry_the_contact_settings_and_physics():
    # the MjSpec builders: elliptic cones, impratio, no-slip, the geoms' solref/solimp, collision
    # bits (pads and features touch only the object), masses, the pads' limit-surface friction
    from regrasp.mujoco import planar, spatial
    from regrasp.mujoco.model import Contact

    s = regrasp.Scene.load(EXAMPLES / "block-low-friction.toml")
    plan = {"path": [{"pose": [0, 0, 0], "pusher": None}, {"pose": [0.002, 0, 0], "pusher": "left"}]}
    m = planar.build(s, plan, Perturbation(finger_friction=1.1, mass=0.9, feature_friction=1.1)).compile()
    c = Contact()
    assert m.opt.cone == mujoco.mjtCone.mjCONE_ELLIPTIC and m.opt.impratio == c.impratio
    assert m.opt.noslip_iterations == c.noslip_iterations and m.opt.timestep == c.timestep
    g = {m.geom(i).name or f"{m.body(m.geom_bodyid[i]).name}{i}": i for i in range(m.ngeom)}
    obj = g["object"]
    assert np.allclose(m.geom_solref[obj], c.solref) and np.allclose(m.geom_solimp[obj][:3], c.solimp)
    assert (m.geom_contype[obj], m.geom_conaffinity[obj]) == (1, 3) and m.geom_condim[obj] == 4
    assert m.body("object").mass[0] == pytest.approx(0.9 * s.mass)
    assert m.body("gripper").mass[0] == 1000.0 and m.nmocap == 1  # one parked feature: the plan's pusher
    pads = [i for i in range(m.ngeom) if m.geom_contype[i] == 2]
    mu = s._core.friction_scale / (2 * s.grip_force) * 1.1
    assert len(pads) == 2 and all(np.allclose(m.geom_friction[i][:2], [mu, s._core.pad_limit_surface_k * mu])
                                  for i in pads)
    feat = [i for i in range(m.ngeom) if m.geom_contype[i] == 4]
    assert len(feat) == 1 and m.geom_conaffinity[feat[0]] == 1
    assert list(m.actuator_gear[:, 0]) == [-1.0, 1.0] and m.nu == 2
    s3 = regrasp.Scene3D.load(EXAMPLES / "pivot-3d.toml")
    for world in (True, False):
        m3 = spatial.build(s3, [0, 0, 0, 1, 0, 0, 0], world=world).compile()
        assert m3.opt.cone == mujoco.mjtCone.mjCONE_ELLIPTIC and m3.nu == 2
        assert m3.nmocap == (len(s3.pusher_names) if world else 0)
        assert m3.body("object").mass[0] == pytest.approx(s3.mass)


def test_execution_takes_a_plan_or_its_dict():
    s = regrasp.Scene.load(EXAMPLES / "block-high-friction.toml")
    p = regrasp.plan(s, seed=0)
    a, b = execute_plan(s, p), execute_plan(s, p.to_json())
    assert np.array_equal(a.final_pose, b.final_pose) and a.success
    from regrasp.mujoco.spatial import execute_plan3d

    s3 = regrasp.Scene3D.load(EXAMPLES / "offset-3d.toml")
    d = s3.plan(seed=0)
    d = d.to_json() if hasattr(d, "to_json") else d

    class PlanLike:  # what a regrasp.Plan offers: the plan file's dict
        def to_json(self):
            return d

    r, r_dict = execute_plan3d(s3, PlanLike(), view="planner"), execute_plan3d(s3, d, view="planner")
    assert r["success"] and r["final_pose"] == r_dict["final_pose"]
