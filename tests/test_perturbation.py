"""One perturbed world for every rig (issue "One world"): :class:`regrasp.Perturbation` checks
its fields, draws the same worlds the three old types drew from the same seed, and the old names
give it with a DeprecationWarning."""

import numpy as np
import pytest

import regrasp
from regrasp import ArgumentError, Perturbation
from regrasp.examples import path as example


def test_a_seed_draws_the_old_worlds():
    """The draw's stream, against numpy's: the planar engine's (3 factors, features with the
    fingers), the arm campaign's (4 factors) and the hand's (3 factors, a shift, a turn)."""
    s = 0.2
    u = np.random.default_rng(7).uniform(1 - s, 1 + s, 3)
    p = Perturbation.draw(np.random.default_rng(7), s, features="finger")
    assert p.factors == (u[0], u[1], u[2], u[0])
    u = np.random.default_rng(7).uniform(1 - s, 1 + s, 4)
    assert Perturbation.draw(np.random.default_rng(7), s, features="drawn").factors == tuple(u)
    r = np.random.default_rng(7)
    u, xz, t = r.uniform(1 - s, 1 + s, 3), r.uniform(-0.004, 0.004, 2), r.uniform(-0.1, 0.1)
    h = Perturbation.draw(np.random.default_rng(7), s, shift=0.004, turn=0.1)
    assert h.factors == (u[0], u[1], u[2], 1.0) and h.shift == (xz[0], 0.0, xz[1]) and h.turn == t


def test_draw_scales_the_base_and_keeps_its_start():
    base = Perturbation(0.5, 2.0, 1.0, 0.8, pose=(0, 0, 0.01, 1, 0, 0, 0))
    p = Perturbation.draw(np.random.default_rng(1), 0.1, base=base)
    assert 0.45 <= p.finger_friction <= 0.55 and 1.8 <= p.grip <= 2.2 and p.feature_friction == 0.8
    assert p.pose == base.pose and not p.nominal and Perturbation().nominal


@pytest.mark.parametrize("kw, field", [
    ({"finger_friction": 0.0}, "perturbation.finger_friction"), ({"grip": float("nan")}, "perturbation.grip"),
    ({"mass": True}, "perturbation.mass"), ({"feature_friction": "1"}, "perturbation.feature_friction"),
    ({"shift": (0.0, 0.0)}, "perturbation.shift"), ({"shift": (0.0, np.inf, 0.0)}, "perturbation.shift"),
    ({"turn": 4.0}, "perturbation.turn"), ({"pose": (0, 0, 0, 0, 0, 0, 0)}, "perturbation.pose"),
])
def test_bad_fields_are_named(kw, field):
    with pytest.raises(ArgumentError) as e:
        Perturbation(**kw)
    assert e.value.field == field


@pytest.mark.parametrize("kw, field", [({"spread": 1.0}, "spread"), ({"features": "all"}, "features")])
def test_bad_draws_are_named(kw, field):
    with pytest.raises(ArgumentError) as e:
        Perturbation.draw(np.random.default_rng(0), **{"spread": 0.1, **kw})
    assert e.value.field == field


def test_the_old_names_give_the_one_type_with_a_warning():
    from regrasp.dexterity.world import Perturbation as Hand
    from regrasp.execution.arm import Scales
    from regrasp.mujoco.planar import Perturbation as Planar

    with pytest.warns(DeprecationWarning, match="regrasp.Perturbation"):
        a = Planar(friction=0.9, mass=1.1)
    assert isinstance(a, Perturbation) and a.factors == (0.9, 1.0, 1.1, 0.9)  # features followed the fingers
    with pytest.warns(DeprecationWarning):
        assert Planar(0.9, pusher_friction=1.2).feature_friction == 1.2
    with pytest.warns(DeprecationWarning):
        b = Scales(finger_friction=0.8)
    assert isinstance(b, Perturbation) and b.factors == (0.8, 1.0, 1.0, 1.0)  # the features nominal
    with pytest.warns(DeprecationWarning):
        c = Hand(friction=0.9, turn=0.1)
    assert c.factors == (0.9, 1.0, 1.0, 1.0) and c.turn == 0.1
    with pytest.warns(DeprecationWarning):
        d = Planar.draw(0.2, np.random.default_rng(7))
    assert d == Perturbation.draw(np.random.default_rng(7), 0.2, features="finger")
    with pytest.warns(DeprecationWarning):
        e = Hand.draw(np.random.default_rng(7), 0.2, 0.004, 0.1)
    assert e == Perturbation.draw(np.random.default_rng(7), 0.2, shift=0.004, turn=0.1)


def test_the_quasistatic_world_is_the_scaled_scene():
    scene = regrasp.Scene.load(example("block-low-friction"))
    w = Perturbation(0.8, 1.5, 2.0, 1.1).scene(scene)
    assert w.grip_force == pytest.approx(1.5 * scene.grip_force)
    assert w.pad_friction == pytest.approx(0.8 * scene.pad_friction)
    assert w.mass == pytest.approx(2.0 * scene.mass)
    assert [p.friction for p in w.pushers] == pytest.approx([1.1 * p.friction for p in scene.pushers])
