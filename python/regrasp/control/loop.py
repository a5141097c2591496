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

from .. import progress
from ..errors import ArgumentError, RegraspError, check_seed
from ..mujoco.model import plan_dict
from ..pose import body_twist
from ..sim.quasistatic import simulate_push
from ..scene.perturbation import Perturbation
from ..scene.planar import Scene
from ..scene.settings import mpc_defaults
from ..fields import check_count, check_number, check_vector

ENGINES = ("quasistatic", "mujoco")
POLICIES = ("mpc", "open_loop")


@dataclass
class Poke:
    """At time ``t`` [s] the object is displaced in the grasp by ``delta`` = [dx, dz, dθ]."""

    t: float
    delta: np.ndarray

    @classmethod
    def parse(cls, text: str) -> "Poke":
        """A poke from the CLI's text ``"t,dx,dz,dtheta"`` (s, m, m, rad); ArgumentError when
        malformed."""
        try:
            v = [float(x) for x in text.split(",")]
        except ValueError as e:
            raise ArgumentError(f"invalid `--poke`: {text!r} is not T,dx,dz,dtheta", "--poke") from e
        if len(v) != 4 or not np.all(np.isfinite(v)) or v[0] < 0:
            raise ArgumentError(f"invalid `--poke`: {text!r} must be 4 finite numbers T,dx,dz,dtheta with T >= 0", "--poke")
        return cls(v[0], np.array(v[1:]))


@dataclass
class ControlResult:
    """The outcome of one :func:`control` run: success, final pose and its error to the goal
    ``[x, z, theta]`` (m, m, rad), re-plans, the median MPC step time [s] and the recorded traces."""
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
        """The result as a JSON-ready dict (lists, not arrays)."""
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
        """The object's pose ``[x, z, theta]`` (m, m, rad) in the grasp now (a copy)."""
        return self.q.copy()

    def push(self, pusher: str, twist, duration: float, belief=None):
        """Pushes with ``pusher`` at body ``twist`` ``[vx, vz, omega]`` (m/s, m/s, rad/s) for ``duration``
        [s] (one quasi-static step; ``belief`` is unused by this plant)."""
        r = simulate_push(self.scene, self.q, pusher, twist, duration, dt=duration / 2)
        self.q = np.asarray(r["pose"][-1], float)

    def idle(self, duration: float):
        """Waits ``duration`` [s]: the quasi-static object does not move."""
        pass

    def poke(self, delta):
        """Displaces the object in the grasp by ``delta`` ``[dx, dz, dtheta]`` (m, m, rad)."""
        self.q = self.q + np.asarray(delta, float)


def _plant(engine: str, scene: Scene, q0, perturb: Perturbation):
    if engine == "quasistatic":
        return QuasistaticPlant(perturb.scene(scene), q0)
    from ..mujoco.planar import WorldRig

    return WorldRig(scene, q0, perturb)


def _plan_dict(plan) -> dict:
    d = plan_dict(plan)
    if not isinstance(d, dict) or "path" not in d or len(d["path"]) < 1:
        raise ArgumentError("invalid `plan`: no path", "plan")
    return d


def _check_arguments(engine, policy, dt, speed, horizon, max_time, start_error, noise, seed, pokes) -> np.ndarray:
    if not isinstance(engine, str) or engine not in ENGINES:
        raise ArgumentError(f"invalid `engine`: must be one of {ENGINES} (got {engine!r})", "engine")
    if not isinstance(policy, str) or policy not in POLICIES:
        raise ArgumentError(f"invalid `policy`: must be one of {POLICIES} (got {policy!r})", "policy")
    # bounds: a control period up to 10 s, the core's pusher speed limit (100 m/s), a day of
    # control, measurement noise up to 1 m
    check_number(dt, "dt", high=10.0), check_number(speed, "speed", high=100.0), check_count(horizon, "horizon", 1, 10_000)
    if max_time is not None:
        check_number(max_time, "max_time", high=86_400.0)
    check_number(noise, "noise", strict=False, high=1.0)
    check_seed(seed)
    if not all(isinstance(p, Poke) for p in _iterable(pokes, "pokes")):
        raise ArgumentError("invalid `pokes`: a list of Poke (Poke.parse('T,dx,dz,dtheta'))", "pokes")
    return check_vector(start_error, 3, "start_error")


def _iterable(x, name: str) -> list:
    if isinstance(x, (str, bytes, dict)):
        raise ArgumentError(f"invalid `{name}`: a list (got {type(x).__name__})", name)
    try:
        return list(x)
    except TypeError:
        raise ArgumentError(f"invalid `{name}`: a list (got {type(x).__name__})", name) from None


class ControlRun:
    """One run of :func:`control`: the plant (the simulated world), the MPC, the pokes still to
    come and what was recorded. :meth:`tick` is one control period of ``dt`` [s]. ``plant``:
    makes the world from the object's start pose ``[x, z, theta]`` (m, m, rad) (default: the
    ``engine``'s, e.g. :class:`~regrasp.execution.arm_loop.ArmPlant` for the arm)."""

    def __init__(self, scene: Scene, plan, engine: str, policy: str, pokes, start_error, perturb: Perturbation,
                 controller_scene: Scene | None, noise: float, seed: int, dt: float, speed: float, horizon: int,
                 max_time: float | None, mpc: dict, plant=None):
        path = _plan_dict(plan)["path"]
        poses = [list(map(float, k["pose"])) for k in path]
        task = scene.task
        self.scene, self.policy, self.engine, self.noise, self.dt = scene, policy, engine, noise, dt
        self.goal = np.asarray(task.goal if task is not None else poses[-1], float)
        cscene = controller_scene or scene
        self.ctrl = cscene.mpc(poses, [k["pusher"] for k in path], self.goal.tolist(), dt=dt, horizon=horizon,
                               speed=speed, seed=check_seed(seed), **mpc)
        self.knots = np.asarray(self.ctrl.knots)
        self.knot_pushers = self.ctrl.knot_pushers
        self.pokes = sorted(pokes, key=lambda k: k.t)
        last_poke = max((pk.t for pk in self.pokes), default=0.0)
        if max_time is None:
            # time for the plan at its speed, slack for re-plans, and for recovering after the last poke
            n = len(self.knots)
            max_time = max(2.5 * n * dt + 6.0, last_poke + 1.5 * n * dt + 6.0)
        elif last_poke > max_time:
            raise ArgumentError(f"invalid `pokes`: a poke at {last_poke} s comes after `max_time` ({max_time} s)",
                                "pokes")
        self.max_time = max_time
        q0 = np.asarray(poses[0], float) + start_error
        if not scene.admissible(q0):
            raise ArgumentError("invalid `start_error`: the object's start pose puts the pad off the object",
                                "start_error")
        self.plant = _plant(engine, scene, q0, perturb) if plant is None else plant(q0)
        self.rng = np.random.default_rng(seed)
        self.pending = list(self.pokes)
        self.ts, self.qs, self.refs, self.used, self.statuses, self.times = [], [], [], [], [], []
        self.t, self.k, self.stuck, self.failure = 0.0, 0, 0, ""
        self.world_failed = False

    def measure(self) -> np.ndarray:
        """Applies the pokes due, records the true pose and returns its (noisy) measurement."""
        while self.pending and self.pending[0].t <= self.t + 1e-9:
            self.plant.poke(self.pending.pop(0).delta)
        q = self.plant.pose()
        self.ts.append(self.t)
        self.qs.append(q)
        if self.noise > 0:
            return q + self.rng.normal(0.0, self.noise, 3) * np.array([1.0, 1.0, 1.0 / self.scene.length])
        return q + 0.0

    def _record(self, ref, status: str, pusher):
        self.refs.append(ref)
        self.statuses.append(status)
        self.used.append(pusher)

    def _push(self, pusher: str, twist, belief) -> bool:
        try:
            self.plant.push(pusher, twist, self.dt, belief)
        except RegraspError as e:  # the world rejected the push (e.g. the grasp cannot hold the object)
            self.world_failed, self.failure = True, self._world_failure(e)
            return False
        return True

    def _world_failure(self, e: RegraspError) -> str:
        """What the world's refusal ``e`` of a push means, in the user's terms, with the time [s]
        and the object's pose (m, m, rad)."""
        q = [round(float(v), 5) + 0.0 for v in self.plant.pose()]
        field = getattr(e, "field", None)
        # the pose refused, or a push the simulator stopped because the pad left the object
        if (field == "pose" and "not admissible" in str(e)) or (field == "push" and "finger pad leaves the object" in str(e)):
            return (f"the object left the admissible region at t = {self.t:.2f} s (the finger pad no longer "
                    f"entirely on the object): pose {q} (m, m, rad)")
        return f"the world could not go on at t = {self.t:.2f} s, pose {q} (m, m, rad): {e}"

    def _wait(self) -> bool:
        """Nothing to push: goes on only while pokes are to come (the plant idles a period)."""
        if not self.pending:
            return False
        self.plant.idle(self.dt)
        return True

    def mpc_tick(self, meas) -> bool:
        """One MPC step from the measured pose ``meas`` ``[x, z, theta]`` (m, m, rad), the command sent to
        the plant; False when the controller stops (at the goal or stuck)."""
        c = self.ctrl.step(meas.tolist())
        status = c["status"]
        if status in ("tracking", "replanned"):  # steps that solved the QP (not at goal or stuck)
            self.times.append(c["solve_time_s"])
        if status == "replanned":
            self.knots = np.asarray(self.ctrl.knots)
        self._record(self.knots[min(c["knot"], len(self.knots) - 1)], status, c["pusher"])
        if status == "at_goal":
            return self._wait()
        if status == "stuck":
            self.stuck += 1
            if self.stuck >= 3 and not self.pending:
                self.failure = "stuck: no push of the plan helps and re-planning found none"
                return False
            self.plant.idle(self.dt)
            return True
        self.stuck = 0
        return self._push(c["pusher"], c["twist"], meas)

    def open_loop_tick(self) -> bool:
        """The plan's next push at its planned time, whatever the object does."""
        k, knots = self.k, self.knots
        if k + 1 >= len(knots):
            self._record(knots[-1], "done", None)
            return self._wait()
        self._record(knots[k], "open_loop", self.knot_pushers[k + 1])
        if not self._push(self.knot_pushers[k + 1], body_twist(knots[k], knots[k + 1]) / self.dt, knots[k]):
            return False
        self.k += 1
        return True

    def tick(self) -> bool:
        """One control period: pokes, measurement, action. False: the run is over."""
        meas = self.measure()
        return self.mpc_tick(meas) if self.policy == "mpc" else self.open_loop_tick()

    def result(self) -> ControlResult:
        """What the run recorded, as a :class:`ControlResult`."""
        q = self.plant.pose()
        if not self.ts or self.ts[-1] != self.t:
            self.ts.append(self.t)
            self.qs.append(q)
            ref = self.refs[-1] if self.refs else self.knots[-1]
            self._record(ref, self.statuses[-1] if self.statuses else "", None)
        err, ok = self.scene.goal_error(q, self.goal)
        ok = ok and not self.world_failed
        failure = self.failure
        if not ok and not failure:
            failure = "time out" if self.t > self.max_time else "ended outside the tolerance"
        return ControlResult(self.engine, self.policy, ok, q, err, self.ctrl.replans if self.policy == "mpc" else 0,
                             float(np.median(self.times)) if self.times else 0.0, np.array(self.ts), np.array(self.qs),
                             np.array(self.refs), self.used, self.statuses,
                             [(pk.t, pk.delta.tolist()) for pk in self.pokes], failure)


def control(scene: Scene, plan, engine: str = "quasistatic", policy: str = "mpc", pokes=(), start_error=(0.0, 0.0, 0.0),
            perturb: Perturbation = Perturbation(), controller_scene: Scene | None = None, noise: float = 0.0,
            seed: int = 0, dt: float | None = None, speed: float | None = None, horizon: int | None = None,
            max_time: float | None = None, **mpc) -> ControlResult:
    """Runs ``plan`` (a ``regrasp.Plan`` or its dict) closed loop (``policy="mpc"``) or open loop
    in ``engine``.

    ``controller_scene``: the scene whose cones constrain the MPC and its re-planning (e.g.
    ``scene.robust()``; default ``scene``). ``perturb``: the world's physics (factors on
    friction, grip force, mass). ``start_error``: the object starts this far from the plan's
    start (the plan was made for a wrong estimate). ``noise``: standard deviation of the pose
    measurement [m, m·(1/L) for θ]. Success: the object's true pose within the task's tolerance.
    ``dt`` [s], ``speed`` [m/s], ``horizon`` and the other MPC settings default to the core's
    (``regrasp._core.mpc_defaults()``).
    """
    d = mpc_defaults()
    dt, speed, horizon = (d[k] if v is None else v for k, v in (("dt", dt), ("speed", speed), ("horizon", horizon)))
    se = _check_arguments(engine, policy, dt, speed, horizon, max_time, start_error, noise, seed, pokes)
    run = ControlRun(scene, plan, engine, policy, pokes, se, perturb, controller_scene, noise, seed, dt, speed, horizon,
                     max_time, mpc)
    with progress.bar(round(run.max_time, 3), f"control ({policy}, {engine})", unit="s") as bar:
        while run.t <= run.max_time + 1e-9 and run.tick():
            run.t += dt
            bar.update(dt)
    return run.result()


__all__ = ["Poke", "ControlResult", "ControlRun", "control", "QuasistaticPlant"]
