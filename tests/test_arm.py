"""Plans executed by the real arm in the workcell (regrasp.execution.arm, `regrasp execute`), with
the real engine: the joint trajectory checked by forward kinematics against the world motion,
the measured in-hand poses against the object's and the TCP's world poses (4 x 4 matrices), the
result against the plan's goal and the scene's tolerance; refusals name the push."""

import json

import numpy as np
import pytest

import regrasp
from regrasp import ExecutionError
from regrasp.execution import Trajectory, world_motion
from regrasp import Perturbation
from regrasp.execution.arm import build_robot, execute_arm, grasp_of, solve_arm, where
from regrasp.robot.ik import MAX_JUMP
from regrasp.robot.pads import Pads
from regrasp.workcell import Workcell
from regrasp.workcell.description import Robot

from .conftest import pose_matrix as T, run_cli

pytest.importorskip("mink")
CASES: dict = {}


def case(name):
    """(scene, plan, motion, robot, tcp, arm trajectory) of bundled example ``name``."""
    if name not in CASES:
        scene = regrasp.load_scene(regrasp.examples.path(name))
        plan = regrasp.plan(scene, seed=0)
        motion = world_motion(scene, plan)
        robot, _, _, tcp = build_robot(scene, motion)
        CASES[name] = (scene, plan, motion, robot, tcp, solve_arm(robot, motion, tcp))
    return CASES[name]


def test_grasp_of_a_mesh_is_its_extent_across_the_pads():
    scene = regrasp.load_scene(regrasp.examples.path("offset-3d"))
    start = np.asarray(scene.task[0], float)
    width, centre = grasp_of(scene, start)
    v = np.asarray(scene.mesh()[0], float)
    y = (T(start) @ np.c_[v, np.ones(len(v))].T)[1]  # independent: the 4 x 4 matrix
    assert width == pytest.approx(y.max() - y.min(), abs=1e-12)
    assert centre == pytest.approx((y.max() + y.min()) / 2, abs=1e-12)
    assert grasp_of(regrasp.load_scene(regrasp.examples.path("t-shape")), np.r_[0, 0, 0, 1.0, 0, 0, 0]) == (0.012, 0.0)


def test_pads_of_a_scene_cover_its_pad_shape():
    p = Pads.of_scene(regrasp.load_scene(regrasp.examples.path("block-xztheta"))).points()  # a 7 mm disc
    r = np.hypot(p[:, 0], p[:, 2] - p[:, 2].mean())
    assert len(p) == 13 and r.max() + 0.001 <= 0.007 + 1e-12 and r.min() == pytest.approx(0.0, abs=1e-12)
    q = Pads(3, 4, 0.001, ("rectangle", 0.01, 0.02)).points()
    assert len(q) == 12 and np.ptp(q[:, 0]) == pytest.approx(0.008) and np.ptp(q[:, 2]) == pytest.approx(0.018)


@pytest.mark.parametrize("name", ["block-3d", "block-fixtureless"])
def test_the_joint_trajectory_puts_the_tcp_on_the_world_motion(name):
    scene, plan, motion, robot, tcp, arm = case(name)
    assert arm.q.shape == (len(motion.times), 6) and list(arm.joint_names) == list(robot.arm_joints)
    lim = robot.joint_limits()
    assert np.all(arm.q >= lim[:, 0]) and np.all(arm.q <= lim[:, 1])
    assert np.abs(np.diff(arm.q, axis=0)).max() <= MAX_JUMP
    for i in range(0, len(arm.q), 37):  # independent: forward kinematics against G_i ∘ tcp as matrices
        got = T(robot.tcp_pose(arm.q[i]))
        want = T(motion.gripper[i]) @ T(tcp)
        assert np.abs(got[:3, 3] - want[:3, 3]).max() < 1e-3
        assert np.abs(got[:3, :3] - want[:3, :3]).max() < 0.01


def test_the_arm_executes_a_3d_plan_in_the_workcell():
    scene, plan, motion, robot, tcp, arm = case("block-3d")
    r = execute_arm(scene, plan, motion, trajectory=arm)
    assert r.success, r.goal_error
    goal = np.asarray(plan.poses[-1], float)
    assert np.linalg.norm(r.in_hand[-1][:3] - goal[:3]) == pytest.approx(r.goal_error[0], abs=1e-12)
    assert r.goal_error[0] <= np.linalg.norm(scene.task[2][:3]) and r.max_creep < 1e-3
    # the arm followed its joint trajectory; the object stayed near the plan all along
    assert np.abs(r.q - arm.q).max() < 0.01 and r.tracking.tcp_error < 3e-3
    assert np.linalg.norm(r.in_hand[:, :3] - r.planned[:, :3], axis=1).max() < 3e-3


def test_a_world_perturbation_changes_the_world_but_not_the_trajectory():
    scene, plan, motion, robot, tcp, arm = case("block-3d")
    k = Perturbation(finger_friction=0.8, grip=0.5, mass=3.0, feature_friction=1.2)
    scaled, body, _, _ = build_robot(scene, motion, scales=k)
    m0, m1 = robot.model, scaled.model
    assert m1.body_mass[body] == pytest.approx(3.0 * m0.body_mass[body])
    pad = robot.pad_geoms[0][0]
    assert m1.geom_friction[pad, 0] == pytest.approx(0.8 * m0.geom_friction[pad, 0])
    fixture = m0.geom("fixture").id
    assert m1.geom_friction[fixture, 0] == pytest.approx(1.2 * m0.geom_friction[fixture, 0])
    heavy = execute_arm(scene, plan, motion, scales=k, trajectory=arm)
    nominal = execute_arm(scene, plan, motion, trajectory=arm)
    assert np.array_equal(heavy.trajectory.q, nominal.trajectory.q)
    assert np.abs(heavy.in_hand - nominal.in_hand).max() > 1e-5


def test_an_arm_out_of_reach_is_refused_naming_the_push():
    scene, plan, motion, *_ = case("block-3d")
    far = Workcell("far", motion.workcell.table, motion.workcell.features, Robot("ur5e", [3.0, 0, 0.75, 1, 0, 0, 0]))
    m = world_motion(scene, plan, far)
    with pytest.raises(ExecutionError, match=r"the arm cannot execute the transfer before push 0 .*unreachable") as e:
        execute_arm(scene, plan, m)
    assert e.value.field == "robot"
    assert where(m, int(np.flatnonzero(m.push == 0)[0])).startswith("push 0 (approach, pusher ")


def test_the_trajectory_file_carries_the_joints(tmp_path):
    scene, plan, motion, robot, tcp, arm = case("block-3d")
    path = motion.to_trajectory(arm).save(tmp_path / "t.json")
    t = Trajectory.load(path)
    assert t.robot == "ur5e-2f85" and t.joint_names == list(robot.arm_joints)
    assert np.array_equal(t.q, arm.q) and np.array_equal(t.gripper, motion.gripper)
    raw = json.loads(path.read_text())
    assert len(raw["samples"][5]["q"]) == 6


def test_execute_cli(tmp_path):
    plan = tmp_path / "plan.json"
    scene = regrasp.examples.path("block-3d")
    assert run_cli("plan", scene, "--out", plan)[0] == 0
    code, out, err = run_cli("execute", scene, "--plan", plan, "--trajectory", tmp_path / "traj.json", "--json")
    assert code == 0, err
    r = json.loads(out)
    assert {"success", "goal_error", "max_creep", "robot", "duration_s"} <= set(r) and r["success"] is True
    # the 2F-85's own sensing by default: its force setting, no measurement
    assert r["grip_sensing"] == "open-loop" and "holding" not in r  # a 3-D scene's hold is not tested yet
    assert r["robot"] == "ur5e-2f85" and r["pushes"][0]["feature"]
    assert Trajectory.load(tmp_path / "traj.json").q.shape[1] == 6
    code, out, err = run_cli("execute", scene, "--plan", plan, "--robot", "free-gripper", "--json")
    free = json.loads(out)
    assert free["robot"] == "free-gripper" and free["success"] is True and code == 0, err
    code, out, err = run_cli("execute", scene, "--plan", plan, "--robot", "free-gripper")  # the text for people
    assert code == 0 and out.startswith("block-3d: free-gripper in workcell default-block-3d") and " mm, " in out, err


def test_execute_cli_refusals(tmp_path):
    scene = regrasp.examples.path("block-3d")
    code, _, err = run_cli("execute", scene, "--plan", tmp_path / "p.json", "--robot", "kuka")
    assert code == 2 and "--robot" in err and "ur5e-2f85" in err
    code, _, err = run_cli("execute", scene, "--plan", tmp_path / "p.json", "--trajectory", tmp_path / "t.txt")
    assert code == 2 and "--trajectory" in err
    code, _, err = run_cli("execute", scene, "--plan", tmp_path / "p.json", "--trajectory", scene)
    assert code == 2
    for extra in (["--grip-sensing", "psychic"], ["--grip-sensing", "sensor:0.1,nan,100"],
                  ["--grip-sensing", "ideal", "--robot", "free-gripper"], ["--grip-sensing", "ideal", "--plan-only"]):
        code, _, err = run_cli("execute", scene, "--plan", tmp_path / "p.json", *extra)
        assert code == 2 and "--grip-sensing" in err and "Traceback" not in err, (extra, err)
    for name in ("block-3d", "block-xztheta"):
        regrasp.plan(regrasp.load_scene(regrasp.examples.path(name)), seed=0).save(tmp_path / f"{name}.json")
    bad = [("block-3d", ["--start-error", "0.001,0,0"]),  # planar only
           ("block-3d", ["--start-error", "0.001,0,0", "--closed-loop"]),
           ("block-xztheta", ["--start-error", "0.001,0"]),
           ("block-xztheta", ["--start-error", "0.001,nan,0", "--closed-loop"]),
           ("block-xztheta", ["--start-error", "0.001,0,0", "--robot", "free-gripper"]),
           ("block-xztheta", ["--start-error", "0.5,0,0"]),  # the pad off the object
           ("block-xztheta", ["--start-error", "0,0.5,0", "--closed-loop"])]
    for name, extra in bad:
        code, out, err = run_cli("execute", regrasp.examples.path(name), "--plan", tmp_path / f"{name}.json", *extra)
        assert code == 2 and "--start-error" in err and "Traceback" not in err, (extra, err)


def test_the_workcell_and_the_object_touch_with_the_stiff_contact_settings():
    """The table, the features and the object take the model's contact settings (a stiff
    aluminium-on-steel contact), not MuJoCo's soft default (0.02 s): with that, a 24 N push
    pressed the block 1 mm into the table and every planar push ended 1 mm short."""
    import mujoco

    from regrasp.mujoco.model import Contact

    scene, plan, motion, robot, tcp, arm = case("block-fixtureless")
    m, d = robot.model, mujoco.MjData(robot.model)
    d.qpos[:] = robot.data.qpos
    mine = [g for g in range(m.ngeom) if m.geom_bodyid[g] == 0 or m.body(m.geom_bodyid[g]).name == "object"]
    assert len(mine) >= 3
    assert np.allclose(m.geom_solref[mine], Contact().solref) and np.allclose(m.geom_solimp[mine, :3], Contact().solimp)
    # independent: the block pressed onto the table top with 24 N stays within 0.05 mm of it
    body = m.body("object").id
    jq, jv = m.jnt_qposadr[m.body_jntadr[body]], m.jnt_dofadr[m.body_jntadr[body]]
    top = m.geom_pos[m.geom("table").id][2] + m.geom_size[m.geom("table").id][2]
    d.qpos[jq:jq + 7] = [0.9, -0.3, top + 0.04, 1, 0, 0, 0]  # clear of the arm and the features, its bottom face on the table
    d.qvel[jv:jv + 6] = 0
    d.xfrc_applied[body, 2] = -24.0
    for _ in range(400):
        mujoco.mj_step(m, d)
    assert 0.0 <= top - (d.xpos[body][2] - 0.04) < 5e-5


def test_the_robot_is_built_with_its_fingers_on_the_object():
    """The IK freezes the fingers as built: they must sit where they hold the object (the 2F-85's
    linkage moves in and down as it closes, so an open hand's clearance to a feature is wrong)."""
    scene, plan, motion, robot, tcp, arm = case("block-3d")
    width, _ = grasp_of(scene, motion.in_hand[0])
    m, d = robot.model, robot.data
    R = T(robot.tcp_pose())
    # independent: the pad spheres' innermost surfaces, in the TCP frame (y across the pads)
    ys = [np.linalg.inv(R) @ np.r_[d.geom_xpos[g], 1.0] for side in robot.pad_geoms for g in side]
    rad = m.geom_size[robot.pad_geoms[0][0], 0]
    left = [p[1] for p in ys[:len(robot.pad_geoms[0])]]
    right = [p[1] for p in ys[len(robot.pad_geoms[0]):]]
    gap = abs(np.mean(left) - np.mean(right)) - 2 * rad
    assert gap == pytest.approx(width, abs=5e-4)


def test_a_finger_too_near_the_table_is_refused_with_the_exact_clearance():
    """prism-3d's `ground` push holds the prism's apex on the table 13 mm below the pads' centre:
    the closed 2F-85's fingers come within 1 mm (CONTACT_CLEARANCE) of the table and of the
    fixture's top. The IK reaches the pose (mink's collision limit, 2 mm more cautious, alone
    stopped it 1 mm short and 2.8 mm clear) and the exact clearance refuses it, naming the
    finger, the table and the distance."""
    import re

    from regrasp.execution.arm import CONTACT_CLEARANCE, arm_motion

    scene = regrasp.load_scene(regrasp.examples.path("prism-3d"))
    with pytest.raises(ExecutionError) as e:
        arm_motion(scene, regrasp.plan(scene, seed=0))
    text = str(e.value)
    for feature in ("table", "fixture"):
        m = re.search(r"collision: the arm or gripper ([0-9.]+) mm from the table or an obstacle \(gripper/(left|right)_\w+ and "
                      + feature + r"; it keeps 1 mm\); closest ([0-9.]+) mm", text)
        assert m, text
        assert float(m.group(1)) < CONTACT_CLEARANCE * 1e3 and float(m.group(3)) <= 0.1


def test_the_plate_faces_the_robot_within_its_reach():
    """pivot-3d's patch pivot goes to the default workcell's plate, which faces the robot: the arm
    can follow it (facing away, the plate was beyond the UR5e's reach)."""
    from regrasp.execution.arm import CONTACT_CLEARANCE, first_solution
    from regrasp.robot.ik import fixed_geoms, ik_path

    scene = regrasp.load_scene(regrasp.examples.path("pivot-3d"))
    motion = world_motion(scene, regrasp.plan(scene, seed=0))
    assert motion.assignments[0].feature == "plate"
    normal = regrasp.pose.quat_rotate(motion.workcell.feature("plate").pose[3:], [0.0, 0, 1])
    assert normal[0] == pytest.approx(-1.0)  # pushes along world −x, towards the robot at the origin
    robot, _, _, tcp = build_robot(scene, motion)
    push = np.flatnonzero(motion.push == 0)
    targets = regrasp.pose.compose_rows(motion.gripper[push], np.broadcast_to(tcp, (len(push), 7)))
    avoid = fixed_geoms(robot)
    q = ik_path(robot, targets, first_solution(robot, targets[0], avoid), avoid=avoid, min_distance=CONTACT_CLEARANCE)
    assert np.all(np.isfinite(q)) and len(q) == len(push)


def _object_hand_contacts(robot, motion, tcp, i):
    """MuJoCo's own contacts (mj_forward's collision detection) between the object at in-hand
    pose ``i`` of ``motion`` and the gripper's bodies other than the pads: [(body name, dist)]."""
    import mujoco

    m = robot.model
    d = mujoco.MjData(m)
    d.qpos[:] = robot.data.qpos
    body = m.body("object").id
    jq = m.jnt_qposadr[m.body_jntadr[body]]
    frame = regrasp.pose.compose(robot.tcp_pose(), regrasp.pose.inverse(tcp))
    d.qpos[jq:jq + 7] = regrasp.pose.compose(frame, motion.in_hand[i])
    mujoco.mj_forward(m, d)
    pads = {int(m.geom_bodyid[g]) for side in robot.pad_geoms for g in side}
    out = []
    for c in d.contact[:d.ncon]:
        b1, b2 = int(m.geom_bodyid[c.geom1]), int(m.geom_bodyid[c.geom2])
        if body in (b1, b2):
            other = b2 if b1 == body else b1
            if other not in pads and m.body(other).name.startswith("gripper/"):
                out.append((m.body(other).name, float(c.dist)))
    return out


def test_the_arm_holds_still_while_the_fingers_close():
    """close_on holds the arm's joints with the servo while the fingers close on offset-3d's
    block: the TCP moves 0.003 mm (with the actuators merely commanded to the measured joints,
    the arm sagged 0.54 mm and the block started 0.5 mm up in the hand)."""
    import mujoco

    from regrasp.execution.arm import arm_motion, close_on

    scene = regrasp.load_scene(regrasp.examples.path("offset-3d"))
    am = arm_motion(scene, regrasp.plan(scene, seed=0))
    motion, arm = am.motion, am.trajectory
    r, body, geoms, tcp = build_robot(scene, motion)
    r.set_q(arm.q[0])
    jq = r.model.jnt_qposadr[r.model.body_jntadr[body]]
    r.data.qpos[jq:jq + 7] = regrasp.pose.compose(regrasp.pose.compose(r.tcp_pose(), regrasp.pose.inverse(tcp)),
                                                  motion.in_hand[0])
    mujoco.mj_forward(r.model, r.data)
    before = r.tcp_pose()
    close_on(r, body, geoms, float(motion.grip_force[0]))
    assert np.linalg.norm(r.tcp_pose()[:3] - before[:3]) < 5e-5


def _brute_clearance(robot, motion, tcp):
    """hand_clearance's minimum the slow way: every sample, every pair of the object's and
    the gripper's colliding geoms (pads' bodies left out by name), a fixed 50 mm search."""
    import mujoco

    m = robot.model
    d = mujoco.MjData(m)
    d.qpos[:] = robot.data.qpos
    body = m.body("object").id
    jq = m.jnt_qposadr[m.body_jntadr[body]]
    hand = [g for g in range(m.ngeom) if m.body(m.geom_bodyid[g]).name.startswith("gripper/")
            and not m.body(m.geom_bodyid[g]).name.endswith("_pad") and (m.geom_contype[g] or m.geom_conaffinity[g])]
    obj = [g for g in range(m.ngeom) if m.geom_bodyid[g] == body]
    frame = regrasp.pose.compose(robot.tcp_pose(), regrasp.pose.inverse(tcp))
    best = np.inf
    for h in motion.in_hand:
        d.qpos[jq:jq + 7] = regrasp.pose.compose(frame, h)
        mujoco.mj_kinematics(m, d)
        best = min([best] + [mujoco.mj_geomDistance(m, d, o, g, 0.05, None) for o in obj for g in hand])
    return best


def test_a_plan_that_puts_the_object_into_the_gripper_is_refused():
    """pivot-3d's lift raises the block 10 mm in the hand turned 0.4 rad: its corner goes 2.4 mm
    into the 2F-85's housing, which the planner (it sees only the pads) cannot know; executed,
    the housing pressed the block with ≈ 170 N and the run failed. Refused before the arm
    moves, naming the push and the part; MuJoCo's own collision detection finds the contact at
    the reported pose, and none on block-3d, whose object stays clear of the hand."""
    from regrasp.execution.arm import arm_motion, hand_clearance

    scene = regrasp.load_scene(regrasp.examples.path("pivot-3d"))
    plan = regrasp.plan(scene, seed=0)
    with pytest.raises(ExecutionError, match=r"cannot be done in this hand: at push 1 \(push, pusher ground.* goes "
                       r"([0-9.]+) mm into the gripper's `base`") as e:
        arm_motion(scene, plan)
    motion = world_motion(scene, plan)
    assert e.value.field == f"plan.path[{motion.assignments[1].first + 1}].pusher"
    robot, _, _, tcp = build_robot(scene, motion)
    dist, i, part = hand_clearance(robot, motion, tcp)
    assert part == "gripper/base" and -4e-3 < dist < -1e-3 and motion.push[i] == 1
    hits = _object_hand_contacts(robot, motion, tcp, i)
    assert hits and min(h[1] for h in hits) == pytest.approx(dist, abs=5e-4)
    assert not _object_hand_contacts(robot, motion, tcp, 0)  # at the start the block is clear
    assert dist == pytest.approx(_brute_clearance(robot, motion, tcp), abs=1e-9)
    scene, plan, motion, robot, tcp, arm = case("block-3d")
    dist, i, _ = hand_clearance(robot, motion, tcp)
    assert dist > 1e-3 and not _object_hand_contacts(robot, motion, tcp, i)
    assert dist == pytest.approx(_brute_clearance(robot, motion, tcp), abs=1e-9)
    # held between pushes (t-shape's T at its start, inside the base): the plan's pose is named
    scene = regrasp.load_scene(regrasp.examples.path("t-shape"))
    with pytest.raises(ExecutionError, match=r"at the transfer before push 0 .* goes [0-9.]+ mm into the gripper's `base`") as e:
        arm_motion(scene, regrasp.plan(scene, seed=0))
    assert e.value.field == "plan.path[0].pose"


def test_a_top_push_slides_under_the_ledge_lengthwise_between_the_fingers(tmp_path):
    """block-low-friction's `top`, 40 mm above the pads' centre, pushed down by the ledge: the
    ledge's bar enters between the fingers along its length, 3 mm above the block and under the
    2F-85's housing (across it, the fingers meet the bar; 20 mm above the block, the housing
    does), and the arm executes the push."""
    from regrasp.execution.arm import arm_motion
    from regrasp.execution.world_motion import SLIDE_GAP

    text = open(regrasp.examples.path("block-low-friction")).read()
    keep = [p for p in text.split("[[pushers]]")[1:] if 'name = "top"' in p]
    head = text.split("[[pushers]]")[0].replace('name = "block-low-friction"', 'name = "block-top"')
    task = "[task]" + text.split("[task]")[1].replace("goal = [0.012, 0.008, 0.0]", "goal = [0.0, -0.008, 0.0]")
    (tmp_path / "top.toml").write_text(head + "[[pushers]]" + keep[0].split("[task]")[0] + task)
    scene = regrasp.load_scene(tmp_path / "top.toml")
    plan = regrasp.plan(scene, seed=0)
    am = arm_motion(scene, plan)
    m = am.motion
    assert [(a.pusher, a.feature) for a in m.assignments] == [("top", "ledge")] and not am.refused
    # the approach slides along the ledge (world x), across the grasp axis (world y), SLIDE_GAP below it
    ledge = m.workcell.feature("ledge")
    slide = [j for j in range(len(m.labels)) if m.labels[j] == "approach" and m.push[j] == 0]
    G = m.gripper[slide]
    grasp_axis = np.array([T(g)[:3, 1] for g in G])
    moves = np.diff(G[:, :3], axis=0)
    along = moves[np.linalg.norm(moves, axis=1) > 1e-9]
    assert np.abs(along[:, 1]).max() < 1e-9 and np.abs(along[:, 0]).max() > 0
    assert np.abs(grasp_axis[:, 0]).max() < 1e-9
    corners = np.c_[np.asarray(scene.outline)[:, 0], np.zeros(4), np.asarray(scene.outline)[:, 1], np.ones(4)]
    top = (T(m.object[slide[0]]) @ corners.T)[2].max()
    assert ledge.pose[2] - top == pytest.approx(SLIDE_GAP, abs=1e-6)
    r = execute_arm(scene, plan, m, trajectory=am.trajectory)
    assert r.success, r.goal_error


def test_the_arm_executes_the_non_convex_bracket():
    """The L-bracket (two convex parts, issue 18) run by the arm in its default workcell: MuJoCo
    collides its parts with the pads, the plate and the ground."""
    scene, plan, motion, robot, tcp, arm = case("bracket-pivot-3d")
    r = execute_arm(scene, plan, motion, trajectory=arm)
    assert r.success, r.goal_error
