"""3-D scenes (``dimension = 3``): a box or a convex mesh in a parallel-jaw grasp, pushers as
rigid point sets; poses are ``[x, y, z, qw, qx, qy, qz]`` of the object frame in the gripper
frame, twists ``[vx, vy, vz, wx, wy, wz]`` body twists of the object frame. The format is
documented in ``crates/regrasp-core/src/scene3d.rs`` and the README."""

from __future__ import annotations

from pathlib import Path
from typing import Optional

import numpy as np

from .. import _core
from ..errors import ArgumentError, check_seed


class Scene3D:
    def __init__(self, core: "_core.Scene3D", path: Optional[Path] = None):
        self._core = core
        self.path = path

    @classmethod
    def load(cls, path) -> "Scene3D":
        p = Path(path)
        try:
            text = p.read_text()
        except OSError as e:
            raise ArgumentError(f"invalid `path`: cannot read {p}: {e}", "path") from e
        return cls(_core.Scene3D.from_toml(text, str(p.parent)), p)

    @classmethod
    def from_toml(cls, text: str, base=None) -> "Scene3D":
        return cls(_core.Scene3D.from_toml(text, None if base is None else str(base)))

    def __repr__(self) -> str:
        return f"Scene3D({self.name!r}, pushers={self.pusher_names})"

    name = property(lambda self: self._core.name)
    pusher_names = property(lambda self: self._core.pusher_names)
    length = property(lambda self: self._core.length)
    mass = property(lambda self: self._core.mass)
    inertia = property(lambda self: self._core.inertia)

    @property
    def task(self):
        s, g, t = self._core.task
        return np.array(s), np.array(g), np.array(t)

    def mesh(self):
        return self._core.mesh()

    def pad_contacts(self, pose) -> list:
        return [np.array(p) for p in self._core.pad_contacts(list(np.asarray(pose, float)))]

    def quasistatic_problem(self, pose, pusher: str, h: float = 1.0):
        return self._core.quasistatic_problem(list(np.asarray(pose, float)), pusher, h)

    def simulate_push(self, pose, pusher: str, twist, duration: float, dt: float = 0.05) -> dict:
        return self._core.simulate_push(list(np.asarray(pose, float)), pusher, list(np.asarray(twist, float)),
                                        float(duration), float(dt))


    def plan(self, start=None, goal=None, **settings) -> dict:
        """T-RRT* over SE(3) with inverse-dynamics unit steps (thesis §4.2): a plan dict like the
        planar plan file (poses [x, y, z, qw, qx, qy, qz]; each step also carries the pusher's
        body twist ``pusher_twist`` over unit time) plus ``solves`` and ``valid``. ``settings``
        override the defaults of ``regrasp._core.planner_defaults(3)``."""
        if "seed" in settings:
            settings["seed"] = check_seed(settings["seed"])
        s = None if start is None else [float(x) for x in start]
        g = None if goal is None else [float(x) for x in goal]
        r = self._core.plan(s, g, settings)
        r["valid"] = all(self.validate_path(r["path"])) if len(r["path"]) > 1 else True
        return r

    def validate_path(self, path: list) -> list:
        """Whether each step of a 3-D plan's path can be taken by its pusher (see
        ``regrasp::trrt3d::validate_path3``)."""
        path = check_plan3d(self, {"path": path})
        has = [k.get("pusher_twist") is not None for k in path]
        tw = [k["pusher_twist"] if h else [0.0] * 6 for k, h in zip(path, has)] if any(has) else None
        return self._core.validate_path([list(map(float, k["pose"])) for k in path], [k["pusher"] for k in path], tw)

    def replay(self, plan: dict, dt: float = 0.25, feedback: bool = False, max_replans: int = 10, seed: int = 0) -> dict:
        """Replays a 3-D plan in the quasi-static simulator: each step's pusher moves with the
        step's twist for unit time from wherever the object is. Returns the final pose, the
        error to the goal (position [m] and angle [rad]), success (within the task's tolerance),
        the poses after each step and the re-plans made (``feedback``: see :func:`run_plan3d`)."""
        path = check_plan3d(self, plan)

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


def twist_in(rel, u) -> list:
    """Body twist ``u`` of a frame B expressed in frame A, where ``rel`` = A⁻¹B (the adjoint):
    ``[R v + p × (R ω), R ω]``."""
    from scipy.spatial.transform import Rotation

    rel, u = np.asarray(rel, float), np.asarray(u, float)
    R = Rotation.from_quat([rel[4], rel[5], rel[6], rel[3]])
    w = R.apply(u[3:])
    return (R.apply(u[:3]) + np.cross(rel[:3], w)).tolist() + w.tolist()


def goal_report(scene: "Scene3D", q) -> dict:
    """The final pose, its error to the task's goal (position [m], angle [rad]) and whether it
    is within the task's tolerance."""
    q = np.asarray(q, float)
    _, goal, tol = scene.task
    dp = q[:3] - goal[:3]
    ang = quat_angle(q[3:], goal[3:])
    return {"final_pose": q.tolist(), "goal_error": dp.tolist() + [ang],
            "success": bool(np.all(np.abs(dp) <= tol[:3]) and ang <= tol[3])}


def run_plan3d(scene: "Scene3D", path: list, step, q0, feedback: bool = False, max_replans: int = 10, seed: int = 0):
    """Executes a 3-D path with ``step(a, b) -> measured pose`` (one plan step from path entry
    ``a`` to ``b``), from measured pose ``q0``. Closed loop by re-planning when ``feedback``: after
    a step that leaves the object off the plan by more than half the goal tolerance (position or
    angle), or when the plan ends outside the tolerance, the T-RRT* plans again from the measured
    pose (at most ``max_replans`` times; seeds ``seed + 1, ...``). Returns the final pose, the poses
    after each step and the number of re-plans."""
    _, goal, tol = scene.task
    if not (isinstance(max_replans, (int, np.integer)) and max_replans >= 0):
        raise ArgumentError("invalid `max_replans`: a non-negative whole number", "max_replans")

    def off(q, ref):
        return bool(np.any(np.abs(q[:3] - np.asarray(ref[:3], float)) > tol[:3] / 2) or quat_angle(q[3:], ref[3:]) > tol[3] / 2)

    from ..errors import RegraspError

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
                    new = scene.plan(start=q, seed=seed + replans)
                except RegraspError:  # e.g. a pad off the object at the measured pose
                    new = {"path": []}
                if len(new["path"]) >= 2:
                    path, i = new["path"], 0
            if i + 1 >= len(path):
                break
        q = np.asarray(step(path[i], path[i + 1]), float)
        poses.append(q)
        i += 1
    return q, poses, replans


def check_plan3d(scene: "Scene3D", plan) -> list:
    """The path of a 3-D plan, checked: poses of 7 numbers, known pushers, twists of 6 numbers.
    Errors name the field."""
    if not isinstance(plan, dict) or not isinstance(plan.get("path"), list) or len(plan["path"]) < 1:
        raise ArgumentError("invalid `plan`: a dict with a non-empty `path` list", "plan.path")
    for i, k in enumerate(plan["path"]):
        if not isinstance(k, dict) or "pose" not in k:
            raise ArgumentError(f"invalid `plan.path[{i}]`: needs a `pose`", f"plan.path[{i}].pose")
        try:
            q = np.asarray(k["pose"], float)
        except (TypeError, ValueError):
            q = np.full(1, np.nan)
        if q.shape != (7,) or not np.all(np.isfinite(q)) or np.linalg.norm(q[3:]) < 1e-9:
            raise ArgumentError(f"invalid `plan.path[{i}].pose`: 7 finite numbers [x, y, z, qw, qx, qy, qz]",
                                f"plan.path[{i}].pose")
        if i > 0 and k.get("pusher") not in scene.pusher_names:
            raise ArgumentError(f"invalid `plan.path[{i}].pusher`: no pusher {k.get('pusher')!r} in the scene",
                                f"plan.path[{i}].pusher")
        if i > 0 and k.get("pusher_twist") is None and scene._core.is_plane(k["pusher"]):
            raise ArgumentError(f"invalid `plan.path[{i}].pusher_twist`: a step of plane {k['pusher']!r} needs its "
                                "pusher twist (a plane only rolls the object)", f"plan.path[{i}].pusher_twist")
        if i > 0 and k.get("pusher_twist") is not None:
            try:
                u = np.asarray(k["pusher_twist"], float)
            except (TypeError, ValueError):
                u = np.full(1, np.nan)
            if u.shape != (6,) or not np.all(np.isfinite(u)):
                raise ArgumentError(f"invalid `plan.path[{i}].pusher_twist`: 6 finite numbers",
                                    f"plan.path[{i}].pusher_twist")
    return plan["path"]


def quat_angle(a, b) -> float:
    """Angle [rad] of the rotation between unit quaternions a and b ([w, x, y, z])."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    d = abs(float(a @ b) / (np.linalg.norm(a) * np.linalg.norm(b)))
    return float(2 * np.arccos(min(1.0, d)))


def twist_between(a, b) -> list:
    """The constant body twist taking pose a to pose b in unit time (SE(3) log, the core's)."""
    return list(_core.se3_log([float(x) for x in a], [float(x) for x in b]))


def is_3d(path) -> bool:
    """Whether a scene file is a 3-D scene (``dimension = 3``)."""
    import tomllib

    try:
        return tomllib.loads(Path(path).read_text()).get("dimension") == 3
    except (OSError, tomllib.TOMLDecodeError):
        return False
