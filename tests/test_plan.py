"""The regrasp planner on the bundled examples, its baselines, the CLI and bad requests."""

import json
import subprocess
import sys

import numpy as np
import pytest

import regrasp
from regrasp.sim.quasistatic import replay_plan

from .conftest import EXAMPLES, ROOT

PLANNED = ["block-low-friction", "block-high-friction", "block-xztheta", "t-shape", "block-tilted-gripper"]


@pytest.mark.parametrize("name", PLANNED)
def test_every_example_plans_for_20_seeds(name):
    sc = regrasp.Scene.load(EXAMPLES / f"{name}.toml")
    t = sc.task
    switches, plain_switches = [], []
    for seed in range(20):
        p = regrasp.plan(sc, seed=seed, time_limit=5.0)
        assert p.found, (seed, p.stop_reason)
        assert p.valid, (seed, min(p.step_margins))
        end = p.poses[-1]
        assert np.all(np.abs(end - t.goal) <= t.tolerance), (seed, end)
        assert np.allclose(p.poses[0], t.start)
        switches.append(p.switch_overs)
        plain_switches.append(regrasp.plan(sc, seed=seed, time_limit=5.0, plain=True).switch_overs)
    assert np.mean(switches) < np.mean(plain_switches), (switches, plain_switches)


def test_high_friction_pushers_give_one_direct_side_push():
    sc = regrasp.Scene.load(EXAMPLES / "block-high-friction.toml")
    p = regrasp.plan(sc, seed=0)
    assert p.switch_overs == 0 and set(p.pushers[1:]) == {"left"}
    # with the low-friction pushers the same diagonal needs more than one pusher
    lo = regrasp.plan(regrasp.Scene.load(EXAMPLES / "block-low-friction.toml"), seed=0)
    assert len(set(lo.pushers[1:])) >= 2


@pytest.mark.parametrize("propagation", ["stable_check", "mncp"])
def test_baselines_plan_too(propagation):
    sc = regrasp.Scene.load(EXAMPLES / "block-low-friction.toml")
    p = regrasp.plan(sc, seed=1, propagation=propagation, time_limit=20.0)
    assert p.found and p.propagation == propagation


def test_plans_replay_in_the_quasistatic_simulator():
    sc = regrasp.Scene.load(EXAMPLES / "t-shape.toml")
    p = regrasp.plan(sc, seed=2)
    rep = replay_plan(sc, p.to_json())
    assert rep.success, rep.goal_error


def test_plan_cli_writes_the_contract_file(tmp_path):
    out, png, gif = tmp_path / "p.json", tmp_path / "p.png", tmp_path / "p.gif"
    r = subprocess.run([sys.executable, "-m", "regrasp.cli", "plan", str(EXAMPLES / "block-xztheta.toml"), "--out",
                        str(out), "--seed", "4", "--plot", str(png), "--animate", str(gif)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    d = json.loads(out.read_text())
    for k in ("scene", "found", "stop_reason", "planning_time_s", "nodes", "switch_overs", "path"):
        assert k in d
    assert d["found"] and d["stop_reason"] == "goal_reached" and d["path"][0]["pusher"] is None
    assert all(isinstance(k["pusher"], str) for k in d["path"][1:])
    assert png.stat().st_size > 20_000 and gif.stat().st_size > 20_000
    # the plan file replays with `regrasp simulate`
    r = subprocess.run([sys.executable, "-m", "regrasp.cli", "simulate", str(EXAMPLES / "block-xztheta.toml"), "--plan",
                        str(out), "--json"], capture_output=True, text=True)
    assert r.returncode == 0 and json.loads(r.stdout)["success"], r.stdout + r.stderr


def test_a_search_out_of_time_exits_1_with_the_best_partial_plan(tmp_path):
    out = tmp_path / "p.json"
    r = subprocess.run([sys.executable, "-m", "regrasp.cli", "plan", str(ROOT / "benches" / "scenes" / "u-shape.toml"),
                        "--time-limit", "0.002", "--out", str(out)], capture_output=True, text=True)
    assert r.returncode == 1 and "no plan found" in r.stderr
    d = json.loads(out.read_text())
    assert d["found"] is False and d["stop_reason"] == "time_limit" and len(d["path"]) >= 1


def test_a_goal_no_push_can_move_towards_exits_1_unreachable(tmp_path):
    # only the top pusher, which pushes the block down in the grasp (gravity too): the task's
    # goal is up and right
    text = (EXAMPLES / "block-low-friction.toml").read_text()
    parts = text.split("[[pushers]]")
    top = [p for p in parts[1:] if 'name = "top"' in p][0]
    f = tmp_path / "top-only.toml"
    f.write_text(parts[0] + "[[pushers]]" + top)
    out = tmp_path / "p.json"
    r = subprocess.run([sys.executable, "-m", "regrasp.cli", "plan", str(f), "--out", str(out)],
                       capture_output=True, text=True)
    assert r.returncode == 1 and "no plan found: unreachable: no push can move the pad's centre" in r.stderr, r.stderr
    d = json.loads(out.read_text())
    assert d["found"] is False and d["stop_reason"] == "unreachable" and len(d["path"]) == 1
    assert d["planning_time_s"] < 1.0


def test_bad_requests():
    sc = regrasp.Scene.load(EXAMPLES / "block-low-friction.toml")
    with pytest.raises(regrasp.ArgumentError) as e:
        regrasp.plan(sc, start=[0.03, 0.0, 0.0])
    assert e.value.field == "start"
    with pytest.raises(regrasp.ArgumentError):
        regrasp.plan(sc, goal=[np.nan, 0.0, 0.0])
    with pytest.raises(regrasp.ArgumentError):
        regrasp.plan(sc, propagation="teleport")
    p = regrasp.plan(sc, time_limit=0.0, connect=False)
    assert not p.found and p.stop_reason == "time_limit" and len(p.path) == 1


def test_point_pushers_only_plans_replay_in_the_simulator():
    """Issue 18, item 1: a scene whose pushers are all points is planned (steps in contact-point
    velocity, each the object's flow under the pusher's motion); every plan passes the exact test
    along its flows, and the quasi-static simulator (an independent solver, same ellipsoidal pad
    model: the scene on the ellipsoid) driving the pushers as planned ends within the task's tolerance."""
    sc = regrasp.Scene.load(ROOT / "benches" / "scenes" / "point-pushers.toml").with_limit_surface("ellipsoid")
    t = sc.task
    for seed in range(3):
        p = regrasp.plan(sc, seed=seed, time_limit=10.0)
        assert p.found and p.valid, (seed, p.stop_reason)
        assert np.all(np.abs(p.poses[-1] - t.goal) <= t.tolerance)
        r = replay_plan(sc, p, support="limit_surface")
        assert r.success, (seed, r.goal_error)
        assert r.max_pusher_slip < 1e-9


def test_point_pushers_plans_on_the_true_surface_replay_on_fine_point_set_pads():
    """The same on the exact limit surface (the default), replayed with pads of 8 rings of points
    (216 a pad, whose limit surface is close to the exact one): the simulator ends within the
    task's tolerance."""
    sc = regrasp.Scene.load(ROOT / "benches" / "scenes" / "point-pushers.toml")
    assert sc.limit_surface == "true"
    t = sc.task
    for seed in range(3):
        p = regrasp.plan(sc, seed=seed, time_limit=10.0)
        assert p.found and p.valid, (seed, p.stop_reason)
        assert np.all(np.abs(p.poses[-1] - t.goal) <= t.tolerance)
        r = replay_plan(sc, p, support="points", rings=8)
        assert r.success, (seed, r.goal_error)


def test_a_point_pushers_step_that_does_not_land_is_invalid():
    """A point pusher imposes only its contact point's velocity: a step whose rotation is not the
    one its mechanics give (here, the pure translation of a planned step kept, its rotation
    doubled) lands elsewhere and fails the check with a negative margin."""
    sc = regrasp.Scene.load(ROOT / "benches" / "scenes" / "point-pushers.toml")
    p = regrasp.plan(sc, seed=0, time_limit=10.0)
    assert p.found and p.valid
    d = p.to_json()
    k = next(i for i in range(1, len(p.poses)) if abs(p.poses[i][2] - p.poses[i - 1][2]) > 1e-3)
    a, b = p.poses[k - 1], np.array(p.poses[k], float)
    b[2] = a[2] + 2.0 * (b[2] - a[2])
    d["path"][k]["pose"] = b.tolist()
    d.pop("step_margins", None)
    bad = regrasp.Plan.from_json(d, sc)
    bad.check(sc)
    assert not bad.valid and bad.step_margins[k - 1] < 0
    assert all(m >= 0 for i, m in enumerate(bad.step_margins) if i not in (k - 1, k))


def test_the_cost_per_node_is_timed_against_ompls_rrtstar_grown_to_the_same_size():
    """`regrasp bench`'s planner-per-node row: OMPL's RRT* (the real library) grows the tree size
    asked, and the row's ratio is OMPL's time per node over ours."""
    pytest.importorskip("ompl")
    from regrasp.bench.planners import ompl_rrtstar_cpu, run_node_cost

    for n in (2, 40, 300):
        seconds, grown = ompl_rrtstar_cpu(n)
        assert grown == n and seconds > 0
    r = run_node_cost(seeds=2, examples=("t-shape",))["plan_node_t-shape"]
    assert r["median_s"] > 0 and r["baseline_median_s"] > 0 and r["median_nodes"] >= 2
    assert r["ratio"] == pytest.approx(r["baseline_median_s"] / r["median_s"])
