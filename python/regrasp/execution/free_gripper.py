"""A world motion (:func:`~regrasp.execution.world_motion`) executed in MuJoCo by a free-flying
gripper in the workcell: the baseline the arm (``regrasp.robot``) is compared with.

The model (``mujoco.MjSpec``): world gravity along −z (the scene's magnitude); the table and
every workcell feature as fixed geoms, their physical bodies (:mod:`regrasp.workcell.shapes`: a
block its box, an edge the rim of a bar, a corner a ball tip, a face a plate); a block edge that
renders a push also gets a capsule of radius :data:`FEATURE_RADIUS` just behind the push's
contact frame (MuJoCo's box-edge contact with a face lets a sticking line push slip:
block-high-friction slips 1.6 mm down a bare box edge and holds on the capsule); the object and the pads of ``regrasp.mujoco`` (the planar
model's pads and lamina for a planar scene, the 3-D model's pads and object otherwise), the pads
on a driven 6-DoF gripper body (``regrasp.mujoco.model.add_driven_body``) squeezed with the
motion's grip force. The object starts in the hand at the motion's first world pose; the
gripper follows the motion's samples (poses interpolated within each sample interval, one
MuJoCo step at a time). Measured: the object's pose in the gripper frame all along; success
when its final pose is within the scene's goal tolerance of the plan's goal."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import pose as P
from ..errors import ArgumentError
from ..extras import need
from ..workcell.description import Workcell
from ..workcell.shapes import EDGE_RADIUS
from .world_motion import WorldMotion

#: Radius [m] of the capsule behind a pushed block edge (an edge feature's bar's).
FEATURE_RADIUS = EDGE_RADIUS
#: Time [s] the gripper holds still at the start before the motion (the pads settle).
SETTLE = 0.2


@dataclass
class FreeGripperResult:
    """A free-gripper execution: ``success`` (the final in-hand pose within the scene's goal
    tolerance of the plan's goal); ``goal_error``: planar ``[x, z, theta]`` (m, m, rad) or 3-D
    ``[position, angle]`` (m, rad) differences; ``max_creep`` [m] and ``max_creep_angle`` [rad]:
    the most the object moved in the gripper frame within a run of non-push samples (transfer,
    approach, retreat), from where it was at the run's start; ``duration`` [s] simulated;
    ``times`` (n,) [s], ``in_hand`` (n, 7) (m, unit quaternion) the object's measured pose in the
    gripper frame at each motion sample; ``planned`` (n, 7) the motion's; ``gripper`` and
    ``object`` (n, 7) the measured world poses of the gripper and the object."""
    success: bool
    goal_error: np.ndarray
    max_creep: float
    max_creep_angle: float
    duration: float
    times: np.ndarray
    in_hand: np.ndarray
    planned: np.ndarray
    gripper: np.ndarray
    object: np.ndarray


def build(scene, motion: WorldMotion, workcell: Workcell | None = None):
    """The model (a ``mujoco.MjSpec``; see the module's doc) of ``motion`` executed for ``scene``
    in ``workcell`` (default: the motion's): the world (:func:`~regrasp.mujoco.world.build`) with
    the pads on a driven 6-DoF gripper and, for each push on an edge, a capsule along it."""
    from ..mujoco import model as M
    from ..mujoco.world import Layout, build as build_world

    workcell = motion.workcell if workcell is None else workcell
    names = {f.name for f in workcell.features}
    lengths = {c.name: c.length for c in workcell.contacts()}

    def edges(spec):
        for a in motion.assignments:
            if ".edges[" in a.feature and a.feature.split(".")[0] in names and a.feature in lengths:
                x = P.quat_rotate(a.frame[3:], [lengths[a.feature] / 2, 0.0, 0])
                c = a.frame[:3] - P.quat_rotate(a.frame[3:], [0.0, 0, 1]) * FEATURE_RADIUS
                mu = workcell.feature(a.feature.split(".")[0]).friction
                M.add_geom(spec.worldbody, "capsule", [FEATURE_RADIUS], M.FEATURE_BITS, [mu],
                           name=f"{a.feature}-push{a.index}", fromto=np.r_[c - x, c + x], condim=3)

    start = np.zeros(3) if scene.dimension == 2 else motion.in_hand[0]
    return build_world(Layout(scene, start, "gripper", spatial=True, workcell=workcell,
                              name=f"{scene.name}-free-gripper"), M.Contact(), extra=edges)


def _tolerance_error(scene, plan, q) -> tuple[np.ndarray, bool]:
    """The goal error of in-hand pose ``q`` (m, unit quaternion) and whether it is within the
    scene's goal tolerance (the plan's last pose when the scene has no task)."""
    goal = np.asarray(plan.poses[-1], float)
    if scene.dimension == 2:
        R = P.quat_matrix(q[3:])
        return scene.goal_error([q[0], q[2], np.arctan2(R[2, 0], R[0, 0])], goal)
    err, ok = scene.goal_error(q, np.r_[goal[:3], goal[3:] / np.linalg.norm(goal[3:])])
    return np.array([float(np.linalg.norm(err[:3])), err[3]]), ok


def execute_free_gripper(scene, plan, motion: WorldMotion, workcell: Workcell | None = None) -> FreeGripperResult:
    """Executes ``motion`` (the :class:`WorldMotion` of ``plan`` for ``scene``) in MuJoCo with a
    free-flying gripper in ``workcell`` (default: the motion's; another one, e.g. with a feature
    removed, checks that the feature does the pushing) and measures it (see
    :class:`FreeGripperResult`)."""
    mujoco = need("mujoco", "mujoco")
    from ..mujoco.model import Contact, Driver, Rig

    if not isinstance(motion, WorldMotion):
        raise ArgumentError(f"invalid `motion`: a WorldMotion (got {type(motion).__name__})", "motion")
    if workcell is not None and not isinstance(workcell, Workcell):
        raise ArgumentError(f"invalid `workcell`: a Workcell (got {type(workcell).__name__})", "workcell")
    rig = Rig(build(scene, motion, workcell), Contact(), float(motion.grip_force[0]))
    m, d = rig.model, rig.data
    drv = Driver(m, "gripper")
    obj = m.body("object").id
    jadr = int(m.jnt_qposadr[m.body_jntadr[obj]])
    drv.set(d, motion.gripper[0])
    d.qpos[jadr:jadr + 7] = motion.object[0]
    mujoco.mj_forward(m, d)

    Gs, Ws = [], []

    def in_hand() -> np.ndarray:
        Gs.append(np.asarray(d.qpos[drv.qadr], float).copy())
        Ws.append(np.r_[d.xpos[obj], d.xquat[obj]])
        return P.compose(P.inverse(Gs[-1]), Ws[-1])

    for _ in range(int(round(SETTLE / rig.dt))):
        drv.move(d, motion.gripper[0], rig.dt)
        rig.step()
    Gs.clear(), Ws.clear()
    out = [in_hand()]
    for i in range(1, len(motion.times)):
        n = max(1, int(round((motion.times[i] - motion.times[i - 1]) / rig.dt)))
        a, b = motion.gripper[i - 1], motion.gripper[i]
        for s in np.arange(1, n + 1) / n:
            drv.move(d, P.interpolate(a, b, [s])[0] if s < 1 else b, rig.dt)
            rig.step()
        out.append(in_hand())
    H = np.array(out)
    creep, turn = 0.0, 0.0
    labels = list(motion.labels)
    start = None
    for i, lab in enumerate(labels):
        if lab == "push":
            start = None
            continue
        if start is None:
            start = i
        creep = max(creep, float(np.linalg.norm(H[i, :3] - H[start, :3])))
        turn = max(turn, P.quat_angle(H[i, 3:], H[start, 3:]))
    err, ok = _tolerance_error(scene, plan, H[-1])
    return FreeGripperResult(ok, err, creep, turn, float(d.time), motion.times.copy(), H, motion.in_hand.copy(),
                             np.array(Gs), np.array(Ws))
