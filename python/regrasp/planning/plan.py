"""Regrasp planning and plan files, for planar and 3-D scenes alike.

``plan(scene)`` runs the Rust core's T-RRT* (planar: motion-cone steps, thesis ch. 4; 3-D:
inverse-dynamics and rolling steps, §4.2) and returns a :class:`Plan`. ``Plan.to_json()`` is the
plan file of ``docs/plan-file.md`` for the plan's dimension; :meth:`Plan.load` is the one reader
of plan files and :meth:`Plan.from_json` of plan dicts, both checking every field they use.
"""

from __future__ import annotations

import json
import numbers
import weakref
from dataclasses import dataclass, field
from pathlib import Path
from typing import Optional

import numpy as np

from .. import _core
from ..errors import ArgumentError, check_seed
from ..fields import MAX_ANGLE, MAX_COORDINATE, MAX_PLAN_STEPS, finite_number
from ..files import as_path, parse_json, read_text, same_file as _same_file, write_text

#: the keys of a plan file, in the order they are written (docs/plan-file.md), by dimension
KEYS = {
    2: ("scene", "found", "stop_reason", "reason", "planning_time_s", "nodes", "switch_overs", "path", "iterations", "cost",
        "goal_distance", "propagation", "seed", "first_time_s", "first_switch_overs", "step_margins", "valid"),
    3: ("scene", "found", "stop_reason", "reason", "planning_time_s", "nodes", "iterations", "switch_overs", "cost",
        "goal_distance", "propagation", "seed", "first_time_s", "first_switch_overs", "solves", "path", "valid"),
}
#: numbers in a pose: planar [x, z, theta], 3-D [x, y, z, qw, qx, qy, qz]
POSE_SIZE = {2: 3, 3: 7}
POSE_TEXT = {2: "[x, z, theta]", 3: "[x, y, z, qw, qx, qy, qz]"}
#: the JSON type of each summary key (docs/plan-file.md)
SUMMARY_TYPES = {
    "scene": "str", "found": "bool", "stop_reason": "str", "reason": "str", "planning_time_s": "float", "nodes": "int",
    "iterations": "int", "switch_overs": "int", "cost": "float", "goal_distance": "float", "propagation": "str",
    "seed": "int", "solves": "int", "step_margins": "float[]", "valid": "bool", "first_time_s": "float",
    "first_switch_overs": "int",
}
#: the scene object of each plan made by :func:`plan` (for its display), outside the plan's
#: state: its file, equality and copies are unchanged
_SCENES: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()
#: smallest step margin that counts as sticking (``valid``)
MARGIN_TOL = 1e-9


def planner_defaults(dimension: int) -> dict:
    """The planner's settings and their defaults for ``dimension`` 2 or 3 (the Rust core's)."""
    if dimension not in (2, 3):
        raise ArgumentError(f"invalid `dimension`: 2 or 3 (got {dimension!r})", "dimension")
    return dict(_core.planner_defaults(dimension))


# --- checking plan values ----------------------------------------------------------------------

def _numbers(v, n: int, where: str, what: str) -> np.ndarray:
    """``v`` as n finite numbers, or an ArgumentError naming ``where``."""
    ok = isinstance(v, (list, tuple, np.ndarray)) and len(v) == n and all(finite_number(x) for x in v)
    a = np.asarray(v, float) if ok else None
    if a is None or not np.all(np.isfinite(a)):
        raise ArgumentError(f"invalid `{where}`: {what} (got {v!r})", where)
    return a


def _pose(v, dim: int, where: str) -> np.ndarray:
    q = _numbers(v, POSE_SIZE[dim], where, f"{POSE_SIZE[dim]} finite numbers {POSE_TEXT[dim]}")
    return check_pose(q, dim, where)


def check_pose(q: np.ndarray, dim: int, where: str) -> np.ndarray:
    """Pose ``q`` of a plan when it is physical: positions within ``MAX_COORDINATE`` (m) of the
    origin, a planar angle within ``MAX_ANGLE`` (rad), a 3-D quaternion neither zero nor huge;
    else an ArgumentError naming ``where``."""
    n = 2 if dim == 2 else 3
    if np.max(np.abs(q[:n])) > MAX_COORDINATE:
        raise ArgumentError(f"invalid `{where}`: positions must be within {MAX_COORDINATE:g} m of the origin "
                            f"(got {q.tolist()})", where)
    if dim == 2 and abs(q[2]) > MAX_ANGLE:
        raise ArgumentError(f"invalid `{where}`: the angle must be within {MAX_ANGLE:g} rad (got {q[2]:g})", where)
    if dim == 3 and not 1e-9 <= np.linalg.norm(q[3:]) <= 1e6:
        raise ArgumentError(f"invalid `{where}`: the quaternion [qw, qx, qy, qz] must have a norm in [1e-9, 1e6] "
                            f"(got {q[3:].tolist()})", where)
    return q


def _is_type(v, t: str) -> bool:
    """Whether ``v`` is a value of JSON type ``t`` of docs/plan-file.md (numbers finite)."""
    if t == "str":
        return isinstance(v, str)
    if t == "bool":
        return isinstance(v, bool)
    if t == "int":
        return isinstance(v, numbers.Integral) and not isinstance(v, bool)
    if t == "float":
        return finite_number(v)
    return isinstance(v, list) and all(_is_type(x, "float") for x in v)  # float[]


def _summary_value(v, key: str, where: str):
    """A summary value of the type the plan file documents for ``key``."""
    t = SUMMARY_TYPES[key]
    if not _is_type(v, t):
        raise ArgumentError(f"invalid `{where}`: expected {t} (got {v!r})", where)
    return [float(x) for x in v] if t == "float[]" else (float(v) if t == "float" else v)


def _dimension_of(path: list, scene, name: str) -> int:
    """The plan's dimension: the scene's, else the length of the first pose (3 or 7)."""
    if scene is not None:
        return scene.dimension
    first = path[0].get("pose") if isinstance(path[0], dict) else None
    for dim, n in POSE_SIZE.items():
        if isinstance(first, (list, tuple, np.ndarray)) and len(first) == n:
            return dim
    raise ArgumentError(f"invalid `{name}.path[0].pose`: 3 numbers {POSE_TEXT[2]} or 7 numbers {POSE_TEXT[3]} "
                        f"(got {first!r})", f"{name}.path[0].pose")


def _entry(k, i: int, dim: int, name: str):
    """(pose, pusher, pusher twist) of path entry ``i``, checked."""
    where = f"{name}.path[{i}]"
    if not isinstance(k, dict):
        raise ArgumentError(f"invalid `{where}`: an object with `pose` and `pusher` (got {k!r})", where)
    q = _pose(k.get("pose"), dim, f"{where}.pose")
    pusher = k.get("pusher")
    if not (isinstance(pusher, str) or (i == 0 and pusher is None)):
        what = "null (the start) or a pusher's name" if i == 0 else "the name of the step's pusher"
        raise ArgumentError(f"invalid `{where}.pusher`: {what} (got {pusher!r})", f"{where}.pusher")
    twist = None
    if dim == 3 and i > 0 and k.get("pusher_twist") is not None:
        twist = _numbers(k["pusher_twist"], 6, f"{where}.pusher_twist", "6 finite numbers [vx, vy, vz, wx, wy, wz]")
    return q, pusher, twist


# --- the plan ----------------------------------------------------------------------------------

@dataclass(eq=False, repr=False)
class Plan:
    """A regrasp plan, planar (``dimension`` 2, poses ``[x, z, theta]`` (m, m, rad)) or 3-D
    (``dimension`` 3, poses ``[x, y, z, qw, qx, qy, qz]`` (m, m, m, unit quaternion)), with the
    planner's statistics.

    ``poses``: (n, 3) or (n, 7) array, ``poses[0]`` the start. ``pushers[i]``: the pusher that
    moves the object from ``poses[i-1]`` to ``poses[i]`` (``pushers[0]`` is None). 3-D:
    ``pusher_twists[i]``, the pusher's body twist ``[vx, vy, vz, wx, wy, wz]`` (m/s, rad/s) over step i
    (None for the start, or where a
    plan file gives none). A statistic is None when the plan was read from a file without it.

    ``plan[key]`` reads the key of :meth:`to_json` (kept for compatibility with code written for
    plan dicts: ``plan["found"]``, ``plan["path"]``).
    """

    dimension: int
    poses: np.ndarray
    pushers: list
    pusher_twists: Optional[list] = None
    scene: Optional[str] = None
    found: Optional[bool] = None
    stop_reason: Optional[str] = None
    #: why no plan can exist, with ``stop_reason`` "unreachable" (decided before the search)
    reason: Optional[str] = None
    planning_time_s: Optional[float] = None
    nodes: Optional[int] = None
    iterations: Optional[int] = None
    switch_overs: Optional[int] = None
    cost: Optional[float] = None
    goal_distance: Optional[float] = None
    propagation: Optional[str] = None
    seed: Optional[int] = None
    #: the first plan found, before the anytime refinement (setting ``refine``): when [s], and its
    #: switch-overs (``planning_time_s`` and ``switch_overs`` are the final plan's)
    first_time_s: Optional[float] = None
    first_switch_overs: Optional[int] = None
    #: 3-D: inverse and forward dynamics problems solved during the search
    solves: Optional[int] = None
    #: planar: smallest exact-test margin along each step (≥ 0: the step sticks along its length)
    step_margins: Optional[list] = None
    #: every step passes the step check (planar: the exact motion-cone test; 3-D: ``Scene3D.validate_path``)
    valid: Optional[bool] = None
    #: the scene file the plan was made for (:meth:`save` never overwrites it)
    scene_file: Optional[Path] = field(default=None, repr=False)

    def __post_init__(self):
        if self.dimension not in (2, 3):
            raise ArgumentError(f"invalid `dimension`: 2 or 3 (got {self.dimension!r})", "dimension")
        self.poses = np.asarray(self.poses, float).reshape(-1, POSE_SIZE[self.dimension])
        self.pushers = list(self.pushers)
        if len(self.poses) < 1 or len(self.pushers) != len(self.poses):
            raise ArgumentError("invalid `pushers`: one per pose (None for the start), at least one pose", "pushers")
        if self.dimension == 3:
            tw = self.pusher_twists if self.pusher_twists is not None else [None] * len(self.poses)
            if len(tw) != len(self.poses):
                raise ArgumentError("invalid `pusher_twists`: one per pose (None for the start)", "pusher_twists")
            self.pusher_twists = [None if u is None or i == 0 else np.asarray(u, float) for i, u in enumerate(tw)]

    def __repr__(self) -> str:
        return (f"Plan(dimension={self.dimension}, scene={self.scene!r}, found={self.found}, "
                f"steps={len(self.poses) - 1}, switch_overs={self.switch_overs}, valid={self.valid})")

    def _repr_html_(self) -> str:
        """Jupyter's display: the browser view of the plan when it knows its scene (a plan made
        by :func:`plan`), else its summary (found, stop reason, steps, switch-overs, time)."""
        from ..viz.viewer import plan_html

        return plan_html(self, _SCENES.get(self))

    # -- views ---------------------------------------------------------------------------------

    @property
    def path(self) -> list:
        """The plan file's ``path``: ``[{"pose", "pusher"[, "pusher_twist"]}, ...]``."""
        out = []
        for i, (q, name) in enumerate(zip(self.poses, self.pushers)):
            k = {"pose": [float(x) for x in q], "pusher": name}
            if self.dimension == 3 and self.pusher_twists[i] is not None:  # type: ignore[index]
                k["pusher_twist"] = [float(x) for x in self.pusher_twists[i]]  # type: ignore[index]
            out.append(k)
        return out

    def to_json(self) -> dict:
        """The plan file's object (docs/plan-file.md) for the plan's dimension; a statistic the
        plan does not know (read from a file without it) is left out."""
        out = {}
        for k in KEYS[self.dimension]:
            v = self.path if k == "path" else getattr(self, k)
            if v is not None:
                out[k] = [float(x) for x in v] if k == "step_margins" else _plain(v)
        return out

    def __getitem__(self, key: str):
        d = self.to_json()
        if key not in d:
            raise KeyError(key)
        return d[key]

    def __contains__(self, key) -> bool:
        return key in self.to_json()

    def get(self, key: str, default=None):
        """The value of ``key`` in :meth:`to_json`, or ``default`` (as ``dict.get``)."""
        return self.to_json().get(key, default)

    # -- reading -------------------------------------------------------------------------------

    @classmethod
    def from_json(cls, d, scene=None, name: str = "plan") -> "Plan":
        """A plan from a plan-file object. Needs ``path`` (a non-empty list of entries with a
        ``pose`` and, after the first, a ``pusher``; 3-D steps may carry ``pusher_twist``); every
        documented key present is checked, other keys are ignored. With ``scene`` the plan must
        be for its dimension and pushers. Errors name the field: ``plan.path[3].pose``."""
        if not isinstance(d, dict):
            raise ArgumentError(f"invalid `{name}`: a JSON object with a `path` (got {type(d).__name__})", name)
        path = d.get("path")
        if not isinstance(path, list) or not path:
            raise ArgumentError(f"invalid `{name}.path`: a non-empty list of {{pose, pusher}} entries", f"{name}.path")
        if len(path) - 1 > MAX_PLAN_STEPS:
            raise ArgumentError(f"invalid `{name}.path`: has {len(path) - 1} steps; at most {MAX_PLAN_STEPS} are allowed "
                                "(docs/guarantees.md, Limits)", f"{name}.path")
        dim = _dimension_of(path, scene, name)
        poses, pushers, twists = zip(*(_entry(k, i, dim, name) for i, k in enumerate(path)))
        stats = {k: _summary_value(d[k], k, f"{name}.{k}") for k in KEYS[dim] if k != "path" and d.get(k) is not None}
        if "step_margins" in stats and len(stats["step_margins"]) != len(path) - 1:
            raise ArgumentError(f"invalid `{name}.step_margins`: one per step ({len(path) - 1})", f"{name}.step_margins")
        p = cls(dim, np.array(poses), list(pushers), list(twists) if dim == 3 else None, **stats)
        if scene is not None:
            p.check_for(scene, name)
        return p

    @classmethod
    def load(cls, path, scene=None) -> "Plan":
        """Reads a plan file (see :meth:`from_json`); errors name the field (``plan.path[3].pose``)."""
        p = as_path(path, "plan")
        d = parse_json(read_text(p, "plan"), "plan",
                       lambda why: ArgumentError(f"invalid `plan`: {p}: {why}", "plan"))
        if not isinstance(d, dict):
            raise ArgumentError(f"invalid `plan`: {p} is not a plan file: a JSON object with a `path` "
                                f"(got a JSON {_json_type(d)})", "plan")
        return cls.from_json(d, scene)

    def check_limits(self, name: str = "plan") -> None:
        """Whether the plan is one a world can run: at most ``MAX_PLAN_STEPS`` steps, every pose
        finite and physical (:func:`check_pose`); ArgumentError naming the field."""
        q = np.asarray(self.poses, float)
        if q.ndim != 2 or q.shape[1] != POSE_SIZE.get(self.dimension, -1) or not len(q):
            raise ArgumentError(f"invalid `{name}.path`: poses of {POSE_SIZE.get(self.dimension)} numbers "
                                f"(got shape {q.shape})", f"{name}.path")
        if len(q) - 1 > MAX_PLAN_STEPS:
            raise ArgumentError(f"invalid `{name}.path`: has {len(q) - 1} steps; at most {MAX_PLAN_STEPS} are allowed "
                                "(docs/guarantees.md, Limits)", f"{name}.path")
        for i, row in enumerate(q):
            if not np.all(np.isfinite(row)):
                raise ArgumentError(f"invalid `{name}.path[{i}].pose`: finite numbers (got {row.tolist()})",
                                    f"{name}.path[{i}].pose")
            check_pose(row, self.dimension, f"{name}.path[{i}].pose")

    def check_for(self, scene, name: str = "plan") -> None:
        """Whether the plan is for ``scene``: its dimension, its pushers; a plane pusher's 3-D step
        needs its pusher twist (a plane only rolls the object). ArgumentError naming the field."""
        if not all(hasattr(scene, a) for a in ("dimension", "pusher_names", "_core")):
            raise ArgumentError(f"invalid `scene`: a regrasp Scene or Scene3D (got {type(scene).__name__})", "scene")
        self.check_limits(name)
        if scene.dimension != self.dimension:
            kind = {2: "a planar", 3: "a 3-D"}
            n = POSE_SIZE[scene.dimension]
            raise ArgumentError(f"invalid `{name}.path[0].pose`: {kind[self.dimension]} plan for {kind[scene.dimension]} "
                                f"scene, whose poses are {n} numbers {POSE_TEXT[scene.dimension]}", f"{name}.path[0].pose")
        for i, k in enumerate(self.pushers[1:], 1):
            if k not in scene.pusher_names:
                raise ArgumentError(f"invalid `{name}.path[{i}].pusher`: no pusher {k!r} in the scene "
                                    f"(its pushers: {', '.join(scene.pusher_names)})",
                                    f"{name}.path[{i}].pusher")
            if self.dimension == 3 and self.pusher_twists[i] is None and scene._core.is_plane(k):  # type: ignore[index]
                raise ArgumentError(f"invalid `{name}.path[{i}].pusher_twist`: a step of plane {k!r} needs its pusher "
                                    "twist (a plane only rolls the object)", f"{name}.path[{i}].pusher_twist")

    # -- checking and writing ------------------------------------------------------------------

    def check(self, scene) -> bool:
        """Re-validates every step on ``scene`` and sets ``valid`` (planar: also ``step_margins``,
        the exact motion-cone test at 64 poses along each step, a point pusher's along its flow; 3-D:
        ``Scene3D.validate_path``)."""
        self.check_for(scene)
        if self.dimension == 2:
            self.step_margins = [float(m) for m in validate(scene, self)] if len(self.poses) > 1 else []
            self.valid = all(m >= -MARGIN_TOL for m in self.step_margins)
        else:
            self.valid = all(scene.validate_path(self)) if len(self.poses) > 1 else True
        return self.valid

    def save(self, path) -> Path:
        """Writes the plan file atomically (a temporary file in the same folder, then renamed over
        ``path``). Refuses to overwrite the scene file the plan was made from."""
        p = as_path(path, "path")
        if self.scene_file is not None and same_file(p, self.scene_file):
            raise ArgumentError(f"invalid `path`: {p} is the scene file the plan was made from (not overwritten)", "path")
        text = json.dumps(self.to_json(), indent=1, allow_nan=False)
        try:
            write_text(p, text)
        except OSError as e:
            raise ArgumentError(f"invalid `path`: cannot write {p}: {e.strerror or e}", "path") from e
        return p


def _json_type(v) -> str:
    """The JSON type name of a parsed value."""
    names = {list: "array", str: "string", bool: "boolean", int: "number", float: "number", type(None): "null"}
    return names.get(type(v), type(v).__name__)


def _plain(v):
    """Plan values as JSON types (numpy scalars to Python numbers)."""
    if isinstance(v, np.generic):
        return v.item()
    return v


def same_file(a: Path, b: Path) -> bool:
    """Whether ``a`` and ``b`` name one file (see :func:`regrasp.files.same_file`)."""
    return _same_file(a, b)


def as_plan(plan, scene=None, name: str = "plan") -> Plan:
    """A :class:`Plan` from a Plan or a plan dict, checked against ``scene`` when given."""
    if isinstance(plan, Plan):
        if scene is not None:
            plan.check_for(scene, name)
        return plan
    return Plan.from_json(plan, scene, name)


# --- planning ----------------------------------------------------------------------------------

def _pose_argument(v, name: str):
    """``start``/``goal`` as a list of floats for the core (None: the scene's task)."""
    if v is None:
        return None
    try:
        a = np.asarray(v, dtype=float)
    except (TypeError, ValueError, OverflowError) as e:
        raise ArgumentError(f"invalid `{name}`: a pose, a list of numbers (got {v!r})", name) from e
    if a.ndim != 1:
        raise ArgumentError(f"invalid `{name}`: a pose, a list of numbers (got shape {a.shape})", name)
    return a.tolist()


def validate(scene, plan, checks: int = 64) -> list:
    """Smallest exact-test margin along each step of a planar plan (a :class:`Plan` or its
    ``path`` list; see :attr:`Plan.step_margins`)."""
    p = plan if isinstance(plan, Plan) else as_plan({"path": plan})
    return scene._core.validate_path(p.poses.tolist(), p.pushers, checks)


def plan(scene, start=None, goal=None, **settings) -> Plan:
    """Plans a regrasp of ``scene`` (a :class:`~regrasp.Scene` or :class:`~regrasp.Scene3D`)
    from ``start`` to ``goal`` (default: the scene's task) and checks its steps (``valid``).

    ``settings`` override the planner's defaults, which are the Rust core's:
    ``planner_defaults(scene.dimension)`` lists them (``seed``, ``time_limit`` [s],
    ``max_nodes``, ``step``, ``goal_bias``, ...; planar also ``propagation``: "motion_cone" (this
    library), "stable_check" (random steps kept when a force-balance LP passes, ICRA 2018) or
    "mncp" (inverse quasi-static dynamics), ``margin``, ``plain`` and ``guide``: the share of
    samples drawn along the pad's path around walls when the straight one leaves the object). An
    unknown setting is an
    ArgumentError naming it.
    """
    if "seed" in settings:
        settings["seed"] = check_seed(settings["seed"])
    r = scene._core.plan(_pose_argument(start, "start"), _pose_argument(goal, "goal"), settings)
    p = Plan.from_json(r)
    p.scene_file = scene.path
    p.check(scene)
    _SCENES[p] = scene
    return p
