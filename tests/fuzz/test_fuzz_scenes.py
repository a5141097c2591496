"""Fuzz: every bundled example scene (planar and 3-D), mutated, through every loader; a scene
that loads is exercised a little (cones, hold ratio, a short plan)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

import regrasp

from .harness import fuzz_settings, run
from .strategies import EXAMPLES, PLANAR, SPATIAL, mutated_scene, to_toml


#: a budget small enough that a plan of a mutated scene ends quickly
PLAN_BUDGET = dict(time_limit=0.2, max_nodes=40, seed=0)


def test_emitter_round_trips_every_example():
    """The TOML emitter writes back what tomllib read (the mutations rely on it)."""
    import tomllib

    for name in PLANAR + SPATIAL:
        d = tomllib.loads((EXAMPLES / name).read_text())
        assert tomllib.loads(to_toml(d)) == d, name


def test_unmutated_examples_load():
    for name in PLANAR:
        assert regrasp.Scene.from_toml(to_toml(__import__("tomllib").loads((EXAMPLES / name).read_text())))
    for name in SPATIAL:
        assert regrasp.Scene3D.from_toml((EXAMPLES / name).read_text(), EXAMPLES)


def exercise_planar(scene: regrasp.Scene) -> dict:
    """A little of everything a loaded planar scene answers, as plain data to check for NaN."""
    out = {"length": scene.length, "mass": scene.mass, "com": scene.com, "rho": scene.rho,
           "outline": scene.outline, "pushers": scene.pushers}
    task = scene.task
    pose = task.start if task is not None else np.zeros(3)
    for name in scene.pusher_names[:2]:
        try:
            cone = scene.motion_cone(pose, name, check_hold=False)
        except (regrasp.ArgumentError, regrasp.GraspError):
            continue
        g = cone.generators
        out[f"cone.{name}"] = {"generators": g, "gravity_free": cone.gravity_free_generators,
                               "contains": cone.contains([0.01, 0.0, 0.0]), "margin": cone.margin([0.0, 0.01, 0.0]),
                               "project": cone.project([0.01, 0.01, 0.1])}
        r = cone.grip_force_range(cone.central_twist())
        out[f"range.{name}"] = None if r is None else [r[0]] + ([] if r[1] == float("inf") else [r[1]])
    try:
        out["hold"] = scene.hold_ratio(pose)
    except (regrasp.ArgumentError, regrasp.GraspError):
        pass
    if task is not None:
        out["plan"] = regrasp.plan(scene, **PLAN_BUDGET)
    return out


def exercise_spatial(scene: regrasp.Scene3D) -> dict:
    start, goal, tol = scene.task
    out = {"length": scene.length, "mass": scene.mass, "inertia": scene.inertia, "task": [start, goal, tol]}
    try:
        out["pads"] = scene.pad_contacts(start)
    except regrasp.ArgumentError:
        pass
    out["plan"] = regrasp.plan(scene, **PLAN_BUDGET)
    return out


def load_planar(d: dict, loader: str) -> regrasp.Scene:
    if loader == "dict":
        return regrasp.Scene.from_dict(d)
    return regrasp.Scene.from_toml(to_toml(d))


@fuzz_settings(150, 6000)
@given(case=mutated_scene(PLANAR), loader=st.sampled_from(["toml", "dict"]))
def test_mutated_planar_scene(case, loader):
    name, d, what, must = case
    repro = f"{name} via {loader}: {what}"
    scene = run("scene.planar.load", repro, lambda: load_planar(d, loader), reject=must)
    if scene is not None:
        run("scene.planar.exercise", repro, lambda: exercise_planar(scene))


@fuzz_settings(80, 4000)
@given(case=mutated_scene(SPATIAL))
def test_mutated_spatial_scene(case):
    name, d, what, must = case
    repro = f"{name}: {what}"
    scene = run("scene.spatial.load", repro, lambda: regrasp.Scene3D.from_toml(to_toml(d), EXAMPLES), reject=must)
    if scene is not None:
        run("scene.spatial.exercise", repro, lambda: exercise_spatial(scene))


@fuzz_settings(40, 500)
@given(case=mutated_scene(PLANAR + SPATIAL))
def test_mutated_scene_file(case, tmp_path_factory):
    """`load_scene` on a mutated file (both dimensions, told apart by the file)."""
    name, d, what, must = case
    p = tmp_path_factory.mktemp("scene") / name
    (p.parent / "meshes").symlink_to(EXAMPLES / "meshes")  # the examples' meshes, relative to the file
    p.write_text(to_toml(d))
    run("scene.load_scene", f"{name}: {what}", lambda: regrasp.load_scene(p), reject=must)
