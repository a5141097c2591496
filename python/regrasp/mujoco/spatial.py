"""3-D plans executed in MuJoCo (:func:`execute_plan3d`), in the world's view (``view="world"``,
the default and what `regrasp simulate SCENE_3D --engine mujoco` runs: features fixed where each
push needs them, the gripper — a driven 6-DoF body carrying the pads — moving with the inverse of
the virtual pusher's motion) or in the planner's view (``view="planner"``: the pads fixed, each
pusher's feature on a driven 6-DoF body that follows the plan's pusher motion).

Gravity: the scene's gravity is given in the gripper frame, and the world's view keeps it there
(MuJoCo's gravity is the scene's vector, the gripper starts at the identity): as the gripper
turns with the inverse pusher motion, gravity in MuJoCo does not turn with it, while the planner
assumed it fixed in the gripper frame. The bundled examples turn the gripper by at most their
regrasp angle and execute within tolerance in both views (`docs/execution3d.py` prints both); a
plan with large gripper rotations should be executed in the planner's view.

The model (:func:`build`, a ``mujoco.MjSpec`` from the pieces of ``regrasp.mujoco.model``; the
execution itself is :class:`SpatialExecution`): the object, a sphere or the scene's convex mesh,
with its mass, centre of mass and inertia. The pads:
as in the planar model (``regrasp.mujoco.model``), one contact point each through a large sphere
on a slide joint along Y, squeezed by a force actuator, with sliding friction ``μ_s`` and
torsional friction ``(2/3) r μ_s`` (the pad's ring of points at 2/3 of its radius in the
quasi-static model). Features: a 1.5 mm sphere behind a point pusher, a capsule behind a line
pusher, a thin plate behind a patch. A push with a new pusher brings its feature 2 mm behind
where it meets the object (where the object is), approaches until it touches, then moves with
the plan's pusher twist of each step over unit time (the step's `pusher_twist`, else the twist
between the poses). Same contact settings as the planar model (elliptic cones, impratio, no-slip).
"""

from __future__ import annotations

import numpy as np

from .. import progress
from ..errors import ArgumentError
from ..pose import compose, integrate, inverse, tangents, twist_between
from .model import Contact, Driver, Rig, plan_dict
from .spatial_parts import (PAD_BALL, PARK, PLANE_HALF, R_FEATURE, _quat, _shift,  # noqa: F401 (their home
                            add_feature_geoms, add_object3d, add_pads3d)  # noqa: F401 until 0.2)

GAP = 0.002
IDENTITY = np.r_[0.0, 0, 0, 1, 0, 0, 0]


def plane_frame(scene, name: str, pose) -> np.ndarray:
    """For a plane pusher brought against the object at ``pose`` (m, unit quaternion): the pose, in the pusher's frame
    (the object frame then), of the plane's own frame (origin at the contact, +Z its normal)."""
    pts, n, _ = scene.pusher_spec(name, pose)
    n = np.asarray(n, float) / np.linalg.norm(n)
    return np.r_[np.asarray(pts, float).mean(axis=0), _quat(*tangents(n), n)]


def build(scene, start, friction_scale: float = 1.0, grip_scale: float = 1.0, mass_scale: float = 1.0,
          contact: Contact = Contact(), pad: str = "point", world: bool = False, feature_scale: float | None = None):
    """The model of a 3-D execution, a ``mujoco.MjSpec`` (``.compile()`` it; ``.to_xml()`` is its
    MJCF): planner's view (pads fixed, features on driven 6-DoF bodies) or, with ``world``, the
    world's view (the pads on a driven 6-DoF gripper, features fixed where they are put: mocap
    bodies). ``grip_scale`` is the controls' (:class:`SpatialExecution`), not the model's;
    ``feature_scale``: the features' friction factor (None: ``friction_scale``, the pads')."""
    from ..scene.perturbation import Perturbation
    from .world import Layout, build as build_world

    fs = friction_scale if feature_scale is None else feature_scale
    return build_world(Layout(scene, np.asarray(start, float), "gripper" if world else "fixed",
                              pushers=tuple(scene.pusher_names), features="parked" if world else "driven",
                              perturbation=Perturbation(friction_scale, 1.0, mass_scale, fs), pad=pad), contact)


def _check_options(pad: str, view: str):
    if pad not in ("point", "ring"):
        raise ArgumentError(f"invalid `pad`: 'point' or 'ring' (got {pad!r})", "pad")
    if view not in ("world", "planner"):
        raise ArgumentError(f"invalid `view`: 'world' or 'planner' (got {view!r})", "view")


class SpatialExecution(Rig):
    """A 3-D plan executed in MuJoCo step by step (see :func:`execute_plan3d`): the model, the
    gripper's driver (world's view) or the features' drivers (planner's view), the feature in use
    (its pusher, its pose :attr:`P` in the grasp and its normal :attr:`n` in the object frame) and
    where it is fixed in the world's view (:attr:`F`)."""

    def __init__(self, scene, start, friction_scale: float = 1.0, grip_scale: float = 1.0, mass_scale: float = 1.0,
                 contact: Contact = Contact(), pad: str = "point", view: str = "world", feature_scale: float | None = None):
        _check_options(pad, view)
        self.scene, self.view, self.world = scene, view, view == "world"
        spec = build(scene, start, friction_scale, grip_scale, mass_scale, contact, pad, world=self.world,
                     feature_scale=feature_scale)
        super().__init__(spec, contact, scene.grip_force * grip_scale)
        self.gripper = Driver(self.model, "gripper") if self.world else None
        self.drivers = {} if self.world else {p: Driver(self.model, f"feature_{p}") for p in scene.pusher_names}
        if self.world:
            self.gripper.set(self.data, IDENTITY)
        for i, d in enumerate(self.drivers.values()):
            d.set(self.data, np.r_[PARK + [0.1 * i, 0, 0], 1, 0, 0, 0])
        self.forward()
        self.obj = self.model.body("object").id
        self.creep = 0.005 * self.dt  # approach and back-off at 5 mm/s
        self.pusher, self.P, self.n, self.F = None, None, None, None
        # the feature body's pose in the pusher's frame: identity for rigid pushers (built in the
        # object frame), the plane's frame for planes (set when the plane is brought)
        self.T = IDENTITY

    def in_grasp(self) -> np.ndarray:
        """The object's pose in the grasp (the gripper frame)."""
        G = self.gripper.pose if self.world else IDENTITY
        return compose(inverse(G), np.r_[self.data.xpos[self.obj], self.data.xquat[self.obj]])

    def place(self, P):
        """One time step with the feature in use at pose ``P`` in the grasp (None: nothing moves)."""
        if self.world:
            self.gripper.move(self.data, self.gripper.pose if P is None else compose(self.F, inverse(P)), self.dt)
        for p, d in self.drivers.items():
            d.move(self.data, compose(P, self.T) if p == self.pusher and P is not None else d.pose, self.dt)
        self.step()

    def put(self, p: str, P) -> set:
        """Puts pusher ``p``'s feature at ``P`` in the grasp (where it stays, in the world's view);
        returns its geoms."""
        self.T = plane_frame(self.scene, p, self.in_grasp()) if self.scene.is_plane(p) else IDENTITY
        if self.world:
            self.F = compose(self.gripper.pose, P)
            F = compose(self.F, self.T)
            m = self.mocap(f"feature_{p}")
            self.data.mocap_pos[m], self.data.mocap_quat[m] = F[:3], F[3:]
        else:
            self.drivers[p].set(self.data, compose(P, self.T))
        self.pusher = p
        self.forward()
        return self.geoms(f"feature_{p}")

    def park(self, p: str):
        """Moves pusher ``p``'s feature out of the way (far from the object)."""
        if self.world:
            self.data.mocap_pos[self.mocap(f"feature_{p}")] = PARK
        else:
            self.drivers[p].set(self.data, np.r_[PARK, 1, 0, 0, 0])

    def settle(self, duration: float):
        """Lets the object settle in the grasp for ``duration`` [s], no pusher in contact."""
        for _ in range(int(duration / self.dt)):
            self.place(None)

    def back_off(self):
        """Moves the feature in use the gap back along its normal, then parks it (a switch-over)."""
        P0 = self.P.copy()
        for k in range(1, int(GAP / self.creep) + 1):
            self.P = compose(P0, _shift(-self.n * self.creep * k))
            self.place(self.P)
        self.park(self.pusher)

    def approach(self, p: str):
        """Brings pusher ``p``'s feature (the one in use backs off first): the gap back from where
        it meets the object (as the object is now), then closer until it touches (at most 3
        gaps)."""
        if self.pusher is not None:
            self.back_off()
        _, n, _ = self.scene.pusher_spec(p, self.in_grasp())
        self.n = np.asarray(n, float) / np.linalg.norm(n)
        self.P = compose(self.in_grasp(), _shift(-GAP * self.n))
        ids = self.put(p, self.P)
        for _ in range(int(3 * GAP / self.creep)):
            if self.touching(ids):
                break
            self.P = compose(self.P, _shift(self.n * self.creep))
            self.place(self.P)

    def push(self, a: dict, b: dict) -> np.ndarray:
        """One step of the plan, from path entry ``a`` to ``b``: brings b's pusher if it is a new
        one, then moves it with the step's pusher twist over unit time. Returns the object's
        measured pose in the grasp."""
        p = b["pusher"]
        if self.pusher != p:
            self.approach(p)
        u = b.get("pusher_twist")
        u = np.asarray(twist_between(a["pose"], b["pose"]) if u is None else u, float)
        # the step's twist is the pusher's body twist in the object's frame at the step's start
        # (where the planner and the quasi-static replay put the pusher); the feature, wherever
        # it is now (offset D from that frame), makes the same rigid motion: P(t) = A exp(ut) D
        # (a plane: the planned frame, so it makes its planned motion in the gripper frame and
        # stays level whatever the object's measured pose)
        A = np.asarray(a["pose"], float) if self.scene.is_plane(p) else self.in_grasp()
        D = compose(inverse(A), self.P)
        n = int(round(1.0 / self.dt))
        for k in range(1, n + 1):
            self.P = compose(A, compose(integrate(IDENTITY, u, k / n), D))
            self.place(self.P)
        return self.in_grasp()

    def run(self, path: list, settle: float = 0.2, feedback: bool = False, max_replans: int = 10,
            seed: int = 0) -> dict:
        """Holds the object for ``settle`` [s], then executes ``path`` step by step (re-planning
        from the measured pose with ``feedback``, see :func:`execute_plan3d`)."""
        from ..scene.spatial import goal_report, run_plan3d

        self.settle(settle)
        with progress.bar(len(path) - 1, "MuJoCo execution", unit="step") as bar:
            def push(a: dict, b: dict) -> np.ndarray:
                q = self.push(a, b)
                bar.update(1)
                return q

            q, poses, replans = run_plan3d(self.scene, path, push, self.in_grasp(), feedback, max_replans, seed)
        return {"engine": "mujoco", "view": self.view, **goal_report(self.scene, q), "poses": np.array(poses),
                "replans": replans}


def execute_plan3d(scene, plan, friction_scale: float = 1.0, grip_scale: float = 1.0, mass_scale: float = 1.0,
                   contact: Contact = Contact(), settle: float = 0.2, pad: str = "point", view: str = "world",
                   feedback: bool = False, max_replans: int = 10, seed: int = 0, feature_scale: float | None = None) -> dict:
    """Executes a 3-D plan (a ``regrasp.Plan`` or its dict) in MuJoCo; returns the final pose, the
    error to the goal (position, angle), success, the object's pose in the grasp after each step
    and the re-plans made.

    ``feedback``: closed loop by re-planning — after each step the object's pose is measured; when
    it is off the plan by more than half the goal tolerance (position or angle), or the plan ends
    outside the tolerance, the T-RRT* plans again from the measured pose (at most
    ``max_replans`` times) and execution goes on with the new plan.

    ``view="world"``: each push's feature is fixed where the push needs it (2 mm back, then the
    gripper approaches until it touches), the gripper moves with the inverse of the virtual
    pusher's motion and backs off 2 mm before a switch-over. ``view="planner"``: the pads fixed,
    the feature (on a driven body) follows the virtual pusher's motion. Either way the feature's
    pose in the grasp, ``P``, follows the plan's pusher twists (each a body twist in the object's
    frame at the step's start, as the planner and the quasi-static replay apply it); only what
    moves differs."""
    from ..scene.spatial import check_plan3d

    _check_options(pad, view)
    path = check_plan3d(scene, plan_dict(plan))
    ex = SpatialExecution(scene, path[0]["pose"], friction_scale, grip_scale, mass_scale, contact, pad, view, feature_scale)
    return ex.run(path, settle, feedback, max_replans, seed)
