"""Closed loop in the world with the arm (issue 15, item 6): the object's in-hand pose measured in
MuJoCo, the arm (:mod:`regrasp.execution.arm`: the UR5e + 2F-85 holding the object in the
workcell) moving the gripper so that the workcell's fixed features push it.

:class:`ArmPlant` is a plant of :class:`~regrasp.control.loop.ControlRun` (``pose``, ``push``,
``idle``, ``poke``): ``push(pusher, twist, duration)`` renders the pusher's commanded body twist
(in the object frame at the measured pose) with the feature assigned to that pusher
(:func:`~regrasp.execution.assignment.assign`): the feature is fixed in the world, so the gripper
moves by the inverse of the intended object motion, ``G(s) = G ∘ O ∘ O(s)⁻¹`` with ``O`` the
object's in-hand pose at the push's start and ``O(s) = O exp(s ξ)``. A push with another pusher
than the one in contact first switches over (:class:`~regrasp.execution.world_motion.Segments`:
retreat by the clearance, transfer at the safe height, approach to the new feature's contact at
the measured pose). The gripper's poses every ``timing.sample_period`` are solved by one reused
:class:`~regrasp.robot.ik.IKSolver`, each seeded by the previous joints, and tracked
(:func:`~regrasp.robot.tracking.track`) with the grip force loop running.

:func:`control_arm`: planar scenes by the MPC (``_core.Mpc`` through ``ControlRun``, one command
per control period); 3-D scenes by re-planning (:func:`regrasp.scene.spatial.run_plan3d`: after
each step of the plan the pose is measured; off the plan by more than half the tolerance, or at
the plan's end outside it, the T-RRT* plans again from it), each step pushed at the timing's
push speed; a sticking step against its feature from the step's planned start
(``push(..., absolute=True)``), so that the arm's lag and the start's offset do not add up."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .. import pose as P
from ..errors import ArgumentError, ExecutionError, RegraspError
from ..extras import need
from ..scene.perturbation import Perturbation
from ..scene.settings import mpc_defaults
from .arm import CONTACT_CLEARANCE, arm_motion, build_robot, close_on, first_solution, grip_ceiling
from .assignment import assign, pusher_contact
from .world_motion import Segments, Timing, grip_force


#: The grip calibration (:meth:`ArmPlant.calibrate`): each step lowers the grip by this share,
CALIBRATION_STEP = 0.04
#: held this long [s],
CALIBRATION_DWELL = 0.05
#: until the object has moved this far [m] in the hand
CALIBRATION_SLIP = 3e-4
#: or turned this far [rad],
CALIBRATION_TURN = 5e-3
#: or down to this share of the grip at which the nominal pads would let it slip.
CALIBRATION_FLOOR = 0.6

#: how long [s] the arm holds still after its retreat from the last feature before the
#: regrasp's end pose is measured (:meth:`ArmPlant.release`)
RELEASE_DWELL = 0.3


@dataclass
class ArmLoopResult:
    """A closed-loop run with the arm: ``success`` (the object's in-hand pose after the retreat
    from the last feature within the scene's goal tolerance, the world not having refused a
    push); ``goal_error`` planar ``[x, z, theta]`` (m, m, rad) or 3-D
    ``[position, angle]`` (m, rad) to the task's goal; ``replans`` (the MPC's or the
    T-RRT*'s); ``duration`` [s] simulated; ``switch_overs`` made; ``final`` the measured in-hand
    pose (planar ``[x, z, theta]`` or ``[x, y, z, qw, qx, qy, qz]``); ``failure`` why not (""
    on success); ``control`` the planar run's :class:`~regrasp.control.loop.ControlResult`
    (None in 3-D)."""
    success: bool
    goal_error: np.ndarray
    replans: int
    duration: float
    switch_overs: int
    final: np.ndarray
    failure: str = ""
    control: object = field(default=None, repr=False)


class ArmPlant:
    """The arm holding the object in the workcell in MuJoCo, as a control plant (see the
    module's doc). ``scene``, ``plan``: the plan being executed (its world motion gives the start
    above the first push, the safe height and the pushers' features); ``start``: the object's
    in-hand start pose (planar ``[x, z, theta]`` or 3-D; default the plan's); ``workcell``,
    ``robot``, ``scales`` (:class:`~regrasp.execution.arm.Scales`), ``timing``
    (:class:`~regrasp.execution.world_motion.Timing`), ``sensing`` (the grip loop's) as for an
    open-loop execution."""

    def __init__(self, scene, plan, start=None, workcell=None, robot: str | None = None,
                 scales: Perturbation = Perturbation(), timing: Timing = Timing(), sensing=None):
        mujoco = need("mujoco", "robot")
        from ..robot.ik import IKError, IKSolver, fixed_geoms

        self.scene, self.timing, self._mj = scene, timing, mujoco
        # the plan's world motion whose features the arm can follow (arm_motion: the next feature
        # of a push the arm cannot follow with the first), for the features and the start
        self.motion = arm_motion(scene, plan, workcell, robot, scales, timing).motion
        self.safe = self.motion.workcell.top() + timing.clearance  # Segments' safe height base
        wc = self.motion.workcell
        self.features = {}
        for a in self.motion.assignments:
            self.features.setdefault(a.pusher, a)
        r, body, geoms, tcp = build_robot(scene, self.motion, robot, scales)
        self.robot, self.body, self.tcp, self.untcp = r, body, tcp, P.inverse(tcp)
        m = r.model
        avoid = fixed_geoms(r)
        self.G = self.motion.gripper[0].copy()  # the gripper's commanded world pose
        try:
            q0 = first_solution(r, P.compose(self.G, tcp), avoid)
        except IKError as e:
            raise ExecutionError(f"the arm cannot reach the start above the first push: {e}", "robot") from None
        r.set_q(q0)
        O = self.motion.in_hand[0] if start is None else self._spatial(start)
        jq = m.jnt_qposadr[m.body_jntadr[body]]
        self._jq, self._jv = jq, m.jnt_dofadr[m.body_jntadr[body]]
        r.data.qpos[jq:jq + 7] = P.compose(r.tcp_pose(), self.untcp, O)  # at the arm's actual TCP
        mujoco.mj_forward(m, r.data)
        # the plan's grip, raised between pushes as the open loop's (:meth:`switch`), and from
        # the start: the object is held before the first feature is met
        self.grip_force, self.world_grip = float(grip_force(scene)), scales.grip
        self.grip_ceiling = grip_ceiling(r)
        start_grip = self.transfer_grip(P.spatial_to_planar(O) if scene.dimension == 2 else O)
        self.grip = close_on(r, body, geoms, start_grip * scales.grip, sensing)
        self.grip_gain = 1.0
        self.solver = IKSolver(r, avoid)
        self.contact_solver = IKSolver(r, avoid, CONTACT_CLEARANCE)  # fingers near the feature in contact
        self.q = r.q.copy()  # the arm's commanded joints
        self.current: str | None = None
        self.switch_overs = 0
        self._world = wc
        if start_grip > self.grip_force:  # gravity needs a raised grip: the world's pads measured first
            self.calibrate(start_grip)

    def calibrate(self, raised: float) -> float:
        """Measures how much grip the world's pads need to hold the object (planar scenes): the
        arm holding still, the grip lowered from ``raised`` [N] by :data:`CALIBRATION_STEP` every
        :data:`CALIBRATION_DWELL` until the measured in-hand pose moves by
        :data:`CALIBRATION_SLIP` or turns by :data:`CALIBRATION_TURN` (or down to :data:`CALIBRATION_FLOOR` of where the nominal pads
        would slip), then raised again. The plan's grip is scaled by the ratio of the grip it
        slipped at to where the nominal pads slip (``grip_gain`` >= 1, within the ceiling), so the
        world's pads hold the object as the plan's cones assume: a world whose friction, grip or
        mass is off nominal by more than the scene declares would otherwise drop it at the first
        push. Returns the gain."""
        pose = self.pose()
        if self.scene.dimension != 2 or not self.scene.admissible(pose):
            return self.grip_gain  # 3-D, or partly off the pads: no nominal slip grip to compare with
        share = float(self.scene.hold_ratio(pose))  # gravity's share of the nominal pads' friction at the plan's grip
        nominal = self.grip_force * share  # [N] where the nominal pads would slip
        if not (math.isfinite(nominal) and nominal > 0):  # nothing to hold up: nothing to measure
            return self.grip_gain
        g, slipped = raised, None
        while g * (1 - CALIBRATION_STEP) >= CALIBRATION_FLOOR * nominal:
            g *= 1 - CALIBRATION_STEP
            self.grip.set_force(g * self.world_grip)
            self.idle(CALIBRATION_DWELL)
            d = self.pose() - pose
            if np.hypot(d[0], d[1]) > CALIBRATION_SLIP or abs(d[2]) > CALIBRATION_TURN:
                slipped = g
                break
        self.grip.set_force(raised * self.world_grip)
        self.idle(CALIBRATION_DWELL)
        if slipped is not None:
            self.grip_gain = min(max(1.0, slipped / nominal), max(1.0, self.grip_ceiling / self.grip_force))
            self.grip_force *= self.grip_gain
        return self.grip_gain

    # -- measurement ----------------------------------------------------------------------------

    def in_hand(self) -> np.ndarray:
        """The object's measured pose in the gripper frame ``[x, y, z, qw, qx, qy, qz]`` (m)."""
        from ..robot.grip import body_pose

        G = P.compose(self.robot.tcp_pose(), self.untcp)
        return P.compose(P.inverse(G), body_pose(self.robot.data, self.body))

    def pose(self) -> np.ndarray:
        """The object's measured in-hand pose: planar ``[x, z, theta]`` (m, m, rad) or 3-D
        ``[x, y, z, qw, qx, qy, qz]`` (m, unit quaternion)."""
        H = self.in_hand()
        return P.spatial_to_planar(H) if self.scene.dimension == 2 else H

    def _spatial(self, q) -> np.ndarray:
        q = np.asarray(q, float)
        return np.asarray(P.planar_to_spatial(q), float) if self.scene.dimension == 2 else q

    # -- motion ---------------------------------------------------------------------------------

    def feature(self, pusher: str, pose):
        """The :class:`~regrasp.execution.assignment.Assignment` rendering ``pusher`` (the plan's,
        else assigned at ``pose``); ExecutionError naming the pusher when no feature serves it."""
        if pusher not in self.features:
            poses = np.array([pose, pose], float)
            try:
                self.features[pusher] = assign(self.scene, poses, [None, pusher], self._world)[0]
            except ExecutionError as e:
                raise ExecutionError(f"pusher `{pusher}`: {str(e).split(': ', 1)[-1]}", "workcell") from None
        return self.features[pusher]

    def _follow(self, times, Gs, what: str, contact=True):
        """Moves the gripper through world poses ``Gs`` at ``times`` [s] (from now): IK from the
        commanded joints, then the arm tracks them; ExecutionError naming ``what`` when the arm
        cannot. ``contact``: whether each pose is in contact with a feature (one for all, or one
        per pose: the arm keeps :data:`~regrasp.execution.arm.CONTACT_CLEARANCE` then, else the
        IK's ``MIN_DISTANCE``)."""
        from ..robot.ik import IKError
        from ..robot.tracking import track

        qs, q = [self.robot.q], self.q
        near = np.broadcast_to(np.asarray(contact, bool), (len(Gs),))
        for i, G in enumerate(Gs):
            try:
                solver = self.contact_solver if near[i] else self.solver
                q = solver.solve(P.compose(G, self.tcp), q, field=f"{what}[{i}]")
            except IKError as e:
                why = str(e).split(": ", 1)[-1]
                raise ExecutionError(f"the arm cannot execute {what}: {why}", "robot") from None
            qs.append(q)
        t = np.r_[0.0, np.asarray(times, float)]
        track(self.robot, t, np.array(qs), settle=0.0, grip=self.grip, ease=False)
        self.q, self.G = q, np.asarray(Gs[-1], float)

    def switch(self, pusher: str, O) -> None:
        """Switch-over to ``pusher`` with the object at in-hand pose ``O`` (m, unit quaternion):
        retreat from the feature in contact, transfer at the safe height, approach the new
        pusher's feature until it meets the object; the grip raised meanwhile as the open loop
        raises it (:meth:`transfer_grip`). Where it is raised, it is lowered back to the plan's
        only once the feature touches the object, the arm holding still for
        :data:`~regrasp.execution.holding.SETTLE_SAMPLES` samples (the open loop lowers it over
        the approach's last samples: a world whose pads hold less than nominal drops the object
        there, before the feature can support it)."""
        from .holding import SETTLE_SAMPLES

        pose = P.spatial_to_planar(O) if self.scene.dimension == 2 else O
        a = self.feature(pusher, pose)
        Pk = P.compose(O, pusher_contact(self.scene, pusher, pose).frame)
        seg = Segments(self.timing, self.safe, _reach(self.scene, O), self.G, self.motion.envelope,
                       self.motion.workcell.robot.base[:3], self.motion.workcell.contacts())
        G0, pre = seg.meeting(a, Pk)
        if self.current is not None:
            seg.retreat(self.features[self.current], O)
        seg.transfer(pre, a, O)
        seg.approach(G0, a, O)
        what = f"the switch-over to pusher `{pusher}` ({a.feature})"
        if len(seg.poses) > 1:
            times, poses = np.asarray(seg.times[1:], float), seg.poses[1:]
            near = [lab in ("approach", "retreat") for lab in seg.samples.label[1:]]
            raised = self.transfer_grip(pose)
            self.grip.set_force(raised * self.world_grip)
            self._follow(times, poses, what, near)
            if raised > self.grip_force:  # at contact: the feature supports the object as the grip settles
                self.grip.set_force(self.grip_force * self.world_grip)
                self.idle(SETTLE_SAMPLES * self.timing.sample_period)
        self.current = pusher
        self.switch_overs += 1

    def transfer_grip(self, pose) -> float:
        """The grip [N] between pushes with the object at in-hand ``pose``: raised until gravity
        takes at most :func:`~regrasp.execution.holding.transfer_share` of the pads' friction
        (planar scenes; the scene's gravity, which a transfer keeps in the gripper frame), within
        :func:`~regrasp.execution.arm.grip_ceiling`; the plan's grip otherwise."""
        from .holding import transfer_share

        if self.scene.dimension != 2:
            return self.grip_force
        if not self.scene.admissible(pose):  # the object has slid (partly) off the pads: hold what is left
            return max(self.grip_force, self.grip_ceiling)
        share = float(self.scene.hold_ratio(pose))
        return self.grip_force * min(max(1.0, share / transfer_share(self.scene)),
                                     max(1.0, self.grip_ceiling / self.grip_force))

    def push(self, pusher: str, twist, duration: float, belief=None, absolute: bool = False):
        """Pushes with ``pusher``'s feature at body ``twist`` (planar ``[vx, vz, omega]`` (m/s,
        m/s, rad/s), 3-D ``[v, omega]``, in the object frame) for ``duration`` [s], from the
        object's ``belief`` pose (default: measured; after a switch-over, measured again).
        The gripper moves from its commanded pose by the inverse of the object's motion, or,
        ``absolute``, from where the feature meets the pusher with the object at the belief
        (``G = F ∘ (O ∘ C)⁻¹``, as the open loop renders a plan step): the step then ends where
        the feature holds the object at the step's end whatever the arm's lag left before."""
        if self.current != pusher:
            self.switch(pusher, self.in_hand() if belief is None else self._spatial(belief))
            belief = None
        q = self.pose() if belief is None else np.asarray(belief, float)
        O = self._spatial(q)
        tw = np.asarray(twist, float)
        n = max(1, math.ceil(duration / self.timing.sample_period - 1e-9))
        s = duration * np.arange(1, n + 1) / n
        if self.scene.dimension == 2:
            from ..pose import integrate_pose

            Os = [self._spatial(integrate_pose(q, tw, t)) for t in s]
        else:
            Os = [P.integrate(O, tw, t) for t in s]
        G = self.G
        if absolute:
            G = P.compose(self.features[pusher].frame, P.inverse(P.compose(O, pusher_contact(self.scene, pusher, q).frame)))
        self._follow(s, [P.compose(G, O, P.inverse(o)) for o in Os], f"the push with pusher `{pusher}`")

    def release(self) -> None:
        """Ends a regrasp as the open loop's world motion does: retreats from the feature in
        contact (if any) by the clearance, then holds still :data:`RELEASE_DWELL`: the object's
        pose in the hand is the regrasp's once no feature touches it. The grip meanwhile: the
        plan's where gravity leaves the pads enough (:meth:`transfer_grip`); where it needs a
        raised grip, the ceiling (:func:`~regrasp.execution.arm.grip_ceiling`): after the last
        push nothing is to slide any more, and the world's friction, grip and mass may be further
        from nominal than the scene declares."""
        if self.current is not None:
            O = self.in_hand()
            seg = Segments(self.timing, self.safe, _reach(self.scene, O), self.G, self.motion.envelope,
                           self.motion.workcell.robot.base[:3], self.motion.workcell.contacts())
            seg.retreat(self.features[self.current], O)
            grip = self.transfer_grip(self.pose())
            self.grip.set_force((grip if grip <= self.grip_force else max(grip, self.grip_ceiling)) * self.world_grip)
            self._follow(seg.times[1:], seg.poses[1:], "the retreat after the last push",
                         [lab == "retreat" for lab in seg.samples.label[1:]])
            self.current = None
        self.idle(RELEASE_DWELL)

    def idle(self, duration: float):
        """Holds the arm still for ``duration`` [s] (the grip loop running)."""
        from ..robot.tracking import track

        track(self.robot, [0.0, duration], np.array([self.robot.q, self.q]), settle=0.0, grip=self.grip, ease=False)

    def poke(self, delta):
        """Displaces the object in the grasp by planar ``delta`` ``[dx, dz, dtheta]`` (m, m, rad)
        (the feature in contact retreats first)."""
        if self.current is not None:
            seg = Segments(self.timing, self.safe, _reach(self.scene, self.in_hand()), self.G, self.motion.envelope,
                           self.motion.workcell.robot.base[:3], self.motion.workcell.contacts())
            seg.retreat(self.features[self.current], self.in_hand())
            self._follow(seg.times[1:], seg.poses[1:], "the retreat before a poke",
                         [lab == "retreat" for lab in seg.samples.label[1:]])
            self.current = None
        d = self.robot.data
        G = P.compose(self.robot.tcp_pose(), self.untcp)
        d.qpos[self._jq:self._jq + 7] = P.compose(G, self._spatial(self.pose() + np.asarray(delta, float)))
        d.qvel[self._jv:self._jv + 6] = 0.0
        self._mj.mj_forward(self.robot.model, d)
        self.idle(0.1)

    @property
    def time(self) -> float:
        """The simulated time [s] since the model was built."""
        return float(self.robot.data.time)


def _reach(scene, O) -> float:
    """The object's reach [m] from the gripper origin at in-hand pose ``O``."""
    from .motion_check import object_points

    return float(np.max(np.linalg.norm(P.transform(O, object_points(scene)), axis=1)))


def goal_error(scene, plan, pose) -> tuple[np.ndarray, bool]:
    """(error, within tolerance) of the in-hand ``pose`` (planar ``[x, z, theta]`` or 3-D) to the
    scene's task goal (the plan's last pose without a task): planar ``[x, z, theta]`` (m, m, rad),
    3-D ``[position, angle]`` (m, rad)."""
    q = np.asarray(pose, float)
    if scene.dimension == 2:
        return scene.goal_error(q, None if scene.task is not None else plan.poses[-1])
    err, ok = scene.goal_error(q)
    return np.array([float(np.linalg.norm(err[:3])), err[3]]), ok


def control_arm(scene, plan, workcell=None, scales: Perturbation = Perturbation(), robot: str | None = None,
                timing: Timing = Timing(), seed: int = 0, max_replans: int = 10, max_time: float | None = None,
                start_error=(0.0, 0.0, 0.0), sensing=None, **mpc) -> ArmLoopResult:
    """Executes ``plan`` (a :class:`~regrasp.Plan` of ``scene``) closed loop with the arm in
    ``workcell`` (default: the scene's default workcell) in a world perturbed by ``scales``
    (see the module's doc): planar by the MPC (``mpc``: its settings, e.g. ``dt`` [s], ``speed``
    [m/s], ``horizon``; ``max_time`` [s] of control, default ControlRun's), 3-D by re-planning
    (at most ``max_replans``, seeds ``seed + 1, ...``). Raises ExecutionError naming a pusher of
    the plan that no feature serves, or a move the arm cannot make. ``start_error`` (planar
    ``[x, z, theta]`` (m, m, rad)): the object starts this far from the plan's start in the
    grasp, unknown to the controller until it measures it (thesis Fig 5-9; planar only)."""
    from ..planning.plan import Plan

    if not isinstance(plan, Plan):
        raise ArgumentError(f"invalid `plan`: a regrasp Plan (got {type(plan).__name__})", "plan")
    if not isinstance(scales, Perturbation):
        raise ArgumentError(f"invalid `scales`: a regrasp.Perturbation (got {type(scales).__name__})", "scales")
    from ..fields import check_vector

    if scene.dimension != 2 and np.any(check_vector(start_error, 3, "start_error") != 0):
        raise ArgumentError("invalid `start_error`: planar scenes only (3-D re-planning starts from the plan's start)",
                            "start_error")
    _check_features(scene, plan, workcell)
    if scene.dimension == 2:
        return _control_planar(scene, plan, workcell, scales, robot, timing, seed, max_time, start_error, mpc, sensing)
    return _control_spatial(scene, plan, workcell, scales, robot, timing, seed, max_replans, sensing)


def _check_features(scene, plan, workcell) -> None:
    """ExecutionError naming each pusher of ``plan`` that no feature of the workcell serves."""
    from .layout import default_workcell

    wc = default_workcell(scene) if workcell is None else workcell
    try:
        assign(scene, np.asarray(plan.poses, float), list(plan.pushers), wc)
    except ExecutionError as e:
        raise ExecutionError(str(e), "workcell") from None


def controller_scene(scene, plan, workcell=None):
    """The planar ``scene`` with only the pushers the workcell can render, for the MPC and its
    re-planning: the plan's and those a feature serves
    (:func:`~regrasp.execution.assignment.assign`) at every pose of the plan; ``scene`` itself when it needs none removed
    or has no source text to rebuild from."""
    from .layout import default_workcell

    wc = default_workcell(scene) if workcell is None else workcell
    poses = np.asarray(plan.poses, float)
    keep = set(plan.pushers[1:])
    for p in scene.pusher_names:
        if p not in keep and all(_served(scene, p, q, wc) for q in poses):
            keep.add(p)
    return with_pushers(scene, keep)


def with_pushers(scene, keep):
    """The planar ``scene`` with only the pushers named in ``keep`` (rebuilt from its source text);
    ``scene`` itself when it has none to remove or no source text to rebuild from."""
    import json
    import tomllib

    from ..scene.planar import Scene

    keep = set(keep)
    src = getattr(scene, "source", None)
    if keep >= set(scene.pusher_names) or not src or getattr(scene, "_ops", ()):
        return scene
    d = tomllib.loads(src[1]) if src[0] == "toml" else json.loads(src[1])
    d["pushers"] = [p for p in d.get("pushers", []) if p.get("name") in keep]
    return Scene.from_dict(d)


def _served(scene, pusher: str, pose, workcell) -> bool:
    """Whether a feature of ``workcell`` serves ``pusher`` with the object at in-hand ``pose``."""
    try:
        assign(scene, np.array([pose, pose], float), [None, pusher], workcell)
    except ExecutionError:
        return False
    return True


def _control_planar(scene, plan, workcell, scales, robot, timing, seed, max_time, start_error, mpc,
                    sensing=None) -> ArmLoopResult:
    from ..control.loop import ControlRun, _check_arguments

    d = mpc_defaults()
    dt, speed, horizon = (mpc.pop(k, d[k]) for k in ("dt", "speed", "horizon"))
    se = _check_arguments("quasistatic", "mpc", dt, speed, horizon, max_time, start_error, 0.0, seed, ())  # before any work
    made = []

    def plant(q0):
        made.append(ArmPlant(scene, plan, q0, workcell, robot, scales, timing, sensing))
        return made[0]

    run = ControlRun(scene, plan, "arm", "mpc", (), se, Perturbation(), controller_scene(scene, plan, workcell),
                     0.0, seed, dt, speed, horizon, max_time, mpc, plant=plant)
    while run.t <= run.max_time + 1e-9 and run.tick():
        run.t += dt
    c = run.result()
    arm = made[0]
    if run.world_failed:
        err, _ = goal_error(scene, plan, c.final_pose)
        return ArmLoopResult(False, err, c.replans, arm.time, arm.switch_overs, c.final_pose, c.failure, c)
    final, err, ok, failure = _released(arm, scene, plan, c.failure)  # the regrasp ends with the hand off the features
    return ArmLoopResult(ok, err, c.replans, arm.time, arm.switch_overs, final, failure if not ok else "", c)


def _released(arm: ArmPlant, scene, plan, failure: str) -> tuple[np.ndarray, np.ndarray, bool, str]:
    """After :meth:`ArmPlant.release`: the in-hand pose, its error to the goal, whether within the
    tolerance, and the run's failure — ``failure`` (the control's), the arm's when it cannot
    retreat, or, when the release moved the object out of the tolerance, how far it moved."""
    before = arm.pose()
    _, held = goal_error(scene, plan, before)
    try:
        arm.release()
    except RegraspError as e:  # the arm cannot retreat: the regrasp is not done, saying why
        q = arm.pose()
        return q, goal_error(scene, plan, q)[0], False, failure or str(e)
    q = arm.pose()
    err, ok = goal_error(scene, plan, q)
    if held and not ok and not failure:
        if scene.dimension == 2:
            turn = abs(math.remainder(float(q[2] - before[2]), 2 * math.pi))
            moved = f"{np.linalg.norm((q - before)[:2]) * 1e3:.2f} mm, {np.degrees(turn):.2f}°"
        else:
            moved = f"{np.linalg.norm((q - before)[:3]) * 1e3:.2f} mm, {np.degrees(P.quat_angle(before[3:], q[3:])):.2f}°"
        failure = f"the object moved {moved} in the hand in the retreat from the last feature"
    return q, err, ok, failure


def sticking(scene, a: dict, b: dict) -> bool:
    """Whether the 3-D plan step from path entry ``a`` to ``b`` sticks: its pusher (not a plane,
    whose contact rolls over the object) moves with the object (its pusher twist, when given,
    the object's own twist)."""
    if scene.is_plane(b["pusher"]):
        return False
    u = b.get("pusher_twist")
    return u is None or bool(np.allclose(u, P.twist_between(a["pose"], b["pose"]), rtol=1e-6, atol=1e-9))


def _control_spatial(scene, plan, workcell, scales, robot, timing, seed, max_replans, sensing=None) -> ArmLoopResult:
    from ..scene.spatial import check_plan3d, run_plan3d

    arm = ArmPlant(scene, plan, None, workcell, robot, scales, timing, sensing)
    path = check_plan3d(scene, plan)

    def step(a: dict, b: dict) -> np.ndarray:
        u = b.get("pusher_twist")
        u = np.asarray(P.twist_between(a["pose"], b["pose"]) if u is None else u, float)
        if arm.current != b["pusher"]:
            arm.switch(b["pusher"], arm.in_hand())
        # the step's duration at the timing's push speeds (the plan's twist is per unit time)
        T = max(np.linalg.norm(u[:3]) / timing.push_speed, np.linalg.norm(u[3:]) / timing.push_turn,
                timing.sample_period)
        # a sticking step rendered against the feature from the step's planned start, as the
        # open loop does; else from the commanded pose (a plane's from the planned pose)
        plane, sticks = bool(scene.is_plane(b["pusher"])), sticking(scene, a, b)
        A = np.asarray(a["pose"], float) if plane or sticks else None
        arm.push(b["pusher"], u / T, T, A, absolute=sticks)
        return arm.pose()

    failure, replans = "", 0
    try:
        q, _, replans = run_plan3d(scene, path, step, arm.pose(), True, max_replans, seed)
    except RegraspError as e:  # the arm cannot go on, or no re-plan: the run ends, saying why
        q, failure = arm.pose(), str(e)
    q, err, ok, failure = _released(arm, scene, plan, failure)
    if not ok and not failure:
        failure = "ended outside the tolerance"
    return ArmLoopResult(ok, err, replans, arm.time, arm.switch_overs, q, failure if not ok else "")
