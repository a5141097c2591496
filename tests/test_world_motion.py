"""The gripper's world-frame trajectory of a plan in a workcell (regrasp.execution), checked
independently: 4 x 4 matrices and scipy's expm, not the package's pose algebra."""

import time

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from scipy.linalg import expm

import regrasp
from regrasp import ArgumentError, ExecutionError, Plan
from regrasp.execution import Timing, world_motion
from regrasp.execution.assignment import MAX_TILT
from regrasp.execution.motion_check import PENETRATION_LIMIT, edge_points, object_points
from regrasp.execution.trajectory import LABELS
from regrasp.execution.world_motion import SLIDE_GAP
from regrasp.execution import default_workcell
from regrasp.workcell import Table, Workcell
from regrasp.workcell.description import Feature, Robot

from .conftest import plan_of, rotation_matrix as rot, pose_matrix as T

EXAMPLE_WORKCELL = regrasp.examples.ROOT / "workcells" / "workcell-ur5e.toml"


def T_planar(q):
    """4 x 4 matrix of a planar pose [x, z, theta]: x-z plane, theta turning x towards z."""
    x, z, th = q
    c, s = np.cos(th), np.sin(th)
    m = np.eye(4)
    m[:3, :3] = [[c, 0, -s], [0, 1, 0], [s, 0, c]]
    m[:3, 3] = [x, 0, z]
    return m


def hat(xi):
    m = np.zeros((4, 4))
    v, w = xi[:3], xi[3:]
    m[:3, :3] = [[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]]
    m[:3, 3] = v
    return m


def contact_matrix(pts, n):
    """The pusher's contact frame in the object frame from its points and normal (3-D)."""
    pts, n = np.asarray(pts, float), np.asarray(n, float) / np.linalg.norm(n)
    o = pts.mean(axis=0)
    if len(pts) == 2:
        x = (pts[1] - pts[0]) / np.linalg.norm(pts[1] - pts[0])
        z = n - (n @ x) * x
        z /= np.linalg.norm(z)
    else:
        z = n
        a = np.array([1.0, 0, 0]) if abs(n[0]) < 0.9 else np.array([0, 1.0, 0])
        x = np.cross(n, a)
        x /= np.linalg.norm(x)
    m = np.eye(4)
    m[:3, :3], m[:3, 3] = np.column_stack([x, np.cross(z, x), z]), o
    return m


def pusher_matrices(scene, plan, a):
    """Independently: the pusher's contact frame in the gripper frame at each knot of push ``a``."""
    if scene.dimension == 2:
        p = scene.pusher(a.pusher)
        pts = np.column_stack([p.points[:, 0], np.zeros(len(p.points)), p.points[:, 1]])
        C = contact_matrix(pts, [p.normal[0], 0, p.normal[1]])
        return {k: T_planar(plan.poses[k]) @ C for k in range(a.first, a.last + 1)}   # sticking
    pts, n, _ = scene._core.pusher_spec(a.pusher, list(plan.poses[a.first]))
    Pk = {a.first: T(plan.poses[a.first]) @ contact_matrix(pts, n)}
    for k in range(a.first + 1, a.last + 1):
        O = T(plan.poses[k - 1])
        xi = plan.pusher_twists[k]
        if xi is None:
            xi = np.array(regrasp.pose.twist_between(plan.poses[k - 1], plan.poses[k]))
        Pk[k] = O @ expm(hat(xi)) @ np.linalg.inv(O) @ Pk[k - 1]
    return Pk


CASES = ["block-low-friction", "t-shape", "block-tilted-gripper", "pivot-3d", "ball-roll-3d", "offset-3d"]


def motion(name, **kw):
    scene, plan = plan_of(name)
    return scene, plan, world_motion(scene, plan, **kw)


@pytest.mark.parametrize("name", CASES)
def test_gripper_renders_the_plan_with_the_fixed_feature(name):
    scene, plan, m = motion(name)
    contacts = {c.name: c for c in m.workcell.contacts()}
    assert [(a.first, a.last) for a in m.assignments][0][0] == 0
    assert m.assignments[-1].last == len(plan.poses) - 1
    knots = iter(m.knots)
    for a in m.assignments:
        F = T(a.frame)
        c = contacts[a.feature]
        assert np.allclose(F[:3, 3], c.frame[:3], atol=1e-12)                  # at the feature's contact
        C = rot(c.frame[3:])
        if c.kind == "edge":                                                    # along the edge, pushing
            assert np.isclose(abs(F[:3, 0] @ C[:, 0]), 1)                       # within its cone
            assert np.arccos(np.clip(F[:3, 2] @ C[:, 2], -1, 1)) <= c.cone + 1e-9
        else:
            assert np.allclose(F[:3, 2], C[:, 2], atol=1e-12)                   # pushing its way
        for k, Pk in pusher_matrices(scene, plan, a).items():
            kk, j = next(knots)
            assert kk == k and m.push[j] == a.index
            # G_k ∘ P_k = F at every knot
            assert np.abs(T(m.gripper[j]) @ Pk - F).max() < 1e-9, (a.pusher, k)
            assert np.allclose(m.in_hand[j], np.asarray(plan.poses[k]) if scene.dimension == 3
                               else regrasp.pose.planar_to_spatial(plan.poses[k]), atol=1e-12)
        if scene.dimension == 2:                                                # a sticking push keeps
            W = m.object[m.push == a.index][np.array(m.labels)[m.push == a.index] == "push"]
            assert np.abs(W - W[0]).max() < 1e-9                                # the object still


@pytest.mark.parametrize("name", CASES)
def test_the_motion_is_continuous_timed_and_held(name):
    scene, plan = plan_of(name)
    tm = Timing()
    scene, plan, m = motion(name, timing=tm)
    n = len(m.times)
    assert m.gripper.shape == m.object.shape == m.in_hand.shape == (n, 7) and len(m.labels) == n
    assert set(m.labels) <= set(LABELS) and m.labels[0] == "start" and m.labels.count("start") == 1
    dt = np.diff(m.times)
    assert m.times[0] == 0 and np.all(dt > 0) and np.all(dt <= tm.sample_period + 1e-12)
    force = scene.grip_force if scene.dimension == 2 else scene._core.grip_force
    assert np.all(m.grip_force == force)
    reach = max(np.linalg.norm(T(m.in_hand[i])[:3, :3] @ object_points(scene).T + m.in_hand[i][:3, None], axis=0).max()
                for i in range(n))
    for X, what in ((m.gripper, "gripper"), (m.object, "object")):
        step = np.linalg.norm(np.diff(X[:, :3], axis=0), axis=1)
        turn = 2 * np.arccos(np.clip(np.abs(np.sum(X[1:, 3:] * X[:-1, 3:], axis=1)), 0, 1))
        assert np.all(turn <= tm.move_turn * dt + 1e-6), what
        assert np.all(step <= (tm.move_speed + tm.move_turn * (reach if what == "object" else 0)) * dt + 1e-6), what
    # the object's world pose is the gripper's composed with the planned pose in the hand
    for i in range(n):
        assert np.abs(T(m.object[i]) - T(m.gripper[i]) @ T(m.in_hand[i])).max() < 1e-12
    json = m.to_dict()
    assert len(json["times"]) == n and json["duration_s"] == m.duration > 0


@pytest.mark.parametrize("name", ["block-low-friction", "pivot-3d", "t-shape"])
def test_approach_retreat_and_transfers_clear_the_features(name):
    scene, plan = plan_of(name)
    tm = Timing(clearance=0.03)
    m = world_motion(scene, plan, timing=tm)
    labels = np.array(m.labels)
    pts = object_points(scene)
    for a in m.assignments:
        F = T(a.frame)
        P0 = pusher_matrices(scene, plan, a)
        idx = np.flatnonzero(m.push == a.index)
        for part in ("approach", "retreat"):
            js = idx[labels[idx] == part]
            assert len(js) >= 1
            Pk = P0[a.first] if part == "approach" else P0[a.last]
            # the pusher's contact point, seen from the feature's frame: on its normal line,
            # between contact and the pre-contact distance (the clearance, or SLIDE_GAP under a
            # feature it slides under lengthwise: there, before the approach and after the
            # retreat, it moves along the edge only, SLIDE_GAP off it, and starts or ends past its end)
            local = np.array([(np.linalg.inv(F) @ T(m.gripper[j]) @ Pk)[:3, 3] for j in js])
            off = np.abs(local[:, 0]) > 1e-9
            slide = off.any()
            gap = SLIDE_GAP if slide else tm.clearance
            assert slide == ((name, a.feature) == ("t-shape", "ledge"))
            if slide:
                ends = local[off]
                assert np.allclose(ends[:, 1:], [0.0, SLIDE_GAP], atol=1e-9)
                assert np.abs(local[0 if part == "approach" else -1, 0]) > m.workcell.feature("ledge").length / 2
                k = np.flatnonzero(off)
                assert np.all(np.diff(k) == 1)
                if part == "approach":   # the slide ends at the pre-contact pose; the approach follows
                    assert k[0] == 0 and local[k[-1] + 1, 2] == pytest.approx(SLIDE_GAP, abs=1e-9)
                    js, local = js[k[-1] + 2:], local[k[-1] + 2:]
                else:
                    assert k[-1] == len(off) - 1 and k[0] > 0
                    js, local = js[:k[0]], local[:k[0]]
            assert np.allclose(local[:, :2], 0, atol=1e-9)
            assert np.all(local[:, 2] >= -1e-9) and np.all(local[:, 2] <= gap + 1e-9)
            # it ends in contact (approach) or the gap away (retreat), and starts from the gap
            # away (the pre-contact pose before the approach) or in contact (the push's end)
            before = (np.linalg.inv(F) @ T(m.gripper[js[0] - 1]) @ Pk)[:3, 3]
            assert np.allclose(before[:2], 0, atol=1e-9)
            assert local[-1, 2] == pytest.approx(0.0 if part == "approach" else gap, abs=1e-9)
            assert before[2] == pytest.approx(gap if part == "approach" else 0.0, abs=1e-9)
            assert np.all(np.diff(local[:, 2]) * (1 if part == "retreat" else -1) > 0)   # monotone
    # transfers at the safe height: every point of the object above every feature by the clearance
    top = m.workcell.top()
    high = [j for j in np.flatnonzero(labels == "transfer") if np.isclose(m.gripper[j, 2], m.safe_height)]
    assert high
    for j in high:
        world = (T(m.object[j]) @ np.c_[pts, np.ones(len(pts))].T)[:3]
        assert world[2].min() > top + tm.clearance - 1e-9
    # during every transfer, the next (or last) push's contact point stays at least the clearance
    # from its feature's contact point
    frames = {a.index: pusher_matrices(scene, plan, a) for a in m.assignments}
    for j in np.flatnonzero(labels == "transfer"):
        a = next((a for a in m.assignments if np.any(m.push[j:] == a.index)), m.assignments[-1])
        Pk = frames[a.index][a.first if np.any(m.push[j:] == a.index) else a.last]
        d = np.linalg.norm((T(m.gripper[j]) @ Pk)[:3, 3] - a.frame[:3])
        assert d >= tm.clearance - 1e-9


def test_a_push_no_feature_serves_is_refused_naming_it():
    scene, plan = plan_of("block-low-friction")
    bare = Workcell("bare", Table(0.75, [1.2, 0.8], 0.5, [0.5, 0]), (), Robot("ur5e", [0, 0, 0.75, 1, 0, 0, 0]))
    pushers = plan.pushers
    k = next(i for i in range(1, len(pushers)) if pushers[i] == "left")
    with pytest.raises(ExecutionError) as e:
        world_motion(scene, plan, bare)
    assert e.value.field == f"plan.path[{k}].pusher"
    assert "`left`" in str(e.value) and "push " in str(e.value) and "edge" in str(e.value)
    # a feature of the right kind but too little friction is refused too, saying so
    slick = Feature("slick", "block", [0.5, 0.25, 0.8, 1, 0, 0, 0], 0.01, [0.1, 0.1, 0.1])
    w = Workcell("slick", Table(0.75, [1.2, 0.8], 0.5, [0.5, 0]), (slick,), Robot("ur5e", [0, 0, 0.75, 1, 0, 0, 0]))
    with pytest.raises(ExecutionError, match="friction"):
        world_motion(scene, plan, w)
    # an edge shorter than the line pusher is refused
    short = Feature("short", "edge", [0.5, 0.25, 0.9, 0.7071067811865476, 0, 0.7071067811865476, 0], 0.9, length=0.01)
    w = Workcell("short", Table(0.75, [1.2, 0.8], 0.5, [0.5, 0]), (short,), Robot("ur5e", [0, 0, 0.75, 1, 0, 0, 0]))
    with pytest.raises(ExecutionError, match="shorter"):
        world_motion(scene, plan, w)


def test_the_example_workcell_renders_a_plan_and_bad_arguments_are_refused():
    scene, plan = plan_of("block-low-friction")
    w = Workcell.load(EXAMPLE_WORKCELL)
    m = world_motion(scene, plan, w, start=[0.3, 0, 1.2, 1, 0, 0, 0])
    assert np.allclose(m.gripper[0], [0.3, 0, 1.2, 1, 0, 0, 0])
    assert {a.feature for a in m.assignments} <= {c.name for c in w.contacts()}
    with pytest.raises(ArgumentError) as e:
        world_motion(scene, plan, w, start=[0, 0, 0, 0, 0, 0, 0])
    assert e.value.field == "start"
    with pytest.raises(ArgumentError) as e:
        Timing(push_speed=0)
    assert e.value.field == "timing.push_speed"
    with pytest.raises(ArgumentError) as e:
        world_motion(scene, {"path": []})
    assert e.value.field == "plan"
    scene3, plan3 = plan_of("offset-3d")
    with pytest.raises(ArgumentError) as e:
        world_motion(scene, plan3)
    assert e.value.field == "plan.path[0].pose"
    with pytest.raises(ArgumentError) as e:
        world_motion(scene, Plan(dimension=2, poses=[plan.poses[0]], pushers=[None]))
    assert e.value.field == "plan.path"
    surface = regrasp.load_scene(regrasp.examples.path("block-on-incline"))
    with pytest.raises(ArgumentError) as e:
        world_motion(surface, Plan(dimension=2, poses=[[0, 0, 0], [0, 0.001, 0]], pushers=[None, "finger"]))
    assert e.value.field == "scene"


def test_time_to_turn_a_plan_into_a_world_trajectory():
    scene, plan = plan_of("t-shape")
    w = default_workcell(scene)
    world_motion(scene, plan, w)
    t0 = time.perf_counter()
    m = world_motion(scene, plan, w)
    elapsed = time.perf_counter() - t0
    print(f"\nt-shape: {len(plan.poses)} knots, {len(m.times)} samples, {elapsed * 1e3:.1f} ms")
    assert elapsed < 1.0


@settings(max_examples=25, deadline=None)
@given(st.floats(-np.pi, np.pi), st.floats(0.02, 0.2), st.floats(-0.3, 0.3), st.floats(0.02, 0.2))
@example(0.0, 0.125, 0.0, 0.0625)                  # the object would go below the table top
@example(0.0, 0.125, 0.0, 0.03)                    # the edges too short
def test_any_fixture_block_either_renders_the_plan_exactly_or_refuses_naming_the_push(yaw, side, y, height):
    scene, plan = plan_of("block-low-friction")
    block = Feature("fixture", "block", [0.5, y, 0.75 + height / 2, np.cos(yaw / 2), 0, 0, np.sin(yaw / 2)], 0.9,
                    [side, side, height])
    w = Workcell("w", Table(0.75, [1.2, 0.8], 0.9, [0.5, 0]), (block,), Robot("ur5e", [0, 0, 0.75, 1, 0, 0, 0]))
    # the side pusher (a line) needs a block edge at least as long as it: the block's longest
    longest = np.linalg.norm(np.diff(scene.pusher("left").points, axis=0))
    try:
        m = world_motion(scene, plan, w)
    except ExecutionError as e:
        assert e.field.startswith("plan.path[")
        if "hits feature `fixture`" in str(e):
            # the table's contact is at its centre, (0.5, 0): a block standing near it is in the way
            # of an object pushed there (or of the object on its way to the block's edge)
            reach = np.linalg.norm(object_points(scene), axis=1).max()
            assert abs(y) <= reach + side / np.sqrt(2) + 0.03, str(e)
            return
        assert "`left`" in str(e)
        if "no feature" in str(e):
            # a horizontal edge would turn gravity by 90°: only the block's vertical edges serve
            assert height < longest
            return
        # the object would go below the table: the same block 1 m higher renders the push with
        # the object lower than 1 m above the table top (checked with 4 x 4 matrices)
        assert "below the table top" in str(e) and height >= longest
        high = Feature("fixture", "block", block.pose + [0, 0, 1, 0, 0, 0, 0], 0.9, [side, side, height])
        m = world_motion(scene, plan, Workcell("w", w.table, (high,), w.robot))
        a = next(a for a in m.assignments if a.pusher == "left")
        pts = np.c_[object_points(scene), np.ones(len(object_points(scene)))].T
        low = min((T(m.object[j]) @ pts)[2].min() for j in np.flatnonzero(m.push == a.index))
        assert low - 1.0 < 0.75 - PENETRATION_LIMIT
        return
    assert height >= longest
    for a in m.assignments:
        F = T(a.frame)
        for k, Pk in pusher_matrices(scene, plan, a).items():
            j = next(j for kk, j in m.knots if kk == k and m.push[j] == a.index)
            assert np.abs(T(m.gripper[j]) @ Pk - F).max() < 1e-9


BAD_ARGS = [None, 3, "x", float("nan"), [], [1.0] * 6, [float("inf")] * 7, {"a": 1}, np.zeros((2, 7))]


@settings(max_examples=60, deadline=None)
@given(st.sampled_from(["scene", "plan", "workcell", "timing", "start"]), st.sampled_from(BAD_ARGS))
def test_bad_arguments_give_errors_naming_them(arg, value):
    scene, plan = plan_of("block-low-friction")
    kw = {"scene": scene, "plan": plan, "workcell": None, "timing": Timing(), "start": None} | {arg: value}
    if arg in ("workcell", "start") and value is None:
        return                            # the defaults
    with pytest.raises(ArgumentError) as e:
        world_motion(**kw)
    assert e.value.field.split(".")[0] == arg, (arg, value, e.value.field)


# block-tilted-gripper: its plan (seed 0) starts pushes with the block turned by up to 0.014 rad
# on the exact limit surface (0.004 rad on the ellipsoid), and the incline features' tilt follows
@pytest.mark.parametrize("name, most", [("pivot-single-3d", np.radians(5.0)), ("offset-3d", 1e-9),
                                        ("block-tilted-gripper", 2e-2)])
def test_gravity_tilt_is_reported_and_kept_small_by_the_edge_cone(name, most):
    scene, plan, m = motion(name)
    g = scene._core.gravity if scene.dimension == 3 else [scene.gravity[0][0], 0, scene.gravity[0][1]]
    g = np.asarray(g) / np.linalg.norm(g)
    for a in m.assignments:
        j = next(j for k, j in m.knots if k == a.first and m.push[j] == a.index)
        world_g = rot(m.gripper[j][3:]) @ g
        tilt = np.arccos(np.clip(-world_g[2], -1, 1))
        assert tilt == pytest.approx(a.tilt, abs=1e-9)
        assert tilt <= most + 1e-9, (a.pusher, np.degrees(tilt))
        if a.feature == "table" and scene.dimension == 2:
            # the table pushes straight up: the tilt is the angle between the pusher's normal
            # (turned by the object's pose) and the scene's "up"
            n = scene.pusher(a.pusher).normal
            th = plan.poses[a.first][2]
            n = [np.cos(th) * n[0] - np.sin(th) * n[1], 0, np.sin(th) * n[0] + np.cos(th) * n[1]]
            assert tilt == pytest.approx(np.arccos(np.clip(-np.dot(n, g), -1, 1)), abs=1e-9)


def test_max_tilt_refuses_pushes_that_would_turn_gravity():
    scene, plan = plan_of("t-shape")
    cell = default_workcell(scene)
    # the default cell's ledge pushes t-shape's `top` down: no tilt
    assert [(a.pusher, a.feature) for a in world_motion(scene, plan).assignments][0] == ("top", "ledge")
    assert all(a.tilt <= MAX_TILT for a in world_motion(scene, plan).assignments)
    # without it, the raised block's underside edges push down, 45° less the edge cone off vertical
    # (the object slides under them lengthwise, SLIDE_GAP below; the block raised 0.1 m more or not)
    f = cell.feature("fixture")
    higher = Feature(f.name, f.kind, f.pose + np.r_[0, 0, 0.1, 0, 0, 0, 0], f.friction, f.size)
    for block in (f, higher):
        under = world_motion(scene, plan, Workcell("no-ledge", cell.table, (block,), cell.robot)).assignments[0]
        assert under.pusher == "top" and under.tilt == pytest.approx(np.radians(5.0), abs=1e-6)
    no_ledge = Workcell("no-ledge", cell.table, (higher,), cell.robot)
    with pytest.raises(ExecutionError) as e:
        world_motion(scene, plan, no_ledge, max_tilt=np.radians(4.0))
    assert "`top`" in str(e.value) and "max_tilt 4.0°" in str(e.value)
    # a tall block standing on the table offers no underside edge: nothing pushes down
    f = cell.feature("fixture")
    tall = Feature("fixture", "block", [*f.pose[:2], 0.75 + 0.2, 1, 0, 0, 0], f.friction, [f.size[0], f.size[1], 0.4])
    no_ledge = Workcell("tall", cell.table, (tall,), cell.robot)
    m = world_motion(scene, plan, no_ledge, max_tilt=np.pi)
    worst = max(m.assignments, key=lambda a: a.tilt)
    assert worst.pusher == "top" and worst.tilt > np.radians(80)
    with pytest.raises(ExecutionError) as e:
        world_motion(scene, plan, no_ledge, max_tilt=np.radians(45))
    assert "`top`" in str(e.value) and "max_tilt" in str(e.value)
    assert e.value.field == f"plan.path[{worst.first + 1}].pusher"
    ok = world_motion(scene, plan, no_ledge, max_tilt=worst.tilt + 1e-9)
    assert [a.feature for a in ok.assignments] == [a.feature for a in m.assignments]
    with pytest.raises(ArgumentError) as e:
        world_motion(scene, plan, max_tilt=-1.0)
    assert e.value.field == "max_tilt"


@pytest.mark.parametrize("name", ["block-low-friction", "block-xztheta", "pivot-3d", "offset-3d", "block-3d"])
def test_the_object_meets_the_feature_and_its_penetration_is_measured(name):
    """Convex objects: the pusher's own points lie on the feature's contact plane at the knots; the
    reported penetration is the deepest object point behind that plane during the push, and it
    is 0 when every step of the push sticks (the pusher moves with the object)."""
    scene, plan = plan_of(name)
    m = world_motion(scene, plan)
    pts = edge_points(scene)
    assert len(pts) > len(object_points(scene))
    labels = np.array(m.labels)
    contacts = {c.name: c for c in m.workcell.contacts()}
    for a, reported in zip(m.assignments, m.penetration):
        F = T(a.frame)
        c = contacts[a.feature]
        deepest = 0.0
        for j in np.flatnonzero((m.push == a.index) & (labels == "push")):
            local = (np.linalg.inv(F) @ T(m.object[j]) @ np.c_[pts, np.ones(len(pts))].T)[:3]
            if c.kind == "face":            # only points over the face's rectangle (turned by phi)
                r = np.linalg.norm(local[:2], axis=0)
                ang = np.arctan2(local[1], local[0]) + np.arctan2(*(np.linalg.inv(T(c.frame)) @ F)[[1, 0], 0])
                inside = (np.abs(r * np.cos(ang)) <= c.extent[0] + 1e-9) & (np.abs(r * np.sin(ang)) <= c.extent[1] + 1e-9)
                local = local[:, inside]
            if local.shape[1]:
                deepest = max(deepest, -local[2].min())
        assert reported == pytest.approx(deepest, abs=1e-12)
        sticks = all(plan.dimension == 2 or plan.pusher_twists[k] is None or np.allclose(
            plan.pusher_twists[k], regrasp.pose.twist_between(plan.poses[k - 1], plan.poses[k]), atol=1e-9)
            for k in range(a.first + 1, a.last + 1))
        if sticks:
            assert reported < 1e-9, (a.pusher, reported)
        for k, j in m.knots:
            if m.push[j] != a.index:
                continue
            if scene.dimension == 2:
                pp = scene.pusher(a.pusher).points
                pp = np.column_stack([pp[:, 0], np.zeros(len(pp)), pp[:, 1]])
            else:
                pp = np.asarray(scene._core.pusher_spec(a.pusher, list(plan.poses[k]))[0])
            local = (np.linalg.inv(F) @ T(m.object[j]) @ np.c_[pp, np.ones(len(pp))].T)[:3]
            if sticks or k == a.first:
                assert np.abs(local[2]).max() < 1e-9
    if name == "pivot-3d":                 # the pivot swings the object past the small plate
        assert m.assignments[0].feature == "plate" and m.penetration[0] < PENETRATION_LIMIT


def test_a_push_through_a_large_face_is_refused_naming_it():
    """pivot-3d turns its object about its patch pusher: on the fixture block's 10 cm face (the
    plate removed) the object would go 1.45 mm into the block."""
    scene, plan = plan_of("pivot-3d")
    cell = default_workcell(scene)
    plate = cell.feature("plate")
    assert plate.size[0] < 0.05                          # sized to the patch, not the block
    no_plate = Workcell("no-plate", cell.table, tuple(f for f in cell.features if f.name != "plate"), cell.robot)
    with pytest.raises(ExecutionError) as e:
        world_motion(scene, plan, no_plate)
    assert "`corner`" in str(e.value) and "mm into feature `fixture.faces" in str(e.value)
    assert e.value.field == "plan.path[1].pusher"


def test_under_the_ledge_transfers_go_beside_it():
    """t-shape's `top` is pushed down by the ledge: the object reaches under it from the side, and
    no transfer sample puts the object across the ledge's edge line (checked in the edge's frame)."""
    scene, plan = plan_of("t-shape")
    m = world_motion(scene, plan)
    ledge = m.workcell.feature("ledge")
    Linv = np.linalg.inv(T(ledge.pose))
    pts = np.c_[object_points(scene), np.ones(len(object_points(scene)))].T
    labels = np.array(m.labels)
    crossed = 0
    for j in np.flatnonzero(labels != "push"):
        local = (Linv @ T(m.object[j]) @ pts)[:3]
        over = local[0].max() > -ledge.length / 2 and local[0].min() < ledge.length / 2
        if over and local[1].min() < 0 < local[1].max() and local[2].min() < 0 < local[2].max():
            crossed += 1
    assert crossed == 0
    a = m.assignments[0]
    assert a.feature == "ledge" and rot(a.frame[3:])[2, 2] == pytest.approx(-1)   # pushing down
