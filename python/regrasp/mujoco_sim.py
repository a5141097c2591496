"""Independent check in MuJoCo (the real engine): a planar scene as an MJCF model, and pushes
executed in it.

The model is the planner's view (gripper fixed, virtual pusher moving): two finger pads on
slide joints squeeze the object with the scene's grip force (force actuators, not a position
clamp); the pusher is a kinematic (mocap) body; gravity has the scene's direction. Contact
settings make a grasp hold when it should: elliptic friction cones, ``impratio`` and the
no-slip solver (soft contact alone lets a pinched object creep, mujoco issue #3328); the pads'
torsional friction coefficient is ``k μ_s`` with ``k = 0.6 r``, so that MuJoCo's elliptic cone
of a pad contact is the scene's ellipsoidal limit surface.

This first version handles rectangular outlines (boxes); general outlines come with the
execution module.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .errors import ArgumentError
from .scene import Scene

THICKNESS = 0.012  # m, object thickness along the grasp axis
PAD_DEPTH = 0.004  # m, pad cylinder height


@dataclass
class Settings:
    timestep: float = 5e-4
    impratio: float = 20.0
    noslip_iterations: int = 20
    cone: str = "elliptic"
    settle: float = 0.3  # s before the push


def _box(scene: Scene):
    o = scene.outline
    lo, hi = o.min(axis=0), o.max(axis=0)
    corners = {(lo[0], lo[1]), (hi[0], lo[1]), (hi[0], hi[1]), (lo[0], hi[1])}
    if len(o) != 4 or {tuple(p) for p in o} != corners:
        raise ArgumentError("invalid `scene`: the MuJoCo model handles rectangular outlines only", "object.outline")
    return lo, hi


def _quat_y(theta: float) -> np.ndarray:
    """Quaternion of the planar angle theta (CCW in the X-Z drawing = rotation by −theta about +Y)."""
    return np.array([np.cos(-theta / 2), 0.0, np.sin(-theta / 2), 0.0])


def mjcf(scene: Scene, pose, pusher: str, settings: Settings = Settings()) -> str:
    """MJCF of the scene with the object at ``pose`` and ``pusher`` in contact."""
    if scene.kind != "grasp" or scene.pad is None or scene.pad[0] != "circle":
        raise ArgumentError("invalid `scene`: the MuJoCo model needs a grasp with circular pads", "grasp")
    lo, hi = _box(scene)
    mu_s = scene._core.friction_scale / (2 * scene.grip_force)
    r = scene.pad[1]
    k = 0.6 * r
    gdir, g = scene.gravity
    p = scene.pusher(pusher)
    c = (lo + hi) / 2
    half = (hi - lo) / 2
    q = np.asarray(pose, float)
    R = np.array([[np.cos(q[2]), -np.sin(q[2])], [np.sin(q[2]), np.cos(q[2])]])
    pos = R @ c + q[:2]
    quat = _quat_y(q[2])
    # pusher geometry in its own frame (= object frame at the start): a thin plate behind the
    # contact line, or a small sphere for a point pusher
    n = p.normal / np.linalg.norm(p.normal)
    if len(p.points) == 2:
        mid = p.points.mean(axis=0) - n * 0.003
        length = np.linalg.norm(p.points[1] - p.points[0]) / 2
        ang = np.arctan2(n[1], n[0])
        pusher_geom = (f'<geom type="box" size="0.003 0.01 {length:.6f}" pos="{mid[0]:.6f} 0 {mid[1]:.6f}" '
                       f'quat="{" ".join(f"{x:.8f}" for x in _quat_y(ang))}" friction="{p.friction} 0 0" '
                       f'condim="3"/>')
    else:
        ctr = p.points[0] - n * 0.002
        pusher_geom = (f'<geom type="sphere" size="0.002" pos="{ctr[0]:.6f} 0 {ctr[1]:.6f}" '
                       f'friction="{p.friction} 0 0" condim="3"/>')
    m = scene.mass
    Ic = m * scene.length**2  # planar moment of inertia about the COM
    y_pad = THICKNESS / 2 + PAD_DEPTH / 2
    return f"""<mujoco model="{scene.name}">
  <option timestep="{settings.timestep}" gravity="{gdir[0] * g} 0 {gdir[1] * g}" cone="{settings.cone}"
          impratio="{settings.impratio}" noslip_iterations="{settings.noslip_iterations}"/>
  <default><geom solref="0.002 1" solimp="0.95 0.99 0.0005"/></default>
  <worldbody>
    <body name="object" pos="{pos[0]:.6f} 0 {pos[1]:.6f}" quat="{' '.join(f'{x:.8f}' for x in quat)}">
      <freejoint/>
      <inertial pos="{scene.com[0] - c[0]:.6f} 0 {scene.com[1] - c[1]:.6f}" mass="{m}"
                diaginertia="{Ic} {Ic} {Ic}"/>
      <geom name="object" type="box" size="{half[0]:.6f} {THICKNESS / 2} {half[1]:.6f}" friction="0 0 0" condim="4"/>
    </body>
    <body name="pad_left" pos="0 {y_pad} 0">
      <joint name="pad_left" type="slide" axis="0 1 0" damping="20"/>
      <geom type="cylinder" size="{r} {PAD_DEPTH / 2}" euler="90 0 0" mass="0.05" friction="{mu_s} {k * mu_s} 0" condim="4"/>
    </body>
    <body name="pad_right" pos="0 {-y_pad} 0">
      <joint name="pad_right" type="slide" axis="0 1 0" damping="20"/>
      <geom type="cylinder" size="{r} {PAD_DEPTH / 2}" euler="90 0 0" mass="0.05" friction="{mu_s} {k * mu_s} 0" condim="4"/>
    </body>
    <body name="pusher" mocap="true" pos="{q[0]:.6f} 0 {q[1]:.6f}" quat="{' '.join(f'{x:.8f}' for x in quat)}">
      {pusher_geom}
    </body>
  </worldbody>
  <actuator>
    <motor joint="pad_left" gear="-1" ctrllimited="false"/>
    <motor joint="pad_right" gear="1" ctrllimited="false"/>
  </actuator>
</mujoco>"""


def object_pose(scene: Scene, model, data) -> np.ndarray:
    """Object pose [x, z, theta] in the gripper frame (object frame, not the box centre)."""
    import mujoco

    bid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "object")
    R = data.xmat[bid].reshape(3, 3)
    theta = np.arctan2(R[2, 0], R[0, 0])
    lo, hi = _box(scene)
    c = (lo + hi) / 2
    R2 = np.array([[np.cos(theta), -np.sin(theta)], [np.sin(theta), np.cos(theta)]])
    pos = np.array([data.xpos[bid][0], data.xpos[bid][2]]) - R2 @ c
    return np.array([pos[0], pos[1], theta])


def simulate_push(scene: Scene, pose, pusher: str, twist, duration: float, record_dt: float = 0.02,
                  settings: Settings = Settings()) -> dict:
    """Executes a push in MuJoCo: the pads squeeze for ``settings.settle`` s, then the pusher
    moves with constant body ``twist`` (object frame at the start). Returns times and object
    poses in the gripper frame (time 0 = start of the push)."""
    import mujoco

    from .quasistatic import integrate_pose

    model = mujoco.MjModel.from_xml_string(mjcf(scene, pose, pusher, settings))
    data = mujoco.MjData(model)
    data.ctrl[:] = scene.grip_force
    mujoco.mj_forward(model, data)
    steps_settle = int(round(settings.settle / settings.timestep))
    for _ in range(steps_settle):
        mujoco.mj_step(model, data)
    start = object_pose(scene, model, data)
    qp = np.asarray(pose, float)
    u = np.asarray(twist, float)
    t, poses = [0.0], [start]
    n = int(round(duration / settings.timestep))
    every = max(1, int(round(record_dt / settings.timestep)))
    for k in range(1, n + 1):
        qk = integrate_pose(qp, u, k * settings.timestep)
        data.mocap_pos[0] = [qk[0], 0.0, qk[1]]
        data.mocap_quat[0] = _quat_y(qk[2])
        mujoco.mj_step(model, data)
        if k % every == 0:
            t.append(k * settings.timestep)
            poses.append(object_pose(scene, model, data))
    return {"t": np.array(t), "pose": np.array(poses), "settled_pose": start}
