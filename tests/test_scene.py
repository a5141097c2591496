import json
import subprocess
import sys

import numpy as np
import pytest

import regrasp

from .conftest import EXAMPLES, block_dict


PLANAR = [p for p in sorted(EXAMPLES.glob("*.toml")) if "dimension = 3" not in p.read_text()]


@pytest.mark.parametrize("path", PLANAR, ids=lambda p: p.stem)
def test_every_example_loads_and_gives_cones(path):
    sc = regrasp.Scene.load(path)
    q = sc.task.start if sc.task is not None else np.zeros(3)
    for p in sc.pusher_names:
        cone = sc.motion_cone(q, p)
        g = cone.generators
        assert np.isfinite(g).all() and len(g) == 2 * len(sc.pusher(p).points)
        assert all(abs(cone.margin(x)) < 1e-7 for x in g)


@pytest.mark.parametrize(
    "edit, field",
    [
        (lambda d: d["object"].update(mass=-1.0), "object.mass"),
        (lambda d: d["object"].pop("mass"), "object.mass"),
        (lambda d: d["grasp"].update(force=0.0), "grasp.force"),
        (lambda d: d["grasp"].update(friction=-0.1), "grasp.friction"),
        (lambda d: d["grasp"].update(pad_radius=-0.1), "grasp.pad_radius"),
        (lambda d: d["pushers"][0].update(friction=-0.2), "pushers[0].friction"),
        (lambda d: d["object"].update(outline=[[0, 0], [0.05, 0.08], [0.05, 0], [0, 0.08]]), "object.outline"),
        (lambda d: d["pushers"][0].update(points=[[-0.03, 0.0]]), "pushers[0].points[0]"),
        (lambda d: d["pushers"][0].update(normal=[-1.0, 0.0]), "pushers[0].normal"),
        (lambda d: d["gravity"].update(direction=[0.0, -2.0]), "gravity.direction"),
        (lambda d: d["task"].update(goal=[0.03, 0.0, 0.0]), "task.goal"),
        (lambda d: d["task"].update(tolerance=[1e-3, 1e-3, 0.0]), "task.tolerance[2]"),
        (lambda d: d["object"].update(mass=5.0), "grasp.force"),
        (lambda d: d["object"].update(mass=float("nan")), "object.mass"),
        (lambda d: d.pop("task"), "task"),
    ],
)
def test_invalid_scenes_name_the_field(edit, field):
    d = block_dict()
    edit(d)
    with pytest.raises(regrasp.SceneError) as e:
        regrasp.Scene.from_dict(d)
    assert e.value.field == field, str(e.value)
    assert field in str(e.value)


def test_unknown_keys_are_rejected():
    d = block_dict()
    d["grasp"]["frcition"] = 0.5
    with pytest.raises(regrasp.SceneError) as e:
        regrasp.Scene.from_dict(d)
    assert "frcition" in str(e.value)


def test_missing_file_is_an_argument_error(tmp_path):
    with pytest.raises(regrasp.ArgumentError) as e:
        regrasp.Scene.load(tmp_path / "none.toml")
    assert e.value.field == "path"


def test_non_convex_admissible_set():
    t = regrasp.Scene.load(EXAMPLES / "t-shape.toml")
    # pad at object point c: pose -c for theta = 0
    assert t.admissible([0.0, 0.02, 0.0])  # in the stem
    assert t.admissible([-0.025, -0.03, 0.0])  # in the bar
    assert not t.admissible([-0.025, 0.0, 0.0])  # in the notch between bar and stem


def run_cli(*args):
    return subprocess.run([sys.executable, "-m", "regrasp.cli", *args], capture_output=True, text=True)


def test_cli_cone_json_and_plot(tmp_path):
    png = tmp_path / "cone.png"
    r = run_cli("cone", str(EXAMPLES / "block-low-friction.toml"), "--pose", "0.002,0.003,0.05", "--pusher",
                "bottom", "--json", "--plot", str(png))
    assert r.returncode == 0, r.stderr
    out = json.loads(r.stdout)
    for k in ("pusher", "pose", "generators", "gravity_free_generators", "min_grip_force"):
        assert k in out
    assert np.array(out["generators"]).shape == (4, 3)
    assert out["min_grip_force"] > 0
    assert png.stat().st_size > 10_000


def test_cli_exit_codes(tmp_path):
    ex = str(EXAMPLES / "block-low-friction.toml")
    assert run_cli("cone", ex, "--pose", "0,0", "--pusher", "left").returncode == 2
    assert run_cli("cone", ex, "--pose", "0,0,0", "--pusher", "nope").returncode == 2
    assert run_cli("cone", ex, "--pose", "0.05,0,0", "--pusher", "left").returncode == 2
    bad = tmp_path / "bad.toml"
    bad.write_text((EXAMPLES / "block-low-friction.toml").read_text().replace("mass = 0.130", "mass = -1"))
    r = run_cli("cone", str(bad), "--pose", "0,0,0", "--pusher", "left")
    assert r.returncode == 2 and "object.mass" in r.stderr
    # a light grip holds the task poses but not a pose with the pad far from the COM
    weak = tmp_path / "weak.toml"
    weak.write_text((EXAMPLES / "block-low-friction.toml").read_text().replace("force = 20.0", "force = 4.0"))
    r = run_cli("cone", str(weak), "--pose", "0.0175,0,0", "--pusher", "left")
    assert r.returncode == 1 and "cannot hold" in r.stderr, r.stderr


def test_approximation_report_shows_the_polyhedral_error():
    from regrasp.reference.approx_error import approximation_report

    sc = regrasp.Scene.load(EXAMPLES / "block-xztheta.toml")
    rows = approximation_report([sc], (5.0, 80.0), samples=4000)
    by = {(r["pusher"], r["grip_force"]): r for r in rows}
    # point pushers: the generators bound exactly the pusher motions that stick
    assert by[("corner", 5.0)]["false_inside"] == 0 and by[("corner", 5.0)]["false_outside"] == 0
    # line pushers: the error shrinks as the grip force grows (gravity matters less)
    for p in ("left", "bottom"):
        e5 = by[(p, 5.0)]["false_inside"] + by[(p, 5.0)]["false_outside"]
        e80 = by[(p, 80.0)]["false_inside"] + by[(p, 80.0)]["false_outside"]
        assert e80 < e5


def test_views_pickle_in_the_order_they_were_taken():
    import pickle

    s = regrasp.Scene.load(EXAMPLES / "block-low-friction.toml")
    for v in (s.scaled(mass=2.0).with_grip_force(7.0), s.with_grip_force(7.0).scaled(grip=2.0), s.robust({"mass": 0.2}).with_grip_force(9.0)):
        w = pickle.loads(pickle.dumps(v))
        assert (w.grip_force, w.rho, w.mode) == (v.grip_force, v.rho, v.mode)
