"""3-D scenes (``dimension = 3``): a box or a convex mesh in a parallel-jaw grasp, pushers as
rigid point sets; poses are ``[x, y, z, qw, qx, qy, qz]`` of the object frame in the gripper
frame, twists ``[vx, vy, vz, wx, wy, wz]`` body twists of the object frame. The format is
documented in ``crates/regrasp-core/src/scene3d.rs`` and the README."""

from __future__ import annotations

from pathlib import Path
from typing import Optional

import numpy as np

from .. import _core
from ..errors import ArgumentError, RegraspError, SceneError, check_seed
from ..planning.plan import Plan, as_plan
from ..pose import quat_angle, twist_between, twist_in
from ..files import parse_toml
from .common import Task, core_property, read_scene_file
from ..fields import check_flag, check_name, check_number, check_vector


class Scene3D:
    """A validated 3-D scene. Load with :meth:`Scene3D.load` (or :func:`regrasp.load_scene`)."""

    #: poses [x, y, z, qw, qx, qy, qz]
    dimension = 3

    def __init__(self, core: "_core.Scene3D", path: Optional[Path] = None):
        self._core = core
        self.path = path

    @classmethod
    def load(cls, path) -> "Scene3D":
        """The 3-D scene of a scene file (``dimension = 3``; mesh paths relative to its folder). Raises
        ArgumentError when ``path`` cannot be read, SceneError naming the field at fault."""
        p, text = read_scene_file(path)
        return cls(_core_from_toml(text, p.parent), p)

    @classmethod
    def from_toml(cls, text: str, base=None) -> "Scene3D":
        """A 3-D scene from the text of its file; ``base``: the folder mesh paths are relative to."""
        if not isinstance(text, str):
            raise ArgumentError(f"invalid `text`: the scene file's text, a str (got {type(text).__name__})", "text")
        if base is not None and not isinstance(base, (str, Path)):
            raise ArgumentError(f"invalid `base`: a folder path or None (got {type(base).__name__})", "base")
        return cls(_core_from_toml(text, base))

    def __repr__(self) -> str:
        return f"Scene3D({self.name!r}, pushers={self.pusher_names})"

    def _repr_html_(self) -> str:
        """Jupyter's display: the browser view of the scene at its start, the goal dashed."""
        from ..viz.viewer import notebook_html

        return notebook_html(self)

    name = core_property("name", "The scene's name.")
    pusher_names = core_property("pusher_names", "Names of the pushers, in file order (list of str).")
    notes = core_property("notes", "What the loader changed in the file's values: measured pusher points moved onto "
                                   "the object's surface (list of str, empty when nothing moved).")
    length = core_property("length", "Characteristic length L [m] weighing rotation against translation.")
    mass = core_property("mass", "Mass of the object [kg].")
    inertia = core_property("inertia", "Inertia matrix about the centre of mass, object frame [kg·m²], shape (3, 3).")
    com = core_property("com", "Centre of mass ``[x, y, z]`` in the object frame [m], shape (3,).", wrap=np.array)
    grip_force = core_property("grip_force", "Grip force per finger [N].")
    pad_friction = core_property("grip_friction", "The finger pads' Coulomb coefficient μ.")
    pad_radius = core_property("pad_radius", "Radius of the finger pads [m].")
    sphere = core_property("sphere", "The sphere's radius [m] for a spherical object, else None.")
    gravity = core_property("gravity", "Gravity in the gripper frame [m/s²], shape (3,).", wrap=np.array)

    @property
    def pad_limit_surface_k(self) -> float:
        """The ``k`` of a pad's limit surface [m]: 2/3 of its radius (a disc of uniform pressure)."""
        return 2.0 / 3.0 * float(self._core.pad_radius)

    def pusher_spec(self, name: str, pose=None) -> tuple:
        """Pusher ``name`` brought against the object at ``pose`` ``[x, y, z, qw, qx, qy, qz]``
        (default: the task's start): its contact points (k, 3) and normal (3,) in the object frame
        [m] and its friction coefficient."""
        q = None if pose is None else list(map(float, check_vector(pose, 7, "pose")))
        pts, n, mu = self._core.pusher_spec(check_name(name, "pusher"), q)
        return np.asarray(pts, float), np.asarray(n, float), float(mu)

    def pusher_points(self, name: str, pose=None) -> np.ndarray:
        """Contact points (k, 3) [m] of pusher ``name`` in the object frame at ``pose``
        ``[x, y, z, qw, qx, qy, qz]`` (default: the task's start)."""
        q = None if pose is None else list(map(float, check_vector(pose, 7, "pose")))
        return np.asarray(self._core.pusher_points(check_name(name, "pusher"), q), float)

    def pusher_normal(self, name: str) -> np.ndarray:
        """Pusher ``name``'s normal (3,) as the scene gives it (object frame; a plane's: gripper frame)."""
        return np.asarray(self._core.pusher_normal(check_name(name, "pusher")), float)

    def is_plane(self, name: str) -> bool:
        """Whether pusher ``name`` is a plane (its normal fixed in the gripper frame)."""
        return bool(self._core.is_plane(check_name(name, "pusher")))

    @property
    def task(self) -> Task:
        """The task (a :class:`~regrasp.scene.common.Task`, as the planar scene's): start and goal
        poses ``[x, y, z, qw, qx, qy, qz]`` (m, m, m, -, -, -, -) and the tolerance
        ``[x, y, z, angle]`` (m, m, m, rad); unpacks as ``start, goal, tolerance``."""
        return Task(*(np.array(x) for x in self._core.task))

    def goal_error(self, pose, goal=None) -> tuple[np.ndarray, bool]:
        """The error of ``pose`` ``[x, y, z, qw, qx, qy, qz]`` to ``goal`` (default: the task's),
        ``[dx, dy, dz, angle]`` (m, m, m, rad; the angle of the relative rotation), and whether it
        is within the task's tolerance. Decided once, in the core."""
        g = None if goal is None else list(map(float, check_vector(goal, 7, "goal")))
        e, ok = self._core.goal_error(list(map(float, check_vector(pose, 7, "pose"))), g)
        return np.array(e), bool(ok)

    def mesh(self):
        """The object's mesh: vertices (n, 3) in the object frame [m] and triangles (m, 3) (vertex
        indices, uint32); for a non-convex object (an OBJ of convex parts) their convex hull, where
        planes and pads touch it."""
        return self._core.mesh()

    def parts(self) -> list:
        """The object's convex parts (their union is the object), each its vertices (n, 3) [m] and
        triangles (m, 3): ``[mesh()]`` for a convex object."""
        return self._core.parts()

    def surface(self):
        """The object's surface to draw: the parts' vertices stacked and their triangles renumbered
        (``mesh()`` for a convex object)."""
        parts = self.parts()
        if len(parts) == 1:
            return parts[0]
        offsets = np.cumsum([0] + [len(v) for v, _ in parts[:-1]])
        return (np.vstack([np.asarray(v, float) for v, _ in parts]),
                np.vstack([np.asarray(t, np.int64) + o for (_, t), o in zip(parts, offsets)]).astype(np.uint32))

    def pad_contacts(self, pose) -> list:
        """Contact points of the two finger pads at ``pose`` ``[x, y, z, qw, qx, qy, qz]`` (m, quaternion),
        in the object frame [m]: one (k, 3) array per pad."""
        return [np.array(p) for p in self._core.pad_contacts(list(check_vector(pose, 7, "pose")))]

    def quasistatic_problem(self, pose, pusher: str, h: float = 1.0):
        """The quasi-static problem (a ``_core.MncpProblem``) of ``pusher`` in contact at ``pose``
        ``[x, y, z, qw, qx, qy, qz]`` (m, quaternion), with time step ``h`` [s] > 0."""
        return self._core.quasistatic_problem(list(check_vector(pose, 7, "pose")), check_name(pusher, "pusher"), check_number(h, "h"))

    def simulate_push(self, pose, pusher: str, twist, duration: float, dt: Optional[float] = None) -> dict:
        """The pusher moves with constant body ``twist`` (m/s, rad/s) for ``duration`` [s] > 0 in steps
        of ``dt`` [s] > 0 (quasi-static time stepping; default min(0.05 s, ``duration``), as the planar
        :func:`~regrasp.sim.quasistatic.simulate_push`)."""
        from .settings import push_dt

        duration = check_number(duration, "duration")
        dt = push_dt(duration, None if dt is None else check_number(dt, "dt"))
        return self._core.simulate_push(list(check_vector(pose, 7, "pose")), check_name(pusher, "pusher"), list(check_vector(twist, 6, "twist")),
                                        duration, dt)

    def plan(self, start=None, goal=None, **settings) -> Plan:
        """T-RRT* over SE(3) with inverse-dynamics and rolling unit steps (thesis §4.2): the same
        as ``regrasp.plan(self, ...)``, a :class:`~regrasp.Plan` of ``dimension`` 3 (each step
        also carries the pusher's body twist over unit time, ``pusher_twists``; ``solves``;
        ``valid``). ``settings`` override the defaults of ``regrasp.planner_defaults(3)``."""
        from ..planning.plan import plan

        return plan(self, start, goal, **settings)

    def validate_path(self, path) -> list:
        """Whether each step of a 3-D plan (a :class:`~regrasp.Plan`, a plan dict or its
        ``path`` list) can be taken by its pusher (see ``regrasp::trrt3d::validate_path3``)."""
        p = as_plan({"path": path} if isinstance(path, list) else path, self, "path")
        tw = p.pusher_twists
        tw = None if all(u is None for u in tw) else [[0.0] * 6 if u is None else u.tolist() for u in tw]  # type: ignore[union-attr]
        return self._core.validate_path(p.poses.tolist(), p.pushers, tw)

    def replay(self, plan, dt: float = 0.25, feedback: bool = False, max_replans: int = 10, seed: int = 0) -> dict:
        """Replays a 3-D plan (a :class:`~regrasp.Plan` or a plan dict) in the quasi-static
        simulator with time step ``dt`` [s]
        simulator: each step's pusher moves with the step's twist for unit time from wherever
        the object is. Returns the final pose, the error to the goal (position [m] and angle
        [rad]), success (within the task's tolerance), the poses after each step and the
        re-plans made (``feedback``: see :func:`run_plan3d`)."""
        dt, feedback, seed = check_number(dt, "dt"), check_flag(feedback, "feedback"), check_seed(seed)
        path = as_plan(plan, self).path

        def step(a, b):
            u = b.get("pusher_twist")
            u = twist_between(a["pose"], b["pose"]) if u is None else u
            if self._core.is_plane(b["pusher"]):
                # a plane makes its planned motion in the gripper frame (it stays level), whatever
                # the object's measured pose: the twist moved from the planned frame to this one
                u = twist_in(_core.se3_compose(_core.se3_inverse(list(map(float, q[0]))), list(map(float, a["pose"]))), u)
            return np.asarray(self.simulate_push(q[0], b["pusher"], u, 1.0, dt)["pose"][-1], float)

        q = [np.asarray(path[0]["pose"], float)]

        def tracked(a, b):
            q[0] = step(a, b)
            return q[0]

        end, poses, replans = run_plan3d(self, path, tracked, q[0], feedback, max_replans, seed)
        return {"engine": "quasistatic", **goal_report(self, end), "poses": np.array(poses), "replans": replans}


def _core_from_toml(text: str, base):
    """The core's 3-D scene of ``text`` (mesh paths relative to folder ``base``, None: the current
    folder), after :func:`_check_mesh_file`."""
    _check_mesh_file(text, base)
    return _core.Scene3D.from_toml(text, None if base is None else str(base))


def _check_mesh_file(text: str, base) -> None:
    """A missing ``object.mesh`` file is a SceneError naming the folder its path is relative to
    (a copied scene file without its meshes); the core reports every other mesh fault."""
    try:
        obj = parse_toml(text, "(toml)").get("object")
    except ArgumentError:
        return  # the core reports the syntax error with its line (is_3d_text: a too deep one)
    mesh = obj.get("mesh") if isinstance(obj, dict) else None
    if not isinstance(mesh, str) or not mesh.strip():
        return
    folder = Path(base or ".").absolute()
    try:
        found = (folder / mesh).is_file()
    except (OSError, ValueError):  # e.g. a name too long for the file system: the core says why
        return
    if not found:
        raise SceneError(f"scene field `object.mesh`: cannot read {mesh}: no such file (`object.mesh` is relative "
                         f"to the scene file's folder, {folder}; `regrasp examples NAME --copy DIR` copies a "
                         f"bundled scene with its meshes)", "object.mesh")


def goal_report(scene: "Scene3D", q) -> dict:
    """The final pose, its error to the task's goal (position [m], angle [rad]) and whether it
    is within the task's tolerance."""
    q = np.asarray(q, float)
    err, ok = scene.goal_error(q)
    return {"final_pose": q.tolist(), "goal_error": err.tolist(), "success": ok}


def run_plan3d(scene: "Scene3D", path: list, step, q0, feedback: bool = False, max_replans: int = 10, seed: int = 0):
    """Executes a 3-D path with ``step(a, b) -> measured pose`` (one plan step from path entry
    ``a`` to ``b``), from measured pose ``q0``. Closed loop by re-planning when ``feedback``: after
    a step that leaves the object off the plan by more than half the goal tolerance (position or
    angle), or when the plan ends outside the tolerance, the T-RRT* plans again from the measured
    pose (at most ``max_replans`` times; seeds ``seed + 1, ...``). Returns the final pose, the poses
    after each step and the number of re-plans."""
    _, goal, tol = scene.task
    if isinstance(max_replans, bool) or not (isinstance(max_replans, (int, np.integer)) and max_replans >= 0):
        raise ArgumentError("invalid `max_replans`: a non-negative whole number", "max_replans")

    def off(q, ref):
        return bool(np.any(np.abs(q[:3] - np.asarray(ref[:3], float)) > tol[:3] / 2) or quat_angle(q[3:], ref[3:]) > tol[3] / 2)

    q = np.asarray(q0, float)
    poses, replans, i = [q], 0, 0
    while True:
        if feedback and i > 0 and goal_report(scene, q)["success"]:
            break  # at the goal (closed loop: going on with the plan could only move it away)
        stray = i > 0 and i + 1 < len(path) and off(q, path[i]["pose"])
        if i + 1 >= len(path) or stray:
            if feedback and replans < max_replans:
                replans += 1
                try:
                    new = scene.plan(start=q, seed=seed + replans).path
                except RegraspError:  # e.g. a pad off the object at the measured pose
                    new = []
                if len(new) >= 2:
                    path, i = new, 0
            if i + 1 >= len(path):
                break
        q = np.asarray(step(path[i], path[i + 1]), float)
        poses.append(q)
        i += 1
    return q, poses, replans


def check_plan3d(scene: "Scene3D", plan) -> list:
    """The path (a list of entries) of a 3-D plan (a :class:`~regrasp.Plan` or a plan dict),
    checked against ``scene``; errors name the field (``plan.path[2].pusher_twist``)."""
    return as_plan(plan, scene).path
