"""Pushes in Drake in the planner's view (gripper fixed, the virtual pusher moving): a second
engine that shares none of our contact model, for the validation of motion cones
(``regrasp validate --engines ...,drake``) and plan replays (``regrasp simulate --engine drake``).

The model (a ``MultibodyPlant``, discrete, SAP's "similar" approximation; settings pinned in
:data:`SETTINGS`): the object extruded from its outline (:data:`~regrasp.mujoco.model.THICKNESS`
thick along the grasp axis Y, convex pieces) on a planar joint in the gripper's X-Z plane, rigid
hydroelastic; the two pads, compliant hydroelastic prisms of the scene's pad shape
(:data:`PAD_MODULUS`, :data:`PAD_DEPTH`: pressed flat, a pad presses nearly uniformly), each on
a prismatic joint along Y squeezed by the grip force; the pusher's feature (a plate behind a line
pusher's points, a thin cylinder for a point pusher, as the MuJoCo rig's; compliant
hydroelastic, :data:`FEATURE_MODULUS`) on a body driven through X, Z and the turn about −Y by
stiff PD actuators.
Drake's friction is the pads' and the pusher's coefficients (Drake combines two bodies'
coefficients as 2ab/(a+b): the object's is 1 and the others' chosen so that each pair's is the
scene's). Nothing here reads the scene's limit surface, motion cones or pad model: only its
geometry, masses, gravity, friction coefficients and grip force.

Drake's defaults are not used where they mislead: its near-rigid regularisation (SAP's
``near_rigid_threshold``) let light pads sink 0.9 mm into the block and hold it by pressure on the
side walls; it is off here (0). The plain "sap" approximation lets sticking contacts creep (1-3 %
of a 3 mm push inside the motion cone on block-low-friction, against 0.1-0.6 % in MuJoCo);
"similar" creeps a third as much at the same cost. A rigid feature (Drake's point contact with
a rigid object) sank 1 mm into the object at 15 N: the feature is compliant hydroelastic."""

from __future__ import annotations

import numpy as np

from ..extras import need
from ..pose import integrate_pose
from ..scene.planar import Scene

#: The plant's pinned settings: time step [s], contact model, SAP's near-rigid threshold.
SETTINGS = {"time_step": 1e-3, "contact_model": "hydroelastic_with_fallback", "near_rigid_threshold": 0.0,
            "discrete_contact_approximation": "similar"}
#: The pads' hydroelastic modulus [Pa] (a stiff rubber), depth [m] along Y and mesh resolution [m]:
#: a pad deeper than its penetration presses nearly uniformly (the pressure rises with the depth
#: from its face, alike across it but within the penetration of its rim).
PAD_MODULUS = 5e6
PAD_DEPTH = 0.01
PAD_RESOLUTION = 0.001
#: The pusher's feature: compliant hydroelastic too, its modulus [Pa] (a hard plastic; at 5e7 the
#: line contact gave way by 25 µm at one end and lifted 90 µm at the other under the pads' torque,
#: 2-3 % of a push that sticks in MuJoCo and in the cones).
FEATURE_MODULUS = 5e8
#: The pads' and the pusher's Hunt–Crossley dissipation [s/m]; the point-contact stiffness
#: [N/m] where Drake falls back to point contact (none here: every contact has a compliant side).
DISSIPATION = 5.0
POINT_STIFFNESS = 1e6
#: The pads' mass [kg] and their joints' damping [N·s/m]; the driven pusher's mass [kg] and PD
#: gains (per metre or radian) of its three joints.
PAD_MASS, PAD_DAMPING = 0.05, 20.0
PUSHER_MASS, PUSHER_KP, PUSHER_KD = 10.0, 1e7, 1e5
#: the longest push simulated [s] (a bound on its time)
MAX_DURATION = 60.0
#: Where a feature not in use waits (planar pose, m, m, rad): far from the object and the pads.
PARK = (1.0, 1.0, 0.0)


def _pair_friction(mu: float, other: float = 1.0) -> float:
    """The coefficient that, combined by Drake's 2ab/(a+b) with ``other``, gives ``mu``."""
    return mu * other / (2 * other - mu)


class DrakeRig:
    """A Drake model of a planar grasp scene in the planner's view (see the module's doc): the
    object, the pads and one driven feature per pusher in ``pushers`` (parked at :data:`PARK`
    until brought), in a world perturbed by ``perturb`` (its factors on the pads' friction, the
    grip force, the object's mass and the features' friction)."""

    def __init__(self, scene: Scene, pushers, perturb=None):
        from ..errors import ArgumentError
        from ..scene.perturbation import Perturbation

        need("pydrake", "drake")
        if not isinstance(scene, Scene):
            raise ArgumentError(f"invalid `scene`: Drake runs planar scenes (got {type(scene).__name__})", "scene")
        if perturb is not None and not isinstance(perturb, Perturbation):
            raise ArgumentError(f"invalid `perturb`: a regrasp.Perturbation (got {type(perturb).__name__})", "perturb")
        if scene.kind != "grasp":
            raise ArgumentError("invalid `scene`: the Drake model needs a grasp (not an object on a surface)", "scene")
        self.perturb = Perturbation() if perturb is None else perturb
        self.pushers = tuple(pushers)
        mus = [scene.pad_friction * self.perturb.finger_friction] + [
            scene.pusher(p).friction * self.perturb.feature_friction for p in self.pushers]
        if max(mus) >= 2.0:
            raise ArgumentError("invalid `scene`: Drake's friction model takes coefficients below 2 here", "scene")
        self.scene = scene
        self._build()

    def _build(self) -> None:
        from pydrake.all import (AddMultibodyPlant, CollisionFilterDeclaration, DiagramBuilder, FixedOffsetFrame,
                                 GeometrySet, MultibodyPlantConfig, PlanarJoint, PrismaticJoint, RigidTransform,
                                 RotationalInertia, RotationMatrix, Simulator, SpatialInertia)
        from ..mujoco.model import THICKNESS

        s = self.scene
        builder = DiagramBuilder()
        cfg = MultibodyPlantConfig(time_step=SETTINGS["time_step"], contact_model=SETTINGS["contact_model"],
                                   discrete_contact_approximation=SETTINGS["discrete_contact_approximation"],
                                   sap_near_rigid_threshold=SETTINGS["near_rigid_threshold"])
        plant, scene_graph = AddMultibodyPlant(cfg, builder)
        gdir, g = s.gravity
        plant.mutable_gravity_field().set_gravity_vector([gdir[0] * g, 0.0, gdir[1] * g])
        # the plane: F's x along X, y along Z, z along −Y (a planar angle about −Y is θ)
        X_F = RigidTransform(RotationMatrix(np.array([[1.0, 0, 0], [0, 0, -1.0], [0, 1.0, 0]])), [0.0, 0.0, 0.0])
        obj = plant.AddModelInstance("object")
        L, m = s.length, s.mass * self.perturb.mass
        com = np.array([s.com[0], 0.0, s.com[1]])
        side = m * (L**2 / 2 + THICKNESS**2 / 12)
        # a lamina extruded along Y: I_yy = m L² about the centre of mass, as the MuJoCo rig's
        body = plant.AddRigidBody("object", obj, SpatialInertia.MakeFromCentralInertia(
            m, com, RotationalInertia(side, m * L**2, side)))
        F_w = plant.AddFrame(FixedOffsetFrame("F_world", plant.world_frame(), X_F))
        F_o = plant.AddFrame(FixedOffsetFrame("F_object", body.body_frame(), X_F))
        self._object = plant.AddJoint(PlanarJoint("object", F_w, F_o, np.zeros(3)))
        self._object_geometry(plant, body, THICKNESS)
        # pads on prismatic joints along Y, squeezed by actuators
        pads = plant.AddModelInstance("pads")
        self._pads = []
        for name, sign in (("pad_left", 1.0), ("pad_right", -1.0)):
            pb = plant.AddRigidBody(name, pads, SpatialInertia.SolidBoxWithMass(PAD_MASS, 0.01, PAD_DEPTH, 0.01))
            j = plant.AddJoint(PrismaticJoint(name, plant.world_frame(), pb.body_frame(), [0.0, 1.0, 0.0],
                                              damping=PAD_DAMPING))
            j.set_default_translation(sign * (THICKNESS / 2 + PAD_DEPTH / 2))
            plant.AddJointActuator(name, j)
            self._pad_geometry(plant, pb)
            self._pads.append((j, sign))
        plant.set_gravity_enabled(pads, False)
        drv = plant.AddModelInstance("features")
        self._features = {p: self._driven(plant, drv, p) for p in self.pushers}
        plant.set_gravity_enabled(drv, False)
        plant.Finalize()
        # a feature touches only the object (as in MuJoCo): never the pads
        ids = lambda bodies: GeometrySet([g for b in bodies for g in plant.GetCollisionGeometriesForBody(b)])  # noqa: E731
        features = [plant.GetBodyByName(f"feature_{p}") for p in self.pushers]
        pad_bodies = [plant.GetBodyByName(n) for n in ("pad_left", "pad_right")]
        scene_graph.collision_filter_manager().Apply(
            CollisionFilterDeclaration().ExcludeBetween(ids(pad_bodies), ids(features)))
        builder.ExportInput(plant.get_desired_state_input_port(drv), "features_state")
        builder.ExportInput(plant.get_actuation_input_port(pads), "grip")
        builder.ExportInput(plant.get_actuation_input_port(drv), "features_ff")
        self.plant, self.diagram = plant, builder.Build()
        self.simulator = Simulator(self.diagram)
        self.context = self.simulator.get_mutable_context()
        self.plant_context = plant.GetMyMutableContextFromRoot(self.context)
        self._targets = {p: np.array(PARK, float) for p in self.pushers}

    def _driven(self, plant, instance, pusher: str) -> tuple:
        """A feature's body, driven through X, Z and the turn about −Y by PD actuators; its joints."""
        from pydrake.all import PdControllerGains, PrismaticJoint, RevoluteJoint, SpatialInertia

        light = SpatialInertia.SolidBoxWithMass(1e-3 * PUSHER_MASS, 0.01, 0.01, 0.01)
        bx = plant.AddRigidBody(f"{pusher}_x", instance, light)
        bz = plant.AddRigidBody(f"{pusher}_z", instance, light)
        bf = plant.AddRigidBody(f"feature_{pusher}", instance,
                                SpatialInertia.SolidBoxWithMass(PUSHER_MASS, 0.05, 0.05, 0.05))
        joints = (plant.AddJoint(PrismaticJoint(f"{pusher}_x", plant.world_frame(), bx.body_frame(), [1.0, 0.0, 0.0])),
                  plant.AddJoint(PrismaticJoint(f"{pusher}_z", bx.body_frame(), bz.body_frame(), [0.0, 0.0, 1.0])),
                  plant.AddJoint(RevoluteJoint(f"{pusher}_th", bz.body_frame(), bf.body_frame(), [0.0, -1.0, 0.0])))
        joints[0].set_default_translation(PARK[0])
        joints[1].set_default_translation(PARK[1])
        for j in joints:
            plant.AddJointActuator(j.name(), j).set_controller_gains(PdControllerGains(p=PUSHER_KP, d=PUSHER_KD))
        self._feature_geometry(plant, bf, pusher)
        return joints

    def _object_geometry(self, plant, body, thickness: float) -> None:
        from pydrake.all import (AddRigidHydroelasticProperties, AddContactMaterial, Box, CoulombFriction,
                                 ProximityProperties, RigidTransform)
        from ..mujoco.model import _is_rectangle, convex_pieces

        props = ProximityProperties()
        AddRigidHydroelasticProperties(1e-3, props)
        AddContactMaterial(DISSIPATION, POINT_STIFFNESS, CoulombFriction(1.0, 1.0), props)
        o = self.scene.outline
        if _is_rectangle(o):
            lo, hi = o.min(axis=0), o.max(axis=0)
            c = (lo + hi) / 2
            plant.RegisterCollisionGeometry(body, RigidTransform([c[0], 0.0, c[1]]),
                                            Box(hi[0] - lo[0], thickness, hi[1] - lo[1]), "object", props)
            return
        for k, piece in enumerate(convex_pieces(o)):
            verts = np.array([(p[0], y, p[1]) for p in piece for y in (-thickness / 2, thickness / 2)])
            plant.RegisterCollisionGeometry(body, RigidTransform(), _convex(verts, f"object{k}"), f"object{k}", props)

    def _pad_geometry(self, plant, body) -> None:
        from pydrake.all import (AddCompliantHydroelasticProperties, AddContactMaterial, Box, Cylinder,
                                 CoulombFriction, ProximityProperties, RigidTransform, RotationMatrix)

        s = self.scene
        mu = _pair_friction(s.pad_friction * self.perturb.finger_friction)
        props = ProximityProperties()
        AddCompliantHydroelasticProperties(PAD_RESOLUTION, PAD_MODULUS, props)
        AddContactMaterial(DISSIPATION, POINT_STIFFNESS, CoulombFriction(mu, mu), props)
        pad = s.pad
        if pad[0] == "circle":  # a cylinder's axis is its frame's z: turned onto Y
            shape, X = Cylinder(pad[1], PAD_DEPTH), RigidTransform(RotationMatrix.MakeXRotation(np.pi / 2), [0.0, 0.0, 0.0])
        else:
            shape, X = Box(pad[1], PAD_DEPTH, pad[2]), RigidTransform()
        plant.RegisterCollisionGeometry(body, X, shape, body.name(), props)

    def _feature_geometry(self, plant, body, pusher: str) -> None:
        from pydrake.all import (AddCompliantHydroelasticProperties, AddContactMaterial, Box, CoulombFriction,
                                 Cylinder, ProximityProperties, RigidTransform, RotationMatrix)
        from ..mujoco.model import FEATURE_RADIUS

        p = self.scene.pusher(pusher)
        mu = _pair_friction(p.friction * self.perturb.feature_friction)
        props = ProximityProperties()
        AddCompliantHydroelasticProperties(FEATURE_RADIUS / 2, FEATURE_MODULUS, props)
        AddContactMaterial(DISSIPATION, POINT_STIFFNESS, CoulombFriction(mu, mu), props)
        n = np.asarray(p.normal, float) / np.linalg.norm(p.normal)
        depth = 0.04
        if len(p.points) == 2:
            mid = p.points.mean(axis=0) - n * 0.003
            half = np.linalg.norm(p.points[1] - p.points[0]) / 2
            # the plate's x along the normal: a turn about −Y by the normal's angle
            R = RotationMatrix.MakeYRotation(-np.arctan2(n[1], n[0]))
            plant.RegisterCollisionGeometry(body, RigidTransform(R, [mid[0], 0.0, mid[1]]),
                                            Box(0.006, depth, 2 * half), f"feature_{pusher}", props)
        else:
            c = p.points[0] - n * FEATURE_RADIUS
            plant.RegisterCollisionGeometry(body, RigidTransform(RotationMatrix.MakeXRotation(np.pi / 2),
                                                                 [c[0], 0.0, c[1]]),
                                            Cylinder(FEATURE_RADIUS, depth), f"feature_{pusher}", props)

    # --- running -----------------------------------------------------------------------------

    def reset(self, pose) -> None:
        """The object at ``pose`` ``[x, z, theta]`` (m, m, rad), the pads touching it, every
        feature parked, at rest; the grip applied."""
        from ..mujoco.model import THICKNESS

        plant, pc = self.plant, self.plant_context
        self.context.SetTime(0.0)
        plant.SetDefaultContext(pc)  # the joints' default positions, zero velocities
        self._object.set_pose(pc, [pose[0], pose[1]], pose[2])
        for j, sign in self._pads:
            j.set_translation(pc, sign * (THICKNESS / 2 + PAD_DEPTH / 2))
        f = self.scene.grip_force * self.perturb.grip
        self.diagram.get_input_port(1).FixValue(self.context, [-f, f])  # pad_left pushes −Y, pad_right +Y
        self.diagram.get_input_port(2).FixValue(self.context, np.zeros(3 * len(self.pushers)))
        for p in self.pushers:
            self.place(p, PARK)
        self.simulator.Initialize()

    def place(self, pusher: str, pose) -> None:
        """Puts ``pusher``'s feature frame at planar ``pose`` ``[x, z, theta]`` (m, m, rad) at
        once, at rest (to bring it or park it where it touches nothing)."""
        jx, jz, jt = self._features[pusher]
        pc = self.plant_context
        jx.set_translation(pc, pose[0])
        jz.set_translation(pc, pose[1])
        jt.set_angle(pc, pose[2])
        jx.set_translation_rate(pc, 0.0)
        jz.set_translation_rate(pc, 0.0)
        jt.set_angular_rate(pc, 0.0)
        self._targets[pusher] = np.asarray(pose, float)
        self._drive({})

    def _drive(self, velocities: dict) -> None:
        """Every feature's desired joint positions (:attr:`_targets`) and velocities (``velocities``
        by pusher, else 0)."""
        q = np.concatenate([self._targets[p] for p in self.pushers])
        v = np.concatenate([velocities.get(p, np.zeros(3)) for p in self.pushers])
        self.diagram.get_input_port(0).FixValue(self.context, np.r_[q, v])

    def object_pose(self) -> np.ndarray:
        """The object's planar pose now ``[x, z, theta]`` (m, m, rad)."""
        pc = self.plant_context
        return np.r_[self._object.get_translation(pc), self._object.get_rotation(pc)]

    def move(self, pusher: str, path, duration: float, each=None) -> None:
        """Moves ``pusher``'s feature frame along ``path(u)`` (planar poses, u in (0, 1]) over
        ``duration`` [s] in whole time steps; ``each(t)`` after every step."""
        dt = SETTINGS["time_step"]
        n = max(1, int(np.ceil(duration / dt)))
        t0 = self.context.get_time()
        for i in range(1, n + 1):
            a, b = self._targets[pusher], np.asarray(path(i / n), float)
            self._targets[pusher] = b
            self._drive({pusher: (b - a) * n / duration})
            self.simulator.AdvanceTo(t0 + i * duration / n)
            if each is not None:
                each(self.context.get_time())

    def idle(self, duration: float) -> None:
        """The features held where they are for ``duration`` [s]."""
        self._drive({})
        self.simulator.AdvanceTo(self.context.get_time() + duration)


class DrakePushRig(DrakeRig):
    """A Drake model of one pusher of a scene, reset for each push (as
    :class:`regrasp.mujoco.push.PushRig`)."""

    def __init__(self, scene: Scene, pusher: str, perturb=None):
        super().__init__(scene, (pusher,), perturb)
        self.pusher = pusher

    def push(self, pose, twist, duration: float, settle: float = 0.1, record_dt: float = 0.02) -> dict:
        """As :meth:`regrasp.mujoco.push.PushRig.push`: the pusher starts in contact at the
        object's ``pose`` and moves with constant body ``twist`` (m/s, m/s, rad/s) for
        ``duration`` [s] after ``settle`` [s]; times, object poses and pusher poses every
        ``record_dt`` [s]."""
        q0, tw = np.asarray(pose, float), np.asarray(twist, float)
        self.reset(q0)
        self.place(self.pusher, q0)
        self.idle(settle)
        t0 = self.context.get_time()
        dt = SETTINGS["time_step"]
        every = max(1, int(round(record_dt / dt)))
        steps = max(1, int(round(duration / dt)))
        t, poses, pushers = [0.0], [self.object_pose()], [q0]

        def record(now):
            k = int(round((now - t0) / dt))
            if k % every == 0 or k == steps:
                t.append(now - t0)
                poses.append(self.object_pose())
                pushers.append(self._targets[self.pusher].copy())

        self.move(self.pusher, lambda u: integrate_pose(q0, tw, u * steps * dt), steps * dt, record)
        return {"t": np.array(t), "pose": np.array(poses), "pusher_pose": np.array(pushers)}

    def slip_fraction(self, pose, twist, distance: float = 0.003, speed: float = 0.01) -> float:
        """How far the pusher and the object move apart at the contact over a short push of
        ``twist`` (m/s, m/s, rad/s) from ``pose`` (m, m, rad), as a share of it (measured as in
        MuJoCo: :func:`regrasp.mujoco.push.slip_fraction`)."""
        from ..mujoco.push import slip_fraction

        return slip_fraction(self.scene, self.pusher, self.push, pose, twist, distance, speed)

    def sticks(self, pose, twist, distance: float = 0.003, speed: float = 0.01, ratio: float = 0.02) -> bool:
        """Whether the pusher and the object move together over a short push (as MuJoCo's)."""
        from ..mujoco.push import sticks

        return sticks(self.slip_fraction(pose, twist, distance, speed), ratio)


def _convex(verts: np.ndarray, label: str):
    """A Drake ``Convex`` of the points ``verts`` (n, 3) [m]."""
    from pydrake.all import Convex

    return Convex(np.asarray(verts, float).T, label)
