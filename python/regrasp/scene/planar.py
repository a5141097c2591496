"""Scenes and motion cones: the Python face of the Rust core.

Units are SI, angles radians. Poses are ``[x, z, theta]`` of the object frame in the gripper
frame; twists ``[vx, vz, omega]`` in the object frame; wrenches ``[fx, fz, tau]`` (tau
counter-clockwise in the X-Z drawing). See ``docs/scene-file.md`` for the scene file contract.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Optional, Sequence, overload

import numpy as np
from numpy.typing import NDArray

from .. import _core
from ..errors import ArgumentError, SceneError
from ..fields import check_array as _array, check_flag as _flag, check_name as _name
from ..fields import check_number as _number, check_rows as _rows, check_twists as _twists
from ..fields import check_vec_or_rows as _vec_or_rows, check_vector as _vec, plain_numbers
from .common import Task, core_property, read_scene_file

ArrayLike = Sequence[float] | np.ndarray


@dataclass(frozen=True)
class Pusher:
    """A pusher of a planar scene: its contact points (1, 2) (a point pusher) or (2, 2) (a line
    pusher) in the object frame [m], its unit normal (2,) (the direction it pushes the object) and
    its friction coefficient (dimensionless)."""
    name: str
    points: np.ndarray  # (1, 2) point pusher or (2, 2) line pusher, object frame [m]
    normal: np.ndarray  # (2,) unit, the direction the pusher pushes the object
    friction: float


@dataclass(frozen=True)
class Classification:
    """Result of the exact motion-cone test of one twist."""

    feasible: bool
    margin: float  # >= 0 inside; sine of the angle to the nearest limit, scaled wrench space
    active_limit: str  # "slide+t", "slide-t", "roll_about_point_i", "torque", "off_ray"
    pusher_wrench: np.ndarray  # wrench the pusher must apply, object frame
    support_wrench: np.ndarray  # load on the support (finger pads), object frame


class GravityFreeCone:
    """The gravity-free motion cone V_gf = J_s^-1 A J_s^-T W_p (exactly polyhedral)."""

    def __init__(self, cone: "MotionCone"):
        self._cone = cone

    @property
    def generators(self) -> np.ndarray:
        """Generators of the gravity-free cone, one unit twist ``[vx, vz, omega]`` (m/s, m/s, rad/s) a
        row, shape (k, 3)."""
        return self._cone._core.gravity_free_generators

    def margin(self, twist: ArrayLike) -> float:
        """Signed margin of ``twist`` ``[vx, vz, omega]`` (m/s, m/s, rad/s) in the gravity-free cone
        (>= 0 inside, exact: the cone is polyhedral)."""
        return self._cone._core.gravity_free_margin(list(_vec(twist, 3, "twist")))

    def contains(self, twist: ArrayLike, tol: float = 1e-9) -> bool:
        """Whether ``twist`` ``[vx, vz, omega]`` (m/s, m/s, rad/s) lies in the gravity-free cone, up to
        ``tol`` on the margin."""
        return self.margin(twist) >= -tol

    def project(self, twist: ArrayLike) -> np.ndarray:
        """Closest twist of the gravity-free cone to ``twist`` ``[vx, vz, omega]`` (m/s, m/s, rad/s), in
        the metric of :meth:`Scene.metric_twist`."""
        return self._cone._core.project_polyhedral(list(_vec(twist, 3, "twist")), "gravity_free")


class MotionCone:
    """Motion cone of one pusher at one pose (RSS 2018; thesis §3.3).

    ``generators``: polyhedral approximation, one unit twist a row (one per edge of the
    pusher's friction cone; unit in the metric of :meth:`Scene.metric_twist`).
    ``contains``/``margin``/``classify``: the exact test (is the twist producible with a
    sticking pusher?). ``project``: closest feasible twist in that metric. ``gravity_free``:
    the gravity-free cone.
    """

    def __init__(self, core: "_core.MotionCone", scene: "Scene"):
        self._core = core
        self.scene = scene

    def __repr__(self) -> str:
        return f"MotionCone(pusher={self.pusher!r}, pose={list(self.pose)}, shape={self._core.pusher_cone_shape})"

    pusher = core_property("pusher", "Name of the pusher this cone belongs to.")
    pose = core_property("pose", "The pose ``[x, z, theta]`` (m, m, rad) of the cone, shape (3,).", wrap=np.array)
    generators = core_property("generators", "Generators of the polyhedral approximation, one unit twist "
                                             "``[vx, vz, omega]`` (m/s, m/s, rad/s) a row, shape (k, 3).")
    gravity_free_generators = core_property("gravity_free_generators", "Generators of the gravity-free "
                                            "cone, one unit twist (m/s, m/s, rad/s) a row, shape (k, 3).")

    @property
    def gravity_free(self) -> GravityFreeCone:
        """The gravity-free cone of this pusher at this pose (no gravity wrench)."""
        return GravityFreeCone(self)

    hold_ratio = core_property("hold_ratio", "Share of the pads' friction that gravity alone uses (< 1 holds).")
    pusher_edges = core_property("pusher_edges", "The pusher's friction-cone edge wrenches (k, 3), object "
                                                 "frame, scaled by the support's friction (the cone's rays' "
                                                 "preimages; :meth:`ray` of a mix of rows).")
    boundary_segments = core_property("boundary_segments", "Pairs ``(i, j)`` of :attr:`pusher_edges` rows whose "
                                                           "mixes map onto the cone's boundary.")
    support_matrices = core_property("support_matrices", "``(A, Js, wg)``: the limit surface's matrix, the "
                                                         "pusher's contact Jacobians and gravity's wrench "
                                                         "(eq 3.9's terms).")
    is_line_pusher = core_property("line", "A line pusher (two rigidly connected points) rather than a point pusher.")

    @overload
    def contains(self, twist: Sequence[float]) -> bool: ...
    @overload
    def contains(self, twist: Sequence[Sequence[float]]) -> NDArray[np.bool_]: ...
    @overload
    def contains(self, twist: NDArray[np.float64]) -> bool | NDArray[np.bool_]: ...

    def contains(self, twist: ArrayLike | Sequence[Sequence[float]]) -> bool | NDArray[np.bool_]:
        """Exact test of one twist ``[vx, vz, omega]`` (m/s, m/s, rad/s) (a bool) or of each row of an
        (n, 3) array (a bool array): can the pusher produce it while sticking?"""
        return self._core.contains(_vec_or_rows(twist, "twist"))

    @overload
    def margin(self, twist: Sequence[float]) -> float: ...
    @overload
    def margin(self, twist: Sequence[Sequence[float]]) -> NDArray[np.float64]: ...
    @overload
    def margin(self, twist: NDArray[np.float64]) -> float | NDArray[np.float64]: ...

    def margin(self, twist: ArrayLike | Sequence[Sequence[float]]) -> float | NDArray[np.float64]:
        """Signed margin of a twist ``[vx, vz, omega]`` (m/s, m/s, rad/s) in the exact cone: a float
        for one twist, an array for an (n, 3) array (>= 0 inside)."""
        return self._core.margin(_vec_or_rows(twist, "twist"))

    def classify(self, twist: ArrayLike) -> Classification:
        """Exact test of one twist ``[vx, vz, omega]`` (m/s, m/s, rad/s), with the wrenches (N, N, N·m)
        that produce it."""
        d = self._core.classify(list(_vec(twist, 3, "twist")))
        return Classification(
            feasible=d["feasible"],
            margin=d["margin"],
            active_limit=d["active_limit"],
            pusher_wrench=np.array(d["pusher_wrench"]),
            support_wrench=np.array(d["support_wrench"]),
        )

    def project(self, twist: ArrayLike | Sequence[Sequence[float]]) -> np.ndarray:
        """Closest feasible twist (exact cone) to one twist ``[vx, vz, omega]`` (m/s, m/s, rad/s) or
        to each row of an (n, 3) array, in the metric of :meth:`Scene.metric_twist`."""
        return self._core.project(_vec_or_rows(twist, "twist"))

    def project_polyhedral(self, twist: ArrayLike) -> np.ndarray:
        """Closest twist of the polyhedral approximation to ``twist`` (m/s, m/s, rad/s) (non-negative
        least squares)."""
        return self._core.project_polyhedral(list(_vec(twist, 3, "twist")), "approx")

    def contains_polyhedral(self, twist: ArrayLike | Sequence[Sequence[float]]) -> bool | np.ndarray:
        """Membership in the polyhedral approximation of one twist (m/s, m/s, rad/s), or of each row of
        an (n, 3) array."""
        return self._core.contains_polyhedral(_vec_or_rows(twist, "twist"))

    def grip_force_range(self, twist: ArrayLike) -> Optional[tuple[float, float]]:
        """Per-finger grip forces [min, max] (max may be inf) for which the pusher motion of
        ``twist`` sticks (RSS 2018 Theorem 1), or None if no grip force does. A line pusher's
        motion is the whole twist; a point pusher's is only its contact point's velocity (the
        object's rotation rate then depends on the grip force, see ``point_pusher_twist``)."""
        return self._core.grip_force_range(list(_vec(twist, 3, "twist")))

    def min_grip_force(self, twist: ArrayLike) -> Optional[float]:
        """Smallest per-finger grip force [N] for which the pusher motion of ``twist`` (m/s, m/s, rad/s)
        sticks, or None if no grip force does."""
        r = self.grip_force_range(twist)
        return None if r is None else r[0]

    def central_twist(self) -> np.ndarray:
        """A twist well inside the gravity-free cone: the normalized sum of its generators."""
        s = self.scene.metric_twist(self.gravity_free_generators).sum(axis=0)
        return self.scene.metric_twist_inv(s / np.linalg.norm(s))

    def ray(self, wrench: ArrayLike) -> Optional[np.ndarray]:
        """Unit twist of the exact cone produced by pusher wrench ``wrench`` (or None)."""
        return self._core.ray(list(_vec(wrench, 3, "wrench")))

    def point_pusher_twist(self, u: ArrayLike) -> Optional[np.ndarray]:
        """Point pusher: object twist when its contact point moves with velocity ``u``."""
        return self._core.point_pusher_twist(list(_vec(u, 2, "u")))


_STATUS = dict(_core.Scene.status_messages())
_LIMITS = np.array(_core.Scene.limit_labels())


def _errors(status: np.ndarray) -> list:
    return [None if c == 0 else _STATUS[int(c)] for c in status]


@dataclass
class MotionConeBatch:
    """Motion cones of one pusher at many ``poses`` (n, 3) ``[x, z, theta]`` (m, m, rad),
    vectorized in Rust (no Python loop)."""

    scene: "Scene"
    pusher: str
    poses: np.ndarray  # (n, 3)
    generators: np.ndarray  # (n, k, 3), zeros where not valid
    status: np.ndarray  # (n,) uint8, 0 where valid

    @property
    def valid(self) -> np.ndarray:
        """Where each pose has a cone (status 0), bool array (n,)."""
        return self.status == 0

    @property
    def errors(self) -> list:
        """Reason per pose (None where valid)."""
        return _errors(self.status)

    def gravity_free_generators(self) -> np.ndarray:
        """Gravity-free generators at every pose: unit twists (m/s, m/s, rad/s), shape (n, k, 3)."""
        g, _ = self.scene._core.generators_many(self.poses, self.pusher, True)
        return g

    def classify(self, twists) -> dict:
        """Exact test of twist i (m/s, m/s, rad/s) at pose i: dict of arrays feasible, margin,
        active_limit, valid, and the errors (None where valid)."""
        t = _rows(twists, "twists")
        feas, margin, codes, status = self.scene._core.classify_many(self.poses, t, self.pusher)
        return {"feasible": feas, "margin": margin, "active_limit": _LIMITS[codes], "valid": status == 0,
                "errors": _errors(status)}

    def contains(self, twists: ArrayLike) -> NDArray[np.bool_]:
        """Exact test of twist i ``[vx, vz, omega]`` (m/s, m/s, rad/s) at pose i: bool array (n,)."""
        t = _rows(twists, "twists")
        return self.scene._core.classify_many(self.poses, t, self.pusher)[0]

    def margin(self, twists: ArrayLike) -> NDArray[np.float64]:
        """Signed margin of twist i (m/s, m/s, rad/s) at pose i in its exact cone, array (n,)."""
        t = _rows(twists, "twists")
        return self.scene._core.classify_many(self.poses, t, self.pusher)[1]

    def project(self, twists) -> np.ndarray:
        """Closest feasible twist (m/s, m/s, rad/s) to twist i at pose i, array (n, 3)."""
        t = _rows(twists, "twists")
        out, _ = self.scene._core.project_many(self.poses, t, self.pusher)
        return out


def _rebuild_scene(kind: str, text: str, path, ops=()):
    """The scene rebuilt from its source text and the views taken of it, in order (pickling)."""
    s = Scene.from_toml(text) if kind == "toml" else Scene(_core.Scene.from_json(text), None, ("json", text))
    s.path = None if path is None else Path(path)
    for name, kw in ops:
        s = getattr(s, name)(**kw)
    return s


def _non_finite(x, path: str):
    """Dotted path of the first non-finite number in a nested dict/list, or None."""
    if isinstance(x, dict):
        for k, v in x.items():
            r = _non_finite(v, f"{path}.{k}" if path else str(k))
            if r is not None:
                return r
    elif isinstance(x, (list, tuple, np.ndarray)):
        for i, v in enumerate(x):
            r = _non_finite(v, f"{path}[{i}]")
            if r is not None:
                return r
    elif isinstance(x, (float, np.floating)) and not np.isfinite(x):
        return path
    return None


def _jsonable(x):
    if isinstance(x, np.ndarray):
        return x.tolist()
    if isinstance(x, np.generic):
        return x.item()
    raise TypeError(f"{type(x).__name__} is not a scene value")


class Scene:
    """A validated planar scene. Load with :meth:`Scene.load` (TOML) or :meth:`Scene.from_dict`."""

    #: poses [x, z, theta]
    dimension = 2

    def __init__(self, core: "_core.Scene", path: Optional[Path] = None, source: Optional[tuple] = None):
        self._core = core
        self.path = path
        #: ("toml" | "json", text) the scene was built from (to rebuild it in other processes)
        self.source = source

    def __reduce__(self):
        if self.source is None:
            raise TypeError("this scene has no source text to be pickled from")
        kind, text = self.source
        return (_rebuild_scene, (kind, text, None if self.path is None else str(self.path),
                                 getattr(self, "_ops", ())))

    @classmethod
    def load(cls, path) -> "Scene":
        """The planar scene of a TOML scene file (docs/scene-file.md). Raises ArgumentError when
        ``path`` cannot be read, SceneError naming the field at fault."""
        p, text = read_scene_file(path)
        return cls(_core.Scene.from_toml(text), p, ("toml", text))

    @classmethod
    def from_toml(cls, text: str) -> "Scene":
        """A planar scene from the text of its TOML file. Raises SceneError naming the field at
        fault."""
        if not isinstance(text, str):
            raise ArgumentError(f"invalid `text`: the scene file's text, a str (got {type(text).__name__})", "text")
        return cls(_core.Scene.from_toml(text), None, ("toml", text))

    @classmethod
    def from_dict(cls, d: dict) -> "Scene":
        """A scene from a dict with the layout of the TOML file (numbers may be numpy scalars)."""
        if not isinstance(d, dict):
            raise ArgumentError(f"invalid `d`: a scene is a dict with the layout of the TOML file (got {type(d).__name__})", "d")
        bad = _non_finite(d, "")
        if bad is not None:
            raise SceneError(f"scene field `{bad}`: must be a finite number", bad)
        try:
            text = json.dumps(d, allow_nan=False, default=_jsonable)
        except (TypeError, ValueError, RecursionError) as e:
            raise SceneError(f"scene is not serializable: {e}", "(scene)") from e
        return cls(_core.Scene.from_json(text), None, ("json", text))

    def __repr__(self) -> str:
        return f"Scene({self.name!r}, kind={self.kind}, pushers={self.pusher_names})"

    def _repr_html_(self) -> str:
        """Jupyter's display: the browser view of the scene at its start, the goal dashed."""
        from ..viz.viewer import notebook_html

        return notebook_html(self)

    name = core_property("name", "The scene's name.")
    kind = core_property("kind", '"grasp" (object between finger pads) or "surface" (object on a plane).')
    pusher_names = core_property("pusher_names", "Names of the pushers, in file order (list of str).")
    notes = core_property("notes", "What the loader changed in the file's values: measured pusher points moved onto "
                                   "the outline (list of str, empty when nothing moved).")

    @property
    def pushers(self) -> list[Pusher]:
        """Every pusher of the scene, in file order."""
        out = []
        for n in self.pusher_names:
            pts, normal, mu = self._core.pusher(n)
            out.append(Pusher(n, np.asarray(pts), np.asarray(normal), mu))
        return out

    def pusher(self, name: str) -> Pusher:
        """Pusher ``name``; raises ArgumentError listing the names when there is none of that name."""
        pts, normal, mu = self._core.pusher(_name(name, "name"))
        return Pusher(name, np.asarray(pts), np.asarray(normal), mu)

    length = core_property("length", "Characteristic length L [m] weighing rotation against translation.")

    def metric_twist(self, twist) -> np.ndarray:
        """Twists ``[vx, vz, omega]`` (m/s, m/s, rad/s; rows) in the frame-invariant metric: [velocity
        of the COM (m/s), L omega (m/s)]. Norms,
        distances and projections of regrasp are Euclidean in these coordinates."""
        v = _twists(twist, "twist")
        c, L = self.com, self.length
        w = v[..., 2]
        return np.stack([v[..., 0] - w * c[1], v[..., 1] + w * c[0], L * w], axis=-1)

    def metric_twist_inv(self, scaled) -> np.ndarray:
        """Inverse of :meth:`metric_twist`."""
        s = _twists(scaled, "scaled")
        c, L = self.com, self.length
        w = s[..., 2] / L
        return np.stack([s[..., 0] + w * c[1], s[..., 1] - w * c[0], w], axis=-1)

    mass = core_property("mass", "Mass of the object [kg].")
    com = core_property("com", "Centre of mass ``[x, z]`` in the object frame [m], shape (2,).", wrap=np.array)
    outline = core_property("outline", "Vertices of the object's outline in the object frame [m], shape (n, 2).")

    @property
    def gravity(self) -> tuple[np.ndarray, float]:
        """Gravity: its unit direction ``[dx, dz]`` in the gripper frame and its magnitude g [m/s²]."""
        dx, dz, g = self._core.gravity
        return np.array([dx, dz]), g

    grip_force = core_property("grip_force", "Grip force per finger [N] (None on a surface scene).")
    #: a planar object is a lamina, never a sphere (:attr:`Scene3D.sphere`)
    sphere = None
    pad_friction = core_property("pad_friction", "The finger pads' Coulomb coefficient μ (None on a surface scene).")
    pad_limit_surface_k = core_property("pad_limit_surface_k", "The ``k`` of the support's limit surface: its "
                                                               "largest friction moment per unit μN [m].")

    def quasistatic_problem(self, pose, pusher, support, rings, points, merge_fingers, h, speed):
        """The core's instantaneous complementarity problem at ``pose`` (m, m, rad) with ``pusher``
        (None: none) in contact; arguments already checked (see
        :func:`regrasp.sim.quasistatic.problem`, the public door)."""
        return self._core.quasistatic_problem(list(map(float, pose)), pusher, support, rings, points, merge_fingers,
                                              h, speed)

    def simulate_push(self, pose, pusher: str, twist, duration: float, dt: float, support, rings, points,
                      merge_fingers) -> dict:
        """The core's time stepping of one push from ``pose`` (m, m, rad), the pusher moving with
        body ``twist`` (m/s, m/s, rad/s) for ``duration`` [s] in steps of ``dt`` [s] (arguments
        already checked; see :func:`regrasp.sim.quasistatic.simulate_push`, the public door)."""
        return self._core.simulate_push(list(map(float, pose)), pusher, list(map(float, twist)), duration, dt,
                                        support, rings, points, merge_fingers)

    def push_outcomes(self, poses, pusher: str, twists, support, rings, points, merge_fingers):
        """Whether each push (rows of ``poses`` (n, 3) (m, m, rad) and body ``twists`` (n, 3)
        (m/s, m/s, rad/s)) of ``pusher``
        sticks in the quasi-static simulator: (sticks, object twists, residuals, errors) (see
        :mod:`regrasp.mujoco.validation`)."""
        return self._core.push_outcomes(poses, pusher, twists, support, rings, points, merge_fingers)
    pad = core_property("pad", 'The finger pad: ``("circle", radius, radius)`` or ``("rectangle", width, '
                               'height)`` [m]; '
                               "None on a surface.")

    @property
    def task(self) -> Optional[Task]:
        """The scene's task (start, goal, tolerance), or None when the file has none."""
        t = self._core.task
        return None if t is None else Task(*(np.array(x) for x in t))

    def goal_error(self, pose, goal=None) -> tuple[np.ndarray, bool]:
        """The error ``pose − goal`` ``[x, z, theta]`` (m, m, rad; theta wrapped into [−π, π)) and
        whether it is within the task's tolerance (the core's default, 1 mm and 0.0175 rad, without
        a task); ``goal`` defaults to the task's. Decided once, in the core."""
        e, ok = self._core.goal_error(pose, goal)
        return np.array(e), bool(ok)

    def with_grip_force(self, force: float) -> "Scene":
        """The same scene with another grip force per finger (not re-validated: the task's
        poses may not be held at that force)."""
        force = _number(force, "force")
        return self._view(self._core.with_grip_force(force), "with_grip_force", force=force)

    def with_limit_surface(self, model: str) -> "Scene":
        """A copy whose motion cones use limit surface ``model``: ``"true"`` (the exact surface of
        the pad's or footprint's pressure) or ``"ellipsoid"`` (eq 3.7, the thesis' model)."""
        model = _name(model, "limit_surface")
        if model == self.limit_surface:
            return self
        return self._view(self._core.with_limit_surface(model), "with_limit_surface", model=model)

    limit_surface = core_property("limit_surface", 'The limit surface the motion cones use: "true" (exact) or '
                                                   '"ellipsoid" (eq 3.7).')

    def _view(self, core, op: str, **kw) -> "Scene":
        """A view of this scene (a new core) that remembers how it was taken, so it pickles."""
        s = Scene(core, self.path, self.source)
        s._ops = tuple(getattr(self, "_ops", ())) + ((op, kw),)  # type: ignore[attr-defined]
        return s

    mode = core_property("mode", 'Which motion cones this scene answers with: "nominal", "robust" or "fixtureless".')
    uncertainty = core_property("uncertainty", "The ``[uncertainty]`` table (relative spreads), or None.")
    rho = core_property("rho", "ρ = μ_s N / (m g), the one number mass, grip force and finger friction enter the "
                               "planar motion cone through (grasp scenes with gravity; None otherwise).")

    def scaled(self, finger_friction: float = 1.0, grip: float = 1.0, mass: float = 1.0,
               pusher_friction: float = 1.0, mode: str = "nominal") -> "Scene":
        """A copy with the finger friction, grip force, mass and every pusher's friction
        multiplied by the given factors, answering with the cones of ``mode``."""
        f = {k: _number(v, k) for k, v in dict(finger_friction=finger_friction, grip=grip, mass=mass,
                                                pusher_friction=pusher_friction).items()}
        core = self._core.scaled(f["finger_friction"], f["grip"], f["mass"], f["pusher_friction"], _name(mode, "mode"))
        return self._view(core, "scaled", finger_friction=finger_friction, grip=grip, mass=mass,
                          pusher_friction=pusher_friction, mode=mode)

    def robust(self, uncertainty: Optional[dict] = None) -> "Scene":
        """The robust view (thesis §5.1): the worst case of the ranges (ρ_min = μ_s,min N_min /
        (m_max g), lowest pusher friction) whose cones are V(ρ_min) ∩ V_gf — the pushes that
        stick for every value in the ranges. ``uncertainty``: relative spreads
        ``{"pusher_friction", "finger_friction", "grip_force", "mass"}`` (default: the scene's
        ``[uncertainty]`` table)."""
        if uncertainty is not None and not isinstance(uncertainty, dict):
            raise ArgumentError(f"invalid `uncertainty`: a dict of relative spreads (got {uncertainty!r:.60})", "uncertainty")
        u = dict(self.uncertainty or {}) if uncertainty is None else dict(uncertainty)
        if uncertainty is None and self.uncertainty is None:
            raise ArgumentError("invalid `uncertainty`: the scene has no [uncertainty] table; give the spreads", "uncertainty")
        keys = ("pusher_friction", "finger_friction", "grip_force", "mass")
        for k, v in u.items():
            if k not in keys:
                raise ArgumentError(f"invalid `uncertainty.{k}`: unknown (expected {', '.join(keys)})", f"uncertainty.{k}")
            if not (isinstance(v, (int, float)) and not isinstance(v, bool) and 0 <= v < 1):
                raise ArgumentError(f"invalid `uncertainty.{k}`: must be a relative spread in [0, 1) (got {v!r})",
                                    f"uncertainty.{k}")
        f = {k: float(u.get(k, 0.0)) for k in keys}
        s = self.scaled(1 - f["finger_friction"], 1 - f["grip_force"], 1 + f["mass"], 1 - f["pusher_friction"], "robust")
        return s

    def mpc(self, poses, pushers, goal=None, **settings):
        """The MPC of thesis §5.2 (the core's ``Mpc``) tracking the plan ``poses`` (n, 3) [m, m, rad]
        with ``pushers`` (n names) in this scene's cones, towards ``goal`` (default: the task's);
        ``settings`` (``dt`` [s], ``horizon``, ``speed`` [m/s], weights, ``seed``...) default to
        :func:`~regrasp.scene.settings.mpc_defaults`."""
        return _core.Mpc(self._core, poses, pushers, goal, **settings)

    def fixtureless(self) -> "Scene":
        """Fixtureless fixturing (CASE 2018): only pushes by pushers that carry the object's
        weight, inside their gravity-free cones — invariant to mass, grip force and finger
        friction; the object stays put against the feature while the fingers slide over it."""
        return self._view(self._core.scaled(1.0, 1.0, 1.0, 1.0, "fixtureless"), "fixtureless")

    def carries_weight(self, pose, pusher: str) -> bool:
        """Whether ``pusher`` alone can carry the object's weight at ``pose`` ``[x, z, theta]``
        (m, m, rad) (the invariant case
        of §5.1: its gravity-free pushes stick for any mass, grip force and finger friction)."""
        return self._core.carries_weight(list(_vec(pose, 3, "pose")), _name(pusher, "pusher"))

    def admissible(self, pose) -> bool | np.ndarray:
        """Whether the whole finger pad lies on the object at ``pose`` ``[x, z, theta]`` (m, m, rad)
        (or at each row of an (n, 3) array: a bool array)."""
        a = _array(pose, "pose")
        if a.ndim == 2:
            return self._core.admissible_many(_rows(a, "pose"))
        return self._core.admissible(list(_vec(a, 3, "pose")))

    def hold_ratio(self, pose) -> float:
        """Share of the support's friction that gravity alone uses at ``pose`` ``[x, z, theta]``
        (m, m, rad) (< 1 holds). Raises ArgumentError when the pose is not admissible."""
        q = _vec(pose, 3, "pose")
        if not self.admissible(q):
            raise ArgumentError(f"invalid `pose`: {q.tolist()} is not admissible: the finger pad is not entirely on the object", "pose")
        return self._core.hold_ratio(list(q))

    def hold_grip_force(self, pose) -> Optional[float]:
        """Smallest per-finger grip force [N] that holds the object against gravity at ``pose``
        ``[x, z, theta]`` (m, m, rad); None on a surface scene."""
        if self.grip_force is None:
            return None
        return self.grip_force * self.hold_ratio(pose)

    def load_ratio(self, pose, wrench) -> float | np.ndarray:
        """Share of the support's friction that the object-frame wrench ``wrench`` ``[fx, fz, τ]``
        (N, N, N·m about the object's origin, like gravity's) uses at ``pose`` ``[x, z, theta]``
        (m, m, rad), on the limit surface the cones use; rows of (n, 3) arrays give an (n,) array.
        Gravity's is :meth:`hold_ratio`; an arm's motion adds its inertial load. < 1: the pads
        supply the wrench's opposite without slipping."""
        q, w = _array(pose, "pose"), _array(wrench, "wrench")
        if q.ndim == 2 or w.ndim == 2:
            return self._core.load_ratios(_rows(q, "pose"), _rows(w, "wrench"))
        return float(self._core.load_ratios([list(_vec(q, 3, "pose"))], [list(_vec(w, 3, "wrench"))])[0])

    def motion_cone(self, pose, pusher: str, check_hold: bool = True) -> MotionCone:
        """The motion cone of ``pusher`` at ``pose`` ``[x, z, theta]`` (m, m, rad). Raises GraspError
        when the grasp cannot hold the object there (pass ``check_hold=False`` for gravity-free and grip-force queries)."""
        q = plain_numbers(pose, 3) or list(_vec(pose, 3, "pose"))
        return MotionCone(self._core.motion_cone(q, _name(pusher, "pusher"), _flag(check_hold, "check_hold")), self)

    def gravity_free_cone(self, pose, pusher: str) -> GravityFreeCone:
        """The gravity-free cone of ``pusher`` at ``pose`` ``[x, z, theta]`` (m, m, rad) (no hold
        check)."""
        return self.motion_cone(pose, pusher, check_hold=False).gravity_free

    def motion_cones(self, poses, pusher: str, strict: bool = False) -> MotionConeBatch:
        """Motion cones at many ``poses`` (n, 3) ``[x, z, theta]`` (m, m, rad). With ``strict`` the
        first invalid pose raises ArgumentError; else its status says why."""
        q = _rows(poses, "poses")
        g, status = self._core.generators_many(q, _name(pusher, "pusher"), False)
        strict = _flag(strict, "strict")
        if strict and status.any():
            i = int(np.flatnonzero(status)[0])
            raise ArgumentError(f"invalid `poses[{i}]`: {_STATUS[int(status[i])]}", f"poses[{i}]")
        return MotionConeBatch(self, pusher, q, g, status)
