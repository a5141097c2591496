"""The grip loop's sensing (regrasp.robot.sensing): a force sensor's readings delayed, low-passed
and noisy as stated (checked against the closed forms), bad settings refused naming the field,
and in MuJoCo a held box under each kind: the ideal loop holds the requested force, the open
loop the feed-forward's (the linkage's bias under load), the sensor's loop the request within
its noise; the box held by all three."""

import math

import numpy as np
import pytest

from regrasp.errors import ArgumentError
from regrasp.robot.sensing import GripSensing, SensedForces


def test_a_reading_is_the_force_delayed_and_low_passed():
    s = GripSensing("sensor", noise=0.0, delay=0.004, bandwidth=50.0)
    period = 0.001
    sensed = SensedForces(s, period)
    out = np.array([sensed.read([3.0, 1.0])[0] for _ in range(60)])
    assert np.all(out[:4] == 0.0)  # nothing for the delay's 4 periods
    k = np.arange(1, 57)
    want = 3.0 * (1 - np.exp(-2 * math.pi * 50.0 * period * k))  # a first-order step response
    assert np.allclose(out[4:], want, atol=1e-12)


def test_the_noise_has_the_stated_deviation_and_its_seed():
    s = GripSensing("sensor", noise=0.2, delay=0.0, bandwidth=1e3)
    a = SensedForces(s, 0.001)
    r = np.array([a.read([5.0, 5.0]) for _ in range(4000)])[200:]
    assert abs(r.std() - 0.2) < 0.02 and abs(r.mean() - 5.0) < 0.02
    b = SensedForces(s, 0.001)
    assert np.array_equal(np.array([b.read([5.0, 5.0]) for _ in range(4000)])[200:], r)


@pytest.mark.parametrize("text, field", [("magic", "--grip-sensing"), ("sensor:1,2", "--grip-sensing"),
                                         ("sensor:-1,0.01,100", "--grip-sensing"), ("ideal:3", "--grip-sensing")])
def test_bad_sensing_is_refused_naming_the_option(text, field):
    with pytest.raises(ArgumentError) as e:
        GripSensing.parse(text)
    assert e.value.field == field


@pytest.mark.parametrize("kw, field", [({"kind": "x"}, "grip_sensing.kind"), ({"noise": float("nan")}, "grip_sensing.noise"),
                                       ({"delay": -1.0}, "grip_sensing.delay"), ({"bandwidth": 0.0}, "grip_sensing.bandwidth"),
                                       ({"seed": -1}, "grip_sensing.seed"), ({"seed": 1.5}, "grip_sensing.seed")])
def test_bad_settings_are_refused_naming_the_field(kw, field):
    with pytest.raises(ArgumentError) as e:
        GripSensing(**kw)
    assert e.value.field == field


def test_a_held_box_under_each_sensing():
    """A 0.1 kg box at 5 N per finger (about 6 times its holding force) for 1 s: the ideal
    loop settles at the request, the open loop at the feed-forward's bias (the load moves the
    pads through the linkage, +0.3–0.8 N), the sensor's loop at the request within a few noise
    deviations; the box creeps less than 0.1 mm in each."""
    pytest.importorskip("mujoco")
    pytest.importorskip("mink")
    from regrasp.robot.creep import hold_box

    got = {}
    for kind in ("ideal", "open-loop", "sensor"):
        s = GripSensing(kind) if kind != "sensor" else GripSensing("sensor", noise=0.05, delay=0.002, bandwidth=100.0)
        c = hold_box(5.0, duration=1.0, sensing=s)
        got[kind] = np.mean(c.grip_forces)
        assert c.slip < 1e-4, (kind, c.slip)
    assert abs(got["ideal"] - 5.0) < 0.05
    assert 0.3 < got["open-loop"] - 5.0 < 0.8
    assert abs(got["sensor"] - 5.0) < 0.15


@pytest.mark.parametrize("kind", ["ideal", "open-loop"])
def test_a_new_grip_force_is_held(kind):
    """``GripController.set_force`` (the grip raised between pushes): a held box's pads go from
    5 N to 10 N and back within 0.3 s each, measured by the pads' own contacts (the open loop: to
    the feed-forward's, its bias under the load as at 5 N)."""
    mujoco = pytest.importorskip("mujoco")
    pytest.importorskip("mink")
    from regrasp.robot.creep import OBJECT, hold_box
    from regrasp.robot.grip import GripController, pad_forces

    c = hold_box(5.0, duration=0.2, sensing=GripSensing(kind))
    r = c.robot
    box = [r.model.geom(OBJECT).id]
    grip = GripController(r, 5.0, box, sensing=GripSensing(kind))
    bias = 0.0 if kind == "ideal" else np.mean(c.grip_forces) - 5.0

    def run(seconds):
        for _ in range(int(seconds / r.model.opt.timestep)):
            grip.update()
            mujoco.mj_step(r.model, r.data)
        return np.mean(pad_forces(r, box))

    for target in (10.0, 5.0):
        grip.set_force(target)
        assert abs(run(0.3) - target - bias) < 0.15, (kind, target)
