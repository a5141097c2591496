import numpy as np
import pytest

import regrasp
from regrasp.reference.cones import RefParams, classify_numpy_batch, generators_numpy_batch


def random_poses(scene, n, seed=0):
    rng = np.random.default_rng(seed)
    return np.column_stack([rng.uniform(-0.03, 0.03, n), rng.uniform(-0.05, 0.05, n), rng.uniform(-1, 1, n)])


def test_batch_matches_single_calls_and_numpy(block):
    block = block.with_limit_surface("ellipsoid")  # the numpy reference's model
    q = random_poses(block, 3000)
    b = block.motion_cones(q, "left")
    ok = b.valid
    assert 0 < ok.sum() < len(q), "some random poses leave the pad off the object"
    assert np.array_equal(ok, block.admissible(q))
    for i in np.flatnonzero(ok)[:50]:
        assert np.allclose(b.generators[i], block.motion_cone(q[i], "left").generators, atol=1e-14)
    ref = generators_numpy_batch(RefParams.from_scene(block, "left"), q[ok])
    assert np.abs(b.generators[ok] - ref).max() < 1e-10
    # invalid entries: zero generators and a reason, never NaN
    assert np.all(b.generators[~ok] == 0)
    assert all("not admissible" in e for e, v in zip(b.errors, ok) if not v)


def test_batch_classify_and_project(block):
    block = block.with_limit_surface("ellipsoid")  # the numpy reference's model
    q = random_poses(block, 2000, 1)
    q = q[block.admissible(q)]
    rng = np.random.default_rng(2)
    t = rng.normal(size=(len(q), 3)) * np.array([1, 1, 1 / block.length])
    b = block.motion_cones(q, "left")
    r = b.classify(t)
    assert r["valid"].all()
    assert np.array_equal(r["feasible"], classify_numpy_batch(RefParams.from_scene(block, "left"), q, t))
    assert set(r["active_limit"]) <= {"slide+t", "slide-t", "roll_about_point_0", "roll_about_point_1"}
    for i in range(20):
        c = block.motion_cone(q[i], "left").classify(t[i])
        assert c.feasible == r["feasible"][i] and c.margin == pytest.approx(r["margin"][i], abs=1e-14)
        assert c.active_limit == r["active_limit"][i]
    p = b.project(t)
    m = b.margin(p)
    nz = np.linalg.norm(p, axis=1) > 0
    assert (m[nz] > -1e-7).all()
    assert np.allclose(p[r["feasible"]], t[r["feasible"]])


def test_batch_reports_bad_entries_without_raising(block):
    q = np.array([[0, 0, 0], [np.nan, 0, 0], [0.1, 0, 0], [0, 0, 0]], float)
    t = np.array([[1, 0, 0], [1, 0, 0], [1, 0, 0], [0, 0, 0]], float)
    b = block.motion_cones(q, "left")
    assert b.valid.tolist() == [True, False, False, True]
    assert "finite" in b.errors[1] and "admissible" in b.errors[2]
    r = b.classify(t)
    assert r["valid"].tolist() == [True, False, False, False]
    assert r["errors"][3] == "twist is zero"
    with pytest.raises(regrasp.ArgumentError) as e:
        block.motion_cones(q, "left", strict=True)
    assert e.value.field == "poses[1]"
    heavy = block.with_grip_force(0.5)
    assert heavy.motion_cones(q[:1], "left").errors == ["the grasp cannot hold the object against gravity at this pose"]


def test_bad_arguments_name_the_argument(block):
    with pytest.raises(regrasp.ArgumentError) as e:
        block.motion_cone([0, 0], "left")
    assert e.value.field == "pose"
    with pytest.raises(regrasp.ArgumentError) as e:
        block.motion_cone([0, 0, 0], "nope")
    assert e.value.field == "pusher" and "left" in str(e.value)
    cone = block.motion_cone([0, 0, 0], "left")
    with pytest.raises(regrasp.ArgumentError) as e:
        cone.contains([np.nan, 0, 0])
    assert e.value.field == "twist"
    with pytest.raises(regrasp.ArgumentError):
        cone.contains([0, 0, 0])
    with pytest.raises(regrasp.ArgumentError):
        block.motion_cones(np.zeros((3, 2)), "left")
