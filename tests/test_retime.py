"""The arm's time parametrisation (regrasp.execution.retime, TOPP-RA through toppra): the
waypoints kept, the joint limits held at every sample and between samples (divided differences
of the positions, independent of the reported rates), never faster than planned, holds kept,
and the time-optimal duration of a straight move against its closed form."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from regrasp import ArgumentError
from regrasp.execution.retime import retime

pytest.importorskip("toppra")
TOL = 2e-6


def check_limits(r, t_planned, vmax, amax):
    """Every sample within the limits; the divided differences (averages of the true rates over
    the samples' spans) too; the reported velocities integrate to the positions' steps."""
    dt = np.diff(r.times)
    assert np.all(dt > 0)
    assert np.all(dt >= np.diff(t_planned) * (1 - 1e-6)), "faster than planned"
    assert np.all(np.abs(r.qd) <= vmax * (1 + TOL)) and np.all(np.abs(r.qdd) <= amax * (1 + TOL))
    v = np.diff(r.q, axis=0) / dt[:, None]
    assert np.all(np.abs(v) <= vmax * (1 + 1e-3))
    a = 2 * np.diff(v, axis=0) / (dt[1:] + dt[:-1])[:, None]
    assert np.all(np.abs(a) <= amax * (1 + 1e-3)), np.abs(a).max(0)
    # the trapezoid rule on the reported velocities gives the steps, within its error bound for a
    # velocity whose slope stays within the acceleration limit
    trapezoid = 0.5 * (r.qd[1:] + r.qd[:-1]) * dt[:, None]
    assert np.all(np.abs(trapezoid - np.diff(r.q, axis=0)) <= amax * dt[:, None] ** 2 / 4 + 1e-9)


def test_a_cornered_path_with_a_hold_keeps_its_waypoints_and_the_limits():
    # a joint-space L with a dwell at the corner, planned with a speed jump at each end
    t = np.arange(0, 3.0, 0.02)
    n = len(t)
    q = np.zeros((n, 3))
    k1, k2 = n // 3, n // 3 + 20  # moving to k1, holding to k2, then turning 90°
    q[:k1, 0] = np.linspace(0, 0.5, k1)
    q[k1:k2, 0] = 0.5
    q[k2:, 0] = 0.5
    q[k2:, 1] = np.linspace(0, 0.8, n - k2)
    vmax, amax = np.array([1.0, 1.0, 1.0]), np.array([2.0, 2.0, 2.0])
    r = retime(t, q, vmax, amax)
    assert np.array_equal(r.q, q)
    check_limits(r, t, vmax, amax)
    assert {0, k1 - 1, k2 - 1, n - 1} <= set(r.stops)
    hold = r.times[k2 - 1] - r.times[k1 - 1]
    assert hold == pytest.approx(t[k2 - 1] - t[k1 - 1])                      # the dwell kept
    assert np.all(r.qd[[0, k1 - 1, k2 - 1, -1]] == 0)                          # at rest at the stops


@pytest.mark.parametrize("length, vmax, amax, expected", [
    (0.5, 10.0, 2.0, 2 * math.sqrt(0.5 / 2.0)),     # acceleration bound: bang-bang
    (2.0, 0.5, 4.0, 2.0 / 0.5 + 0.5 / 4.0),         # velocity bound: trapezoid
])
def test_a_straight_move_takes_its_time_optimal_duration(length, vmax, amax, expected):
    t = np.linspace(0, 1e-3 * length, 401)  # planned far faster than the arm can: only the limits bind
    q = np.outer(np.linspace(0, length, len(t)), [0.6, 0.8])
    r = retime(t, q, vmax * 0.8, amax * 0.8)  # the second joint (0.8 of the arc length) binds
    assert r.times[-1] == pytest.approx(expected, rel=0.01)
    check_limits(r, t, vmax * 0.8, amax * 0.8)


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 10**6), dof=st.integers(1, 7))
def test_random_paths_hold_the_limits(seed, dof):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(2, 120))
    t = np.cumsum(rng.uniform(0.005, 0.05, n))
    steps = rng.normal(size=(n, dof)) * rng.uniform(1e-4, 0.05)
    steps[rng.random(n) < 0.15] = 0.0  # holds
    q = np.cumsum(steps, axis=0)
    vmax, amax = rng.uniform(0.2, 3.0, dof), rng.uniform(0.5, 10.0, dof)
    r = retime(t, q, vmax, amax)
    assert np.array_equal(r.q, q) and np.all(np.isfinite(r.qd)) and np.all(np.isfinite(r.qdd))
    check_limits(r, t, vmax, amax)


@pytest.mark.parametrize("kw, field", [
    (dict(times=[0.0, 0.0], q=[[0.0], [1.0]]), "times"),
    (dict(times=[0.0], q=[[0.0]]), "times"),
    (dict(times=[0.0, 1.0], q=[[0.0], [float("nan")]]), "q"),
    (dict(times=[0.0, 1.0], q=[0.0, 1.0]), "q"),
    (dict(times=[0.0, 1.0], q=[[0.0], [1.0]], velocity_limit=[-1.0]), "velocity_limit"),
    (dict(times=[0.0, 1.0], q=[[0.0], [1.0]], acceleration_limit="fast"), "acceleration_limit"),
    (dict(times=[0.0, 1.0], q=[[0.0, 1.0], [1.0, 1.0]], velocity_limit=[1.0, 1.0, 1.0]), "velocity_limit"),
])
def test_bad_input_names_the_field(kw, field):
    args = dict(velocity_limit=[1.0], acceleration_limit=[1.0]) | kw
    with pytest.raises(ArgumentError) as e:
        retime(**args)
    assert e.value.field == field
