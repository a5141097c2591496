"""One Plan type for planar and 3-D plans: planning, the plan file (to_json, from_json, load,
save), re-checking, compatibility access, scenes by file and the planner's defaults."""

import json
import shutil
import subprocess
import sys

import numpy as np
import pytest

import regrasp
from regrasp import _core
from regrasp.planning.plan import KEYS

from .conftest import EXAMPLES

IDENTITY = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0]


@pytest.fixture(scope="module")
def planar():
    scene = regrasp.load_scene(EXAMPLES / "t-shape.toml")
    return scene, regrasp.plan(scene, seed=0)


@pytest.fixture(scope="module")
def spatial():
    scene = regrasp.load_scene(EXAMPLES / "offset-3d.toml")
    return scene, regrasp.plan(scene, seed=0)


def test_one_way_to_plan_returns_one_type_for_both_dimensions():
    a = regrasp.plan(regrasp.load_scene("examples/t-shape.toml"))
    b = regrasp.plan(regrasp.load_scene("examples/pivot-3d.toml"))
    assert type(a) is type(b) is regrasp.Plan
    assert (a.dimension, b.dimension) == (2, 3)
    assert a.poses.shape[1] == 3 and b.poses.shape[1] == 7 and a.found and b.found and a.valid and b.valid
    assert type(regrasp.Scene3D.load(EXAMPLES / "offset-3d.toml").plan(seed=0)) is regrasp.Plan


def test_load_scene_tells_the_kinds_apart(tmp_path):
    s2, s3 = regrasp.load_scene(EXAMPLES / "t-shape.toml"), regrasp.load_scene(EXAMPLES / "pivot-3d.toml")
    assert isinstance(s2, regrasp.Scene) and isinstance(s3, regrasp.Scene3D)
    assert (s2.dimension, s3.dimension) == (2, 3) and s2.path == EXAMPLES / "t-shape.toml"
    with pytest.raises(regrasp.ArgumentError) as e:
        regrasp.load_scene(tmp_path / "missing.toml")
    assert e.value.field == "path"
    bad = tmp_path / "four.toml"
    bad.write_text((EXAMPLES / "offset-3d.toml").read_text().replace("dimension = 3", "dimension = 4"))
    with pytest.raises(regrasp.SceneError) as e:
        regrasp.load_scene(bad)
    assert e.value.field == "dimension"


@pytest.mark.parametrize("which", ["planar", "spatial"])
def test_to_json_is_the_plan_file_and_reads_back(which, request, tmp_path):
    scene, p = request.getfixturevalue(which)
    d = p.to_json()
    assert tuple(d) == tuple(k for k in KEYS[p.dimension] if k != "reason")  # a reason only when unreachable
    assert len(d["path"][0]["pose"]) == {2: 3, 3: 7}[p.dimension] and d["path"][0]["pusher"] is None
    assert ("pusher_twist" in d["path"][1]) == (p.dimension == 3)
    assert regrasp.Plan.from_json(d).to_json() == d
    f = p.save(tmp_path / "plan.json")
    assert json.loads(f.read_text()) == d
    back = regrasp.Plan.load(f, scene)
    assert back.to_json() == d and np.array_equal(back.poses, p.poses) and back.pushers == p.pushers
    assert list(tmp_path.iterdir()) == [f], "no temporary file is left behind"


def test_plan_keys_read_like_the_plan_dict(planar, spatial):
    for _, p in (planar, spatial):
        assert p["found"] is p.found and p["path"] == p.path and p["nodes"] == p.nodes
        assert "path" in p and "no_such_key" not in p and p.get("no_such_key", 5) == 5
        with pytest.raises(KeyError):
            p["no_such_key"]
    assert planar[1]["step_margins"] == planar[1].step_margins and "solves" not in planar[1]
    assert spatial[1]["solves"] == spatial[1].solves and "step_margins" not in spatial[1]
    assert spatial[1]["path"][1]["pusher_twist"] == spatial[1].pusher_twists[1].tolist()


def test_a_minimal_plan_file_reads_and_writes_only_what_it_knows():
    p = regrasp.Plan.from_json({"path": [{"pose": [0, 0.02, 0], "pusher": None}, {"pose": [0, 0.01, 0], "pusher": "top"}],
                                "comment": "other keys are ignored"})
    assert p.dimension == 2 and p.found is None and p.valid is None
    assert p.to_json() == {"path": [{"pose": [0.0, 0.02, 0.0], "pusher": None}, {"pose": [0.0, 0.01, 0.0], "pusher": "top"}]}
    p3 = regrasp.Plan.from_json({"path": [{"pose": IDENTITY}, {"pose": [0.004] + IDENTITY[1:], "pusher": "left"}]})
    assert p3.dimension == 3 and p3.pusher_twists == [None, None]
    assert p3.check(regrasp.load_scene(EXAMPLES / "offset-3d.toml")) is True and p3.valid


def _step(pose, pusher="top", **kw):
    return {"pose": pose, "pusher": pusher, **kw}


T_START = {"pose": [0.0, 0.02, 0.0], "pusher": None}
BAD_PLANS = [
    ([], "plan"),
    ({"nodes": 3}, "plan.path"),
    ({"path": []}, "plan.path"),
    ({"path": [T_START, "x"]}, "plan.path[1]"),
    ({"path": [T_START, _step([0.0, 0.01])]}, "plan.path[1].pose"),
    ({"path": [T_START, _step([0.0, float("nan"), 0.0])]}, "plan.path[1].pose"),
    ({"path": [T_START, _step([0.0, "0.01", 0.0])]}, "plan.path[1].pose"),
    ({"path": [T_START, _step([0.0, 0.01, 0.0], None)]}, "plan.path[1].pusher"),
    ({"path": [T_START, _step([0.0, 0.01, 0.0], "teleporter")]}, "plan.path[1].pusher"),
    ({"path": [T_START, _step([0.0, 0.01, 0.0]), _step([0.0, 0.01, 0.0, 1.0, 0.0, 0.0, 0.0])]}, "plan.path[2].pose"),
    ({"path": [T_START], "found": "yes"}, "plan.found"),
    ({"path": [T_START], "nodes": 2.5}, "plan.nodes"),
    ({"path": [T_START], "cost": float("inf")}, "plan.cost"),
    ({"path": [T_START, _step([0.0, 0.01, 0.0])], "step_margins": [0.1, 0.2]}, "plan.step_margins"),
]


@pytest.mark.parametrize("plan,field", BAD_PLANS, ids=[f for _, f in BAD_PLANS])
def test_every_field_is_checked_and_named(plan, field, tmp_path):
    scene = regrasp.load_scene(EXAMPLES / "t-shape.toml")
    f = tmp_path / "plan.json"
    f.write_text(json.dumps(plan))
    with pytest.raises(regrasp.ArgumentError) as e:
        regrasp.Plan.load(f, scene)
    assert e.value.field == field, str(e.value)
    assert f"`{field}`" in str(e.value)


def test_3d_fields_are_checked_and_named(tmp_path):
    ball = regrasp.load_scene(EXAMPLES / "ball-roll-3d.toml")
    offset = regrasp.load_scene(EXAMPLES / "offset-3d.toml")
    cases = [
        (offset, {"path": [{"pose": [0, 0, 0, 0, 0, 0, 0]}]}, "plan.path[0].pose"),
        (offset, {"path": [{"pose": IDENTITY}, _step(IDENTITY, "left", pusher_twist=[0.0] * 5)]}, "plan.path[1].pusher_twist"),
        (ball, {"path": [{"pose": IDENTITY}, _step(IDENTITY, "floor")]}, "plan.path[1].pusher_twist"),  # a plane rolls
        (offset, {"path": [T_START]}, "plan.path[0].pose"),  # a planar plan for a 3-D scene
        (regrasp.load_scene(EXAMPLES / "t-shape.toml"), {"path": [{"pose": IDENTITY}]}, "plan.path[0].pose"),
    ]
    for scene, plan, field in cases:
        with pytest.raises(regrasp.ArgumentError) as e:
            regrasp.Plan.from_json(plan, scene)
        assert e.value.field == field, (plan, str(e.value))
    # without a scene the pose's length tells the dimension
    with pytest.raises(regrasp.ArgumentError) as e:
        regrasp.Plan.from_json({"path": [{"pose": [0.0] * 5}]})
    assert e.value.field == "plan.path[0].pose"
    # and a file that is not JSON
    f = tmp_path / "plan.json"
    f.write_text("{not json")
    with pytest.raises(regrasp.ArgumentError) as e:
        regrasp.Plan.load(f)
    assert e.value.field == "plan"


def test_check_revalidates_the_steps(planar, spatial):
    scene, p = planar
    q = regrasp.Plan.from_json(p.to_json())
    assert q.check(scene) and q.step_margins == pytest.approx(p.step_margins)
    q.poses[-1] = q.poses[-2] + [0.0, 0.01, 0.0]  # the last pusher cannot make this step
    assert q.check(scene) is False and q.step_margins[-1] < 0 and q.valid is False
    scene3, p3 = spatial
    q3 = regrasp.Plan.from_json(p3.to_json())
    q3.poses[-1] = q3.poses[-2] - [0.004, 0, 0, 0, 0, 0, 0]  # a side pusher cannot pull the block back
    q3.pusher_twists[-1] = None
    assert q3.check(scene3) is False
    with pytest.raises(regrasp.ArgumentError) as e:
        p.check(scene3)
    assert e.value.field == "plan.path[0].pose"


def test_save_is_atomic_and_never_overwrites_the_scene_file(tmp_path):
    scene_file = tmp_path / "t-shape.toml"
    shutil.copy(EXAMPLES / "t-shape.toml", scene_file)
    text = scene_file.read_text()
    scene = regrasp.load_scene(scene_file)
    p = regrasp.plan(scene, seed=0)
    assert p.scene_file == scene_file
    with pytest.raises(regrasp.ArgumentError) as e:
        p.save(scene_file)
    assert e.value.field == "path" and scene_file.read_text() == text
    out = tmp_path / "plan.json"
    out.write_text("old")
    p.save(out)
    assert json.loads(out.read_text()) == p.to_json()
    assert sorted(f.name for f in tmp_path.iterdir()) == ["plan.json", "t-shape.toml"]
    with pytest.raises(regrasp.ArgumentError) as e:
        p.save(tmp_path / "missing" / "plan.json")
    assert e.value.field == "path"
    # the command line refuses it before planning
    r = subprocess.run([sys.executable, "-m", "regrasp.cli", "plan", str(scene_file), "--out", str(scene_file)],
                       capture_output=True, text=True)
    assert r.returncode == 2 and "--out" in r.stderr and scene_file.read_text() == text


def test_planner_settings_default_to_the_cores():
    for dim in (2, 3):
        assert regrasp.planner_defaults(dim) == dict(_core.planner_defaults(dim))
    assert "propagation" in regrasp.planner_defaults(2) and "propagation" not in regrasp.planner_defaults(3)
    scene = regrasp.load_scene(EXAMPLES / "t-shape.toml")
    p = regrasp.plan(scene)
    assert p.seed == regrasp.planner_defaults(2)["seed"] and p.propagation == regrasp.planner_defaults(2)["propagation"]
    with pytest.raises(regrasp.ArgumentError) as e:
        regrasp.plan(scene, no_such_setting=1)
    assert e.value.field == "no_such_setting"
    with pytest.raises(regrasp.ArgumentError) as e:
        regrasp.plan(scene, start="nowhere")
    assert e.value.field == "start"
    # the command line leaves every planner option to the core and shows its default
    from regrasp.cli import build_parser

    a = build_parser().parse_args(["plan", "x.toml"])
    assert (a.seed, a.time_limit, a.propagation) == (None, None, None)
    r = subprocess.run([sys.executable, "-m", "regrasp.cli", "plan", "--help"], capture_output=True, text=True)
    assert f"(default: {regrasp.planner_defaults(2)['time_limit']})" in " ".join(r.stdout.split())


def test_the_simulators_and_views_take_a_plan(planar, spatial, tmp_path):
    from regrasp.sim.quasistatic import replay_plan
    from regrasp.viz.viewer import page

    scene, p = planar
    assert replay_plan(scene, p).success and replay_plan(scene, p.to_json()).success
    scene3, p3 = spatial
    assert scene3.replay(p3)["success"] and scene3.replay(p3.to_json())["success"]
    assert scene3.validate_path(p3) == scene3.validate_path(p3.path)
    assert scene3.name in page(scene3, p3)
