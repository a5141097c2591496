"""Property tests of the motion cone through the Python API, against checks written here from
the raw scene values (scipy LP over contact forces, the numpy reference, limits, invariances)."""

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st
from scipy.optimize import linprog

import regrasp
from regrasp.reference.cones import RefParams, generators_numpy

from .conftest import block_scenes, twist_dirs

SETTINGS = settings(max_examples=80, deadline=None, suppress_health_check=[HealthCheck.too_slow])


def load(d, limit_surface=None):
    """The scene of ``d``, on ``limit_surface`` when given (the ellipsoid for the closed forms)."""
    if limit_surface is not None:
        d = {**d, "grasp": {**d["grasp"], "limit_surface": limit_surface}}
    try:
        return regrasp.Scene.from_dict(d)
    except regrasp.SceneError as e:
        assume(e.field != "grasp.force")  # random grasp too weak: rejected at load, by design
        raise


def start_cone(d, limit_surface=None):
    """The scene of ``d`` and the motion cone of its pusher at the task's start."""
    sc = load(d, limit_surface)
    return sc, sc.motion_cone(d["task"]["start"], "p")


def required_pusher_wrench(d, twist, surface="ellipsoid"):
    """Pusher wrench needed for `twist`, from the raw scene dict: the pad's load on the ellipsoid
    (eq 3.10 at a circular pad), or (``"true"``) summed over a 300 × 300 grid of points of the
    pad (Coulomb at each, uniform pressure), minus gravity."""
    q = np.array(d["task"]["start"])
    c, s = np.cos(q[2]), np.sin(q[2])
    R = np.array([[c, -s], [s, c]])
    pad = R.T @ -q[:2]
    S = 2 * d["grasp"]["force"] * d["grasp"]["friction"]
    r = d["grasp"]["pad_radius"]
    v = np.asarray(twist, float)
    if surface == "true":
        xs = (np.arange(300) + 0.5) / 300 * 2 * r - r
        X, Y = np.meshgrid(xs, xs)
        inside = X**2 + Y**2 < r * r
        P = pad + np.c_[X[inside], Y[inside]] @ R  # object-frame points of the pad
        vel = v[:2] + v[2] * np.c_[-P[:, 1], P[:, 0]]
        u = vel / np.linalg.norm(vel, axis=1)[:, None]
        f_pad = S * u.mean(axis=0)
        tau = S * np.mean(P[:, 0] * u[:, 1] - P[:, 1] * u[:, 0])
    else:
        k = 0.6 * r
        vel = R @ (v[:2] + v[2] * np.array([-pad[1], pad[0]]))
        den = np.sqrt(vel @ vel + (k * v[2]) ** 2)
        f_pad = R.T @ vel * (S / den)
        tau = S * k * k * v[2] / den + (pad[0] * f_pad[1] - pad[1] * f_pad[0])
    gd, g = np.array(d["gravity"]["direction"]), d["gravity"]["g"]
    fg = R.T @ gd * d["object"]["mass"] * g
    com = np.array(d["object"]["com"])
    wg = np.array([fg[0], fg[1], com[0] * fg[1] - com[1] * fg[0]])
    return np.array([f_pad[0], f_pad[1], tau]) - wg


def lp_sticks(d, twist, surface="ellipsoid") -> bool:
    """Is there a set of pusher contact forces inside their Coulomb cones giving the wrench?"""
    w = required_pusher_wrench(d, twist, surface)
    p = d["pushers"][0]
    n = np.array(p["normal"], float)
    t = np.array([-n[1], n[0]])
    cols = []
    for r in p["points"]:
        for dvec in (n, t):
            cols.append([dvec[0], dvec[1], r[0] * dvec[1] - r[1] * dvec[0]])
    A_eq = np.array(cols).T
    m = len(p["points"])
    A_ub = []  # |f_t| <= mu f_n at each point
    for i in range(m):
        for sign in (1, -1):
            row = np.zeros(2 * m)
            row[2 * i + 1] = sign
            row[2 * i] = -p["friction"]
            A_ub.append(row)
    bounds = [(0, None) if j % 2 == 0 else (None, None) for j in range(2 * m)]
    scale = np.abs(w).max()
    res = linprog(np.zeros(2 * m), A_ub=np.array(A_ub), b_ub=np.zeros(len(A_ub)), A_eq=A_eq, b_eq=w / scale,
                  bounds=bounds, method="highs")
    return res.status == 0


@SETTINGS
@given(block_scenes(), st.integers(0, 2**31), st.sampled_from(["ellipsoid", "true"]))
def test_exact_test_agrees_with_lp_over_contact_forces(d, seed, surface):
    """Against the LP over the pusher's contact forces with the pad's load from the same limit
    surface: the ellipsoid's closed form, or the true surface summed over the pad's points (whose
    grid is good to about 1e-3 of the load: margins closer to 0 than 2e-3 are not compared)."""
    sc, cone = start_cone(d, surface)
    rng = np.random.default_rng(seed)
    tw = twist_dirs(20, sc.length, rng)
    # and twists near the cone: generator mixes plus noise
    g = cone.generators
    tw = np.vstack([tw, rng.uniform(0, 1, (20, len(g))) @ g + 0.1 * twist_dirs(20, sc.length, rng)])
    margins = cone.margin(tw)
    band = 1e-6 if surface == "ellipsoid" else 2e-3
    for t, m in zip(tw, margins):
        if abs(m) < band:
            continue
        assert (m >= 0) == lp_sticks(d, t, surface), (t, m)


@SETTINGS
@given(block_scenes())
def test_generators_balance_forces_on_the_friction_cone_edges(d):
    sc, cone = start_cone(d, "ellipsoid")
    edges = cone._core.pusher_edges
    for g, e in zip(cone.generators, edges):
        c = cone.classify(g)
        assert abs(c.margin) < 1e-7
        wp = required_pusher_wrench(d, g)  # recomputed independently
        assert np.allclose(wp, c.pusher_wrench, rtol=1e-7, atol=1e-9 * np.abs(wp).max())
        cosang = wp @ e / np.linalg.norm(wp) / np.linalg.norm(e)
        assert cosang > 1 - 1e-10, "pusher wrench along the friction-cone edge"


@SETTINGS
@given(block_scenes())
def test_rust_generators_match_the_numpy_reference(d):
    sc = load(d, "ellipsoid")
    q = d["task"]["start"]
    ref = generators_numpy(RefParams.from_scene(sc, "p"), q)
    assert np.allclose(sc.motion_cone(q, "p").generators, ref, atol=1e-10)


@SETTINGS
@given(block_scenes(g=0.0), st.integers(0, 2**31))
def test_without_gravity_exact_equals_polyhedral(d, seed):
    sc, cone = start_cone(d, "ellipsoid")
    assert np.allclose(cone.generators, cone.gravity_free_generators, atol=1e-12)
    if cone.is_line_pusher:
        tw = twist_dirs(200, sc.length, np.random.default_rng(seed))
        m = cone.margin(tw)
        keep = np.abs(m) > 1e-7
        assert np.array_equal(cone.contains(tw)[keep], cone.contains_polyhedral(tw)[keep])


@SETTINGS
@given(block_scenes(line=True))
def test_zero_pusher_friction_collapses_the_cone(d):
    d["pushers"][0]["friction"] = 0.0
    sc, cone = start_cone(d)
    g = cone.generators
    assert np.allclose(g[0], g[1]) and np.allclose(g[2], g[3])
    tw = twist_dirs(500, sc.length, np.random.default_rng(0))
    assert not cone.contains(tw).any(), "a cone without interior contains no random twist"


@SETTINGS
@given(block_scenes())
def test_large_grip_force_tends_to_gravity_free_cone(d):
    sc = load(d)
    q = d["task"]["start"]
    errs = []
    for f in (1, 10, 100, 1000):
        c = sc.with_grip_force(sc.grip_force * f).motion_cone(q, "p")
        a, b = sc.metric_twist(c.generators), sc.metric_twist(c.gravity_free_generators)
        ang = np.arctan2(np.linalg.norm(np.cross(a, b), axis=1), np.sum(a * b, axis=1))
        errs.append(ang.max())
    assert all(e2 <= e1 * (1 + 1e-6) + 1e-12 for e1, e2 in zip(errs, errs[1:])), errs
    assert errs[-1] <= 0.2 * errs[-2] + 1e-7, errs


@SETTINGS
@given(block_scenes(), st.floats(-0.05, 0.05), st.floats(-0.05, 0.05), st.floats(-3, 3), st.integers(0, 2**31))
def test_invariant_under_a_rigid_change_of_object_frame(d, tx, tz, phi, seed):
    sc = load(d)
    c, s = np.cos(phi), np.sin(phi)
    Rh, th = np.array([[c, -s], [s, c]]), np.array([tx, tz])
    mv = lambda p: (Rh @ np.asarray(p) + th).tolist()  # noqa: E731
    d2 = {**d, "object": {**d["object"]}, "pushers": [dict(d["pushers"][0])], "task": dict(d["task"])}
    d2["object"]["outline"] = [mv(p) for p in d["object"]["outline"]]
    d2["object"]["com"] = mv(d["object"]["com"])
    d2["pushers"][0]["points"] = [mv(p) for p in d["pushers"][0]["points"]]
    d2["pushers"][0]["normal"] = (Rh @ np.asarray(d["pushers"][0]["normal"])).tolist()
    q = np.array(d["task"]["start"])
    R = np.array([[np.cos(q[2]), -np.sin(q[2])], [np.sin(q[2]), np.cos(q[2])]])
    q2 = np.r_[q[:2] - R @ Rh.T @ th, q[2] - phi]
    d2["task"]["start"] = d2["task"]["goal"] = q2.tolist()
    sc2 = regrasp.Scene.from_dict(d2)

    def to2(v):
        lin = Rh @ v[:2] - v[2] * np.array([-th[1], th[0]])
        return np.r_[lin, v[2]]

    c1, c2 = sc.motion_cone(q, "p"), sc2.motion_cone(q2, "p")
    for g1, g2 in zip(c1.generators, c2.generators):
        a = to2(g1)
        assert np.allclose(a / np.linalg.norm(a), g2 / np.linalg.norm(g2), atol=1e-8)
    tw = twist_dirs(50, sc.length, np.random.default_rng(seed))
    m1 = c1.margin(tw)
    m2 = c2.margin(np.array([to2(t) for t in tw]))
    keep = np.abs(m1) > 1e-7
    assert np.array_equal(m1[keep] >= 0, m2[keep] >= 0)
    assert np.allclose(m1, m2, atol=1e-8), "the margin is frame-invariant too"


@SETTINGS
@given(block_scenes(), st.integers(0, 2**31))
def test_projection_is_feasible_and_closest(d, seed):
    sc, cone = start_cone(d)
    rng = np.random.default_rng(seed)
    M = sc.metric_twist
    for t in twist_dirs(5, sc.length, rng):
        p = cone.project(t)
        if np.linalg.norm(M(p)) > 0:
            assert cone.margin(p) > -1e-7
        # no sampled feasible twist is closer
        for _ in range(100):
            wp = rng.uniform(0, 1, len(cone.generators)) ** 3 @ cone._core.pusher_edges
            u = cone.ray(wp)
            u = u * max(0.0, M(u) @ M(t))
            assert np.linalg.norm(M(t - p)) <= np.linalg.norm(M(t - u)) + 1e-9


def test_grip_force_range_brackets_the_stable_pushes(block):
    q = block.task.start
    cone = block.motion_cone(q, "left")
    t = cone.central_twist()
    lo, hi = cone.grip_force_range(t)
    assert 0 < lo < block.grip_force and hi == np.inf
    assert block.with_grip_force(lo * 1.01).motion_cone(q, "left").contains(t)
    assert not block.with_grip_force(lo * 0.99).motion_cone(q, "left").contains(t)
    # a push from below carries the weight: stable at any grip force that holds the object
    b = block.motion_cone(q, "bottom")
    lo_b, _ = b.grip_force_range(b.central_twist())
    assert lo_b == pytest.approx(block.hold_grip_force(q), rel=1e-6)


def test_point_pusher_twist_sticks_and_balances_moments():
    sc = regrasp.Scene.load(__import__("tests.conftest", fromlist=["EXAMPLES"]).EXAMPLES / "block-xztheta.toml")
    cone = sc.motion_cone([0, 0, 0], "corner")
    r = sc.pusher("corner").points[0]
    for ang in np.linspace(0.3, 2.8, 9):
        u = np.array([np.cos(ang), np.sin(ang)])
        t = cone.point_pusher_twist(u)
        assert t is not None
        # the contact point moves along u
        vp = t[:2] + t[2] * np.array([-r[1], r[0]])
        assert np.allclose(vp / np.linalg.norm(vp), u, atol=1e-9)
        # the required wrench passes through the contact point (no moment about it)
        w = cone.classify(t).pusher_wrench
        assert abs(w[2] - (r[0] * w[1] - r[1] * w[0])) < 1e-9 * np.abs(w).max()


def test_grasp_that_cannot_hold_is_an_error_never_a_nan(block):
    weak = block.with_grip_force(0.5)
    with pytest.raises(regrasp.GraspError) as e:
        weak.motion_cone([0, 0, 0], "left")
    assert "cannot hold" in str(e.value) and e.value.field == "grasp.force"
    cone = weak.motion_cone([0, 0, 0], "left", check_hold=False)
    assert np.isfinite(cone.gravity_free_generators).all()
    lo, hi = cone.grip_force_range(cone.central_twist())
    assert lo > 0.5 and np.isfinite(lo)
    with pytest.raises(regrasp.GraspError):
        cone.contains([0, 1, 0])
