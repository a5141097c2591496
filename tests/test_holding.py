"""The pads' hold through an arm's motion (regrasp.execution.holding, the hold test of
``execution.arm.timed``): the object's load from MuJoCo's Jacobians against finite differences
of its forward kinematics; at rest in the scene's own gripper orientation the hold ratio of the
cones; a lift too fast for a heavy object slowed until the pads hold it with the required
margin; one that gravity alone loads beyond it refused naming where."""

import tomllib

import numpy as np
import pytest

import regrasp
from regrasp import pose as P
from regrasp.errors import ExecutionError

pytest.importorskip("mink")
mujoco = pytest.importorskip("mujoco")

from regrasp.execution import default_workcell  # noqa: E402
from regrasp.execution import pick_place as pp  # noqa: E402
from regrasp.execution.arm import timed  # noqa: E402
from regrasp.execution.holding import HOLD_MARGIN, ObjectLoad, required_margin  # noqa: E402
from regrasp.execution.world_motion import WorldMotion  # noqa: E402
from regrasp.robot.ik import ik_path, solve_ik  # noqa: E402

#: The lift's TCP path: straight up this far [m] from this world point, the gripper upright
#: (its frame the world's: the scene's gravity, −z, as planned).
LIFT_FROM, LIFT = np.array([0.45, 0.1, 0.95]), 0.3


def scene_at(hold: float):
    """block-xztheta with its mass scaled so that gravity alone takes ``hold`` of the pads'
    friction at its start (the pad at the block's centre)."""
    s0 = regrasp.load_scene(regrasp.examples.path("block-xztheta"))
    return s0.scaled(mass=hold / s0.hold_ratio(s0.task.start))


def lift(scene, n: int = 61, duration: float = 0.6, in_hand=None):
    """The arm, the object's load and a WorldMotion of a fast vertical lift holding ``scene``'s
    object at ``in_hand`` (default: its start) in-hand pose: (robot, load, motion, tcp, joint path)."""
    wc = default_workcell(scene)
    start = np.asarray(scene.task.start if in_hand is None else in_hand, float)
    in_hand = np.array(P.planar_to_spatial(start))
    G = np.array([np.r_[LIFT_FROM + [0, 0, LIFT * pp.eased(s)], 1.0, 0, 0, 0] for s in np.linspace(0, 1, n)])
    W = P.compose_rows(G, np.broadcast_to(in_hand, G.shape))
    r, body, _, tcp, avoid = pp._arm_robot(scene, wc, W[0], start)
    motion = WorldMotion(np.linspace(0, duration, n), G, W, np.broadcast_to(in_hand, G.shape).copy(),
                         ["transfer"] * n, np.full(n, -1), np.full(n, scene.grip_force), [], [], 1.0, wc)
    targets = P.compose_rows(G, np.broadcast_to(tcp, G.shape))
    q = ik_path(r, targets, solve_ik(r, targets[0], r.kind.home, avoid=avoid), avoid=avoid)
    return r, ObjectLoad(scene, r, body, tcp, motion), motion, tcp, q


def fk_object(r, load, q, i):
    """The object's world pose at joints ``q``, by MuJoCo's forward kinematics."""
    d = mujoco.MjData(r.model)
    d.qpos[:] = r.data.qpos
    d.qpos[r.arm_qpos] = q
    mujoco.mj_kinematics(r.model, d)
    tcp = np.concatenate([d.site_xpos[r.tcp], P.quat_from_matrix(d.site_xmat[r.tcp].reshape(3, 3))])
    return P.compose(P.compose(tcp, load.tcp_inv), load.in_hand[i])


def test_the_load_is_gravity_and_inertia_by_finite_differences():
    """A smooth joint motion q(t) = q0 + A sin(w t) holding the T (its centre of mass 12.9 mm off
    its origin) 10 mm, 5 mm and 0.3 rad off the pad: the wrench from the Jacobians against
    Newton–Euler done numerically and in 3-D — the pads' force m(a − g) and their moment about the
    object's origin dL/dt + (c − o) × F, with the centre of mass, the rotation and the angular
    momentum I_w ω differentiated by central differences (h = 1e-4 s) through forward
    kinematics — turned into the object frame, the moment's planar part about −y."""
    s = regrasp.load_scene(regrasp.examples.path("t-shape"))
    r, load, _, _, q = lift(s, n=5, in_hand=[0.01, 0.005, 0.3])
    q0, amp, w = q[2], np.array([0.3, -0.2, 0.25, 0.4, -0.3, 0.5]), np.array([2.0, 3.0, 2.5, 4.0, 3.5, 5.0])
    h = 1e-4
    qt = lambda t: q0 + amp * np.sin(w * t)  # noqa: E731

    def state(t):
        """(origin, centre of mass, rotation) of the object at time t."""
        W = fk_object(r, load, qt(t), 0)
        R = P.quat_matrix(W[3:])
        return W[:3], W[:3] + R @ load.com, R

    def momentum(t):
        """The angular momentum I_w ω about the centre of mass, ω from Ṙ Rᵀ."""
        (_, _, Ra), (_, _, R), (_, _, Rb) = state(t - h), state(t), state(t + h)
        S = (Rb - Ra) / (2 * h) @ R.T
        om = np.array([S[2, 1], S[0, 2], S[1, 0]])
        return R @ load.inertia @ R.T @ om, om

    for t in (0.1, 0.4, 0.9):
        qd, qdd = amp * w * np.cos(w * t), -amp * w ** 2 * np.sin(w * t)
        got = load.wrenches([0], qt(t)[None], qd[None], qdd[None])[0]
        (_, ca, _), (o, c, R), (_, cb, _) = state(t - h), state(t), state(t + h)
        a = (cb - 2 * c + ca) / h ** 2
        F = load.mass * (a - load.gravity)  # what the pads supply, world
        dL = (momentum(t + h)[0] - momentum(t - h)[0]) / (2 * h)
        M = dL + np.cross(c - o, F)  # the pads' moment about the object's origin, world
        fo, Mo = R.T @ F, R.T @ M
        want = -np.array([fo[0], fo[2], -Mo[1]])  # the load is what the pads resist; planar θ is about −y
        assert np.allclose(got, want, rtol=2e-3, atol=2e-3 * load.mass * 9.81), (got, want)
        # the motion's inertia and turning are a sizeable part of the load tested
        assert np.linalg.norm(a) > 0.5 and np.linalg.norm(momentum(t)[1]) > 0.5
        assert abs(load.com[2]) > 0.01 and abs(got[2]) > 1e-3


def test_at_rest_in_the_planned_orientation_the_ratio_is_the_cones_hold_ratio():
    s = scene_at(0.6)
    r, load, motion, _, q = lift(s, n=5)
    z = np.zeros_like(q)
    got = load.ratios(np.arange(len(q)), q, z, z)
    assert np.allclose(got, s.hold_ratio(s.task.start), rtol=1e-6)
    assert load.mass == pytest.approx(s.mass)


def test_the_required_margin_covers_the_scenes_uncertainty():
    s = regrasp.load_scene(regrasp.examples.path("block-fixtureless"))
    u = s.uncertainty
    worst = (1 + u.get("mass", 0)) / ((1 - u.get("finger_friction", 0)) * (1 - u.get("grip_force", 0)))
    # a ratio that uses all the allowed share stays below 1 − HOLD_MARGIN in the worst corner
    assert (1 - required_margin(s)) * worst == pytest.approx(1 - HOLD_MARGIN)
    assert required_margin(scene_at(0.5)) == pytest.approx(HOLD_MARGIN)


def test_a_lift_too_fast_for_a_heavy_object_is_slowed_until_the_pads_hold():
    """Gravity alone takes 0.9 of the pads' friction; a 0.3 m lift planned in 0.6 s, timed only
    within the joint limits, accelerates the object upward enough to take more than the 0.95
    allowed; timed with the hold test, every sample keeps the required margin, and it takes longer."""
    from regrasp.execution.retime import retime

    s = scene_at(0.9)
    r, load, motion, tcp, q = lift(s)
    plain = retime(motion.times, q, r.kind.velocity_limit, r.kind.acceleration_limit)
    fast = load.holding(q, plain.qd, plain.qdd)
    assert fast.smallest < fast.required  # the test case loads the pads beyond the allowed share
    traj = timed(r, motion, tcp, q, load)
    h = traj.holding
    assert h.holds and h.smallest >= h.required - 1e-9 and h.required == pytest.approx(HOLD_MARGIN)
    again = load.holding(q, traj.qd, traj.qdd)  # recomputed from the returned trajectory
    assert np.nanmax(again.ratio) <= 1 - HOLD_MARGIN + 1e-9
    assert traj.times[-1] - traj.times[0] > plain.times[-1]
    assert "transfer" in h.where and h.to_json()["holds"] is True


def test_a_load_gravity_alone_takes_beyond_the_margin_is_refused_naming_where():
    s = scene_at(0.97)
    r, load, motion, tcp, q = lift(s, n=5)
    with pytest.raises(ExecutionError) as e:
        timed(r, motion, tcp, q, load)
    msg = str(e.value)
    assert "the pads cannot hold the object in the final transfer" in msg and "gravity alone takes 97.0%" in msg
    assert e.value.field == "robot"


def test_the_grip_is_raised_between_pushes_and_the_push_keeps_the_plans():
    """Gravity takes 0.8 of the pads' friction: held samples (start, transfer, retreat, the approach
    but its last SETTLE_SAMPLES) get the grip that makes it TRANSFER_SHARE, at rest; the push and
    the approach's tail keep the plan's grip; a cap bounds it."""
    from regrasp.execution.holding import HELD, SETTLE_SAMPLES, TRANSFER_SHARE

    s = scene_at(0.8)
    r, load, motion, _, q = lift(s, n=61)
    labels = ["start"] + ["transfer"] * 19 + ["approach"] * 20 + ["push"] * 5 + ["retreat"] * 16
    load.labels, load.held = labels, np.array([lab in HELD for lab in labels])
    scale = load.boost(q, max_scale=10.0)
    z = np.zeros_like(q)
    ratio = load.ratios(np.arange(len(q)), q, z, z)
    tail = np.arange(40 - SETTLE_SAMPLES, 40)
    raised = np.array([i for i in range(len(q)) if labels[i] != "push" and i not in tail])
    assert np.allclose(scale[raised], 0.8 / TRANSFER_SHARE, rtol=1e-3)
    assert np.all(scale[tail] == 1.0) and np.all(scale[40:45] == 1.0)
    assert np.allclose(ratio[raised], TRANSFER_SHARE, rtol=1e-3) and np.allclose(ratio[tail], 0.8, rtol=1e-3)
    assert np.all(load.boost(q, max_scale=1.2) <= 1.2)


def test_the_closed_loop_raises_the_grip_between_pushes_as_the_open_loop():
    """``ArmPlant.transfer_grip``: the plan's grip where gravity takes at most TRANSFER_SHARE,
    raised in proportion beyond it, capped by the gripper's ceiling; the ceiling when the
    measured pose has the pads (partly) off the object (no error mid-run)."""
    from types import SimpleNamespace

    import regrasp
    from regrasp.execution.arm_loop import ArmPlant
    from regrasp.execution.holding import TRANSFER_SHARE

    scene = regrasp.load_scene(regrasp.examples.path("block-low-friction"))
    me = SimpleNamespace(scene=scene, grip_force=10.0, grip_ceiling=40.0)
    q = [0.0, 0.0, 0.0]
    share = scene.hold_ratio(q)
    want = 10.0 * max(1.0, share / TRANSFER_SHARE)
    assert ArmPlant.transfer_grip(me, q) == pytest.approx(min(want, 40.0))
    from pathlib import Path

    heavy = regrasp.load_scene(Path(regrasp.examples.__file__).parent / "hard" / "heavy-low-friction.toml")
    goal = heavy.task.goal  # gravity takes 82 % of the pads' friction there
    h = SimpleNamespace(scene=heavy, grip_force=25.0, grip_ceiling=100.0)
    ratio = heavy.hold_ratio(goal)
    assert ratio > TRANSFER_SHARE and ArmPlant.transfer_grip(h, goal) == pytest.approx(25.0 * ratio / TRANSFER_SHARE)
    assert ArmPlant.transfer_grip(SimpleNamespace(scene=heavy, grip_force=25.0, grip_ceiling=30.0), goal) == 30.0
    assert ArmPlant.transfer_grip(me, [0.5, 0.5, 0.0]) == 40.0
    # a scene that declares ±20 % in finger friction, grip and mass: TRANSFER_SHARE in its worst
    # world, 0.5·0.8·0.8/1.2 of the nominal pads' friction (computed here from the definition)
    d = tomllib.loads(heavy.source[1])
    d["uncertainty"] = {"finger_friction": 0.2, "grip_force": 0.2, "mass": 0.2}
    unsure = regrasp.Scene.from_dict(d)
    u = SimpleNamespace(scene=unsure, grip_force=25.0, grip_ceiling=1000.0)
    assert ArmPlant.transfer_grip(u, goal) == pytest.approx(25.0 * ratio / (TRANSFER_SHARE * 0.8 * 0.8 / 1.2))
