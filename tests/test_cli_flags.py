"""No flag is silently ignored: for each command, flag and kind of scene (planar, 3-D) and mode
(engine, open loop, --quick), the flag either has an effect (a file written, the output changed)
or the command refuses it (exit 2, the flag and the reason on stderr)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from .conftest import run_cli as run

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
PLANAR = EXAMPLES / "block-low-friction.toml"
UNCERTAIN = EXAMPLES / "block-fixtureless.toml"  # has an [uncertainty] table
SPATIAL = EXAMPLES / "pivot-3d.toml"
PLAN_ARGS = ["--time-limit", "5", "--seed", "0"]




@pytest.fixture(scope="module")
def plans(tmp_path_factory) -> dict:
    """Plan files of the planar block and of the 3-D pivot."""
    d = tmp_path_factory.mktemp("plans")
    out = {}
    for kind, scene in (("planar", PLANAR), ("3d", SPATIAL)):
        status, _, err = run("plan", scene, *PLAN_ARGS, "--out", d / f"{kind}.json")
        assert status == 0, err
        out[kind] = d / f"{kind}.json"
    return out


def refused(args, flag: str, reason: str) -> None:
    status, out, err = run(*args)
    assert status == 2, f"regrasp {' '.join(map(str, args))}: status {status}, {err}"
    assert f"`{flag}`" in err, err
    assert reason in err, f"the reason ({reason!r}) is not in {err!r}"
    assert "Traceback" not in err and out == ""


# --- refused: (args, flag named, reason said) --------------------------------------------------

REFUSED = [
    # plan, 3-D: the motion-cone modes
    (["plan", SPATIAL, "--robust"], "--robust", "inverse dynamics"),
    (["plan", SPATIAL, "--fixtureless"], "--fixtureless", "inverse dynamics"),
    (["plan", SPATIAL, "--uncertainty", "0.1,0.1,0.1,0.1"], "--uncertainty", "inverse dynamics"),
    (["plan", SPATIAL, "--propagation", "mncp"], "--propagation", "inverse dynamics"),
    # plan, planar: robust cones need an [uncertainty]
    (["plan", PLANAR, "--robust"], "uncertainty", "uncertainty"),
    # cone, approx-error, validate: planar scenes only
    (["cone", SPATIAL, "--pose", "0,0,0", "--pusher", "corner"], "scene", "planar scenes"),
    (["approx-error", SPATIAL], "scene", "planar scenes"),
    (["validate", SPATIAL], "scene", "planar scenes"),
    # validate: options of the engine not run
    (["validate", PLANAR, "--workers", "2"], "--workers", "--engines mujoco"),
    (["validate", PLANAR, "--ray", "local"], "--ray", "--engines mujoco"),
    (["validate", PLANAR, "--engines", "mujoco", "--support", "limit_surface"], "--support", "quasi-static"),
    (["validate", PLANAR, "--engines", "mujoco", "--rings", "8"], "--rings", "quasi-static"),
    (["validate", PLANAR, "--support", "limit_surface", "--rings", "8"], "--rings", "--support points"),
    # the limit surface of the motion cones: planar scenes only
    (["plan", SPATIAL, "--limit-surface", "ellipsoid"], "--limit-surface", "3-D scene"),
    # push, 3-D: the figure is planar
    (["push", SPATIAL, "--pose", "0,0,0,1,0,0,0", "--pusher", "ground", "--twist", "0,0,0.001,0,0,0", "--plot", "P.png"],
     "--plot", "planar"),
    # approx-error: a scene without a grasp has no grip force to vary
    (["approx-error", EXAMPLES / "block-on-incline.toml"], "scene", "no grasp"),
    # bench: -n and --quick; -v (it reads no scene files)
    (["bench", "--quick", "-n", "1000"], "-n", "--quick"),
    (["-v", "bench"], "--verbose", "no scene files"),
]

#: refused given the plan files (PLAN: the planar plan; PLAN3: the 3-D plan)
REFUSED_WITH_PLAN = [
    # simulate, planar, quasi-static world: the MuJoCo options
    (["simulate", PLANAR, "--plan", "PLAN", "--scale-friction", "0.9"], "--scale-friction", "--engine mujoco"),
    (["simulate", PLANAR, "--plan", "PLAN", "--scale-grip", "0.9"], "--scale-grip", "--engine mujoco"),
    (["simulate", PLANAR, "--plan", "PLAN", "--scale-mass", "0.9"], "--scale-mass", "--engine mujoco"),
    (["simulate", PLANAR, "--plan", "PLAN", "--perturb", "0.1"], "--perturb", "--engine mujoco"),
    (["simulate", PLANAR, "--plan", "PLAN", "--video", "V.gif"], "--video", "--engine mujoco"),
    # simulate, MuJoCo: the quasi-static time step; --seed without --perturb
    (["simulate", PLANAR, "--plan", "PLAN", "--engine", "mujoco", "--dt", "0.01"], "--dt", "quasi-static"),
    (["simulate", PLANAR, "--plan", "PLAN", "--engine", "mujoco", "--seed", "3"], "--seed", "--perturb"),
    # simulate, 3-D: the planar figures and perturbation
    (["simulate", SPATIAL, "--plan", "PLAN3", "--plot", "P.png"], "--plot", "planar only"),
    (["simulate", SPATIAL, "--plan", "PLAN3", "--engine", "mujoco", "--perturb", "0.1"], "--perturb", "planar only"),
    (["simulate", SPATIAL, "--plan", "PLAN3", "--engine", "mujoco", "--video", "V.gif"], "--video", "planar only"),
    # control, 3-D: the MPC's options
    (["control", SPATIAL, "--plan", "PLAN3", "--horizon", "3"], "--horizon", "re-plans"),
    (["control", SPATIAL, "--plan", "PLAN3", "--noise", "0.001"], "--noise", "re-plans"),
    (["control", SPATIAL, "--plan", "PLAN3", "--poke", "1,0,0,0"], "--poke", "re-plans"),
    (["control", SPATIAL, "--plan", "PLAN3", "--plot", "P.png"], "--plot", "re-plans"),
    (["control", SPATIAL, "--plan", "PLAN3", "--scale-grip", "0.9"], "--scale-*", "MuJoCo only"),
    # control, planar, open loop: the feedback's options
    (["control", PLANAR, "--plan", "PLAN", "--open-loop", "--horizon", "3"], "--horizon", "open-loop"),
    (["control", PLANAR, "--plan", "PLAN", "--open-loop", "--noise", "0.001"], "--noise", "open-loop"),
    (["control", PLANAR, "--plan", "PLAN", "--open-loop", "--robust"], "--robust", "open-loop"),
    (["control", PLANAR, "--plan", "PLAN", "--open-loop", "--fixtureless"], "--fixtureless", "open-loop"),
]


@pytest.mark.parametrize("args,flag,reason", REFUSED, ids=lambda x: x if isinstance(x, str) else None)
def test_a_flag_without_effect_is_refused_with_the_reason(tmp_path, args, flag, reason):
    refused([tmp_path / a if a in ("P.png", "V.gif") else a for a in args], flag, reason)


@pytest.mark.parametrize("args,flag,reason", REFUSED_WITH_PLAN, ids=lambda x: x if isinstance(x, str) else None)
def test_a_flag_without_effect_on_a_plan_is_refused_with_the_reason(tmp_path, plans, args, flag, reason):
    subst = {"PLAN": plans["planar"], "PLAN3": plans["3d"], "P.png": tmp_path / "P.png", "V.gif": tmp_path / "V.gif"}
    refused([subst.get(a, a) if isinstance(a, str) else a for a in args], flag, reason)
    assert not list(tmp_path.iterdir())  # nothing written


# --- an effect: a file written ------------------------------------------------------------------

@pytest.mark.parametrize("scene,flag,name", [
    (PLANAR, "--plot", "plan.png"),
    (SPATIAL, "--plot", "plan.png"),
    (SPATIAL, "--animate", "plan.gif"),
    (SPATIAL, "--html", "plan.html"),
], ids=lambda x: x.stem if isinstance(x, Path) else x)
def test_plan_figures_are_written_for_both_kinds_of_scene(tmp_path, scene, flag, name):
    status, _, err = run("plan", scene, *PLAN_ARGS, flag, tmp_path / name)
    assert status == 0, err
    data = (tmp_path / name).read_bytes()
    magic = {".png": b"\x89PNG", ".gif": b"GIF8", ".html": b"<"}[Path(name).suffix]
    assert data.lstrip()[:len(magic)].lower() == magic.lower() and len(data) > 1000


def test_plan_animate_of_a_planar_scene_writes_a_gif(tmp_path, plans):
    status, _, err = run("plan", PLANAR, *PLAN_ARGS, "--animate", tmp_path / "a.gif")
    assert status == 0, err
    assert (tmp_path / "a.gif").read_bytes()[:4] == b"GIF8"


def test_plan_html_of_a_planar_scene_writes_the_browser_view(tmp_path):
    """The browser view of a planar plan."""
    status, _, err = run("plan", PLANAR, *PLAN_ARGS, "--html", tmp_path / "p.html")
    assert status == 0, err
    text = (tmp_path / "p.html").read_text()
    assert "<html" in text.lower() and "block-low-friction" in text


def test_the_3d_plot_shows_the_start_goal_and_pusher_runs(tmp_path, plans):
    """plot_plan3d itself: a figure with the plan's poses (more drawn for a longer plan)."""
    from matplotlib.image import imread

    from regrasp import load_scene
    from regrasp.planning.plan import Plan
    from regrasp.viz.plotting3d import plot_plan3d

    scene = load_scene(SPATIAL)
    plan = Plan.load(plans["3d"], scene)
    full = plot_plan3d(scene, plan, tmp_path / "full.png")
    none = plot_plan3d(scene, plan, tmp_path / "ends.png", intermediate=0)
    a, b = imread(full), imread(none)
    assert a.shape == b.shape and (a != b).any()  # the intermediate poses are drawn


# --- an effect: the output changes --------------------------------------------------------------

def _json(*args) -> dict:
    status, out, err = run(*args, "--json")
    assert status in (0, 1), err
    return json.loads(out)


def test_planar_plan_mode_flags_change_the_plan():
    base = _json("plan", UNCERTAIN, *PLAN_ARGS)
    assert _json("plan", UNCERTAIN, *PLAN_ARGS, "--propagation", "stable_check")["propagation"] != base["propagation"]
    # the cones of the mode: other step margins
    assert _json("plan", UNCERTAIN, *PLAN_ARGS, "--robust")["step_margins"] != base["step_margins"]
    assert _json("plan", UNCERTAIN, *PLAN_ARGS, "--uncertainty", "0.2,0.2,0.2,0.2")["step_margins"] != base["step_margins"]
    assert _json("plan", UNCERTAIN, *PLAN_ARGS, "--fixtureless")["step_margins"] != base["step_margins"]


def test_simulate_flags_of_the_engine_run_change_the_result(plans):
    base = _json("simulate", PLANAR, "--plan", plans["planar"])
    assert _json("simulate", PLANAR, "--plan", plans["planar"], "--dt", "0.01") != base


def test_validate_support_changes_the_result():
    args = ("validate", PLANAR, "--pushes", "60")
    assert _json(*args, "--support", "limit_surface")["support_model"] == "limit_surface"
    assert _json(*args)["support_model"] == "points"


def test_cone_twist_changes_the_report():
    args = ("cone", PLANAR, "--pose", "0,0,0", "--pusher", "bottom")
    assert _json(*args, "--twist", "0,0.01,0")["min_grip_force_twist"] != _json(*args)["min_grip_force_twist"]


def test_limit_surface_changes_the_cone_and_is_reported():
    """`--limit-surface` has an effect: the generators differ between the two surfaces, and the
    report says which one it is on (the scene's default: the exact one)."""
    out = {}
    for model in (None, "ellipsoid", "true"):
        flag = [] if model is None else ["--limit-surface", model]
        status, stdout, err = run("cone", PLANAR, "--pose", "0,0,0", "--pusher", "left", "--json", *flag)
        assert status == 0, err
        out[model] = json.loads(stdout)
    assert out[None]["limit_surface"] == out["true"]["limit_surface"] == "true"
    assert out["ellipsoid"]["limit_surface"] == "ellipsoid"
    assert out[None]["generators"] == out["true"]["generators"]
    diff = max(abs(a - b) for g, h in zip(out["true"]["generators"], out["ellipsoid"]["generators"]) for a, b in zip(g, h))
    assert diff > 1e-3
