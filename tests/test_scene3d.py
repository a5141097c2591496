"""3-D scenes and their quasi-static simulation."""

import json
import subprocess
import sys

import numpy as np
import pytest

import regrasp
from regrasp.reference import mncp as mncp_reference

from .conftest import EXAMPLES

IDENTITY = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0]


def test_examples_load_with_mass_properties():
    b = regrasp.Scene3D.load(EXAMPLES / "block-3d.toml")
    # box 50 x 12 x 80 mm, 0.13 kg: I_zz = m (a² + b²) / 12
    assert b.inertia[2, 2] == pytest.approx(0.13 * (0.05**2 + 0.012**2) / 12)
    p = regrasp.Scene3D.load(EXAMPLES / "prism-3d.toml")
    v, t = p.mesh()
    assert v.shape == (6, 3) and t.shape == (8, 3)
    # prism: a triangular face of each pad, 8 ring points on each
    assert [len(x) for x in p.pad_contacts(IDENTITY)] == [8, 8]


def test_3d_forward_solves_meet_constraints_and_agree_with_ipopt():
    s = regrasp.Scene3D.load(EXAMPLES / "block-3d.toml")
    prob = s.quasistatic_problem(IDENTITY, "ground")
    for u in ([0.0, 0.0, 0.01, 0.0, 0.0, 0.0], [0.005, 0.0, 0.01, 0.0, 0.3, 0.0], [0.0, 0.004, 0.01, 0.0, 0.0, 0.2]):
        fast = prob.solve_forward(u)
        assert fast["max_residual"] < 1e-6, fast["residuals"]
        ref = mncp_reference.solve(prob, pusher_twist=u)
        assert ref.max_residual < 1e-6
        assert np.allclose(fast["twist"], ref.twist, atol=1e-6)


def test_3d_pushes():
    s = regrasp.Scene3D.load(EXAMPLES / "block-3d.toml")
    # lifting with the ground patch sticks: the object moves with it
    tr = s.simulate_push(IDENTITY, "ground", [0, 0, 0.01, 0, 0, 0], 0.5, 0.05)
    assert np.allclose(tr["pose"][-1][:3], [0, 0, 0.005], atol=1e-9)
    assert (tr["pusher_sticking"] == 4).all() and tr["residual"].max() < 1e-6
    # the side pusher cannot lift: it slides up the face
    tr = s.simulate_push(IDENTITY, "left", [0, 0, 0.01, 0, 0, 0], 0.3, 0.05)
    assert abs(tr["pose"][-1][2]) < 1e-3 and tr["pusher_slip"].max() > 5e-3


def test_bad_3d_scenes_name_the_field(tmp_path):
    text = (EXAMPLES / "block-3d.toml").read_text()
    cases = {
        "object.mass": text.replace("mass = 0.130", "mass = -1"),
        "pushers[0].points[0]": text.replace("[[-0.025, 0.0, -0.03]", "[[-0.03, 0.0, -0.03]"),
        "pushers[1].normal": text.replace("normal = [0.0, 0.0, 1.0]", "normal = [0.0, 0.0, -1.0]"),
        "task.start": text.replace("start = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0]", "start = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]"),
        "object.mesh": text.replace('shape = "box"', 'shape = "mesh"\nmesh = "nope.obj"').replace("size = [0.05, 0.012, 0.08]\n", ""),
    }
    for field, t in cases.items():
        with pytest.raises(regrasp.SceneError) as e:
            regrasp.Scene3D.from_toml(t, tmp_path)
        assert e.value.field == field, str(e.value)


def test_sphere_and_plane_fields_are_checked(tmp_path):
    text = (EXAMPLES / "ball-roll-3d.toml").read_text()
    cases = {
        "object.radius": text.replace("radius = 0.035", "radius = -0.035"),
        "pushers[0].points": text.replace("plane = true", "plane = true\npoints = [[0.0, 0.0, -0.035]]"),
    }
    box = (EXAMPLES / "block-3d.toml").read_text().replace('shape = "box"', 'shape = "box"\nradius = 0.02')
    cases_box = {"object.radius": box}
    for field, t in {**cases, **cases_box}.items():
        with pytest.raises(regrasp.SceneError) as e:
            regrasp.Scene3D.from_toml(t, tmp_path)
        assert e.value.field == field, str(e.value)
    s = regrasp.Scene3D.from_toml(text)
    # a solid sphere: I = (2/5) m r^2; pads are rings of 8 points on the tangent planes
    assert s.inertia[0, 0] == pytest.approx(0.4 * 0.058 * 0.035**2)
    assert [len(x) for x in s.pad_contacts(IDENTITY)] == [8, 8]
    # the floor touches the ball at its lowest point, wherever the ball has turned
    q = [0, 0, 0, np.cos(0.3), 0, np.sin(0.3), 0]
    pts, n, _ = s._core.pusher_spec("floor", q)
    from scipy.spatial.transform import Rotation

    assert np.allclose(Rotation.from_quat([0, np.sin(0.3), 0, np.cos(0.3)]).apply(pts[0]), [0, 0, -0.035], atol=1e-12)


def test_push_cli_3d():
    r = subprocess.run([sys.executable, "-m", "regrasp.cli", "push", str(EXAMPLES / "prism-3d.toml"), "--pose",
                        "0,0,0,1,0,0,0", "--pusher", "ground", "--twist", "0,0,0.01,0,0,0", "--duration", "0.3",
                        "--json"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    out = json.loads(r.stdout)
    assert out["pusher_sticking_share"] == 1.0 and out["max_residual"] < 1e-6
