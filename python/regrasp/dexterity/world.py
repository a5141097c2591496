"""The world a regrasp action runs in: the arm and its gripper (UR5e + 2F-85 with force-controlled
fingers and distributed-contact pads, :mod:`regrasp.robot`) holding an object at a grasp, above
the workcell's table, in MuJoCo. The world is perturbed per trial (:class:`~regrasp.Perturbation`: the
pads' friction, the grip force, the object's mass and its start pose in the hand). Primitives:
move the hand along a timed TCP path (IK once per path, :func:`solve_path`; followed by the
joint servo, :func:`~regrasp.robot.tracking.track`) under a grip-force schedule
(:class:`GripSchedule`: a per-finger force [N] in time, or open). The object's grasp is read in
the **measured hand frame** (:meth:`HandWorld.hand_frame`: the TCP's axes, its origin midway
between the two pads' face centres as they are now), so that a grasp taken at another width
reads true."""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import Callable, Optional

import numpy as np

from .. import pose as P
from ..scene.perturbation import HandPerturbation, Perturbation as _Perturbation
from ..errors import ArgumentError, SceneError
from ..extras import need

WORK_POINT = (0.40, 0.30, 0.40)  # m, world: where the hand works, 0.40 m above the table's top
POST_X, POST_Y = 0.55, 0.0  # m, world: the face of the workcell's fixed post (facing −x) for prehensile pushes, clear of the arm at the work point
POST_HALF = (0.005, 0.004, 0.30)  # m, the post's half-extents (x, y, z), standing on the table: 8 mm wide, it passes between the fingers
POST_FRICTION = 1.0  # the post's Coulomb friction with the object (a rubber-faced post)
PATH_STEP = 0.01  # s, a hand path's sample spacing for the IK (dense: followed piecewise linearly)
SETTLE = 0.3  # s, after each path, the arm's servo holds its end
OPEN = None  # a grip schedule's value for "fingers open"


@dataclass(frozen=True)
class HandPath:
    """A timed TCP path: ``times`` (n,) [s] increasing from 0, ``poses`` (n, 7) world TCP poses."""

    times: np.ndarray
    poses: np.ndarray

    @staticmethod
    def line(a, b, duration: float, profile: Callable[[np.ndarray], np.ndarray] | None = None) -> "HandPath":
        """From world pose ``a`` to ``b`` in ``duration`` [s] (position linear, orientation
        slerped) along the time-scaling ``profile`` (s in [0, 1] → [0, 1]; default smoothstep:
        at rest at both ends), sampled every :data:`PATH_STEP`."""
        n = max(2, int(np.ceil(duration / PATH_STEP)) + 1)
        t = np.linspace(0.0, duration, n)
        s = t / duration
        u = s * s * (3 - 2 * s) if profile is None else profile(s)
        return HandPath(t, np.array([P.interpolate(a, b, x) for x in u]))

    def then(self, other: "HandPath") -> "HandPath":
        """This path followed by ``other`` (its clock shifted to start where this one ends)."""
        return HandPath(np.concatenate([self.times, self.times[-1] + other.times[1:]]),
                        np.concatenate([self.poses, other.poses[1:]]))


class GripSchedule:
    """The fingers' command in time: ``force(t)`` [N] per finger or :data:`OPEN`; ``t`` [s] on the
    schedule's clock, which starts at :meth:`start`; scaled by the trial's ``grip`` factor. A
    force is held as :class:`~regrasp.robot.grip.GripController` holds one (the feed-forward map
    plus an integral on the pads' mean measured force, time constant ``TAU``, bounded), with
    two differences that a changing force needs: the integral is kept across changes of the
    force, and it also acts when a pad has lost the object (the feed-forward map, measured
    between 9 and 45 N, lets the 2F-85's linkage spring the pads off a box below ≈ 1 N).
    Call :meth:`update` before every ``mj_step``."""

    TAU = 0.02  # s, the force loop's integral time constant

    def __init__(self, world: "HandWorld", force: Callable[[float], Optional[float]]):
        from ..robot.grip import CORRECTION, MIN_CORRECTION, ContactForces, low_force_curve, robot_pad_state

        self.world, self.force = world, force
        r = world.robot
        self.sensor = ContactForces(r.model, r.pad_geoms, np.asarray(world.geoms, int))
        self.gain = robot_pad_state(r)[0]
        u, F = low_force_curve(r)
        self.curve = (u, np.maximum.accumulate(F) + 1e-9 * np.arange(len(F)))  # increasing, for np.interp
        self.correction, self.min_correction = CORRECTION, MIN_CORRECTION
        self.t0, self.next, self.integral = r.data.time, r.data.time, 0.0

    def start(self) -> "GripSchedule":
        """Starts the schedule's clock now."""
        self.t0 = self.next = self.world.robot.data.time
        return self

    def update(self) -> None:
        """Sets the grip actuator's command for now (every grip period; call before each ``mj_step``)."""
        from ..robot.grip import open_gripper

        r, d = self.world.robot, self.world.robot.data
        if d.time + 1e-12 < self.next:
            return
        period = self.world.grip_period
        self.next = d.time + period
        f = self.force(d.time - self.t0)
        if f is None:
            self.integral = 0.0
            open_gripper(r)
            return
        f = float(f) * self.world.perturbation.grip
        ff = self.feedforward(f)
        # bounded below by the command of a quarter of the force (it never opens the hand: the pads
        # would spring off), above as the grip controller (it may close harder where the map reads low)
        low, high = ff - self.feedforward(f / 4), max(self.correction * f, self.min_correction) / self.gain
        measured = float(np.mean(self.sensor(d)))
        self.integral = min(max(self.integral + period / self.TAU * (f - measured) / self.gain, -low), high)
        d.ctrl[r.grip_actuator] = ff + self.integral

    def feedforward(self, f: float) -> float:
        """The actuator force [N] for a per-pad force ``f`` [N]: the measured low-force curve
        below the affine map's range (:func:`~regrasp.robot.grip.low_force_curve`), the map above."""
        from ..robot.grip import grip_command

        u, F = self.curve
        return float(np.interp(f, F, u)) if f < F[-1] else grip_command(self.world.robot, f)


def constant(force: float) -> Callable[[float], float]:
    """A grip schedule's force [N] held all along."""
    return lambda t: force


def ramps(*points) -> Callable[[float], Optional[float]]:
    """A grip schedule's force [N], piecewise linear through ``(time [s], force [N])`` points
    (held before the first and after the last): the fingers' force changed at a rate that their
    linkage follows (a step from 6 N to 0.6 N lets the pads spring off a 0.1 kg box for 60 ms)."""
    t, f = np.array(points, float).T
    return lambda x: float(np.interp(x, t, f))


def add_post(spec) -> None:
    """The workcell's fixed post (:data:`POST_X`, :data:`POST_HALF`, :data:`POST_FRICTION`): a
    bar standing on the table, its face towards the robot (−x), narrow enough to pass between the
    fingers; it collides with the object, the arm and the gripper's body, not the pads (the arm's
    paths keep clear of it, :func:`solve_path`)."""
    from ..mujoco.model import FEATURE_BITS, add_geom

    c = (POST_X + POST_HALF[0], POST_Y, POST_HALF[2])
    add_geom(spec.worldbody, "box", list(POST_HALF), FEATURE_BITS, [POST_FRICTION], pos=list(c), name="post",
             rgba=[0.6, 0.6, 0.65, 1.0])


class HandWorld:
    """The arm holding ``scene``'s object (a :class:`regrasp.Scene3D`) at in-hand pose ``grasp``
    (7,) with the TCP at world pose ``hand`` (7,) (or the arm at joint positions ``q`` [rad]),
    the fingers closed on it at the scene's grip force, in the world ``perturbation``;
    ``robot``: the robot's name (default the default robot's). The object is on a free joint;
    the table under the work point, a post beyond it (:func:`add_post`). The model is compiled once: :meth:`reset` starts another
    trial in it (another perturbation), as a fresh build would, in a fraction of the time."""

    def __init__(self, scene, grasp, hand, perturbation: _Perturbation = _Perturbation(), robot: str | None = None,
                 q=None):
        from ..execution.arm import GRIP_PERIOD, OBJECT_RGBA, grasp_of
        from ..mujoco.world import Layout, build as build_world
        from ..robot.model import DEFAULT_ROBOT, build
        from ..robot.pads import Pads

        self.scene, self.grasp, self.grip_period = scene, np.asarray(grasp, float), GRIP_PERIOD
        width, _ = grasp_of(scene, self.grasp)  # a turn about the grasp axis or a shift across it keeps it
        world = Layout(scene, np.array([0.0, 0.0, -1.0, 1.0, 0.0, 0.0, 0.0]), "robot", object_rgba=OBJECT_RGBA)

        def add(spec):  # the object (put in the hand by reset) and the post, around the robot
            build_world(world, spec=spec, extra=add_post)

        try:
            self.robot = build(robot or DEFAULT_ROBOT, pads=Pads.of_scene(scene),
                               pad_friction=float(scene.pad_friction), grasp_width=width, add=add)
        except ArgumentError as e:
            if e.field == "grasp_width":
                raise ArgumentError(f"invalid `grasp`: the object is {width * 1e3:.1f} mm wide across it; the "
                                    f"2F-85 opens 85 mm", "grasp") from None
            raise
        r = self.robot
        m = r.model
        self.body = m.body("object").id
        self.geoms = [g for g in range(m.ngeom) if m.geom_bodyid[g] == self.body]
        self.jq = int(m.jnt_qposadr[m.body_jntadr[self.body]])
        self.jv = int(m.jnt_dofadr[m.body_jntadr[self.body]])
        self.pads = np.concatenate([np.asarray(p, int) for p in r.pad_geoms])
        self.features = np.array([r.table, m.geom("post").id], int)  # the table and the post
        self.nominal = (m.geom_friction[self.pads, 0].copy(), float(m.body_mass[self.body]),
                        m.body_inertia[self.body].copy(), m.geom_friction[self.features, 0].copy())
        self.q0 = solve_ik_from_home(r, hand) if q is None else np.asarray(q, float)
        self.reset(perturbation)

    def reset(self, perturbation: _Perturbation = _Perturbation()) -> "HandWorld":
        """Starts a trial: the arm at its start, the object at the grasp moved by
        ``perturbation`` (:class:`~regrasp.Perturbation`: its pads', the table's and the post's friction, its mass and the grip force scaled), the fingers closed on it."""
        mujoco = need("mujoco", "robot")
        from ..execution.arm import close_on
        from ..robot.grip import close_fingers
        from ..robot.sensing import GripSensing

        r = self.robot
        m, d = r.model, r.data
        self.perturbation = perturbation
        self.grip_force = float(self.scene.grip_force) * perturbation.grip
        friction, mass, inertia, features = self.nominal
        m.geom_friction[self.pads, 0] = friction * perturbation.finger_friction
        m.geom_friction[self.features, 0] = features * perturbation.feature_friction
        m.body_mass[self.body], m.body_inertia[self.body] = mass * perturbation.mass, inertia * perturbation.mass
        mujoco.mj_resetData(m, d)
        close_fingers(r)
        r.set_q(self.q0)
        half = perturbation.turn / 2
        base = self.grasp if perturbation.pose is None else np.asarray(perturbation.pose, float)
        start = P.compose(np.array([*perturbation.shift, np.cos(half), 0.0, np.sin(half), 0.0]), base)
        d.qpos[self.jq:self.jq + 7] = P.compose(self.hand_frame(), start)
        mujoco.mj_forward(m, d)
        # the actions' own force loop measures the pads' forces (GripSchedule): the closing too
        close_on(r, self.body, self.geoms, self.grip_force, GripSensing("ideal"))
        return self

    # --- reading the world ----------------------------------------------------------------------

    def hand_frame(self) -> np.ndarray:
        """The measured hand frame's world pose: the TCP's axes, its origin midway between the
        pads' face centres now (m)."""
        from ..robot.grip import body_pose
        from ..robot.pads import FACE_Y, LENGTH

        r, d = self.robot, self.robot.data
        centres = [P.transform(body_pose(d, r.model.body(b).id), [0.0, FACE_Y, LENGTH / 2])
                   for b in self.pad_bodies()]
        return np.concatenate([(centres[0] + centres[1]) / 2, r.tcp_pose()[3:]])

    def pad_bodies(self) -> tuple:
        """The (left, right) pad bodies' names."""
        from ..robot.model import GRIPPER_PREFIX

        return tuple(GRIPPER_PREFIX + b for b in self.robot.kind.pad_bodies)

    def object_pose(self) -> np.ndarray:
        """The object's world pose now (m, unit quaternion)."""
        return self.robot.data.qpos[self.jq:self.jq + 7].copy()

    def in_hand(self) -> np.ndarray:
        """The object's pose in the measured hand frame now."""
        return P.compose(P.inverse(self.hand_frame()), self.object_pose())

    def pad_forces(self) -> np.ndarray:
        """The (left, right) pads' normal forces [N] on the object now."""
        from ..robot.grip import pad_forces

        return pad_forces(self.robot, self.geoms)

    def held(self) -> bool:
        """Whether both pads press on the object now."""
        return bool(np.all(self.pad_forces() > 1e-3))

    def loose(self) -> bool:
        """Whether the pads' friction capacity μ (N₁ + N₂) is below the object's weight now (it
        falls, or is free)."""
        m = self.robot.model
        weight = float(m.body_mass[self.body]) * float(np.linalg.norm(m.opt.gravity))
        return bool(float(m.geom_friction[self.pads[0], 0]) * float(self.pad_forces().sum()) < weight)

    def unstable(self) -> bool:
        """Whether MuJoCo's integration blew up since the trial began (a bad acceleration: it
        then resets the state)."""
        mujoco = need("mujoco", "robot")
        return int(self.robot.data.warning[int(mujoco.mjtWarning.mjWARN_BADQACC)].number) > 0

    # --- acting ---------------------------------------------------------------------------------

    def follow(self, path: HandPath, q, force: Callable[[float], Optional[float]], settle: float = SETTLE,
               observe=None) -> None:
        """Moves the arm along joint positions ``q`` (the IK of ``path``, :func:`solve_path`) on
        ``path``'s clock under the grip schedule ``force`` (:class:`GripSchedule`), then holds
        its end ``settle`` [s]."""
        from ..robot.tracking import track

        grip = GripSchedule(self, force).start()
        track(self.robot, path.times, q, settle=settle, grip=grip, ease=False,
              observe=None if observe is None else (lambda t: observe(self)))

    def wait(self, duration: float, force: Callable[[float], Optional[float]], observe=None) -> None:
        """Holds the arm where it is for ``duration`` [s] under the grip schedule ``force``."""
        q = self.robot.q
        self.follow(HandPath(np.array([0.0, duration]), np.zeros((2, 7))), np.array([q, q]), force, 0.0, observe)


RELEASES = (0.004, 0.008, 0.012, 0.016, 0.020)  # s, the openings release_timing measures
RELEASE_AT = 0.05  # s, release_timing: when the fingers are commanded open


@dataclass(frozen=True)
class Release:
    """How the 2F-85 lets go (:func:`release_timing`): commanded open for δ [s], the pads' grip
    cannot hold the object's weight (:meth:`HandWorld.loose`) for ``a`` δ + ``b`` [s], from
    ``delay`` [s] after the command; measured for δ in [``low``, ``high``]."""

    a: float
    b: float
    delay: float
    low: float
    high: float

    def free(self, delta: float) -> float:
        """The free time [s] of an opening of ``delta`` [s]."""
        return self.a * delta + self.b

    def opening(self, free: float) -> float:
        """The opening δ [s] (within the measured range) that leaves the object free for ``free`` [s]."""
        return float(min(max((free - self.b) / self.a, self.low), self.high))


def release_timing(world: "HandWorld", releases=RELEASES) -> Release:
    """The :class:`Release` of ``world``'s grasp: the fingers commanded open for each δ of
    ``releases`` [s] and then closed again at the grip force — the 2F-85's driver runs open at
    full force, and comes back from as far as it went — with the hand still; the free time (the
    object loose, :meth:`HandWorld.loose`: the catch that ends it is an impact of the closing
    pads, which stops the object within a millimetre) a
    least-squares line through the measured ones (the openings that never free the object, or
    let it fall out, left out). ``world`` is left reset in its perturbation. A SceneError (field ``grasp``) when fewer
    than two openings free it or the free time does not grow with δ."""
    releases = sorted(float(d) for d in releases)
    if len(set(releases)) != len(releases) or not releases or releases[0] <= 0:
        raise ArgumentError(f"invalid `releases`: distinct openings > 0 [s] (got {releases})", "releases")
    times, delays, used = [], [], []
    perturbation = world.perturbation
    for delta in releases:
        world.reset(perturbation)
        free: list = []
        force, t0 = world.grip_force / perturbation.grip, world.robot.data.time

        def grip(t: float, delta=delta):
            return OPEN if RELEASE_AT <= t < RELEASE_AT + delta else force

        world.wait(RELEASE_AT + 3 * delta + 0.1, grip, lambda w: free.append(w.robot.data.time) if w.loose() else None)
        if free and world.held():  # freed, and caught again
            times.append(free[-1] - free[0])
            delays.append(free[0] - t0 - RELEASE_AT)
            used.append(delta)
    world.reset(perturbation)
    if len(used) < 2:
        raise SceneError("scene field `grasp`: the gripper does not let the object go and catch it again at "
                         f"fewer than two of the openings {', '.join(f'{1e3 * d:g}' for d in releases)} ms", "grasp")
    a, b = np.polyfit(np.asarray(used, float), np.asarray(times, float), 1)
    if not (np.isfinite(a) and np.isfinite(b) and a > 0):
        raise SceneError("scene field `grasp`: the object's free time does not grow with the opening", "grasp")
    return Release(float(a), float(b), float(np.mean(delays)), float(used[0]), float(used[-1]))


def solve_ik_from_home(robot, hand) -> np.ndarray:
    """Joint positions [rad] putting the TCP at world pose ``hand``: solved from the robot's home
    for the fingers down at ``hand``'s point, then followed (IK continuation, 0.1 rad steps) to
    ``hand``'s orientation — a branch that turns the hand there (a direct solve from home may
    fold the arm under the table for a hand turned fingers up)."""
    from ..robot.ik import ik_path, solve_ik

    hand = np.asarray(hand, float)
    down = np.array([*hand[:3], 1.0, 0.0, 0.0, 0.0])
    q = solve_ik(robot, down, robot.q, field="hand")
    n = max(1, int(np.ceil(P.quat_angle(down[3:], hand[3:]) / 0.1)))
    return ik_path(robot, [P.interpolate(down, hand, k / n) for k in range(1, n + 1)], q)[-1]


def solve_path(robot, path: HandPath, q0) -> np.ndarray:
    """The arm's joint positions (n, 6) [rad] along ``path`` from ``q0`` (IK, one solve per sample;
    the arm and gripper clear of the table and of the post, :func:`add_post`, when there is one)."""
    from ..robot.ik import fixed_geoms, ik_path

    return ik_path(robot, path.poses, q0, avoid=[g for g in fixed_geoms(robot) if g != robot.table])


def hand_clearances(scene, grasps, robot: str | None = None) -> dict:
    """{grasp name: (m, gripper body)}: how far the object at each grasp (``grasps``, of
    ``scene``'s taxonomy) stays from the gripper's body besides the pads (negative: inside it;
    :func:`regrasp.execution.arm.clearance`), the fingers closed at its width. A grasp whose
    object would go into the 2F-85's links above the pads (a wide object held deep) cannot be
    taken: the grasp graph leaves it out. One robot model per grasp width."""
    from ..execution.arm import clearance, grasp_of
    from ..mujoco.world import Layout, build as build_world
    from ..robot.grip import close_fingers
    from ..robot.model import DEFAULT_ROBOT, build
    from ..robot.pads import Pads

    world = Layout(scene, np.array([0.0, 0.0, -1.0, 1.0, 0.0, 0.0, 0.0]), "robot")
    models: dict = {}
    out = {}
    for g in grasps:
        width = round(grasp_of(scene, g.pose)[0], 9)
        if width not in models:
            r = build(robot or DEFAULT_ROBOT, pads=Pads.of_scene(scene), pad_friction=float(scene.pad_friction),
                      grasp_width=width, add=lambda spec: build_world(world, spec=spec))
            close_fingers(r)
            models[width] = r
        r = models[width]
        dist, _, part = clearance(r, r.tcp_pose(), [g.pose])
        out[g.name] = (dist, part)
    return out


def finger_reach(scene, robot: str | None = None) -> float:
    """How far [m] the gripper's lowest colliding part (a pad's grid, a finger's tip link) reaches
    below the TCP along the fingers, closed, with ``scene``'s pads: measured once per pad model
    (the arm's IK keeps it ``MIN_DISTANCE`` off the table)."""
    return _finger_reach(float(scene.pad_radius), float(scene.pad_friction), robot or "")


@lru_cache(maxsize=16)
def _finger_reach(pad_radius: float, friction: float, robot: str) -> float:
    from ..robot.grip import close_fingers
    from ..robot.ik import solve_ik, table_distance
    from ..robot.model import DEFAULT_ROBOT, build
    from ..robot.pads import TIP_SOLREF, Pads

    r = build(robot or DEFAULT_ROBOT, pads=Pads(5, 5, 0.001, ("circle", pad_radius, pad_radius), TIP_SOLREF),
              pad_friction=friction)
    close_fingers(r)
    height = 0.04  # m, the TCP above the table: the fingers within the distance query's reach
    q = solve_ik(r, np.array([WORK_POINT[0], WORK_POINT[1], height, 1.0, 0.0, 0.0, 0.0]), r.q)
    return float(height - table_distance(r, q))


def hand_pose(alpha: float, point=WORK_POINT) -> np.ndarray:
    """The TCP's world pose at ``point`` [m] with the grasp axis along the world's y and the
    hand's x at angle ``alpha`` [rad] from the world's x towards its z (0: fingers down)."""
    x = np.array([np.cos(alpha), 0.0, np.sin(alpha)])
    y = np.array([0.0, 1.0, 0.0])
    return np.concatenate([np.asarray(point, float), P.quat_from_matrix(np.column_stack([x, y, np.cross(x, y)]))])


#: The old name (deprecated): ``regrasp.Perturbation``.
Perturbation = HandPerturbation
