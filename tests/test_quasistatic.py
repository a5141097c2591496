"""The quasi-static complementarity simulator: residuals of every solve, agreement with the
IPOPT reference, known cases, plan replay, validation output, and MuJoCo on a small case."""

import json
import subprocess
import sys

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

import regrasp
from regrasp.reference import mncp as mncp_reference
from regrasp.sim import quasistatic

from .conftest import EXAMPLES, block_scenes

# derandomized: the same examples on every run, so that CI is reproducible (a failure found by
# a random run becomes a regression test below)
SETTINGS = settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow], derandomize=True)


def load(d):
    try:
        return regrasp.Scene.from_dict(d)
    except regrasp.SceneError as e:
        assume(e.field != "grasp.force")
        raise


@SETTINGS
@given(block_scenes(), st.floats(-np.pi, np.pi), st.floats(-1.5, 1.5), st.sampled_from(["points", "limit_surface"]))
def test_every_forward_solve_meets_every_constraint(d, a, b, support):
    sc = load(d)
    q = d["task"]["start"]
    u = sc.metric_twist_inv(np.array([np.cos(a) * np.cos(b), np.sin(a) * np.cos(b), np.sin(b)])) * 0.01
    p = quasistatic.problem(sc, q, "p", support=support, rings=2)
    sol = p.solve_forward(list(u))
    assert sol["max_residual"] < 1e-6, sol["residuals"]
    # the residuals recomputed from the returned forces agree
    r = p.residuals(list(sol["twist"]), list(sol["pusher_twist"]), list(sol["normal_forces"]),
                    [list(f) for f in sol["friction_forces"]])
    assert max(r.values()) < 1e-6


def _edge_scene(com, pad_radius, points, normal, start):
    return {"name": "prop",
            "object": {"outline": [[-0.03125, -0.0234375], [0.03125, -0.0234375], [0.03125, 0.0234375], [-0.03125, 0.0234375]],
                       "mass": 0.5, "com": com},
            "grasp": {"force": 5.0, "friction": 1.0, "pad_radius": pad_radius},
            "gravity": {"direction": [0.0, -1.0], "g": 0.0},
            "pushers": [{"name": "p", "friction": 1.0, "points": points, "normal": normal}],
            "task": {"start": start, "goal": start, "tolerance": [0.001, 0.001, 0.01]}}


# Found by hypothesis: the limit-surface pad model with no gravity and pusher friction 1, where
# Newton from every start stalled (residual 2e-4 to 3e-4) until the forward solve continued in the
# pusher's friction from a frictionless pusher (dynamics/mncp/forward.rs).
NON_CONVERGENCE_CASES = [
    (_edge_scene([0.001953125, 0.0029296875], 0.00390625, [[-0.03125, 0.01875], [-0.03125, -0.01875]], [1.0, 0.0],
                 [0.005126953125, 0.0048828125, 0.0]), 1.625, -1.125),
    (_edge_scene([0.0, 0.0], 0.0078125, [[0.025, 0.0234375], [-0.025, 0.0234375]], [0.0, -1.0], [0.0, 0.0, 0.0]),
     0.0, -0.015625),
]


@pytest.mark.parametrize("k", range(len(NON_CONVERGENCE_CASES)))
def test_once_non_converging_pushes_without_gravity_meet_every_constraint(k):
    """Each solve's residuals, recomputed from its forces, and IPOPT's solution where IPOPT
    converges (in the first case it stops at 'infeasible problem detected', residual 1e-3)."""
    d, a, b = NON_CONVERGENCE_CASES[k]
    sc = regrasp.Scene.from_dict(d)
    u = sc.metric_twist_inv(np.array([np.cos(a) * np.cos(b), np.sin(a) * np.cos(b), np.sin(b)])) * 0.01
    for support in ("limit_surface", "points"):
        p = quasistatic.problem(sc, d["task"]["start"], "p", support=support, rings=2)
        sol = p.solve_forward(list(u))
        assert sol["max_residual"] < 1e-6
        r = p.residuals(list(sol["twist"]), list(sol["pusher_twist"]), list(sol["normal_forces"]),
                        [list(f) for f in sol["friction_forces"]])
        assert max(r.values()) < 1e-6
        if k == 1:
            ref = mncp_reference.solve(p, pusher_twist=u)
            assert np.allclose(sol["twist"], ref.twist, atol=1e-7), (support, sol["twist"], ref.twist)


SLIDE_ALONG_THE_FACE = {
    "name": "prop",
    "object": {"outline": [[-0.0234375, -0.03125], [0.0234375, -0.03125], [0.0234375, 0.03125], [-0.0234375, 0.03125]],
               "mass": 0.5, "com": [0.0, 0.0]},
    "grasp": {"force": 5.0, "friction": 1.0, "pad_radius": 0.0078125},
    "gravity": {"direction": [0.0, -1.0], "g": 0.0},
    "pushers": [{"name": "p", "friction": 0.5, "points": [[-0.01875, -0.03125], [0.01875, -0.03125]], "normal": [0.0, 1.0]}],
    "task": {"start": [0.0, 0.0, 0.0], "goal": [0.0, 0.0, 0.0], "tolerance": [0.001, 0.001, 0.01]}}


@pytest.mark.parametrize("b", [1e-4, -1e-4, 1e-5, 1e-6])
def test_sliding_along_the_face_with_a_tiny_rotation_is_linear_in_it(b):
    """The pusher slides along the face it touches and turns by b of its speed, no gravity: one
    end presses, the object turns in the grasp with a twist proportional to b (found by
    hypothesis; Newton reached it only by continuation in the twist). Checked against the
    solution at b = 1e-3 scaled by b / 1e-3 and by the recomputed residuals."""
    sc = regrasp.Scene.from_dict(SLIDE_ALONG_THE_FACE)
    p = quasistatic.problem(sc, [0.0, 0.0, 0.0], "p", support="limit_surface", rings=1)

    def push(b):
        return sc.metric_twist_inv(np.array([np.cos(b), 0.0, np.sin(b)])) * 0.01

    ref = p.solve_forward(list(push(np.copysign(1e-3, b))))
    sol = p.solve_forward(list(push(b)))
    r = p.residuals(list(sol["twist"]), list(sol["pusher_twist"]), list(sol["normal_forces"]),
                    [list(f) for f in sol["friction_forces"]])
    assert max(r.values()) < 1e-6
    assert np.allclose(sol["twist"], ref["twist"] * abs(b) / 1e-3, rtol=1e-2, atol=1e-12)
    assert np.allclose(sol["normal_forces"], ref["normal_forces"], rtol=1e-3, atol=1e-6)


@pytest.mark.xfail(strict=True, reason="known: a slide along the face turning by 1e-4 of its speed, the pusher "
                                       "withdrawing by 4e-6 of it: every continuation ends 1e-3 from the constraints "
                                       "(accepted: 1e-6); found by a 3,000-example hypothesis sweep")
def test_known_non_convergence_sliding_along_the_face_while_withdrawing():
    d = {"name": "prop",
         "object": {"outline": [[-0.022221579425945354, -0.045454146519454966], [0.022221579425945354, -0.045454146519454966],
                                [0.022221579425945354, 0.045454146519454966], [-0.022221579425945354, 0.045454146519454966]],
                    "mass": 0.2766330394064216, "com": [0.0011110789712972678, 0.004540097808289834]},
         "grasp": {"force": 30.176547364670537, "friction": 0.3, "pad_radius": 0.003},
         "gravity": {"direction": [0.53322292676205, -0.8459747693491299], "g": 0.0},
         "pushers": [{"name": "p", "friction": 0.3217840584255856,
                      "points": [[-0.017777263540756285, -0.045454146519454966], [0.017777263540756285, -0.045454146519454966]],
                      "normal": [0.0, 1.0]}],
         "task": {"start": [-0.0009610789712972677, 0.010121803936429937, 0.0],
                  "goal": [-0.0009610789712972677, 0.010121803936429937, 0.0], "tolerance": [0.001, 0.001, 0.01]}}
    sc = regrasp.Scene.from_dict(d)
    u = sc.metric_twist_inv(np.array([np.cos(1e-4), 0.0, np.sin(1e-4)])) * 0.01
    p = quasistatic.problem(sc, d["task"]["start"], "p", support="limit_surface", rings=1)
    sol = p.solve_forward(list(u))
    assert sol["max_residual"] < 1e-6


@pytest.mark.xfail(strict=True, reason="known: the limit-surface pad just past its limit (the load 0.2 % over it) "
                                       "with the pusher leaving: Newton stalls near rest (residual 2e-5); found by hypothesis")
def test_known_non_convergence_just_past_the_pads_limit():
    d = {"name": "prop",
         "object": {"outline": [[-0.048828125, -0.03125], [0.048828125, -0.03125], [0.048828125, 0.03125], [-0.048828125, 0.03125]],
                    "mass": 0.15625, "com": [-0.01068115234375, 0.0]},
         "grasp": {"force": 10.5, "friction": 0.875, "pad_radius": 0.0032933714635022026},
         "gravity": {"direction": [0.0, -1.0], "g": 10.0},
         "pushers": [{"name": "p", "friction": 1.0, "points": [[0.048828125, -0.025], [0.048828125, 0.025]], "normal": [-1.0, 0.0]}],
         "task": {"start": [-0.012806649432140004, 0.0, 0.0], "goal": [-0.012806649432140004, 0.0, 0.0],
                  "tolerance": [0.001, 0.001, 0.01]}}
    sc = regrasp.Scene.from_dict(d)
    p = quasistatic.problem(sc, d["task"]["start"], "p", support="limit_surface", rings=2)
    u = [0.01, 0.0, 0.0]
    # IPOPT finds the object turning about the pad under gravity (ω ≈ 0.4 rad/s in the unit step)
    ref = mncp_reference.solve(p, pusher_twist=u)
    assert ref.max_residual < 1e-6 and ref.twist[2] == pytest.approx(0.4, rel=0.01)
    sol = p.solve_forward(u)
    assert np.allclose(sol["twist"], ref.twist, atol=1e-5)


@SETTINGS
@given(block_scenes(line=True), st.floats(-np.pi, np.pi), st.floats(-1.5, 1.5))
def test_limit_surface_support_agrees_with_the_motion_cone(d, a, b):
    d["grasp"]["limit_surface"] = "ellipsoid"  # the support's patch is the ellipsoid (eq 3.7)
    sc = load(d)
    q = d["task"]["start"]
    u = sc.metric_twist_inv(np.array([np.cos(a) * np.cos(b), np.sin(a) * np.cos(b), np.sin(b)])) * 0.01
    cone = sc.motion_cone(q, "p")
    m = cone.margin(u)
    assume(abs(m) > 1e-6)
    st_, _, res, err = sc._core.push_outcomes(np.array([q]), "p", np.array([u]), "limit_surface", 1, 0, True)
    assert err[0] is None and res[0] < 1e-6
    assert bool(st_[0]) == (m > 0)


def bench_problem():
    sc = regrasp.Scene.load(EXAMPLES / "block-low-friction.toml")
    return sc, sc._core.quasistatic_problem([0.0, 0.0, 0.0], "left", "points", 0, 4, False)


@pytest.mark.parametrize("u", [[0.01, 0.0, 0.0], [0.002, 0.01, 0.0], [0.01, 0.002, 0.3], [0.01, -0.003, -0.5]])
def test_fast_and_reference_solvers_agree(u):
    _, p = bench_problem()
    fast = p.solve_forward(u)
    ref = mncp_reference.solve(p, pusher_twist=u)
    assert ref.max_residual < 1e-6 and fast["max_residual"] < 1e-6
    # the object's motion is unique in these cases
    assert np.allclose(fast["twist"], ref.twist, atol=1e-6 * 0.01 + 1e-7)


def test_at_512_finger_points_the_fast_solver_agrees_with_ipopt():
    """Issue 17: the linear-time Newton step (dynamics/mncp/arrow.rs) on two pads of 256 points
    each, a sliding push, against IPOPT on the thesis' NLP."""
    u = [0.002, 0.01, 0.0]
    sc = regrasp.Scene.load(EXAMPLES / "block-low-friction.toml")
    p = sc._core.quasistatic_problem([0.0, 0.0, 0.0], "left", "points", 0, 256, False)
    fast = p.solve_forward(u)
    ref = mncp_reference.solve(p, pusher_twist=u)
    assert ref.max_residual < 1e-6 and fast["max_residual"] < 1e-6
    assert np.allclose(fast["twist"], ref.twist, atol=1e-6 * 0.01 + 1e-7), (fast["twist"], ref.twist)


def test_inverse_then_forward_round_trip_and_reference_inverse():
    _, p = bench_problem()
    v = [0.01, 0.001, 0.05]
    inv = p.solve_inverse(v)
    assert inv["max_residual"] < 1e-6
    assert all(s == "stick" for s, lab in zip(inv["states"], inv["labels"]) if lab.startswith("pusher"))
    fwd = p.solve_forward(list(inv["pusher_twist"]))
    assert np.allclose(fwd["twist"], v, atol=1e-9)
    ref = mncp_reference.solve(p, twist=v)
    assert ref.max_residual < 1e-6
    # the object's motion was given; a reference pusher motion reproduces it in the fast solver
    fwd2 = p.solve_forward(list(ref.pusher_twist))
    assert np.allclose(fwd2["twist"], v, atol=1e-6)
    with pytest.raises(regrasp.ArgumentError):
        p.solve_inverse([0.0, 0.01, 0.0])  # a side pusher cannot lift the block straight up


def test_known_cases():
    sc, p = bench_problem()
    # inside the motion cone: the pusher sticks, the fingers slide
    s = p.solve_forward([0.01, 0.0, 0.0])
    assert [x for x, lab in zip(s["states"], s["labels"]) if lab.startswith("pusher")] == ["stick", "stick"]
    assert all(x == "slide" for x, lab in zip(s["states"], s["labels"]) if lab.startswith("finger"))
    # well outside: the pusher slips
    s = p.solve_forward([0.0, 0.01, 0.0])
    assert all(x != "stick" for x, lab in zip(s["states"], s["labels"]) if lab.startswith("pusher"))
    # (almost) zero grip force: the object drops (in a unit step, at about g · 1 s)
    loose = sc.with_grip_force(1e-6)
    pz = loose._core.quasistatic_problem([0.0, 0.0, 0.0], "left", "points", 0, 4, False)
    s = pz.solve_forward([0.01, 0.0, 0.0])
    assert s["twist"][1] < -1.0, s["twist"]


def test_long_push_and_plan_replay(tmp_path):
    sc = regrasp.Scene.load(EXAMPLES / "block-low-friction.toml")
    tr = quasistatic.simulate_push(sc, [0, 0, 0], "left", [0.01, 0, 0], 1.0, 0.05)
    assert tr["residual"].max() < 1e-6
    assert np.allclose(tr["pose"][-1], [0.01, 0, 0], atol=1e-6)
    # a two-push plan: up with the bottom pusher, then right with the left pusher
    plan = {"scene": sc.name, "found": True, "path": [
        {"pose": [0.0, 0.0, 0.0], "pusher": None},
        {"pose": [0.0, 0.008, 0.0], "pusher": "bottom"},
        {"pose": [0.012, 0.008, 0.0], "pusher": "left"}]}
    f = tmp_path / "plan.json"
    f.write_text(json.dumps(plan))
    r = subprocess.run([sys.executable, "-m", "regrasp.cli", "simulate", str(EXAMPLES / "block-low-friction.toml"),
                        "--plan", str(f), "--engine", "quasistatic", "--json"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    out = json.loads(r.stdout)
    assert out["success"] and out["engine"] == "quasistatic"
    assert np.abs(out["goal_error"]).max() < 1e-4 and out["max_pusher_slip"] < 1e-6
    # a plan that pushes up with the side pusher fails and says so
    bad = dict(plan, path=plan["path"][:1] + [{"pose": [0.0, 0.008, 0.0], "pusher": "left"}])
    f.write_text(json.dumps(bad))
    r = subprocess.run([sys.executable, "-m", "regrasp.cli", "simulate", str(EXAMPLES / "block-low-friction.toml"),
                        "--plan", str(f), "--json"], capture_output=True, text=True)
    assert r.returncode == 1 and json.loads(r.stdout)["max_pusher_slip"] > 1e-3


def test_validate_json_and_agreement():
    r = subprocess.run([sys.executable, "-m", "regrasp.cli", "validate", str(EXAMPLES / "block-high-friction.toml"),
                        "--pushes", "120", "--json"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    out = json.loads(r.stdout)
    assert {"pushes", "agreement_quasistatic", "confusion_quasistatic"} <= set(out)
    assert out["pushes"] == 120 and sum(out["confusion_quasistatic"].values()) == out["solved"]
    assert out["agreement_quasistatic"] > 0.85
    assert out["limit_surface"] == "true" and out["rings"] == regrasp._core.validation_rings() == 8
    # with the motion cones' own limit surface as the pads (the ellipsoid), prediction and
    # simulation coincide
    from regrasp.mujoco.validation import validate

    scene = regrasp.Scene.load(EXAMPLES / "block-high-friction.toml")
    ls = validate(scene.with_limit_surface("ellipsoid"), 90, 1, support="limit_surface")
    assert ls["agreement_quasistatic"] > 0.99 and ls["limit_surface"] == "ellipsoid"
    # the exact surface against point-set pads fine enough to share it (8 rings, 216 points)
    fine = validate(scene, 300, 2, rings=8)
    assert fine["rings"] == 8 and fine["agreement_quasistatic"] >= 0.99, fine["confusion_quasistatic"]


def test_ambiguous_pushes_are_those_where_the_object_can_also_stay():
    """A push is ambiguous when it is in the motion cone and no contact point of the pusher moves
    into the object (checked here by hand from the scene's pushers); block-xztheta's corner point
    pusher has many, and the simulator mostly lets the contact open there. Counting either
    outcome as agreeing, xztheta reaches issue 17's 99% against the 8-ring pads."""
    from regrasp.mujoco.validation import samples, validate

    scene = regrasp.Scene.load(EXAMPLES / "block-xztheta.toml")
    rows = samples(scene, 600, 0)
    amb = [r for r in rows if r[5]]
    assert amb and all(r[4] for r in amb)
    for pusher, _kind, pose, u, pred, a in rows:
        p = scene.pusher(pusher)
        recedes = all(np.dot(np.array(u[:2]) + u[2] * np.array([-y, x]), p.normal) <= 1e-9 * np.linalg.norm(u)
                      for x, y in p.points)
        assert scene.hold_ratio(pose) < 1.0
        assert a == (bool(pred) and recedes)
    out = validate(scene, 1200, 0)
    assert out["rings"] == 8 and out["ambiguous_quasistatic"] > 0
    assert out["agreement_either_quasistatic"] >= out["agreement_quasistatic"]
    assert out["agreement_either_quasistatic"] >= 0.99, out["confusion_quasistatic"]


@pytest.mark.parametrize("name", ["block-xztheta", "t-shape"])
def test_plans_make_no_ambiguous_push(name):
    """The planner's steps push into the object: none is a push where the object could as well
    stay in the grasp (deterministic seeds; the twist of a step from its two poses)."""
    from regrasp.planning.plan import plan
    from regrasp.mujoco.validation import static_alternative

    scene = regrasp.Scene.load(EXAMPLES / f"{name}.toml")
    steps = 0
    for seed in range(3):
        r = plan(scene, seed=seed, time_limit=10)
        assert r.found
        P = np.asarray(r.poses, float)
        for k in range(1, len(P)):
            c, s = np.cos(P[k - 1, 2]), np.sin(P[k - 1, 2])
            d = P[k, :2] - P[k - 1, :2]
            u = np.array([c * d[0] + s * d[1], -s * d[0] + c * d[1], P[k, 2] - P[k - 1, 2]])
            if r.pushers[k] is None or not u.any():
                continue
            steps += 1
            assert not static_alternative(scene, r.pushers[k], P[k - 1], u), (seed, k)
    assert steps > 5


def test_push_cli_plot(tmp_path):
    png = tmp_path / "push.png"
    r = subprocess.run([sys.executable, "-m", "regrasp.cli", "push", str(EXAMPLES / "block-low-friction.toml"),
                        "--pose", "0,0,0", "--pusher", "left", "--twist", "0.01,0,0", "--duration", "0.5",
                        "--plot", str(png), "--json"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    out = json.loads(r.stdout)
    assert out["pusher_sticking_share"] == 1.0 and png.stat().st_size > 10_000


def test_mujoco_agrees_with_the_quasistatic_pivot():
    pytest.importorskip("mujoco")
    from regrasp.mujoco import push as mujoco_sim

    sc = regrasp.Scene.load(EXAMPLES / "block-low-friction.toml")
    w = np.radians(10.0)
    twist = [w * -0.04, 0.0, w]
    qs = quasistatic.simulate_push(sc, [0, 0, 0], "bottom", twist, 3.0, 0.05)
    mj = mujoco_sim.simulate_push(sc, [0, 0, 0], "bottom", twist, 3.0)
    # the pusher slips in both: the object turns about half of the pusher's 30 degrees
    assert 0.3 < qs["pose"][-1][2] / (3.0 * w) < 0.7
    assert abs(mj["pose"][-1][2] - qs["pose"][-1][2]) < 0.15 * abs(qs["pose"][-1][2])


def test_the_push_time_step_defaults_to_min_dt_and_duration():
    """dt: time step [s], default min(0.05, duration): a push shorter than DT is one step (no dt
    needed), a longer one steps of DT."""
    sc = regrasp.Scene.load(EXAMPLES / "block-low-friction.toml")
    short = quasistatic.simulate_push(sc, [0, 0, 0], "left", [0.01, 0, 0], 0.03)
    assert np.allclose(short["t"], [0.0, 0.03])
    long = quasistatic.simulate_push(sc, [0, 0, 0], "left", [0.01, 0, 0], 0.2)
    assert np.allclose(np.diff(long["t"]), quasistatic.DT)
    explicit = quasistatic.simulate_push(sc, [0, 0, 0], "left", [0.01, 0, 0], 0.2, 0.05)
    assert np.allclose(long["pose"], explicit["pose"])
    assert quasistatic.push_dt(0.03) == 0.03 and quasistatic.push_dt(1.0) == quasistatic.DT
    assert quasistatic.push_dt(1.0, 0.01) == 0.01
