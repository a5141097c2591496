"""Pick-regrasp-place executed in MuJoCo with the arm (regrasp.execution.pick_place): the block
is picked from the table, regrasped against the default workcell, and placed within the
tolerance (about 35 s: apart from tests/test_pick_place.py to keep each file under a minute)."""

import numpy as np
import pytest

import regrasp
from regrasp.execution import World, execute
from regrasp.execution import pick_place as pp

from .conftest import pose_matrix as T

pytest.importorskip("mink")
pytest.importorskip("mujoco")


def test_block_is_picked_regrasped_and_placed():
    s = regrasp.load_scene(regrasp.examples.path("block-xztheta"))
    r = pp.pick_place(s, seed=1)
    assert r.plan is not None and len(r.motion.assignments) >= 1  # a real regrasp by pushes
    with pytest.raises(regrasp.ArgumentError) as e:  # not with another rig, nor from a moved start
        execute(World(s, rig="free-gripper"), r)
    assert e.value.field == "world.rig"
    with pytest.raises(regrasp.ArgumentError) as e:
        execute(World(s, rig="arm"), r, perturbation=regrasp.Perturbation(shift=(0.01, 0, 0)))
    assert e.value.field == "perturbation.shift"
    x = execute(World(s, rig="arm"), r)  # the one executor runs a pick-regrasp-place too
    run = x.detail
    assert run.held  # in the hand at the place grasp before lowering
    A, B = T(run.final_pose), T(r.place_pose)
    dist = np.linalg.norm(A[:3, 3] - B[:3, 3])
    angle = np.arccos(np.clip((np.trace(A[:3, :3].T @ B[:3, :3]) - 1) / 2, -1, 1))
    assert dist <= pp.PLACE_TOLERANCE[0] and angle <= pp.PLACE_TOLERANCE[1], (dist, angle)
    assert run.success and x.success
    np.testing.assert_allclose(x.goal_error, [dist, angle], atol=1e-9)  # judged against the place: its task
    # it moved: the pick and place poses are 0.18 m apart on the table
    assert np.linalg.norm(A[:3, 3] - T(r.pick_pose)[:3, 3]) > 0.1
