"""Whether the pads hold the object through an arm's motion: at every sample where only the pads
hold it (the start, transfers, approaches, retreats with the fingers closed: not while a feature
pushes it, nor on the table before the fingers close or after they open), the wrench
the pads must supply — gravity, the held object's inertia ``m a`` and its rotational terms
``I α + ω × I ω`` as the arm moves — tested against the pads' limit surface at the grip force
(:meth:`regrasp.Scene.load_ratio`, the test of the motion cones' hold check). The planar limit
surface takes the load in the pads' plane (two forces, the torque about the grasp axis); the
force along the grasp axis and the torques about the plane's axes, which the pads' normal
forces and pressure carry, are not tested.

The object's motion comes from the arm's joints ``q``, velocities ``qd`` and accelerations
``qdd`` through MuJoCo's Jacobians of its centre of mass, rigidly held in the gripper at the
sample's in-hand pose: ``a = J q̈ + J̇ q̇``, ``ω = J_r q̇``, ``α = J_r q̈ + J̇_r q̇``. Its mass,
centre of mass and inertia are those of the object body MuJoCo simulates.

The margin is ``1 − ratio`` (the share of the pads' friction left unused); a world motion must
keep :func:`required_margin`: :data:`HOLD_MARGIN` beyond the scene's ``[uncertainty]`` of finger
friction, grip force and mass (the ratio's worst case under them). Planar scenes only (a 3-D
scene's pads have no limit-surface test here yet: None)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import pose as P

#: The least share of the pads' friction a world motion leaves unused beyond what the scene's
#: uncertainty takes: the model's own error (the limit surface's shape, the pads' pressure).
HOLD_MARGIN = 0.05
#: The samples where only the pads hold the object (their labels).
HELD = ("start", "transfer", "approach", "retreat")
#: Between pushes (from a push's retreat to the next approach's last :data:`SETTLE_SAMPLES`) the
#: grip is raised so that gravity takes at most this share of the pads' friction
#: (:meth:`ObjectLoad.boost`): MuJoCo's pads creep in proportion to their load (the heavy block
#: at 82 % of its torsional hold turned 2 mrad/s in a transfer and 6.6 mrad/s in a retreat, then
#: fell; at 63 %, 0.4 mrad/s, held), and the pushes keep the plan's grip.
TRANSFER_SHARE = 0.5
#: The last samples of an approach held at the plan's grip, so that it has settled at contact.
SETTLE_SAMPLES = 10
#: The most the grip is raised between pushes: this share of the gripper's force range.
MAX_GRIP_SHARE = 0.8


def worst_hold_factor(scene) -> float:
    """``(1 − δμ)(1 − δN) / (1 + δm)`` [−]: the worst world's pads' friction over its weight, as a
    share of the nominal's, with the scene's ``[uncertainty]`` spreads of finger friction, grip
    force and mass (1 without)."""
    u = scene.uncertainty or {}
    dmu, dn, dm = (float(u.get(k, 0.0)) for k in ("finger_friction", "grip_force", "mass"))
    return (1.0 - dmu) * (1.0 - dn) / (1.0 + dm)


def required_margin(scene) -> float:
    """The margin [−] a world motion of ``scene`` must keep: ``1 − (1 − HOLD_MARGIN)·f`` with
    :func:`worst_hold_factor` ``f``."""
    return 1.0 - (1.0 - HOLD_MARGIN) * worst_hold_factor(scene)


def transfer_share(scene) -> float:
    """The share [−] of the nominal pads' friction gravity may take between pushes once the grip
    is raised: :data:`TRANSFER_SHARE` in the worst world the scene's ``[uncertainty]`` declares
    (``TRANSFER_SHARE · f``, :func:`worst_hold_factor` ``f``)."""
    return TRANSFER_SHARE * worst_hold_factor(scene)


@dataclass(frozen=True)
class Holding:
    """The pads' hold along a motion: ``ratio`` (n,) the share of their friction used at each
    sample (NaN where a feature pushes), ``required`` the margin the scene needs, ``where`` the
    least margin's place in the motion (e.g. "the transfer before push 1 (t = 3.20 s)");
    ``smallest`` that margin ``1 − ratio`` and ``at`` its sample."""
    ratio: np.ndarray
    required: float
    where: str = ""

    def to_json(self) -> dict:
        """``smallest_margin``, ``required_margin``, ``sample``, ``where``, ``holds``."""
        return {"smallest_margin": self.smallest, "required_margin": self.required, "sample": self.at,
                "where": self.where, "holds": self.holds}

    @property
    def at(self) -> int:
        """The sample of the least margin (0 when no sample is held)."""
        return int(np.nanargmax(self.ratio)) if np.any(np.isfinite(self.ratio)) else 0

    @property
    def smallest(self) -> float:
        """The least margin ``1 − ratio`` over the held samples (1 when none is held)."""
        return float(1.0 - self.ratio[self.at]) if np.any(np.isfinite(self.ratio)) else 1.0

    @property
    def holds(self) -> bool:
        """Whether every held sample keeps the required margin."""
        return self.smallest >= self.required - 1e-12


class ObjectLoad:
    """The object's load on the pads at arm states, for one world motion (planar ``scene``) on
    the arm ``robot`` (:func:`~regrasp.execution.arm.build_robot`'s, the object's ``body``)
    with the TCP at ``tcp`` in the gripper frame."""

    def __init__(self, scene, robot, body: int, tcp, motion):
        import mujoco

        self.scene, self.robot, self.mj = scene, robot, mujoco
        m = robot.model
        self.data = mujoco.MjData(m)
        self.mass = float(scene.mass)  # the nominal object's (a perturbed model's scales its inertia)
        self.com = np.array(m.body_ipos[body], float)  # object frame [m]
        Ri = P.quat_matrix(m.body_iquat[body])
        scale = self.mass / float(m.body_mass[body])
        self.inertia = scale * Ri @ np.diag(m.body_inertia[body]) @ Ri.T  # about the com, object frame [kg m²]
        self.gravity = np.array(m.opt.gravity, float)
        self.site_body = int(m.site_bodyid[robot.tcp])
        self.tcp_inv = P.inverse(np.asarray(tcp, float))
        self.in_hand = np.asarray(motion.in_hand, float)
        self.planar = np.array([P.spatial_to_planar(h) for h in self.in_hand])
        self.held = np.array([lab in HELD for lab in motion.labels]) & (np.asarray(motion.grip_force, float) > 0)
        self.labels = list(motion.labels)
        self.grip_scale = np.ones(len(self.labels))  # the grip per sample over the motion's (boost)
        self._rest = (None, None)  # (joint path, its ratios at rest at the motion's grip)

    def wrenches(self, idx, q, qd, qdd) -> np.ndarray:
        """The object-frame wrench ``[fx, fz, τ]`` (N, N, N·m about the object's origin, gravity's
        convention) the pads must resist at samples ``idx`` with the arm at ``q``, ``qd`` (len(idx),
        dof) and accelerations ``qdd`` (len(idx), dof), or several of them (k, len(idx), dof: the
        kinematics computed once): gravity and the inertial load, (len(idx), 3) or (k, len(idx), 3)."""
        mj, m, d, r = self.mj, self.robot.model, self.data, self.robot
        dof = r.arm_dof
        qdd = np.asarray(qdd, float)
        many = qdd.ndim == 3
        qdd = qdd if many else qdd[None]
        out = np.zeros((len(qdd), len(idx), 3))
        jp, jr, dp, dr = (np.zeros((3, m.nv)) for _ in range(4))
        for k, i in enumerate(idx):
            d.qpos[:] = r.data.qpos
            d.qpos[r.arm_qpos] = q[k]
            d.qvel[:] = 0.0
            d.qvel[dof] = qd[k]
            mj.mj_kinematics(m, d)
            mj.mj_comPos(m, d)
            mj.mj_comVel(m, d)
            tcp = np.concatenate([d.site_xpos[r.tcp], P.quat_from_matrix(d.site_xmat[r.tcp].reshape(3, 3))])
            W = P.compose(P.compose(tcp, self.tcp_inv), self.in_hand[i])  # the object's world pose
            R = P.quat_matrix(W[3:])
            c = W[:3] + R @ self.com
            mj.mj_jac(m, d, jp, jr, c, self.site_body)
            mj.mj_jacDot(m, d, dp, dr, c, self.site_body)
            w = jr[:, dof] @ qd[k]
            Iw = R @ self.inertia @ R.T
            for v, acc in enumerate(qdd[:, k]):
                a = jp[:, dof] @ acc + dp[:, dof] @ qd[k]
                alpha = jr[:, dof] @ acc + dr[:, dof] @ qd[k]
                f = R.T @ (self.mass * (self.gravity - a))  # gravity and −m a, object frame
                T = R.T @ (Iw @ alpha + np.cross(w, Iw @ w))  # the torque the pads supply about the com
                # planar torque is about −y: the com's moment of f, and −T's component along −y
                out[v, k] = [f[0], f[2], self.com[0] * f[2] - self.com[2] * f[0] + T[1]]
        return out if many else out[0]

    def ratios(self, idx, q, qd, qdd) -> np.ndarray:
        """The share of the pads' friction used at samples ``idx`` (NaN where a feature pushes) at
        the motion's grip; with several accelerations ``qdd`` (k, len(idx), dof), the most."""
        idx = np.asarray(idx, int)
        qdd = np.asarray(qdd, float)
        out = np.full(len(idx), np.nan)
        keep = self.held[idx]
        if keep.any():
            k = np.flatnonzero(keep)
            w = self.wrenches(idx[k], q[k], qd[k], qdd[..., k, :])
            w = w if w.ndim == 3 else w[None]
            ok = np.all(np.isfinite(w), axis=(0, 2))  # a non-finite state cannot be held: inf, not NaN
            out[k[~ok]] = np.inf
            if ok.any():
                j = idx[k[ok]]
                r = [self.scene.load_ratio(self.planar[j], x[ok]) for x in w]
                out[k[ok]] = np.max(r, axis=0) / self.grip_scale[j]
        return out

    def at_rest(self, q) -> np.ndarray:
        """:meth:`ratios` of every sample with the arm at rest at joint path ``q`` (n, dof): gravity
        alone (computed once per path)."""
        if self._rest[0] is not q:
            z = np.zeros_like(q)
            scale, self.grip_scale = self.grip_scale, np.ones(len(self.labels))
            self._rest = (q, self.ratios(np.arange(len(q)), q, z, z))
            self.grip_scale = scale
        return self._rest[1] / self.grip_scale

    def boost(self, q, max_scale: float) -> np.ndarray:
        """Raises the grip between pushes (each run of held samples — retreat, transfers, approach —
        but the last :data:`SETTLE_SAMPLES` of an approach: the push starts at the plan's grip) so
        that gravity takes at most :func:`transfer_share` of the pads' friction there, at most
        ``max_scale`` times the plan's: sets and returns :attr:`grip_scale` (n,) from the arm at
        rest at ``q`` (n, dof)."""
        self.grip_scale = np.ones(len(self.labels))
        still = self.at_rest(q)
        free = self.held.copy()
        for i, lab in enumerate(self.labels):  # an approach's tail: the next SETTLE_SAMPLES are not all approach
            if lab == "approach" and "approach" not in self.labels[i + SETTLE_SAMPLES:i + SETTLE_SAMPLES + 1]:
                free[i] = False
        scale, share = np.ones(len(q)), transfer_share(self.scene)
        i = 0
        while i < len(q):
            if not free[i]:
                i += 1
                continue
            j = i
            while j < len(q) and free[j]:
                j += 1
            worst = np.nanmax(still[i:j], initial=0.0)
            scale[i:j] = min(max(1.0, worst / share), max(1.0, max_scale))
            i = j
        self.grip_scale = scale
        return scale

    def holding(self, q, qd, qdd, where=None) -> Holding:
        """The :class:`Holding` of the whole motion at arm states ``q``, ``qd``, ``qdd`` (n, dof);
        ``where(i)`` names sample ``i``'s place in the motion."""
        ratio = self.ratios(np.arange(len(q)), q, qd, qdd)
        h = Holding(ratio, required_margin(self.scene))
        return Holding(ratio, h.required, where(h.at) if where is not None else "")
