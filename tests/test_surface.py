"""Non-prehensile motion cones: an object on a horizontal or inclined plane."""

import numpy as np
import pytest

import regrasp

from .conftest import EXAMPLES


def incline_scene(incline, friction=0.35):
    text = (EXAMPLES / "block-on-incline.toml").read_text()
    text = text.replace("incline = 0.2", f"incline = {incline}").replace("friction = 0.35", f"friction = {friction}")
    return regrasp.Scene.from_toml(text)


def test_horizontal_plane_cone_is_exactly_polyhedral():
    sc = incline_scene(0.0)
    for p in ("finger", "paddle"):
        c = sc.motion_cone([0.01, -0.02, 0.4], p)
        assert np.allclose(c.generators, c.gravity_free_generators, atol=1e-12)
    # Mason: a point pusher's cone is a fan of 2 twists; Lynch & Mason: a line pusher's is solid
    assert len(sc.motion_cone([0, 0, 0], "finger").generators) == 2
    assert sc.motion_cone([0, 0, 0], "paddle").is_line_pusher


def test_horizontal_cone_matches_the_ellipsoidal_closed_form():
    # support at the COM, J_s = I: a pusher force f at r moves the object along A [f, r x f]
    sc = incline_scene(0.0).with_limit_surface("ellipsoid")
    c = sc.motion_cone([0, 0, 0], "paddle")
    A, Js, wg = c._core.support_matrices
    assert np.allclose(Js, np.eye(3)) and np.allclose(wg, 0)
    for g, e in zip(c.generators, c._core.pusher_edges):
        v = A @ e
        assert np.allclose(g / np.linalg.norm(g), v / np.linalg.norm(v), atol=1e-10)
    # a push through the COM along the normal translates the block without turning it
    t = c.project([0.0, 1.0, 0.0])
    assert c.contains([0.0, 1.0, 0.0]) and np.allclose(t, [0, 1, 0])


def test_fitted_footprint_limit_surface_has_the_right_size():
    # uniform 50 x 80 mm footprint: max friction force mu m g cos(a); max moment about the
    # centre mu m g cos(a) * mean distance to the centre (0.0258 m for this rectangle)
    sc = incline_scene(0.0)
    A, _, _ = sc.motion_cone([0, 0, 0], "paddle")._core.support_matrices
    fmax = 0.35 * 0.130 * 9.81
    assert 1 / np.sqrt(A[0, 0]) == pytest.approx(fmax, rel=0.05)
    w, h = 0.05, 0.08
    xs, zs = np.meshgrid(np.linspace(-w / 2, w / 2, 401), np.linspace(-h / 2, h / 2, 641))
    mean_r = np.hypot(xs, zs).mean()
    tau_max = 1 / np.sqrt(np.linalg.inv(np.linalg.inv(A))[2, 2])
    assert tau_max == pytest.approx(fmax * mean_r, rel=0.1)
    # the exact surface (the default) has that moment itself, and the force for a translation
    c = sc.motion_cone([0, 0, 0], "paddle")
    assert sc.limit_surface == "true"
    assert c.classify([0.0, 0.0, 1.0]).support_wrench[2] == pytest.approx(fmax * mean_r, rel=2e-3)
    assert c.classify([0.0, 1.0, 0.0]).support_wrench == pytest.approx([0.0, fmax, 0.0], abs=1e-3 * fmax)


def test_incline_bends_the_cone_and_levels_off_as_it_flattens():
    errs = []
    for a in (0.3, 0.1, 0.03, 0.01):
        sc = incline_scene(a)
        c = sc.motion_cone([0, 0, 0], "paddle")
        G, GF = sc.metric_twist(c.generators), sc.metric_twist(c.gravity_free_generators)
        errs.append(np.arctan2(np.linalg.norm(np.cross(G, GF), axis=1), np.sum(G * GF, axis=1)).max())
    assert errs[0] > 0.05, errs
    assert all(b < a for a, b in zip(errs, errs[1:])), errs
    assert errs[-1] < 0.15 * errs[1], errs  # ~ tan(incline)


def test_object_sliding_down_by_itself_is_rejected():
    with pytest.raises(regrasp.SceneError) as e:
        incline_scene(0.4, friction=0.3)  # tan 0.4 = 0.42 > 0.3
    assert e.value.field == "surface.friction"


def test_grip_force_is_not_defined_on_a_surface():
    c = incline_scene(0.2).motion_cone([0, 0, 0], "paddle")
    with pytest.raises(regrasp.ArgumentError):
        c.grip_force_range([0.0, 1.0, 0.0])
