"""Fuzz: every public entry point of the Python API with one argument replaced by a bad value
(wrong type or shape, NaN, inf, 1e300, negative or huge counts, empty arrays, unknown pusher
names, bad settings). Only the closed exception set may come out, naming the argument, and no
NaN/inf in any result."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

import regrasp
from regrasp.control import loop
from regrasp.mujoco import push as mj_push
from regrasp.planning import plan as planning
from regrasp.reference import approx_error
from regrasp.mujoco import validation
from regrasp.sim import quasistatic

from .harness import fuzz_settings, run
from .strategies import BAD_SCALARS, EXAMPLES, Weird, bad_values

P = regrasp.load_scene(EXAMPLES / "block-low-friction.toml")
S3 = regrasp.load_scene(EXAMPLES / "pivot-3d.toml")
Z3 = [0.0, 0.0, 0.0]
START3 = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0]
CONE = P.motion_cone(Z3, "left")
BATCH = P.motion_cones(np.zeros((2, 3)), "left")
#: small budgets: every call of the planner ends quickly
BUDGET = dict(time_limit=0.2, max_nodes=50, max_iterations=2000)
PLAN2 = regrasp.plan(P, seed=0, **BUDGET).to_json()
PLAN3 = regrasp.plan(S3, seed=0, time_limit=2.0).to_json()


def _plan_settings(dimension: int) -> list:
    """Bad planner settings: an unknown key, and every setting with a bad value."""
    out = [{"unknown": 1}, {"": 0}, {"max_nodes": -1}, {"max_nodes": 2**70}, {"seed": -1}, {"seed": 2**64},
           {"time_limit": math.nan}, {"time_limit": -1.0}, {"propagation": "nope"}]
    for k in regrasp.planner_defaults(dimension):
        out += [{k: v} for v in (math.nan, -1, -math.inf, "x", None, 1e300, 2**70, [1.0])]
    return out


def _bad_plans(good: dict) -> list:
    path = good["path"]
    return [{"path": []}, {"path": [{}]}, {"path": [{"pose": [math.nan] * len(path[0]["pose"]), "pusher": None}]},
            {"path": path + [{"pose": path[-1]["pose"], "pusher": "nope"}]}, {"path": "x"}, [path], json.dumps(good),
            {"path": [{"pose": p["pose"][:-1], "pusher": p["pusher"]} for p in path]},
            {"path": [{"pose": [1e300] * len(p["pose"]), "pusher": p["pusher"]} for p in path]}]


#: entry point -> (call(**kwargs) returning plain data, default kwargs, kind of bad values per argument)
ENTRIES = {
    "Scene.motion_cone": (lambda pose, pusher, check_hold: P.motion_cone(pose, pusher, check_hold).generators,
                          dict(pose=Z3, pusher="left", check_hold=True), dict(pose="vec3", pusher="name", check_hold="bool")),
    # the batch's outputs (its `poses` are the input as given, bad rows marked by `status`)
    "Scene.motion_cones": (lambda poses, pusher, strict: vars(P.motion_cones(poses, pusher, strict)) | {"scene": None, "poses": None},
                           dict(poses=np.zeros((2, 3)), pusher="left", strict=False),
                           dict(poses="rows3", pusher="name", strict="bool")),
    "Scene.admissible": (lambda pose: P.admissible(pose), dict(pose=Z3), dict(pose="vec3")),
    "Scene.admissible(rows)": (lambda poses: P.admissible(poses), dict(poses=np.zeros((2, 3))), dict(poses="rows3")),
    "Scene.hold_ratio": (lambda pose: P.hold_ratio(pose), dict(pose=Z3), dict(pose="vec3")),
    "Scene.hold_grip_force": (lambda pose: P.hold_grip_force(pose), dict(pose=Z3), dict(pose="vec3")),
    "Scene.carries_weight": (lambda pose, pusher: P.carries_weight(pose, pusher), dict(pose=Z3, pusher="bottom"),
                             dict(pose="vec3", pusher="name")),
    "Scene.metric_twist": (lambda twist: P.metric_twist(twist), dict(twist=Z3), dict(twist="vec3")),
    "Scene.metric_twist_inv": (lambda scaled: P.metric_twist_inv(scaled), dict(scaled=Z3), dict(scaled="vec3")),
    "Scene.with_grip_force": (lambda force: (lambda s: {"grip": s.grip_force, "rho": s.rho,
                                                        "gf": s.motion_cone(Z3, "left", False).gravity_free_generators,
                                                        "g": s.motion_cone(Z3, "left", False).generators})(
                                  P.with_grip_force(force)), dict(force=20.0), dict(force="scalar")),
    "Scene.scaled": (lambda **kw: (lambda s: {"rho": s.rho, "g": s.motion_cone(Z3, "left", False).generators})(
                         P.scaled(**kw)),
                     dict(finger_friction=1.0, grip=1.0, mass=1.0, pusher_friction=1.0, mode="nominal"),
                     dict(finger_friction="scalar", grip="scalar", mass="scalar", pusher_friction="scalar", mode="name")),
    "Scene.robust": (lambda uncertainty: P.robust(uncertainty).rho, dict(uncertainty={"mass": 0.1}),
                     dict(uncertainty="uncertainty")),
    "Scene.pusher": (lambda name: P.pusher(name), dict(name="left"), dict(name="name")),
    "Scene.from_dict": (lambda d: regrasp.Scene.from_dict(d).name, dict(d={}), dict(d="scalar")),
    "Scene.from_toml": (lambda text: regrasp.Scene.from_toml(text).name, dict(text=""), dict(text="scalar")),
    "Scene3D.from_toml": (lambda text, base: regrasp.Scene3D.from_toml(text, base).name,
                          dict(text=(EXAMPLES / "pivot-3d.toml").read_text(), base=None),
                          dict(text="scalar", base="scalar")),
    "load_scene": (lambda path: regrasp.load_scene(path).name, dict(path=EXAMPLES / "t-shape.toml"), dict(path="path")),
    "planner_defaults": (lambda dimension: {k: v for k, v in regrasp.planner_defaults(dimension).items()
                                            if k != "cost_threshold"}, dict(dimension=2), dict(dimension="count")),
    "MotionCone.contains": (lambda twist: CONE.contains(twist), dict(twist=Z3), dict(twist="vec3")),
    "MotionCone.margin": (lambda twist: CONE.margin(twist), dict(twist=Z3), dict(twist="vec3")),
    "MotionCone.classify": (lambda twist: CONE.classify(twist), dict(twist=Z3), dict(twist="vec3")),
    "MotionCone.project": (lambda twist: CONE.project(twist), dict(twist=Z3), dict(twist="vec3")),
    "MotionCone.project(rows)": (lambda twists: CONE.project(twists), dict(twists=np.zeros((2, 3))), dict(twists="rows3")),
    "MotionCone.project_polyhedral": (lambda twist: CONE.project_polyhedral(twist), dict(twist=Z3), dict(twist="vec3")),
    "MotionCone.contains_polyhedral": (lambda twist: CONE.contains_polyhedral(twist), dict(twist=Z3),
                                       dict(twist="vec3")),
    "MotionCone.grip_force_range": (lambda twist: (lambda r: r if r is None else [r[0]] + ([r[1]] if r[1] != math.inf else []))(
                                        CONE.grip_force_range(twist)), dict(twist=[0.0, 0.01, 0.0]), dict(twist="vec3")),
    "MotionCone.ray": (lambda wrench: CONE.ray(wrench), dict(wrench=[1.0, 0.0, 0.0]), dict(wrench="vec3")),
    "MotionCone.point_pusher_twist": (lambda u: CONE.point_pusher_twist(u), dict(u=[0.0, 0.01]), dict(u="vec2")),
    "GravityFreeCone.margin": (lambda twist: CONE.gravity_free.margin(twist), dict(twist=Z3), dict(twist="vec3")),
    "GravityFreeCone.project": (lambda twist: CONE.gravity_free.project(twist), dict(twist=Z3), dict(twist="vec3")),
    "MotionConeBatch.classify": (lambda twists: BATCH.classify(twists), dict(twists=np.zeros((2, 3))), dict(twists="rows3")),
    "MotionConeBatch.contains": (lambda twists: BATCH.contains(twists), dict(twists=np.zeros((2, 3))), dict(twists="rows3")),
    "MotionConeBatch.margin": (lambda twists: BATCH.margin(twists), dict(twists=np.zeros((2, 3))), dict(twists="rows3")),
    "MotionConeBatch.project": (lambda twists: BATCH.project(twists), dict(twists=np.zeros((2, 3))), dict(twists="rows3")),
    "plan(planar)": (lambda start, goal, settings: regrasp.plan(P, start, goal, **(BUDGET | settings)),
                     dict(start=None, goal=None, settings={}), dict(start="vec3", goal="vec3", settings="settings2")),
    "plan(3-D)": (lambda start, goal, settings: regrasp.plan(S3, start, goal, **(BUDGET | settings)),
                  dict(start=None, goal=None, settings={}), dict(start="vec7", goal="vec7", settings="settings3")),
    "Plan.from_json": (lambda d: regrasp.Plan.from_json(d, P), dict(d=PLAN2), dict(d="plan2")),
    "Plan.load": (lambda path: regrasp.Plan.load(path), dict(path=EXAMPLES / "t-shape.toml"), dict(path="path")),
    "Plan.check": (lambda scene: regrasp.Plan.from_json(PLAN2).check(scene), dict(scene=P), dict(scene="scalar")),
    "planning.validate": (lambda plan, checks: planning.validate(P, plan, checks), dict(plan=PLAN2["path"], checks=8),
                          dict(plan="plan2", checks="count")),
    "sim.simulate_push": (lambda **kw: quasistatic.simulate_push(P, **kw),
                          dict(pose=Z3, pusher="bottom", twist=[0.0, 0.01, 0.0], duration=0.1, dt=0.05, support="points"),
                          dict(pose="vec3", pusher="name", twist="vec3", duration="scalar", dt="scalar", support="name")),
    "sim.problem": (lambda pose, pusher, h: quasistatic.problem(P, pose, pusher, h) and None,
                    dict(pose=Z3, pusher="bottom", h=0.05), dict(pose="vec3", pusher="name", h="scalar")),
    "sim.replay_plan": (lambda plan, speed, dt: quasistatic.replay_plan(P, plan, speed, dt),
                        dict(plan=PLAN2, speed=0.05, dt=0.1), dict(plan="plan2", speed="scalar", dt="scalar")),
    "sim.validate": (lambda **kw: validation.validate(P, **kw), dict(pushes=5, seed=0, engines=("quasistatic",), support="points"),
                     dict(pushes="count", seed="count", engines="scalar", support="name")),
    "control": (lambda **kw: loop.control(P, PLAN2, **kw).to_json(),
                dict(engine="quasistatic", policy="mpc", start_error=Z3, dt=0.1, speed=None, horizon=None, max_time=0.3,
                     noise=0.0, seed=0, pokes=()),
                dict(engine="name", policy="name", start_error="vec3", dt="scalar", speed="scalar", horizon="count",
                     max_time="scalar", noise="scalar", seed="count", pokes="scalar")),
    "reference.approximation_error": (lambda **kw: approx_error.approximation_error(P, **kw),
                                      dict(pusher="left", pose=Z3, samples=50, seed=0),
                                      dict(pusher="name", pose="vec3", samples="count", seed="count")),
    "mujoco.simulate_push": (lambda **kw: mj_push.simulate_push(P, **kw),
                             dict(pose=Z3, pusher="bottom", twist=[0.0, 0.01, 0.0], duration=0.02, record_dt=0.01),
                             dict(pose="vec3", pusher="name", twist="vec3", duration="scalar", record_dt="scalar")),
    "Scene3D.pad_contacts": (lambda pose: S3.pad_contacts(pose), dict(pose=START3), dict(pose="vec7")),
    "Scene3D.quasistatic_problem": (lambda pose, pusher, h: S3.quasistatic_problem(pose, pusher, h) and None,
                                    dict(pose=START3, pusher="ground", h=1.0), dict(pose="vec7", pusher="name", h="scalar")),
    "Scene3D.simulate_push": (lambda **kw: S3.simulate_push(**kw),
                              dict(pose=START3, pusher="ground", twist=[0.0] * 6, duration=0.1, dt=0.05),
                              dict(pose="vec7", pusher="name", twist="vec6", duration="scalar", dt="scalar")),
    "Scene3D.validate_path": (lambda path: S3.validate_path(path), dict(path=PLAN3["path"]), dict(path="plan3")),
    "Scene3D.replay": (lambda **kw: S3.replay(**kw), dict(plan=PLAN3, dt=0.25, feedback=False, max_replans=0, seed=0),
                       dict(plan="plan3", dt="scalar", feedback="bool", max_replans="count", seed="count")),
}


def bad_for(kind: str) -> st.SearchStrategy:
    if kind == "settings2":
        return st.sampled_from(_plan_settings(2))
    if kind == "settings3":
        return st.sampled_from(_plan_settings(3))
    if kind in ("plan2", "plan3"):
        return st.sampled_from(_bad_plans(PLAN2 if kind == "plan2" else PLAN3) + BAD_SCALARS)
    if kind == "uncertainty":
        return st.sampled_from([{"mass": v} for v in BAD_SCALARS] + [{"nope": 0.1}, {}, [0.1], "x"])
    if kind == "path":
        return st.sampled_from(["", "/nonexistent/x.toml", str(EXAMPLES), "/dev/null", "/", 0, None, b"\xff",
                                str(EXAMPLES / "meshes" / "prism.obj"), "x" * 5000])
    if kind == "bool":
        return st.sampled_from([None, "yes", 2, math.nan, [], Weird()])
    return bad_values(kind)


@st.composite
def api_case(draw):
    name = draw(st.sampled_from(sorted(ENTRIES)))
    fn, defaults, kinds = ENTRIES[name]
    arg = draw(st.sampled_from(sorted(kinds)))
    value = draw(bad_for(kinds[arg]))
    return name, arg, value


@pytest.mark.parametrize("name", sorted(ENTRIES))
def test_entry_point_works_with_its_defaults(name):
    """Each entry's default call succeeds: a fuzz case differs from a good call by one argument."""
    fn, defaults, _ = ENTRIES[name]
    if name in ("Scene.from_dict", "Scene.from_toml", "Plan.load"):
        pytest.skip("defaults are bad on purpose")
    run(f"api.defaults.{name}", f"{name}(defaults)", lambda: fn(**defaults), timeout=30)


@fuzz_settings(400, 6000)
@given(case=api_case())
def test_bad_argument(case):
    name, arg, value = case
    fn, defaults, _ = ENTRIES[name]
    kw = dict(defaults, **{arg: value})
    run(f"api.{name}", f"{name}({arg}={value!r:.200})", lambda: fn(**kw))


#: bad output paths, all inside a fresh temporary folder (never a real file of the machine)
SAVE_PATHS = ["missing/sub/plan.json", ".", "", "x" * 300, "dir-as-file", "readonly/plan.json", None, 0, b"\xff"]


@fuzz_settings(20, 300)
@given(rel=st.sampled_from(SAVE_PATHS))
def test_plan_save_to_bad_path(rel, tmp_path_factory):
    base = tmp_path_factory.mktemp("save")
    (base / "dir-as-file").mkdir()
    (base / "readonly").mkdir(mode=0o500)
    path = rel if not isinstance(rel, str) else str(base / rel) if rel else rel
    p = regrasp.Plan.from_json(PLAN2)
    run("api.Plan.save", f"Plan.save({rel!r:.200})", lambda: p.save(path) and None)
