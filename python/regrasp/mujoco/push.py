"""Pushes in MuJoCo in the planner's view (gripper fixed, the virtual pusher moving): for the
thesis' experiments and the validation of motion cones against an independent engine.

The model (``regrasp.mujoco.model``): the object extruded from its outline, force-driven pads
fixed in the world, and the pusher's feature on a driven body (its velocity is seen by the
contacts, so its friction drags the object as a real pusher would).
"""

from __future__ import annotations

import numpy as np

from ..extras import need
from ..scene.planar import Scene
from ..fields import check_name, check_number, check_vector

#: the longest push :func:`simulate_push` simulates [s] (MuJoCo steps of 0.5 ms: a bound on its time)
MAX_DURATION = 60.0
from ..pose import integrate_pose, planar_compose, planar_inverse, planar_rotate
from .model import FEATURE_RADIUS, Contact, Driver, Rig, planar_pose, put_object
from .world import Layout, build as build_world

Settings = Contact  # kept for callers of the first version


def _spec(scene: Scene, pusher: str, contact: Contact):
    """The object at the origin held by pads fixed in the world, the pusher's feature on a driven
    body whose frame is the pusher frame."""
    return build_world(Layout(scene, np.zeros(3), "fixed", pushers=(pusher,), features="driven",
                              name=f"{scene.name}-push-{pusher}"), contact)


class PushRig(Rig):
    """A reusable MuJoCo model of one pusher of a scene (reset for each push)."""

    def __init__(self, scene: Scene, pusher: str, contact: Contact = Contact()):
        super().__init__(_spec(scene, pusher, contact), contact, scene.grip_force)
        self.scene, self.pusher = scene, pusher
        self.driver = Driver(self.model, f"feature_{pusher}")

    def reset(self, pose):
        """Resets the simulation with the object at ``pose`` ``[x, z, theta]`` (m, m, rad)."""
        mujoco = need("mujoco", "mujoco")

        mujoco.mj_resetData(self.model, self.data)
        put_object(self.model, self.data, pose)
        self.data.ctrl[:] = self.grip_force
        self.driver.set(self.data, pose)
        self.forward()

    def push(self, pose, twist, duration: float, settle: float = 0.1, record_dt: float = 0.02) -> dict:
        """The pusher starts in contact at the object's ``pose`` (m, m, rad) and moves with constant
        body ``twist`` (m/s, m/s, rad/s) for ``duration`` [s], recorded every ``record_dt`` [s];
        returns times, object poses (gripper frame) and pusher poses."""
        self.reset(pose)
        dt = self.dt
        m, d = self.model, self.data
        q0 = np.asarray(pose, float)
        for _ in range(int(round(settle / dt))):
            self.driver.move(d, q0, dt)
            self.step()
        every = max(1, int(round(record_dt / dt)))
        t, poses, pushers = [0.0], [planar_pose(m, d, "object")], [q0]
        n = int(round(duration / dt))
        for k in range(1, n + 1):
            qp = integrate_pose(q0, twist, k * dt)
            self.driver.move(d, qp, dt)
            self.step()
            if k % every == 0 or k == n:
                t.append(k * dt)
                poses.append(planar_pose(m, d, "object"))
                pushers.append(qp)
        return {"t": np.array(t), "pose": np.array(poses), "pusher_pose": np.array(pushers)}

    def slip_fraction(self, pose, twist, distance: float = 0.003, speed: float = 0.01) -> float:
        """:func:`slip_fraction` of a push of ``twist`` (m/s, m/s, rad/s) from ``pose`` (m, m, rad)
        in this rig."""
        return slip_fraction(self.scene, self.pusher, self.push, pose, twist, distance, speed)

    def sticks(self, pose, twist, distance: float = 0.003, speed: float = 0.01, ratio: float = 0.02) -> bool:
        """Whether the pusher and the object move together over a short push of ``twist``
        (m/s, m/s, rad/s) from ``pose`` (m, m, rad): they move apart at
        the contact by less than ``ratio`` of the push (:meth:`slip_fraction`; soft contacts creep
        by about 1% of a push when the pusher sticks)."""
        return sticks(self.slip_fraction(pose, twist, distance, speed), ratio)


def sticks(slip: float, ratio: float = 0.02) -> bool:
    """Whether a push whose :func:`slip_fraction` is ``slip`` sticks: below ``ratio``; a
    FloatingPointError when the engine diverged (a non-finite slip)."""
    if not np.isfinite(slip):
        raise FloatingPointError("the push diverged (non-finite poses)")
    return slip < ratio


def slip_fraction(scene: Scene, pusher: str, push, pose, twist, distance: float = 0.003, speed: float = 0.01) -> float:
    """How far the pusher and the object move apart at the contact over a short push of
    ``twist`` (m/s, m/s, rad/s) from ``pose`` (m, m, rad) at ``speed`` [m/s] over ``distance``
    [m], as a share of the push, in an engine's ``push(pose, twist, duration, record_dt=...)``
    (times, object and pusher poses: :meth:`PushRig.push`, the Drake rig's): for a line pusher,
    the largest motion of the object relative to the pusher at either end of the line — its
    slide along the contact and its lift-off (a roll about the other end), pressing in by the
    soft contact's compliance left out; for a point pusher, the slide of its contact on the
    object (the object may turn about it)."""
    tw = np.asarray(twist, float)
    norm = float(np.linalg.norm(scene.metric_twist(tw)))
    tw = tw / norm * speed
    pts = scene.pusher(pusher).points
    if len(pts) == 1:
        return _point_slip(scene, pusher, push, pose, tw, distance, speed, pts[0])
    r = push(pose, tw, distance / speed, record_dt=distance / speed)
    rel0 = planar_compose(planar_inverse(r["pusher_pose"][0]), r["pose"][0])
    rel1 = planar_compose(planar_inverse(r["pusher_pose"][-1]), r["pose"][-1])
    n = scene.pusher(pusher).normal
    n = n / np.linalg.norm(n)
    t = np.array([-n[1], n[0]])
    worst = 0.0
    for c in pts:
        # the object's material point at contact point c, seen from the pusher, before and
        # after: its slide along the contact, and how far it lifted off the pusher (pressing
        # further in is the soft contact's compliance, not a slip)
        d = planar_compose(rel1, np.r_[c, 0.0])[:2] - planar_compose(rel0, np.r_[c, 0.0])[:2]
        worst = max(worst, float(np.hypot(d @ t, max(0.0, d @ n))))
    return worst / distance


def _point_slip(scene: Scene, pusher: str, push, pose, twist, distance, speed, c) -> float:
    """A point pusher sticks when its contact does not slide on the object (the object may
    turn about it, rolling on the feature's small cylinder): the tangential slide at the
    contact, integrated over the push (every 2.5 ms)."""
    n = scene.pusher(pusher).normal
    n = n / np.linalg.norm(n)
    r = push(pose, twist, distance / speed, record_dt=0.0025)
    centre = np.r_[c - FEATURE_RADIUS * n, 0.0]
    slide = 0.0
    for k in range(len(r["t"]) - 1):
        q0, q1 = r["pose"][k], r["pose"][k + 1]
        p0, p1 = r["pusher_pose"][k], r["pusher_pose"][k + 1]
        nw = planar_rotate(q0[2], n)
        x = planar_compose(p0, centre)[:2] + FEATURE_RADIUS * nw  # the contact point (world)
        mo = planar_compose(planar_inverse(q0), np.r_[x, 0.0])  # material points there
        mp = planar_compose(planar_inverse(p0), np.r_[x, 0.0])
        d = (planar_compose(q1, mo)[:2] - x) - (planar_compose(p1, mp)[:2] - x)
        slide += abs(d[0] * nw[1] - d[1] * nw[0])
    return float(slide / distance)


def simulate_push(scene: Scene, pose, pusher: str, twist, duration: float, record_dt: float = 0.02,
                  settings: Contact = Contact()) -> dict:
    """A push in MuJoCo: the pads squeeze for 0.3 s, then the pusher moves with constant body
    ``twist`` (m/s, m/s, rad/s; object frame at the start) from ``pose`` (m, m, rad) for ``duration``
    [s], recorded every ``record_dt`` [s]. Returns times and object poses (gripper frame)."""
    pose, twist, pusher = check_vector(pose, 3, "pose"), check_vector(twist, 3, "twist"), check_name(pusher, "pusher")
    duration = check_number(duration, "duration", high=MAX_DURATION)
    record_dt = check_number(record_dt, "record_dt", high=MAX_DURATION)
    rig = PushRig(scene, pusher, settings)
    r = rig.push(pose, twist, duration, settle=0.3, record_dt=record_dt)
    return {"t": r["t"], "pose": r["pose"], "settled_pose": r["pose"][0]}
