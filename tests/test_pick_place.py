"""Pick-regrasp-place (regrasp.execution.pick_place, `regrasp pick-place`): the chosen grasps are
the cheapest of every pair planned by brute force, reachable (checked by the arm's forward
kinematics), keep the fingers above the table, and the motion starts at the pick pose and ends
at the place pose. The MuJoCo execution: tests/test_pick_place_mujoco.py."""

import functools
import json

import numpy as np
import pytest

import regrasp
from regrasp.errors import ExecutionError
from regrasp.execution import pick_place as pp
from regrasp.execution import default_workcell

from .conftest import pose_matrix as T, run_cli

pytest.importorskip("mink")
NAMES = ("block-xztheta", "block-low-friction")


def scene_of(name):
    return regrasp.load_scene(regrasp.examples.path(name))


@pytest.fixture(scope="module")
def chosen():
    """Each scene's pick-place (seed 1) and the brute-force ranking of every grasp pair."""
    out = {}
    for name in NAMES:
        s = scene_of(name)
        wc = default_workcell(s)
        r = pp.pick_place(s, wc, seed=1)
        start, goal = pp.spots(s)
        picks = pp.grasps(s, wc, r.pick_pose, start)
        places = pp.grasps(s, wc, r.place_pose, goal)
        out[name] = (s, wc, r, pp.rank(s, wc, picks, places, seed=1))
    return out


def test_resting_angles_put_a_side_on_the_table():
    s = scene_of("block-xztheta")
    wc = default_workcell(s)
    angles = pp.resting_angles(s)
    assert sorted(np.round(np.degrees(angles)) % 360) == [0, 90, 180, 270]
    out = np.asarray(s.outline, float)
    pts = np.c_[out[:, 0], np.zeros(len(out)), out[:, 1], np.ones(len(out))]
    for a in angles:
        W = T(pp.table_pose(s, wc, [0.4, 0.1], a, yaw=0.3)) @ pts.T
        z = W[2]
        assert abs(z.min() - wc.table.height) < 1e-9  # resting on the table ...
        assert np.sum(np.abs(z - wc.table.height) < 1e-9) == 2  # ... on a side (two corners)


@pytest.mark.parametrize("name", NAMES)
def test_choice_is_the_cheapest_pair(chosen, name):
    s, wc, r, ranked = chosen[name]
    usable = [c for c in ranked if not c.why]
    assert usable, "the brute force found no usable pair"
    robot, _, _, tcp, avoid = pp._arm_robot(s, wc, r.pick_pose, r.pick.in_hand)
    reach = [c for c in usable if pp.reachable(robot, avoid, tcp, c.pick.gripper) is not None
             and pp.reachable(robot, avoid, tcp, c.place.gripper) is not None]
    best = min(c.cost for c in reach)
    assert r.switch_overs == best[0]
    got = [c for c in ranked if c.pick.in_hand == r.pick.in_hand and c.place.in_hand == r.place.in_hand][0]
    assert got.cost == pytest.approx(best)
    # the regrasp plan goes from the pick grasp to the place grasp
    if r.plan is not None:
        assert np.allclose(r.plan.poses[0], r.pick.in_hand, atol=1e-9)
        err = np.abs(np.asarray(r.plan.poses[-1]) - r.place.in_hand)
        assert np.all(err <= np.asarray(s.task.tolerance) + 1e-9)


@pytest.mark.parametrize("name", NAMES)
def test_grasps_are_reachable_and_above_the_table(chosen, name):
    s, wc, r, _ = chosen[name]
    robot, _, _, tcp, _ = pp._arm_robot(s, wc, r.pick_pose, r.pick.in_hand)
    for g, pose, i in ((r.pick, r.pick_pose, r.phases["approach"][1]), (r.place, r.place_pose, r.phases["lower"][1])):
        # the gripper holds the object at its world pose: G ∘ in_hand = W (4 x 4 matrices)
        c, sn = np.cos(g.in_hand[2]), np.sin(g.in_hand[2])
        H = np.eye(4)
        H[:3, :3] = [[c, 0, -sn], [0, 1, 0], [sn, 0, c]]
        H[:3, 3] = [g.in_hand[0], 0, g.in_hand[1]]
        assert np.allclose(T(g.gripper) @ H, T(pose), atol=1e-9)
        # forward kinematics of the arm's joints at that sample put the TCP there
        fk = T(robot.tcp_pose(r.arm.q[i]))
        want = T(g.gripper) @ T(tcp)
        assert np.linalg.norm(fk[:3, 3] - want[:3, 3]) < 1e-3
        assert np.arccos(np.clip((np.trace(fk[:3, :3].T @ want[:3, :3]) - 1) / 2, -1, 1)) < 0.01
        assert g.gripper[2] - wc.table.height >= pp.FINGER_CLEARANCE - 1e-9
        assert T(g.gripper)[2, 2] >= np.cos(pp.MAX_TILT) - 1e-9  # palm up, fingers down


@pytest.mark.parametrize("name", NAMES)
def test_motion_goes_from_pick_to_place(chosen, name):
    s, wc, r, _ = chosen[name]
    m = r.motion
    a, b = r.phases["approach"]
    assert np.allclose(m.object[: b + 1], r.pick_pose)  # on the table until grasped
    assert np.allclose(m.object[r.phases["open"][0]:], r.place_pose, atol=1e-9)
    assert np.allclose(m.grip_force[: b + 1], 0) and np.all(m.grip_force[r.phases["lift"][0]:r.phases["lower"][1]] > 0)
    assert np.all(np.diff(m.times) > 0) and len(r.arm.q) == len(m.times)
    assert np.all(np.abs(np.diff(r.arm.q, axis=0)) < 0.5)  # no branch flip
    assert r.planning_time < 3.0  # measured ≈ 0.85 s on 2 shared cores (target < 1 s)


def test_a_place_too_deep_is_refused_naming_place():
    s = scene_of("block-xztheta")
    with pytest.raises(ExecutionError) as e:
        pp.pick_place(s, depth=0.5)
    assert e.value.field == "place"


def test_an_object_the_hand_cannot_hold_is_refused_naming_the_part():
    """t-shape's T, held in any of its pick grasps, reaches into the 2F-85's base (its top is
    60 mm above the pads' centre, the housing lower): every grasp pair is refused before the arm
    moves, the message naming the part."""
    s = scene_of("t-shape")
    with pytest.raises(ExecutionError, match=r"grasp pairs tried .*goes [0-9.]+ mm into the gripper's `base`") as e:
        pp.pick_place(s, seed=1)
    assert e.value.field == "place"


def assert_left_out(s, blocked: str) -> None:
    """pick_place of ``s`` (seed 1) chooses a regrasp without pusher ``blocked`` and names it left
    out, or its refusal names it."""
    try:
        r = pp.pick_place(s, seed=1)
    except ExecutionError as e:
        assert f"without pushers {blocked}" in str(e) and e.field == "place"
    else:
        assert blocked in r.without and blocked not in {a.pusher for a in r.motion.assignments}


def test_a_pusher_the_arm_cannot_follow_is_left_out_and_named(chosen, monkeypatch):
    """When the arm cannot follow a push (``solve_arm`` raises naming it: its reach, a joint
    limit, the fingers against the feature), the grasp pairs are planned again without that
    pusher. The real ``solve_arm``, wrapped to refuse every push of the pusher that the first
    choice uses (as an arm blocked there would), on block-low-friction: the choice found instead
    uses none of it and names it left out, or the refusal names it (block-low-friction has no
    regrasp without its `bottom` pusher; the choice found instead: the next test's)."""
    from regrasp.execution import arm

    s, _, first, _ = chosen["block-low-friction"]
    blocked = first.motion.assignments[0].pusher
    real = arm.solve_arm

    def solve(robot, motion, tcp, load=None):
        for a in motion.assignments:
            if a.pusher == blocked:
                e = ExecutionError(f"the arm cannot execute push {a.index}: blocked in this test", "robot")
                e.push = a.index
                raise e
        return real(robot, motion, tcp, load)

    monkeypatch.setattr(arm, "solve_arm", solve)
    assert_left_out(s, blocked)


def test_a_pusher_no_feature_serves_is_left_out_and_named(chosen, monkeypatch):
    """When no pair gets as far as the arm because no feature serves a push of its plan (the
    assignment's error names the pusher), the pairs are planned again without that pusher. The
    real ``world_motion``, wrapped to refuse every plan that uses the pusher of the first
    choice's first push as the assignment does, on block-xztheta: the choice found instead uses
    none of it and names it left out, or the refusal names it."""
    s, _, first, _ = chosen["block-xztheta"]
    blocked = first.motion.assignments[0].pusher
    real = pp.world_motion

    def motion(scene, plan, workcell, **kw):
        if blocked in [p for p in plan.pushers if p]:
            e = ExecutionError(f"push 0 (pusher `{blocked}`): no feature of workcell `{workcell.name}` serves it "
                               "in this test", "plan.path[1].pusher")
            e.pusher = blocked
            raise e
        return real(scene, plan, workcell, **kw)

    monkeypatch.setattr(pp, "world_motion", motion)
    assert_left_out(s, blocked)


def test_cli_json(chosen, monkeypatch):
    s, wc, r, _ = chosen["block-low-friction"]
    calls = []

    @functools.wraps(pp.pick_place)  # the options' defaults are read from its signature
    def planned(*a, **k):
        calls.append(k)
        return r

    monkeypatch.setattr(pp, "pick_place", planned)
    status, out, _ = run_cli("pick-place", regrasp.examples.path("block-low-friction"), "--plan-only", "--json")
    assert status == 0
    d = json.loads(out)
    assert {"success", "pick_grasp", "place_error", "switch_overs", "planning_time_s"} <= set(d)
    assert d["pick_grasp"] == pytest.approx(list(r.pick.in_hand), abs=1e-5)
    assert d["switch_overs"] == r.switch_overs and d["executed"] is False
    assert d["place_error"] == pytest.approx([0, 0], abs=1e-6)
    assert calls[0]["seed"] == 0 and calls[0]["depth"] == 0.0 and calls[0]["place"] is None


@pytest.mark.parametrize("bad", ["1,2,3", "a,b,c,d,e,f,g", "0,0,0.8,0,0,0,0", "0,0,nan,1,0,0,0"])
def test_cli_bad_place_exits_2_naming_it(bad):
    status, out, err = run_cli("pick-place", regrasp.examples.path("t-shape"), "--place", bad, "--json")
    assert status == 2 and "--place" in err and out == ""
