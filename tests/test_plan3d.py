"""3-D regrasp planning through the complementarity dynamics (thesis §4.2): T-RRT* over SE(3),
inverse-dynamics step acceptance, replay, CLI and the browser view."""

import json
import shutil
import subprocess
import sys

import numpy as np
import pytest

from regrasp import _core
from regrasp.scene.spatial import Scene3D, quat_angle, twist_between
from regrasp.viz.viewer import write_html

from .conftest import EXAMPLES, ROOT

THREE_D = ["offset-3d", "light-side-3d", "pivot-single-3d", "pivot-3d", "block-3d", "prism-3d", "ball-roll-3d", "pivot-90-3d",
           "offset-pivot-3d", "bracket-pivot-3d"]


@pytest.mark.parametrize("name", THREE_D)
def test_every_3d_example_plans_and_replays(name):
    s = Scene3D.load(EXAMPLES / f"{name}.toml")
    for seed in (0, 1):
        p = s.plan(seed=seed, time_limit=20)
        assert p.found and p.valid, (name, seed, p.stop_reason)
        r = s.replay(p)
        assert r["success"], (name, seed, r["goal_error"])


def test_pivoting_with_a_switch_over_and_with_one_pusher():
    p = Scene3D.load(EXAMPLES / "pivot-3d.toml").plan(seed=0)
    assert p.switch_overs >= 1 and {"corner", "ground"} <= set(p.pushers[1:])
    p1 = Scene3D.load(EXAMPLES / "pivot-single-3d.toml").plan(seed=0)
    assert set(p1.pushers[1:]) == {"corner"}
    # the block turned about the grasp axis (Y)
    q = p1.poses[-1]
    assert quat_angle(q[3:], [1, 0, 0, 0]) > 0.38 and abs(q[4]) < 1e-6 and abs(q[6]) < 1e-6


def test_inverse_dynamics_step_acceptance():
    s = Scene3D.load(EXAMPLES / "offset-3d.toml")
    ident = [0, 0, 0, 1, 0, 0, 0]
    # the side pusher can slide the block along +X in the grasp, not pull it along -X or lift it
    assert s.validate_path([{"pose": ident, "pusher": None}, {"pose": [0.004, 0, 0, 1, 0, 0, 0], "pusher": "left"}]) == [True]
    assert s.validate_path([{"pose": ident, "pusher": None}, {"pose": [-0.004, 0, 0, 1, 0, 0, 0], "pusher": "left"}]) == [False]
    assert s.validate_path([{"pose": ident, "pusher": None}, {"pose": [0, 0, 0.004, 1, 0, 0, 0], "pusher": "left"}]) == [False]
    # an edge contact cannot translate the block without turning it (the moment about the grasp
    # axis must be balanced by the pads' torsional friction)
    e = Scene3D.load(EXAMPLES / "pivot-single-3d.toml")
    assert e.validate_path([{"pose": ident, "pusher": None}, {"pose": [0.004, 0, 0, 1, 0, 0, 0], "pusher": "corner"}]) == [False]


def test_se3_twist_between_inverts_the_plan_steps():
    s = Scene3D.load(EXAMPLES / "pivot-3d.toml")
    p = s.plan(seed=0)
    for a, b in zip(p.path[:-1], p.path[1:]):
        # the stored pusher twist reproduces the step exactly; the SE(3) log between the poses
        # (pusher sticking: the object's twist) reaches it to the simulator's step error
        # (measured 26 um / 0.8 mrad on the corner pivot, 0 elsewhere)
        for u, dp, da in ((b["pusher_twist"], 1e-9, 1e-6), (twist_between(a["pose"], b["pose"]), 1e-4, 2e-3)):
            q = np.asarray(s.simulate_push(a["pose"], b["pusher"], u, 1.0, 0.25)["pose"][-1])
            assert np.linalg.norm(q[:3] - np.asarray(b["pose"][:3])) < dp, (a, b, q)
            assert quat_angle(q[3:], b["pose"][3:]) < da, (a, b, q)
    # the log of a pure rotation about Y is that rotation
    u = twist_between([0, 0, 0, 1, 0, 0, 0], [0, 0, 0, np.cos(0.2), 0, np.sin(0.2), 0])
    assert np.allclose(u, [0, 0, 0, 0, 0.4, 0], atol=1e-12)


def test_plan_and_simulate_cli_3d(tmp_path):
    f, html = tmp_path / "plan.json", tmp_path / "view.html"
    scene = str(EXAMPLES / "pivot-3d.toml")
    r = subprocess.run([sys.executable, "-m", "regrasp.cli", "plan", scene, "--out", str(f), "--html", str(html), "--json"],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    out = json.loads(r.stdout)
    assert out["found"] and out["path"][1]["pusher_twist"] and html.stat().st_size > 3000
    r = subprocess.run([sys.executable, "-m", "regrasp.cli", "simulate", scene, "--plan", str(f), "--json"],
                       capture_output=True, text=True)
    assert r.returncode == 0 and json.loads(r.stdout)["success"], r.stderr
    r = subprocess.run([sys.executable, "-m", "regrasp.cli", "plan", scene, "--robust"], capture_output=True, text=True)
    assert r.returncode == 2 and "3-D" in r.stderr


@pytest.mark.skipif(shutil.which("node") is None, reason="needs node to run the page's script")
def test_browser_view_draws_every_frame(tmp_path):
    s = Scene3D.load(EXAMPLES / "pivot-3d.toml")
    p = s.plan(seed=0)
    page = write_html(s, p, tmp_path / "view.html")
    r = subprocess.run(["node", str(ROOT / "tests" / "js" / "run_viewer.js"), str(page)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    out = json.loads(r.stdout)
    for fr in out["frames"]:
        # the faces turned to the camera (a box shows 2 or 3 faces: 4-6 triangles) and both pads
        assert fr["finite"] and 4 + 2 <= fr["drawn"] <= out["triangles"] + 2
        assert fr["pusher_dots"] >= 2  # the active pusher's contacts
    assert "pusher corner" in out["frames"][0]["info"] and "pusher ground" in out["frames"][-1]["info"]
    assert np.allclose(out["frames"][-1]["pose"], p.poses[-1], atol=1e-9)
    # a ball on the floor: one contact dot (the lowest point), the floor drawn, painted faces
    s = Scene3D.load(EXAMPLES / "ball-roll-3d.toml")
    page = write_html(s, s.plan(seed=0), tmp_path / "ball.html")
    out = json.loads(subprocess.run(["node", str(ROOT / "tests" / "js" / "run_viewer.js"), str(page)],
                                    capture_output=True, text=True, check=True).stdout)
    for fr in out["frames"]:
        assert fr["finite"] and fr["pusher_dots"] == 1 and fr["drawn"] >= out["triangles"] // 3


def test_3d_plans_execute_in_mujoco(tmp_path):
    pytest.importorskip("mujoco")
    from regrasp.mujoco.spatial import execute_plan3d

    for name in ("offset-3d", "pivot-single-3d", "pivot-3d", "prism-3d", "pivot-90-3d", "offset-pivot-3d", "bracket-pivot-3d"):
        s = Scene3D.load(EXAMPLES / f"{name}.toml")
        p = s.plan(seed=0)
        for view in ("world", "planner"):
            r = execute_plan3d(s, p, view=view)
            assert r["success"], (name, view, r["goal_error"])
    f = tmp_path / "plan.json"
    s = Scene3D.load(EXAMPLES / "light-side-3d.toml")
    s.plan(seed=0).save(f)
    r = subprocess.run([sys.executable, "-m", "regrasp.cli", "simulate", str(EXAMPLES / "light-side-3d.toml"), "--plan", str(f),
                        "--engine", "mujoco", "--json"], capture_output=True, text=True)
    assert r.returncode == 0 and json.loads(r.stdout)["engine"] == "mujoco", r.stderr


def test_ball_rolls_on_the_floor_in_mujoco_and_feedback_closes_the_gap(tmp_path):
    """The ball example rolled on the floor in MuJoCo: open loop it turns (it rolls: > 1.4 rad
    of the 1.57) but MuJoCo's contacts roll it a little further per step than the quasi-static
    model (measured 38 mrad at the goal, outside the 17.5 mrad tolerance); re-planning from the
    measured pose (``regrasp control SCENE_3D``) ends within the tolerance."""
    pytest.importorskip("mujoco")
    from regrasp.mujoco.spatial import execute_plan3d

    s = Scene3D.load(EXAMPLES / "ball-roll-3d.toml")
    p = s.plan(seed=0)
    ol = execute_plan3d(s, p)
    assert quat_angle(ol["final_pose"][3:], [1, 0, 0, 0]) > 1.4
    closed = execute_plan3d(s, p, feedback=True)
    assert closed["success"] and closed["replans"] >= 1, closed["goal_error"]
    f = tmp_path / "ball.json"
    p.save(f)
    cli = [sys.executable, "-m", "regrasp.cli", "control", str(EXAMPLES / "ball-roll-3d.toml"), "--plan", str(f), "--json"]
    r = subprocess.run(cli + ["--engine", "mujoco"], capture_output=True, text=True)
    out = json.loads(r.stdout)
    assert r.returncode == 0 and out["success"] and out["policy"] == "replan", r.stderr
    r = subprocess.run(cli + ["--poke", "1,0,0,0"], capture_output=True, text=True)
    assert r.returncode == 2 and "--poke" in r.stderr
    r = subprocess.run(cli + ["--horizon", "7"], capture_output=True, text=True)
    assert r.returncode == 2 and "--horizon" in r.stderr


def test_feedback_replans_after_a_disturbance():
    """Closed loop by re-planning: a world that turns the ball 3 mrad further per step than the
    quasi-static model (as MuJoCo does) ends outside the tolerance open loop, within it with
    re-plans from the measured pose."""
    s = Scene3D.load(EXAMPLES / "ball-roll-3d.toml")
    p = s.plan(seed=0)
    calls = []

    def step(a, b):  # the quasi-static step, plus a 3 mrad extra turn about the grasp axis
        q = np.asarray(s.simulate_push(a["pose"] if not calls else calls[-1], b["pusher"], b["pusher_twist"], 1.0, 0.25)["pose"][-1])
        q = np.array(_core.se3_compose(list(q), [0, 0, 0, np.cos(0.0015), 0, np.sin(0.0015), 0]))
        calls.append(q)
        return q

    from regrasp.scene.spatial import goal_report, run_plan3d

    q, poses, n = run_plan3d(s, p.path, step, p.poses[0], feedback=False)
    assert n == 0 and not goal_report(s, q)["success"], goal_report(s, q)  # open loop: 24 mrad off
    calls.clear()
    q, poses, n = run_plan3d(s, p.path, step, p.poses[0], feedback=True)
    assert n >= 1 and goal_report(s, q)["success"], goal_report(s, q)


CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")


@pytest.mark.skipif(CHROMIUM is None, reason="needs Chromium (Debian package chromium; .ci/run installs it)")
def test_browser_view_in_headless_chromium(tmp_path):
    s = Scene3D.load(EXAMPLES / "pivot-3d.toml")
    p = s.plan(seed=0)
    page = write_html(s, p, tmp_path / "view.html")
    flags = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
             "--disable-background-networking", "--disable-component-update", "--disable-sync",
             f"--user-data-dir={tmp_path / 'profile'}", "--window-size=940,700"]
    r = subprocess.run([CHROMIUM, *flags, "--dump-dom", f"file://{page}#selftest"], capture_output=True, text=True,
                       timeout=120)
    import re

    m = re.search(r'<pre id="selftest">(.*?)</pre>', r.stdout, re.S)
    assert m, r.stderr[-2000:]
    out = json.loads(m.group(1).replace("&quot;", '"').replace("&amp;", "&"))
    area = 900 * 620
    for fr in out["frames"]:
        assert 6 <= fr["drawn"] <= out["triangles"] + 2
        assert 0.01 * area < fr["ink"] < 0.6 * area  # the object is drawn, and fits the canvas
    assert "pusher corner" in out["frames"][0]["info"] and "pusher ground" in out["frames"][-1]["info"]
    assert np.allclose(out["frames"][-1]["pose"], p.poses[-1], atol=1e-9)
    shot = tmp_path / "view.png"
    subprocess.run([CHROMIUM, *[f for f in flags if not f.startswith("--user-data-dir")],
                    f"--user-data-dir={tmp_path / 'profile2'}", f"--screenshot={shot}", f"file://{page}"],
                   capture_output=True, timeout=120)
    assert shot.stat().st_size > 5000


def test_solves_are_deterministic_under_a_seed():
    """The 3-D plan's `solves` counts the solves a sequential search makes (the parallel
    search's extra work is not counted): the same seed and budget give the same count."""
    s = _core.Scene3D.from_toml((EXAMPLES / "pivot-3d.toml").read_text(), str(EXAMPLES))
    settings = {"seed": 3, "time_limit": 600.0, "max_iterations": 20, "cost_threshold": -1.0, "refine": float("inf")}
    runs = [s.plan(None, None, settings) for _ in range(3)]
    assert len({r["solves"] for r in runs}) == 1, [r["solves"] for r in runs]
    assert len({r["nodes"] for r in runs}) == 1 and runs[0]["solves"] > 0


def test_a_non_convex_object_is_its_parts_in_mujoco():
    """The L-bracket (two convex parts): MuJoCo, given the parts as mesh geoms of aluminium's
    density and left to compute the body's mass properties itself, agrees with the scene's (ours
    from the parts' closed triangle meshes); the hull would not. The object's geoms are the parts."""
    mujoco = pytest.importorskip("mujoco")
    from regrasp.mujoco.spatial import build

    s = Scene3D.load(EXAMPLES / "bracket-pivot-3d.toml")
    parts = s.parts()
    assert len(parts) == 2 and len(s.mesh()[0]) == 10
    spec = mujoco.MjSpec()
    body = spec.worldbody.add_body(name="b")
    for k, (v, t) in enumerate(parts):
        spec.add_mesh(name=f"p{k}", uservert=np.ravel(v).tolist(), userface=np.ravel(t).tolist())
        body.add_geom(type=mujoco.mjtGeom.mjGEOM_MESH, meshname=f"p{k}", density=2700.0)
    m = spec.compile()
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    mass = m.body_mass[1]
    assert mass == pytest.approx(2700.0 * 29.76e-6, rel=1e-7)
    assert np.allclose(d.xipos[1], s._core.com, atol=1e-9)
    # MuJoCo's principal inertia (its own frame) against the scene's, scaled to MuJoCo's mass
    I = np.asarray(s.inertia, float) * mass / s.mass
    assert np.allclose(np.sort(np.linalg.eigvalsh(I)), np.sort(m.body_inertia[1]), rtol=1e-6)
    # the execution's model: one mesh geom per part
    model = build(s, s.task[0]).compile()
    obj = model.body("object").id
    assert sum(int(model.geom_bodyid[g] == obj and model.geom_type[g] == mujoco.mjtGeom.mjGEOM_MESH) for g in range(model.ngeom)) == 2
    # the surface drawn: both parts' triangles
    v, t = s.surface()
    assert len(v) == 16 and len(t) == 24 and t.max() == 15
