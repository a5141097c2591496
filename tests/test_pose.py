"""The pose helpers (regrasp.pose) against independent constructions: Rodrigues' formula for
the rotation matrix, axis-angle for slerp, scipy's Rotation where installed."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from regrasp import _core
from regrasp.pose import (planar_compose, planar_inverse, planar_quat, planar_rotate, planar_to_spatial, quat_angle,
                          quat_from_matrix, quat_matrix, quat_rotate, slerp, tangents, turn_onto, twist_between,
                          twist_in)

unit = st.lists(st.floats(-1, 1), min_size=3, max_size=3).filter(lambda v: np.linalg.norm(v) > 1e-3) \
    .map(lambda v: np.asarray(v) / np.linalg.norm(v))
angles = st.floats(-np.pi, np.pi)


def axis_angle(axis, th) -> np.ndarray:
    """The quaternion of a turn by ``th`` about unit ``axis``."""
    return np.r_[np.cos(th / 2), np.sin(th / 2) * np.asarray(axis, float)]


def rodrigues(axis, th) -> np.ndarray:
    """The rotation matrix of a turn by ``th`` about unit ``axis`` (Rodrigues' formula)."""
    K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + np.sin(th) * K + (1 - np.cos(th)) * K @ K


def same_rotation(a, b, tol=1e-9) -> bool:
    return min(np.abs(a - b).max(), np.abs(a + b).max()) < tol


@settings(max_examples=200, deadline=None)
@given(unit, angles)
def test_matrix_is_rodrigues_and_from_matrix_inverts_it(axis, th):
    q = axis_angle(axis, th)
    R = quat_matrix(q)
    assert np.allclose(R, rodrigues(axis, th), atol=1e-12)
    assert np.allclose(R @ R.T, np.eye(3), atol=1e-12) and np.linalg.det(R) == pytest.approx(1)
    back = quat_from_matrix(R)
    assert back[0] >= 0 and same_rotation(back, q)


@settings(max_examples=200, deadline=None)
@given(unit, st.floats(0, 1e-6))
def test_from_matrix_near_a_half_turn(axis, eps):
    """Near 180 degrees the trace is about -1: the method must not divide by a vanishing w."""
    for th in (np.pi - eps, np.pi, -np.pi + eps):
        q = axis_angle(axis, th)
        assert same_rotation(quat_from_matrix(rodrigues(axis, th)), q, 1e-9)


@settings(max_examples=100, deadline=None)
@given(unit, angles, st.lists(st.floats(-1, 1), min_size=3, max_size=3))
def test_rotate_is_the_matrix_and_ignores_the_scale(axis, th, v):
    q = axis_angle(axis, th)
    assert np.allclose(quat_rotate(3.0 * q, v), quat_matrix(q) @ v, atol=1e-12)
    assert np.allclose(quat_rotate(q, [v, v]), [quat_matrix(q) @ v] * 2, atol=1e-12)


@settings(max_examples=200, deadline=None)
@given(unit, unit, st.floats(-3.1, 3.1), st.floats(0, 1))
def test_slerp_turns_at_a_constant_rate_about_one_axis(base, axis, th, s):
    a = axis_angle(base, 0.7)
    b = _mul(a, axis_angle(axis, th))  # a, then a turn by th about axis (body frame)
    assert same_rotation(slerp(a, b, 0), a) and same_rotation(slerp(a, b, 1), b)
    assert same_rotation(slerp(a, b, s), _mul(a, axis_angle(axis, s * th)), 1e-7)
    assert same_rotation(slerp(a, -b, s), slerp(a, b, s), 1e-9)  # -b is the same rotation


@settings(max_examples=200, deadline=None)
@given(unit, unit, st.floats(1e-9, np.pi))
def test_quat_angle_is_the_turn_between(base, axis, th):
    a = axis_angle(base, 1.1)
    assert quat_angle(a, _mul(a, axis_angle(axis, th))) == pytest.approx(th, rel=1e-7, abs=1e-12)
    assert quat_angle(a, -a) == 0.0


@settings(max_examples=200, deadline=None)
@given(unit, unit, st.floats(0.1, 10))
def test_turn_onto_is_the_least_turn_taking_one_direction_onto_the_other(u, v, scale):
    q = turn_onto(scale * u, v)
    assert np.linalg.norm(q) == pytest.approx(1) and np.allclose(quat_rotate(q, u), v, atol=1e-9)
    # the least turn: by the angle between them (2 acos |w| of the quaternion)
    angle = np.arccos(np.clip(u @ v, -1, 1))
    assert 2 * np.arccos(min(1.0, abs(q[0]))) == pytest.approx(angle, abs=1e-6)
    assert np.allclose(quat_rotate(turn_onto(u, -u), u), -u, atol=1e-12)  # opposite: a half turn


@settings(max_examples=200, deadline=None)
@given(unit)
def test_tangents_complete_a_right_handed_orthonormal_frame(n):
    t1, t2 = tangents(5 * n)
    F = np.c_[t1, t2, n]
    assert np.allclose(F.T @ F, np.eye(3), atol=1e-12) and np.linalg.det(F) == pytest.approx(1)


@settings(max_examples=100, deadline=None)
@given(st.floats(-1, 1), st.floats(-1, 1), angles, st.lists(st.floats(-1, 1), min_size=3, max_size=3))
def test_planar_poses_are_turns_about_y(x, z, th, b):
    q = [x, z, th]
    # the quaternion about y moves x-z points as the planar rotation does
    p = quat_rotate(planar_quat(th), [b[0], 0.0, b[1]])
    assert np.allclose(p[[0, 2]], planar_rotate(th, b[:2]), atol=1e-12) and abs(p[1]) < 1e-12
    assert np.allclose(planar_quat(th), axis_angle([0, 1, 0], -th), atol=1e-12)
    # composition and inverse agree with the 3-D pose algebra of the core
    P, B = planar_to_spatial(q), planar_to_spatial(b)
    c = planar_to_spatial(planar_compose(q, b))
    assert np.allclose(c[:3], _core.se3_compose(P, B)[:3], atol=1e-12)
    assert same_rotation(np.asarray(c[3:]), np.asarray(_core.se3_compose(P, B)[3:]))
    assert np.allclose(planar_compose(q, planar_inverse(q))[:2], 0, atol=1e-12)


@settings(max_examples=50, deadline=None)
@given(unit, angles, st.lists(st.floats(-1, 1), min_size=9, max_size=9))
def test_twist_in_is_the_adjoint(axis, th, r):
    """Integrating u in frame B is integrating twist_in(A⁻¹B, u) in frame A: A exp(Ad u) = B exp(u) B⁻¹ A."""
    rel = np.r_[r[:3], axis_angle(axis, th)]
    u = np.asarray(r[3:], float)
    lhs = _core.se3_integrate(list(rel), list(u), 0.3)  # B exp(u t), A = identity
    rhs = _core.se3_compose(_core.se3_integrate([0, 0, 0, 1, 0, 0, 0], twist_in(rel, u), 0.3), list(rel))
    assert np.allclose(lhs[:3], rhs[:3], atol=1e-9) and same_rotation(np.asarray(lhs[3:]), np.asarray(rhs[3:]))
    # |ω| < π here: the log of exp(u) is u
    assert np.allclose(twist_between([0, 0, 0, 1, 0, 0, 0], _core.se3_integrate([0, 0, 0, 1, 0, 0, 0], list(u), 1.0)),
                       u, atol=1e-9)


def test_against_scipy():
    Rotation = pytest.importorskip("scipy.spatial.transform").Rotation
    rng = np.random.default_rng(3)
    for q in rng.normal(size=(200, 4)):
        r = Rotation.from_quat(np.r_[q[1:], q[0]])  # scipy's order: [x, y, z, w]
        assert np.allclose(quat_matrix(q), r.as_matrix(), atol=1e-12)
        s = r.as_quat()
        assert same_rotation(quat_from_matrix(r.as_matrix()), np.r_[s[3], s[:3]])
    a, b = rng.normal(size=(2, 4))
    from scipy.spatial.transform import Slerp
    ra, rb = Rotation.from_quat([np.r_[a[1:], a[0]], np.r_[b[1:], b[0]]])
    for s in (0.0, 0.25, 0.5, 1.0):
        ref = Slerp([0, 1], Rotation.concatenate([ra, rb]))([s]).as_matrix()[0]
        assert np.allclose(quat_matrix(slerp(a, b, s)), ref, atol=1e-9)
    assert quat_angle(a, b) == pytest.approx((ra.inv() * rb).magnitude(), abs=1e-9)


def _mul(a, b) -> np.ndarray:
    """The quaternion product a b (independent of the module)."""
    w1, v1, w2, v2 = a[0], np.asarray(a[1:]), b[0], np.asarray(b[1:])
    return np.r_[w1 * w2 - v1 @ v2, w1 * v2 + w2 * v1 + np.cross(v1, v2)]
