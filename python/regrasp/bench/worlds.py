"""The worlds: MuJoCo against the quasi-static simulator, the world motion, the arm's inverse kinematics and steps, the grasp graph."""

from __future__ import annotations

import time

import numpy as np

from .. import examples as bundled
from ..extras import need
from ..scene.planar import Scene
from .timing import _median_time


def run_mujoco(steps: int = 4000) -> dict:
    """MuJoCo's speed on the gripper scene (steps per second) beside the quasi-static
    simulator's time for the same push (10 mm at 10 mm/s)."""
    mujoco = need("mujoco", "mujoco")

    from ..mujoco.push import PushRig
    from ..sim.quasistatic import simulate_push

    scene = Scene.load(bundled.path("block-low-friction"))
    rig = PushRig(scene, "left")
    rig.reset([0.0, 0.0, 0.0])

    def run_steps():
        for _ in range(steps):
            mujoco.mj_step(rig.model, rig.data)

    t_steps = _median_time(run_steps, 3)
    duration = 1.0
    t_mj = _median_time(lambda: rig.push([0, 0, 0], [0.01, 0, 0], duration, settle=0.0, record_dt=duration), 3)
    t_qs = _median_time(lambda: simulate_push(scene, [0, 0, 0], "left", [0.01, 0, 0], duration, 0.05), 3)
    return {
        "mujoco_steps": {
            "median_s": t_steps / steps, "baseline_median_s": None, "ratio": None,
            "baseline": f"none: MuJoCo's own step (timestep {rig.contact.timestep} s: {steps / t_steps:.0f} steps/s)",
            "steps_per_s": steps / t_steps,
        },
        "push_10mm_quasistatic_vs_mujoco": {
            "median_s": t_qs, "baseline_median_s": t_mj, "ratio": t_mj / t_qs,
            "baseline": "the same push in MuJoCo (quasi-static: 20 steps of 50 ms)",
        },
    }


#: the examples whose seed-0 plans `run_world_motion` turns into world motions (default workcells)
WORLD_MOTION_EXAMPLES = ("block-low-friction", "t-shape", "block-xztheta", "pivot-3d", "offset-3d")


def run_world_motion(reps: int = 5, examples=WORLD_MOTION_EXAMPLES) -> dict:
    """Time to turn a plan into the gripper's world-frame motion in its default workcell
    (:func:`regrasp.execution.world_motion`: push assignment, knots, timed samples), per example:
    the median over ``reps`` [s]; issue 15's target is under 100 ms."""
    from ..execution import world_motion
    from ..planning.plan import plan
    from ..scene import load_scene
    from ..execution.layout import default_workcell

    out = {}
    for name in examples:
        scene = load_scene(bundled.path(name))
        p, cell = plan(scene, seed=0), default_workcell(scene)
        t = _median_time(lambda: world_motion(scene, p, cell), reps)
        out[f"world_motion_{name}"] = {"median_s": t, "baseline_median_s": None, "ratio": None,
                                       "baseline": f"none: target < 100 ms ({len(p.poses) - 1} plan steps)"}
    return out


def run_ik(poses: int = 40, reps: int = 3) -> dict:
    """The UR5e + 2F-85's inverse kinematics along a path (:func:`regrasp.robot.ik.ik_path`): the
    gripper from its home pose 1 mm per pose along world x and down; median time per pose [s]."""
    need("mujoco", "robot")  # before mink, which imports it
    need("mink", "robot")
    from ..robot.ik import ik_path
    from ..robot.model import build

    robot = build()
    q0 = robot.q
    home = robot.tcp_pose(q0)
    path = [np.r_[home[:3] + 1e-3 * k * np.array([1.0, 0.0, -0.5]), home[3:]] for k in range(1, poses + 1)]
    t = _median_time(lambda: ik_path(robot, path, q0), reps)
    return {"ik_path_per_pose": {"median_s": t / poses, "baseline_median_s": None, "ratio": None,
                                 "baseline": f"none: {poses} poses 1.1 mm apart (mink, DAQP; accept 1 mm / 0.01 rad)"}}


def run_arm_steps(steps: int = 1000, reps: int = 3, example: str = "block-3d") -> dict:
    """MuJoCo's speed with the arm (:mod:`regrasp.execution.arm`): the UR5e + 2F-85 holding the
    seed-0 plan's object of ``example`` at the world motion's start in its default workcell, the
    grip loop updated at its period, ``steps`` steps; against the free-flying gripper's model of
    the same motion (:mod:`regrasp.execution.free_gripper`) in the same run. Median time per step
    [s] (steps per second: its inverse)."""
    mujoco = need("mujoco", "robot")
    need("mink", "robot")
    from ..execution import world_motion
    from ..execution.arm import GRIP_PERIOD, build_robot, close_on
    from ..execution.free_gripper import build as free_build
    from ..mujoco.model import Contact, Rig
    from ..planning.plan import plan
    from ..robot.ik import solve_ik
    from ..scene import load_scene
    from ..pose import compose, inverse

    scene = load_scene(bundled.path(example))
    motion = world_motion(scene, plan(scene, seed=0))
    robot, body, geoms, tcp = build_robot(scene, motion)
    robot.set_q(solve_ik(robot, compose(motion.gripper[0], tcp), robot.kind.home))
    m, d = robot.model, robot.data
    jq = m.jnt_qposadr[m.body_jntadr[body]]
    d.qpos[jq:jq + 7] = compose(robot.tcp_pose(), inverse(tcp), motion.in_hand[0])
    mujoco.mj_forward(m, d)
    grip = close_on(robot, body, geoms, float(motion.grip_force[0]))
    grip.period = GRIP_PERIOD

    def arm():
        for _ in range(steps):
            grip.update()
            mujoco.mj_step(m, d)

    rig = Rig(free_build(scene, motion), Contact(), float(motion.grip_force[0]))

    def free():
        for _ in range(steps):
            rig.step()

    t, base = _median_time(arm, reps) / steps, _median_time(free, reps) / steps
    return {"arm_step": {"median_s": t, "baseline_median_s": base, "ratio": t / base,
                         "baseline": f"the free-flying gripper's model of the same motion ({example}); "
                                     f"{1 / t:,.0f} steps/s with the arm"}}


def run_grasp_graph(trials: int = 3, name: str = "prism", workers: int = 1) -> dict:
    """The grasp graph of bundled object ``name`` (:func:`regrasp.dexterity.graph.build_graph`)
    with ``trials`` runs per edge in ``workers`` processes (its time and throughput, in the
    baseline's note), and one trial of its first edge in the model compiled once per edge and
    reset (as the graph runs them) against the same trials each in a freshly compiled world (with
    its IK) in the same run: median time per trial [s]."""
    need("mujoco", "robot")
    need("mink", "robot")
    need("networkx", "robot")
    from ..dexterity.actions import action
    from ..dexterity.graph import Settings, _object, build_graph, edges_to_measure, fitting, perturbations
    from ..dexterity.objects import object_path
    from ..dexterity.trial import Runner

    path = str(object_path(name))
    t0 = time.perf_counter()
    g = build_graph(path, Settings(trials=trials), workers=workers)
    build = time.perf_counter() - t0
    n = sum(e.trials for e in g.edges)
    scene, tax, obj = _object(path)
    grasp, act, params = edges_to_measure(obj, Settings(trials=trials), fitting(scene, tax))[0]
    setup = action(act).setup(obj, tax.grasp(grasp), params)
    worlds = perturbations(Settings(trials=trials + 1), "bench")
    runner = Runner(scene, tax, tax.grasp(grasp), setup)
    runner.run(worlds[0])  # compiled and its path solved once
    reused = [runner.run(p).seconds for p in worlds[1:]]
    fresh = [Runner(scene, tax, tax.grasp(grasp), setup).run(p).seconds for p in worlds[1:]]
    t, base = float(np.median(reused)), float(np.median(fresh))
    return {"grasp_graph_trial": {"median_s": t, "baseline_median_s": base, "ratio": t / base,
                                  "baseline": f"a trial ({grasp} {act}) in a freshly compiled world with its IK; the "
                                              f"{name}'s whole graph: {len(g.edges)} edges, {n} trials in {build:.1f} s "
                                              f"with {workers} worker(s), {n / build:.2f} trials/s"}}


def run_plan_only(reps: int = 3, name: str = "block-xztheta") -> dict:
    """A trajectory a controller can load, without simulating (``regrasp execute --plan-only``:
    the world motion, the arm's IK, the time parametrisation and the file written): the median
    CPU time over ``reps`` [s] against the simulated execution of the same plan (once); issue
    41's target is under 10 s."""
    need("mujoco", "robot")
    need("mink", "robot")
    import tempfile
    from pathlib import Path

    from ..execution import World, execute
    from ..execution.arm import arm_motion
    from ..planning.plan import plan
    from ..scene import load_scene
    from .timing import _median_cpu

    scene = load_scene(bundled.path(name))
    p = plan(scene, seed=0)
    with tempfile.TemporaryDirectory() as d:
        def plan_only():
            am = arm_motion(scene, p)
            am.motion.to_trajectory(am.trajectory).save(Path(d) / "t.yaml")
        t = _median_cpu(plan_only, reps)
        base = _median_cpu(lambda: execute(World(scene, rig="arm"), p), 1)
    return {f"plan_only_{name}": {"median_s": t, "baseline_median_s": base, "ratio": base / t,
                                  "baseline": "the simulated execution (MuJoCo, the arm), CPU time; target < 10 s"}}
