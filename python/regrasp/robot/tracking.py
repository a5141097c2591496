"""Joint position control of the arm in MuJoCo following a timed joint trajectory: the arm's
position actuators (PD, Menagerie's gains) with the links' weight compensated (``gravcomp``) and
a velocity feed-forward (the target shifted by ``kv/kp · q̇_ref``, so that the damping term
tracks the reference's speed rather than braking it); the tracking error measured."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ArgumentError
from ..extras import need

START_TOLERANCE = 0.005  # rad, the largest joint error between the arm now and a trajectory's start
SAMPLE = 0.01  # s, the eased reference's sample spacing
STIFFNESS = 4.0  # the joint loop's proportional gain added to the actuators' (a stiff servo, as an industrial arm's): kp·(1 + STIFFNESS)
INTEGRAL_TIME = 0.08  # s, the joint loop's integral time (no static error under load; with STIFFNESS and the actuators' kp/kv = 5 /s, damping ratio 0.7)
INTEGRAL_BOUND = 0.05  # rad, the integral term's bound (anti-windup)
CONTROL_PERIOD = 0.002  # s, the joint servo's period (500 Hz, a UR's controller); the grip loop runs faster


@dataclass(frozen=True)
class Tracking:
    """How the arm followed a trajectory: ``max_error`` [rad] the largest joint error over the
    run, ``rms_error`` [rad] its root mean square (all joints), ``final_error`` [rad] the largest
    joint error at the end, ``tcp_error`` [m] the largest TCP position error."""

    max_error: float
    rms_error: float
    final_error: float
    tcp_error: float


class Servo:
    """The arm's joint servo, run every :data:`CONTROL_PERIOD`: the position actuators' PD
    (Menagerie's gains ``kp``, ``kv``) with the target shifted by ``kv/kp · q̇_ref`` (velocity
    feed-forward) and by a bounded integral of the joint error (:data:`INTEGRAL_TIME`,
    :data:`INTEGRAL_BOUND`): no static error under a load (a push, the fingers closing)."""

    def __init__(self, robot):
        m = robot.model
        self.robot = robot
        self.kp = m.actuator_gainprm[robot.arm_actuators, 0]
        self.kv = -m.actuator_biasprm[robot.arm_actuators, 2]
        self.integral = np.zeros(len(robot.arm_qpos))
        self.steps = max(1, int(round(CONTROL_PERIOD / m.opt.timestep)))  # simulation steps per period
        self.period = self.steps * m.opt.timestep  # s

    def command(self, q_ref, v_ref=None) -> None:
        """Sets the actuators' targets for the next period towards ``q_ref`` [rad] moving at
        ``v_ref`` [rad/s] (default: at rest)."""
        r, d = self.robot, self.robot.data
        e = q_ref - d.qpos[r.arm_qpos]
        self.integral += (1.0 + STIFFNESS) * self.period / INTEGRAL_TIME * e
        np.clip(self.integral, -INTEGRAL_BOUND, INTEGRAL_BOUND, out=self.integral)
        d.ctrl[r.arm_actuators] = q_ref + STIFFNESS * e + self.integral + (0.0 if v_ref is None else self.kv / self.kp * v_ref)


def reference(times, qs, t: float) -> tuple:
    """(q [rad], q̇ [rad/s]) of the piecewise-linear joint trajectory through ``qs`` (n, 6) at
    ``times`` (n,) [s] at time ``t`` [s] (held at its ends)."""
    i = min(max(int(np.searchsorted(times, t, side="right")) - 1, 0), len(times) - 2)
    h = times[i + 1] - times[i]
    s = min(max((t - times[i]) / h, 0.0), 1.0)
    dq = qs[i + 1] - qs[i]
    return qs[i] + s * dq, dq / h if times[0] <= t <= times[-1] else np.zeros(qs.shape[1])


def smooth(times, qs, dt: float) -> tuple:
    """The joint trajectory through ``qs`` (n, 6) [rad] at ``times`` (n,) [s] resampled every
    ``dt`` [s] or less with each segment eased (smoothstep: zero speed at every waypoint), as
    (times, qs). A segment of ``dt`` or shorter gets no inner sample: :func:`reference` is then
    linear across it (no easing; the waypoints of a densely sampled path are passed at speed)."""
    times, qs = np.asarray(times, float), np.asarray(qs, float)
    out_t, out_q = [], []
    for i in range(len(times) - 1):
        n = max(1, int(np.ceil((times[i + 1] - times[i]) / dt)))
        for k in range(n):
            s = k / n
            e = s * s * (3 - 2 * s)
            out_t.append(times[i] + s * (times[i + 1] - times[i]))
            out_q.append(qs[i] + e * (qs[i + 1] - qs[i]))
    out_t.append(times[-1])
    out_q.append(qs[-1])
    return np.array(out_t), np.array(out_q)


def track(robot, times, qs, settle: float = 0.5, grip=None, ease: bool = True, observe=None) -> Tracking:
    """Runs the arm along joint positions ``qs`` (n, 6) [rad] at ``times`` (n,) [s] (increasing;
    eased between waypoints, :func:`smooth`) from ``qs[0]``, then ``settle`` [s] more, under
    position control (PD + feed-forward + integral, :data:`CONTROL_PERIOD`; the trajectory's clock starts now, at ``times[0]``), and measures the :class:`Tracking` errors (against the eased reference).
    ``grip``: a :class:`~regrasp.robot.grip.GripController` updated every step (an object held
    meanwhile). ``ease``: False follows ``qs`` piecewise linearly (a densely sampled path, passed
    at speed). ``observe(t)``: called after every control period (:data:`CONTROL_PERIOD`) with the trajectory's clock ``t`` [s]. The arm must already be at ``qs[0]`` (within ``START_TOLERANCE``): it is never
    teleported there (that would leave a held object behind); else an ArgumentError naming
    ``qs[0]`` and the start error (move there first, e.g. with a track from ``robot.q``)."""
    mujoco = need("mujoco", "robot")
    times, qs = np.asarray(times, float), np.asarray(qs, float)
    if times.ndim != 1 or len(times) < 2 or np.any(np.diff(times) <= 0):
        raise ArgumentError("invalid `times`: at least 2 increasing times [s]", "times")
    if qs.shape != (len(times), len(robot.arm_qpos)):
        raise ArgumentError(f"invalid `qs`: shape ({len(times)}, {len(robot.arm_qpos)}) [rad] (got {qs.shape})", "qs")
    m, d = robot.model, robot.data
    start_error = np.abs(robot.q - qs[0])
    if start_error.max() > START_TOLERANCE:
        j = int(np.argmax(start_error))
        raise ArgumentError(f"invalid `qs[0]`: the arm is {start_error[j]:.4f} rad from it at joint "
                            f"{robot.arm_joints[j]} (more than {START_TOLERANCE} rad; move there first: "
                            f"track from robot.q)", "qs[0]")
    ref_t, ref_q = smooth(times, qs, SAMPLE) if ease else (times, qs)
    servo = Servo(robot)
    errs, tcp_err = [], 0.0
    data_ref = mujoco.MjData(m)
    start = d.time  # the trajectory's times[0] is now
    clock = lambda: times[0] + d.time - start  # noqa: E731
    while clock() < times[-1] + settle:
        q_ref, v_ref = reference(ref_t, ref_q, clock())
        servo.command(q_ref, v_ref)
        for _ in range(servo.steps):
            if grip is not None:
                grip.update()
            mujoco.mj_step(m, d)
        if observe is not None:
            observe(clock())
        q_ref, _ = reference(ref_t, ref_q, clock())
        errs.append(np.abs(d.qpos[robot.arm_qpos] - q_ref))
        if len(errs) % 5 == 0:
            data_ref.qpos[:] = d.qpos
            data_ref.qpos[robot.arm_qpos] = q_ref
            mujoco.mj_kinematics(m, data_ref)
            tcp_err = max(tcp_err, float(np.linalg.norm(data_ref.site_xpos[robot.tcp] - d.site_xpos[robot.tcp])))
    e = np.array(errs)
    return Tracking(float(e.max()), float(np.sqrt((e ** 2).mean())), float(e[-1].max()), tcp_err)
