"""Closed-loop control of a regrasp (thesis §5.2): the MPC of ``regrasp._core.Mpc`` (Rust; a QP
per step over non-negative weights of the motion-cone generators, clarabel) tracks a plan in a
simulated world — our quasi-static simulator or MuJoCo in the world's view — with the object's
pose in the grasp as the measurement (optionally noisy), pokes during execution, a wrong
start-pose estimate and perturbed physics; it re-plans (T-RRT*) from the measured pose when the
plan's pushers stop making progress.

The same loop executes a plan open loop (``policy="open_loop"``): the plan's pushes at their
planned times whatever the object does, for comparison.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .. import _core
from ..errors import ArgumentError, RegraspError, check_seed
from ..mujoco.planar import Perturbation
from ..sim.quasistatic import body_twist, simulate_push
from ..scene.planar import Scene

ENGINES = ("quasistatic", "mujoco")
POLICIES = ("mpc", "open_loop")


@dataclass
class Poke:
    """At time ``t`` [s] the object is displaced in the grasp by ``delta`` = [dx, dz, dθ]."""

    t: float
    delta: np.ndarray

    @classmethod
    def parse(cls, text: str) -> "Poke":
        try:
            v = [float(x) for x in text.split(",")]
        except ValueError as e:
            raise ArgumentError(f"invalid `--poke`: {text!r} is not T,dx,dz,dtheta", "--poke") from e
        if len(v) != 4 or not np.all(np.isfinite(v)) or v[0] < 0:
            raise ArgumentError(f"invalid `--poke`: {text!r} must be 4 finite numbers T,dx,dz,dtheta with T >= 0", "--poke")
        return cls(v[0], np.array(v[1:]))


@dataclass
class ControlResult:
    engine: str
    policy: str
    success: bool
    final_pose: np.ndarray
    goal_error: np.ndarray
    replans: int
    mpc_step_median_s: float
    t: np.ndarray = field(repr=False, default=None)
    poses: np.ndarray = field(repr=False, default=None)  # true object pose in the grasp
    reference: np.ndarray = field(repr=False, default=None)  # the reference knot tracked
    pushers: list = field(repr=False, default_factory=list)
    statuses: list = field(repr=False, default_factory=list)
    pokes: list = field(repr=False, default_factory=list)
    failure: str = ""

    def to_json(self) -> dict:
        return {
            "engine": self.engine,
            "policy": self.policy,
            "success": bool(self.success),
            "final_pose": self.final_pose.tolist(),
            "goal_error": self.goal_error.tolist(),
            "replans": int(self.replans),
            "mpc_step_median_s": float(self.mpc_step_median_s),
            "steps": len(self.statuses),
            "failure": self.failure,
        }


class QuasistaticPlant:
    """Our quasi-static simulator as the world: each control period the pusher is put in contact
    with the object where it is and moves with the commanded body twist."""

    def __init__(self, scene: Scene, q0):
        self.scene = scene
        self.q = np.asarray(q0, float)

    def pose(self) -> np.ndarray:
        return self.q.copy()

    def push(self, pusher: str, twist, duration: float, belief=None):
        r = simulate_push(self.scene, self.q, pusher, twist, duration, dt=duration / 2)
        self.q = np.asarray(r["pose"][-1], float)

    def idle(self, duration: float):
        pass

    def poke(self, delta):
        self.q = self.q + np.asarray(delta, float)


def _plant(engine: str, scene: Scene, q0, perturb: Perturbation):
    if engine == "quasistatic":
        world = scene.scaled(perturb.friction, perturb.grip, perturb.mass, perturb.pusher)
        return QuasistaticPlant(world, q0)
    from ..mujoco.planar import WorldRig

    return WorldRig(scene, q0, perturb)


def _plan_dict(plan) -> dict:
    d = plan if isinstance(plan, dict) else plan.to_json()
    if "path" not in d or len(d["path"]) < 1:
        raise ArgumentError("invalid `plan`: no path", "plan")
    return d


def control(scene: Scene, plan, engine: str = "quasistatic", policy: str = "mpc", pokes=(), start_error=(0.0, 0.0, 0.0),
            perturb: Perturbation = Perturbation(), controller_scene: Scene | None = None, noise: float = 0.0,
            seed: int = 0, dt: float = 0.1, speed: float = 0.01, horizon: int = 5, max_time: float | None = None,
            **mpc) -> ControlResult:
    """Runs ``plan`` closed loop (``policy="mpc"``) or open loop in ``engine``.

    ``controller_scene``: the scene whose cones constrain the MPC and its re-planning (e.g.
    ``scene.robust()``; default ``scene``). ``perturb``: the world's physics (factors on
    friction, grip force, mass). ``start_error``: the object starts this far from the plan's
    start (the plan was made for a wrong estimate). ``noise``: standard deviation of the pose
    measurement [m, m·(1/L) for θ]. Success: the object's true pose within the task's tolerance.
    """
    if engine not in ENGINES:
        raise ArgumentError(f"invalid `engine`: must be one of {ENGINES} (got {engine!r})", "engine")
    if policy not in POLICIES:
        raise ArgumentError(f"invalid `policy`: must be one of {POLICIES} (got {policy!r})", "policy")
    if not (dt > 0 and speed > 0 and np.isfinite(dt) and np.isfinite(speed)):
        raise ArgumentError("invalid `dt`/`speed`: must be positive", "dt")
    if not isinstance(horizon, (int, np.integer)) or horizon < 1:
        raise ArgumentError(f"invalid `horizon`: must be a whole number of steps >= 1 (got {horizon!r})", "horizon")
    if max_time is not None and not (np.isfinite(max_time) and max_time > 0):
        raise ArgumentError("invalid `max_time`: must be a positive number of seconds", "max_time")
    se = np.asarray(start_error, float)
    if se.shape != (3,) or not np.all(np.isfinite(se)):
        raise ArgumentError("invalid `start_error`: must be 3 finite numbers dx, dz, dtheta", "start_error")
    p = _plan_dict(plan)
    path = p["path"]
    poses = [list(map(float, k["pose"])) for k in path]
    names = [k["pusher"] for k in path]
    task = scene.task
    goal = np.asarray(task.goal if task is not None else poses[-1], float)
    tol = np.asarray(task.tolerance if task is not None else [1e-3, 1e-3, 0.0175], float)
    cscene = controller_scene or scene
    ctrl = _core.Mpc(cscene._core, poses, names, goal.tolist(), dt=dt, horizon=horizon, speed=speed, seed=check_seed(seed), **mpc)
    knots = np.asarray(ctrl.knots)
    knot_pushers = ctrl.knot_pushers
    last_poke = max((pk.t for pk in pokes), default=0.0)
    if max_time is None:
        # time for the plan at its speed, slack for re-plans, and for recovering after the last poke
        max_time = max(2.5 * len(knots) * dt + 6.0, last_poke + 1.5 * len(knots) * dt + 6.0)
    elif last_poke > max_time:
        raise ArgumentError(f"invalid `pokes`: a poke at {last_poke} s comes after `max_time` ({max_time} s)", "pokes")
    q0 = np.asarray(poses[0], float) + se
    if not scene.admissible(q0):
        raise ArgumentError("invalid `start_error`: the object's start pose puts the pad off the object", "start_error")
    plant = _plant(engine, scene, q0, perturb)
    rng = np.random.default_rng(seed)
    pending = sorted(pokes, key=lambda k: k.t)
    L = scene.length
    ts, qs, refs, used, sts, times = [], [], [], [], [], []
    t, k, stuck, failure = 0.0, 0, 0, ""
    while t <= max_time + 1e-9:
        while pending and pending[0].t <= t + 1e-9:
            plant.poke(pending.pop(0).delta)
        q = plant.pose()
        meas = q + (rng.normal(0.0, noise, 3) * np.array([1.0, 1.0, 1.0 / L]) if noise > 0 else 0.0)
        ts.append(t)
        qs.append(q)
        if policy == "mpc":
            c = ctrl.step(meas.tolist())
            if c["status"] in ("tracking", "replanned"):  # steps that solved the QP (not at goal or stuck)
                times.append(c["solve_time_s"])
            if c["status"] == "replanned":
                knots = np.asarray(ctrl.knots)
            refs.append(knots[min(c["knot"], len(knots) - 1)])
            sts.append(c["status"])
            used.append(c["pusher"])
            if c["status"] == "at_goal":
                if not pending:
                    break
                plant.idle(dt)
            elif c["status"] == "stuck":
                stuck += 1
                if stuck >= 3 and not pending:
                    failure = "stuck: no push of the plan helps and re-planning found none"
                    break
                plant.idle(dt)
            else:
                stuck = 0
                try:
                    plant.push(c["pusher"], c["twist"], dt, meas)
                except RegraspError as e:  # the world rejected the push (e.g. the grasp cannot hold the object)
                    failure = f"the world failed: {e}"
                    break
        else:
            if k + 1 >= len(knots):
                sts.append("done")
                used.append(None)
                refs.append(knots[-1])
                if not pending:
                    break
                plant.idle(dt)
            else:
                tw = body_twist(knots[k], knots[k + 1]) / dt
                refs.append(knots[k])
                sts.append("open_loop")
                used.append(knot_pushers[k + 1])
                try:
                    plant.push(knot_pushers[k + 1], tw, dt, knots[k])
                except RegraspError as e:
                    failure = f"the world failed: {e}"
                    break
                k += 1
        t += dt
    q = plant.pose()
    if not ts or ts[-1] != t:
        ts.append(t)
        qs.append(q)
        refs.append(refs[-1] if refs else knots[-1])
        sts.append(sts[-1] if sts else "")
        used.append(None)
    err = q - goal
    ok = bool(np.all(np.abs(err) <= tol)) and not failure.startswith("the world")
    if not ok and not failure:
        failure = "time out" if t > max_time else "ended outside the tolerance"
    return ControlResult(engine, policy, ok, q, err, ctrl.replans if policy == "mpc" else 0,
                         float(np.median(times)) if times else 0.0, np.array(ts), np.array(qs), np.array(refs), used, sts,
                         [(pk.t, pk.delta.tolist()) for pk in sorted(pokes, key=lambda k: k.t)], failure)


__all__ = ["Poke", "ControlResult", "control", "QuasistaticPlant"]
