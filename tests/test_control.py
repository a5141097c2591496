"""Robust motion cones, fixtureless fixturing and the MPC (thesis ch. 5)."""

import json
import subprocess
import sys

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

import regrasp
from regrasp import _core
from regrasp.control.loop import Poke, control
from regrasp.errors import ArgumentError, SceneError
from regrasp.planning.plan import validate as plan_validate

from .conftest import EXAMPLES

SPREAD = {"pusher_friction": 0.2, "finger_friction": 0.2, "grip_force": 0.2, "mass": 0.2}


def load(name):
    return regrasp.Scene.load(EXAMPLES / f"{name}.toml")


@settings(max_examples=60, deadline=None)
@given(name=st.sampled_from(["block-high-friction", "block-xztheta", "t-shape", "block-tilted-gripper"]),
       k=st.integers(0, 10), scales=st.lists(st.floats(0.8, 1.2), min_size=4, max_size=4),
       x=st.floats(-0.004, 0.004), z=st.floats(-0.004, 0.004), th=st.floats(-0.2, 0.2))
def test_robust_generators_stick_for_every_value_in_the_range(name, k, scales, x, z, th):
    s = load(name)
    r = s.robust(SPREAD)
    q = [x, z, th]
    if not s.admissible(q) or r.hold_ratio(q) >= 0.95:
        return
    pusher = s.pusher_names[k % len(s.pusher_names)]
    g = r.motion_cone(q, pusher).generators
    world = s.scaled(*scales)
    for v in g:
        assert world.motion_cone(q, pusher).margin(v) >= -1e-7


def test_invariant_case_and_fixtureless_pushes():
    s = load("block-low-friction")
    assert s.carries_weight([0, 0, 0], "bottom") and not s.carries_weight([0, 0, 0], "left")
    fx = regrasp.Scene.load(EXAMPLES / "block-fixtureless.toml")
    p = regrasp.plan(fx.fixtureless(), seed=0)
    assert p.found and p.valid and set(p.pushers[1:]) == {"table"}
    # every step sticks whatever the grip force, finger friction and mass
    for f, n, m in [(0.5, 0.5, 2.0), (2.0, 4.0, 0.3), (1.0, 0.5, 1.0)]:
        world = fx.scaled(f, n, m)
        assert min(plan_validate(world, p.path)) >= -1e-9, (f, n, m)
    # a side pusher has no fixtureless push
    assert len(s.fixtureless().motion_cone([0, 0, 0], "left").generators) == 0
    assert len(s.fixtureless().motion_cone([0, 0, 0], "bottom").generators) == 4


def test_uncertainty_table_and_errors():
    fx = regrasp.Scene.load(EXAMPLES / "block-fixtureless.toml")
    assert fx.uncertainty == pytest.approx(SPREAD)
    assert fx.robust().mode == "robust" and fx.fixtureless().mode == "fixtureless"
    assert fx.robust().rho == pytest.approx(fx.rho * 0.8 * 0.8 / 1.2)
    text = (EXAMPLES / "block-fixtureless.toml").read_text().replace("mass = 0.2", "mass = 1.5")
    with pytest.raises(SceneError) as e:
        regrasp.Scene.from_toml(text)
    assert e.value.field == "uncertainty.mass"
    with pytest.raises(ArgumentError) as e:
        load("block-low-friction").robust()
    assert e.value.field == "uncertainty"
    with pytest.raises(ArgumentError):
        load("block-low-friction").robust({"mass": -0.1})


def test_robust_plan_sticks_in_sampled_worlds():
    s = load("block-high-friction")
    r = s.robust(SPREAD)
    p = regrasp.plan(r, seed=0)
    assert p.found and p.valid
    rng = np.random.default_rng(0)
    for _ in range(10):
        world = s.scaled(*rng.uniform(0.8, 1.2, 4))
        assert min(plan_validate(world, p.path)) >= -1e-9


def test_mpc_qp_solution_satisfies_its_cone_constraints():
    s = load("t-shape")
    p = regrasp.plan(s, seed=0)
    m = _core.Mpc(s._core, [k["pose"] for k in p.path], p.pushers, speed=0.01)
    q = np.array(p.path[0]["pose"]) + [0.001, -0.001, 0.02]
    steps, ok = m.solve_qp(q.tolist(), 0)
    assert ok and steps
    for st_ in steps:
        w = np.asarray(st_["weights"])
        assert np.all(w >= 0)
        v = w @ st_["generators"]
        assert np.linalg.norm(s.metric_twist(v)) <= 0.01 * (1 + 1e-5)
    c = m.step(q.tolist())
    assert c["status"] == "tracking"
    assert s.motion_cone(q, c["pusher"]).margin(c["twist"]) >= 0.01 - 1e-9
    assert c["solve_time_s"] < 0.05


def test_mpc_rejects_a_poke_where_open_loop_fails():
    s = load("block-low-friction")
    p = regrasp.plan(s, seed=0)
    poke = [Poke(0.8, np.array([0.0025, -0.0025, 0.0]))]
    ol = control(s, p, policy="open_loop", pokes=poke)
    mpc = control(s, p, pokes=poke)
    assert not ol.success and mpc.success, (ol.goal_error, mpc.goal_error, mpc.failure)
    assert mpc.mpc_step_median_s < 0.01
    # a wrong start estimate, too
    assert control(s, p, start_error=[0.003, 0.0, np.radians(3)]).success


def test_control_cli_mujoco(tmp_path):
    f = tmp_path / "plan.json"
    s = load("block-high-friction")
    regrasp.plan(s, seed=0).save(f)
    png = tmp_path / "ctl.png"
    r = subprocess.run([sys.executable, "-m", "regrasp.cli", "control", str(EXAMPLES / "block-high-friction.toml"),
                        "--plan", str(f), "--engine", "mujoco", "--poke", "0.3,0.002,0,0", "--start-error", "0.002,0,0.03",
                        "--scale-friction", "0.9", "--json", "--plot", str(png)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr + r.stdout
    out = json.loads(r.stdout)
    assert set(out) >= {"engine", "success", "final_pose", "goal_error", "replans", "mpc_step_median_s"}
    assert out["engine"] == "mujoco" and out["success"] and png.stat().st_size > 10_000
    r = subprocess.run([sys.executable, "-m", "regrasp.cli", "control", str(EXAMPLES / "block-high-friction.toml"),
                        "--plan", str(f), "--poke", "oops"], capture_output=True, text=True)
    assert r.returncode == 2 and "--poke" in r.stderr


def test_plan_cli_robust_and_fixtureless(tmp_path):
    scene = str(EXAMPLES / "block-fixtureless.toml")
    for flag in ("--robust", "--fixtureless"):
        r = subprocess.run([sys.executable, "-m", "regrasp.cli", "plan", scene, flag, "--json"], capture_output=True, text=True)
        assert r.returncode == 0, r.stderr
        assert json.loads(r.stdout)["found"]
    r = subprocess.run([sys.executable, "-m", "regrasp.cli", "plan", str(EXAMPLES / "block-low-friction.toml"), "--robust"],
                       capture_output=True, text=True)
    assert r.returncode == 2 and "uncertainty" in r.stderr


def test_control_arguments_are_checked(tmp_path):
    f = tmp_path / "plan.json"
    s = load("block-high-friction")
    p = regrasp.plan(s, seed=0)
    p.save(f)
    cli = [sys.executable, "-m", "regrasp.cli"]
    for extra, field in ((["--horizon", "0"], "--horizon"), (["--dt", "-1"], "--dt"), (["--scale-mass", "0"], "scale-mass"),
                         (["--seed", "-1"], "--seed")):
        r = subprocess.run(cli + ["control", str(EXAMPLES / "block-high-friction.toml"), "--plan", str(f)] + extra,
                           capture_output=True, text=True)
        assert r.returncode == 2 and field in r.stderr, (extra, r.stderr)
    # planar-only commands name the problem for a 3-D scene; a planar plan for a 3-D scene too
    for cmd in (["cone", str(EXAMPLES / "pivot-3d.toml"), "--pose", "0,0,0", "--pusher", "ground"],
                ["validate", str(EXAMPLES / "pivot-3d.toml")]):
        r = subprocess.run(cli + cmd, capture_output=True, text=True)
        assert r.returncode == 2 and "3-D scene" in r.stderr, (cmd, r.stderr)
    r = subprocess.run(cli + ["control", str(EXAMPLES / "pivot-3d.toml"), "--plan", str(f)], capture_output=True, text=True)
    assert r.returncode == 2 and "plan.path[0].pose" in r.stderr, r.stderr
    # a poke after the time limit is an error, not silently dropped; a late poke extends the default
    with pytest.raises(ArgumentError, match="pokes"):
        control(s, p, pokes=[Poke(50.0, np.zeros(3))], max_time=10.0)
    r = control(s, p, pokes=[Poke(30.0, np.array([0.002, 0.0, 0.0]))])
    assert r.t[-1] >= 30.0 and r.success
    with pytest.raises(ArgumentError, match="horizon"):
        control(s, p, horizon=-1)
    for bad in (-1, 2.5, True):
        with pytest.raises(ArgumentError, match="seed"):
            regrasp.plan(s, seed=bad)
    with pytest.raises(ArgumentError, match="seed"):
        regrasp.Scene3D.load(EXAMPLES / "ball-roll-3d.toml").plan(seed=-1)


def test_simulate_cli_3d_rejects_planar_flags(tmp_path):
    f = tmp_path / "plan.json"
    s3 = regrasp.Scene3D.load(EXAMPLES / "offset-3d.toml")
    p3 = s3.plan(seed=0)  # a regrasp.Plan (or, before it, the plan dict)
    f.write_text(json.dumps(p3.to_json() if hasattr(p3, "to_json") else p3))
    cli = [sys.executable, "-m", "regrasp.cli", "simulate", str(EXAMPLES / "offset-3d.toml"), "--plan", str(f)]
    r = subprocess.run(cli + ["--video", str(tmp_path / "v.gif")], capture_output=True, text=True)
    assert r.returncode == 2 and "planar only" in r.stderr
    r = subprocess.run(cli + ["--scale-grip", "-1", "--engine", "mujoco"], capture_output=True, text=True)
    assert r.returncode == 2 and "scale-grip" in r.stderr
    r = subprocess.run(cli + ["--dt", "0.05", "--json"], capture_output=True, text=True)
    assert r.returncode == 0 and json.loads(r.stdout)["success"], r.stderr


@pytest.mark.parametrize("horizon", [5, 20, 40])
def test_mpc_qp_optimum_matches_the_condensed_qp_solved_by_scipy(horizon):
    """The MPC's sparse QP (poses kept as variables, step_qp.rs) reaches the optimum of the same
    QP written independently in condensed form (regrasp.bench.solvers.mpc_qp_condensed) and
    solved by SLSQP: its cost no higher, its constraints met."""
    pytest.importorskip("scipy")
    from regrasp.bench.solvers import _mpc_qp_scipy, mpc_qp_condensed
    from regrasp.scene.settings import mpc_defaults

    s = load("t-shape")
    p = regrasp.plan(s, seed=0)
    settings = {**mpc_defaults(), "horizon": horizon}
    m = s.mpc(p.poses.tolist(), p.pushers, horizon=horizon)
    q = (p.poses[0] + [0.0005, -0.0005, 0.01]).tolist()
    steps, ok = m.solve_qp(q, 0)
    knots = np.asarray(m.knots)
    targets = [knots[min(1 + i, len(knots) - 1)] for i in range(len(steps))]
    P, c, T, offs, sizes = mpc_qp_condensed(s, q, steps, targets, settings)
    ours = np.concatenate([st_["weights"] for st_ in steps]) / settings["speed"]
    ref = _mpc_qp_scipy(s, q, steps, targets, settings) / settings["speed"]
    cost = lambda a: 0.5 * a @ P @ a + c @ a  # noqa: E731
    assert ok and np.all(ours >= 0)
    for i in range(len(sizes)):
        assert np.linalg.norm(ours[offs[i]:offs[i] + sizes[i]] @ T[i]) <= 1 + 1e-6
    assert cost(ours) <= cost(ref) + 1e-6 * max(1.0, abs(cost(ref))), (cost(ours), cost(ref))
