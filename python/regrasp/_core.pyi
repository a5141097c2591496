"""The compiled core of regrasp: scenes, motion cones, quasi-static dynamics, planning, control
and SE(3) pose algebra (the Python API wraps it: `regrasp.Scene`, `regrasp.plan`, ...).
Units are SI (m, rad, N, kg, s)."""

# Stubs of the compiled module (crates/regrasp-py). Arguments are checked at run time (an
# ArgumentError naming the argument); the annotations give what each one means. Planar poses are
# [x, z, theta] (m, m, rad), planar twists [vx, vz, omega] (m/s, m/s, rad/s); 3-D poses
# [x, y, z, qw, qx, qy, qz] (m, unit quaternion), 3-D body twists [vx, vy, vz, wx, wy, wz]
# (m/s, rad/s). The docstrings are the bindings' doc comments (tests/test_types.py checks that
# they agree).

from typing import Any, Sequence, final

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "Scene",
    "MotionCone",
    "MncpProblem",
    "Scene3D",
    "Mpc",
    "planner_defaults",
    "mpc_defaults",
    "quasistatic_defaults",
    "validation_rings",
    "limit_surface_default",
    "se3_log",
    "se3_integrate",
    "se3_compose",
    "se3_inverse",
    "MAX_MAGNITUDE",
    "LIMITS",
    "__version__",
]

__version__: str
MAX_MAGNITUDE: float
LIMITS: dict[str, float]

_Floats = NDArray[np.float64]
_Bools = NDArray[np.bool_]
_Codes = NDArray[np.uint8]
_Names = Sequence[str | None]

@final
class Scene:
    """A validated planar scene (immutable)."""

    @staticmethod
    def from_toml(text: str) -> Scene:
        """Parse and validate a scene from TOML text."""
    @staticmethod
    def from_json(text: str) -> Scene:
        """Parse and validate a scene from JSON text (same layout as the TOML file)."""
    @property
    def name(self) -> str:
        """The scene's name."""
    @property
    def kind(self) -> str:
        """"grasp" (object between finger pads) or "surface" (object on a plane)."""
    @property
    def pusher_names(self) -> list[str]:
        """Names of the pushers, in file order."""
    @property
    def notes(self) -> list[str]:
        """What the loader changed in the file's values (pusher points snapped onto the outline)."""
    @property
    def length(self) -> float:
        """Characteristic length L [m] weighing rotation against translation."""
    @property
    def mass(self) -> float:
        """Mass of the object [kg]."""
    @property
    def com(self) -> tuple[float, float]:
        """Centre of mass `(x, z)` in the object frame [m]."""
    @property
    def gravity(self) -> tuple[float, float, float]:
        """Gravity: `(dx, dz, g)`, its unit direction in the gripper frame and magnitude g [m/s²]."""
    @property
    def grip_force(self) -> float | None:
        """Grip force per finger [N] (None on a surface)."""
    @property
    def friction_scale(self) -> float:
        """The support's friction force capacity [N]: 2μN between the pads, μ·m·g·cos(incline) on
        a surface (what the motion cones scale the pushers' wrenches by)."""
    @property
    def pad_friction(self) -> float | None:
        """The finger pads' Coulomb coefficient μ (None on a surface)."""
    @property
    def outline(self) -> _Floats:
        """Vertices of the outline in the object frame [m], shape (n, 2)."""
    @property
    def pad_limit_surface_k(self) -> float:
        """The `k` of the support's limit surface (its largest friction moment per unit μN)."""
    @property
    def pad(self) -> tuple[str, float, float] | None:
        """Pad description: ("circle", radius, radius) or ("rectangle", width, height); None on a surface."""
    def pusher(self, name: str) -> tuple[_Floats, tuple[float, float], float]:
        """Pusher `name`: (points (k, 2), normal (2,), friction)."""
    @property
    def task(self) -> tuple[list[float], list[float], list[float]] | None:
        """(start, goal, tolerance) or None."""
    def goal_error(self, pose: ArrayLike, goal: ArrayLike | None = None) -> tuple[list[float], bool]:
        """The error `pose − goal` `[x, z, theta]` (m, m, rad; theta wrapped into [−π, π)) and
        whether it is within the task's tolerance (the default tolerance without a task);
        `goal` defaults to the task's."""
    def admissible(self, pose: ArrayLike) -> bool:
        """Whether the whole finger pad lies on the object at `pose` `[x, z, theta]` (m, m, rad)."""
    def admissible_many(self, poses: ArrayLike) -> _Bools:
        """`admissible` at each row of `poses` (n, 3) (m, m, rad): a bool array."""
    def hold_ratio(self, pose: ArrayLike) -> float:
        """Share of the support's friction that gravity alone uses at `pose` `[x, z, theta]` (m, m, rad)
        (< 1 holds)."""
    def load_ratios(self, poses: ArrayLike, wrenches: ArrayLike) -> _Floats:
        """The share of the support's friction each object-frame wrench row of `wrenches` (n, 3) (N, N,
        N·m about the object's origin) uses at the pose row of `poses` (n, 3) (m, m, rad): (n,)."""
    def with_grip_force(self, force: float) -> Scene:
        """The same scene with grip force `force` [N] per finger (grasp scenes)."""
    def with_limit_surface(self, model: str) -> Scene:
        """A copy whose motion cones use limit surface `model`, "true" or "ellipsoid"."""
    @property
    def limit_surface(self) -> str:
        """The limit surface the motion cones use: "true" or "ellipsoid"."""
    def motion_cone(self, pose: ArrayLike, pusher: str, check_hold: bool | None = None) -> MotionCone:
        """The motion cone of pusher `pusher` at `pose` `[x, z, theta]` (m, m, rad) (raises GraspError if the grasp cannot
        hold, unless `check_hold` is False)."""
    def generators_many(self, poses: ArrayLike, pusher: str, gravity_free: bool) -> tuple[_Floats, _Codes]:
        """Polyhedral (or gravity-free) generators at many `poses` (n, 3) (m, m, rad): (generators (n, k, 3),
        status (n,) uint8; 0 = ok, see `status_messages`)."""
    def classify_many(self, poses: ArrayLike, twists: ArrayLike, pusher: str) -> tuple[_Bools, _Floats, _Codes, _Codes]:
        """Exact test of twist i (m/s, m/s, rad/s) at pose i (m, m, rad): (feasible, margin, active-limit codes, status)."""
    def project_many(self, poses: ArrayLike, twists: ArrayLike, pusher: str) -> tuple[_Floats, _Codes]:
        """Closest feasible twist to twist i (m/s, m/s, rad/s) at pose i (m, m, rad): (projections (n, 3), status)."""
    @staticmethod
    def limit_labels() -> list[str]:
        """Labels of the contact-limit codes returned by `classify_many`."""
    @staticmethod
    def status_messages() -> list[tuple[int, str]]:
        """Messages of the batch status codes."""
    def quasistatic_problem(
        self,
        pose: ArrayLike,
        pusher: str | None = None,
        support: str | None = None,
        rings: int | None = None,
        points: int | None = None,
        merge_fingers: bool | None = None,
        h: float | None = None,
        speed: float | None = None,
    ) -> MncpProblem:
        """The quasi-static problem of `pusher` (or no pusher) at `pose` (m, m, rad), time step `h` [s],
        pusher `speed` [m/s]; the options default to
        `quasistatic_defaults()`."""
    def push_outcomes(
        self,
        poses: ArrayLike,
        pusher: str,
        twists: ArrayLike,
        support: str | None = None,
        rings: int | None = None,
        points: int | None = None,
        merge_fingers: bool | None = None,
    ) -> tuple[_Bools, _Floats, _Floats, list[str | None]]:
        """Instantaneous pushes: pusher `pusher` at pose i (m, m, rad) moving with twist i (m/s, m/s,
        rad/s; object frame).
        Returns (sticks (n,), object twists (n, 3), max residual (n,), errors (None if solved))."""
    def simulate_push(
        self,
        pose: ArrayLike,
        pusher: str,
        twist: ArrayLike,
        duration: float,
        dt: float,
        support: str | None = None,
        rings: int | None = None,
        points: int | None = None,
        merge_fingers: bool | None = None,
    ) -> dict[str, Any]:
        """Explicit time stepping of one push from `pose` (m, m, rad): pusher body `twist` (m/s, m/s,
        rad/s) constant (object frame at t = 0) for `duration` [s] in steps of `dt` [s]."""
    def plan(
        self, start: ArrayLike | None = None, goal: ArrayLike | None = None, settings: dict[str, Any] | None = None
    ) -> dict[str, Any]:
        """T-RRT* regrasp plan (see `regrasp.plan`): `settings` overrides the defaults of
        `planner_defaults(2)`. Returns a dict."""
    def validate_path(self, poses: ArrayLike, pushers: _Names, checks: int | None = None) -> list[float]:
        """Smallest exact-test margin along each step of a path (poses, pusher names), checked at
        `checks` poses a step (default: the planner's `checks`)."""
    @property
    def mode(self) -> str:
        """The cone mode: "nominal", "robust" or "fixtureless"."""
    @property
    def uncertainty(self) -> dict[str, float] | None:
        """The `[uncertainty]` table as a dict of relative spreads (None when absent)."""
    @property
    def rho(self) -> float | None:
        """`ρ = μ_s N / (m g)` (grasp scenes)."""
    def scaled(
        self,
        finger_friction: float | None = None,
        grip: float | None = None,
        mass: float | None = None,
        pusher_friction: float | None = None,
        mode: str | None = None,
    ) -> Scene:
        """A copy with scaled parameters and a cone mode (see `regrasp.robust`; default: the
        nominal cone)."""
    def carries_weight(self, q: ArrayLike, pusher: str) -> bool:
        """Whether pusher `pusher` alone can carry the object's weight at pose `q` (the invariant case)."""

@final
class MotionCone:
    """The motion cone of one pusher at one pose."""

    @property
    def pusher(self) -> str:
        """Name of the pusher."""
    @property
    def pose(self) -> list[float]:
        """The pose `[x, z, theta]` (m, m, rad)."""
    @property
    def length(self) -> float:
        """Characteristic length L [m] of the twist metric diag(1, 1, L²)."""
    @property
    def hold_ratio(self) -> float:
        """Share of the pads' friction that gravity alone uses (< 1 holds)."""
    @property
    def line(self) -> bool:
        """Whether the pusher is a line pusher (two rigidly connected points)."""
    @property
    def generators(self) -> _Floats:
        """Generators of the polyhedral approximation, one unit twist a row."""
    @property
    def gravity_free_generators(self) -> _Floats:
        """Generators of the gravity-free cone, one unit twist (m/s, m/s, rad/s) a row."""
    @property
    def pusher_edges(self) -> _Floats:
        """Edge wrenches of the pusher's generalized friction cone (unit normal force), one a row."""
    @property
    def boundary_segments(self) -> list[tuple[int, int]]:
        """Pairs of edge indices spanning the boundary fans of the pusher's friction cone."""
    @property
    def support_matrices(self) -> tuple[_Floats, _Floats, _Floats]:
        """The ellipsoidal limit-surface matrix A (eq 3.7, support frame; the cones use it only on
        the ellipsoid), J_s and the gravity wrench."""
    def ray(self, wrench: ArrayLike) -> _Floats | None:
        """Motion-cone ray (unit twist) produced by pusher wrench `wrench` `[fx, fz, tau]` (N, N, N·m),
        or None."""
    def classify(self, twist: ArrayLike) -> dict[str, Any]:
        """Exact test of one twist `[vx, vz, omega]` (m/s, m/s, rad/s): dict(feasible, margin,
        active_limit, pusher_wrench, support_wrench), wrenches `[fx, fz, tau]` (N, N, N·m)."""
    def margin(self, twist: ArrayLike) -> float | _Floats:
        """Signed margins of one twist `[vx, vz, omega]` (m/s, m/s, rad/s) or of an (n, 3) array of twists."""
    def contains(self, twist: ArrayLike) -> bool | _Bools:
        """Exact membership of one twist (m/s, m/s, rad/s) or of an (n, 3) array of twists."""
    def contains_polyhedral(self, twist: ArrayLike) -> bool | _Bools:
        """Membership in the polyhedral approximation, of one twist (m/s, m/s, rad/s) or an (n, 3) array."""
    def gravity_free_margin(self, twist: ArrayLike) -> float:
        """Margin of a twist (m/s, m/s, rad/s) in the gravity-free cone (exact, polyhedral)."""
    def project(self, twist: ArrayLike) -> _Floats:
        """Closest feasible twist (m/s, m/s, rad/s; metric diag(1, 1, L²)), exact cone, to one twist
        or to each row of an (n, 3) array."""
    def project_polyhedral(self, twist: ArrayLike, which: str | None = None) -> _Floats:
        """Closest twist (m/s, m/s, rad/s) in a polyhedral cone: `which` "approx" (default) or
        "gravity_free"."""
    def grip_force_range(self, twist: ArrayLike) -> tuple[float, float] | None:
        """Per-finger grip-force range (min, max) [N] for which the pusher motion of `twist`
        (m/s, m/s, rad/s) sticks, or None."""
    def point_pusher_twist(self, u: ArrayLike) -> _Floats | None:
        """Point pushers: object twist (m/s, m/s, rad/s) when the contact point moves with velocity
        `u` [m/s] (object frame), or None."""
    @property
    def pusher_cone_shape(self) -> str:
        """Shape of the pusher's friction cone: "solid", "fan", "ray" or "full"."""

@final
class MncpProblem:
    """One instantaneous quasi-static problem (thesis §3.2): contacts, mass matrix, gravity."""

    @property
    def dim(self) -> int:
        """Dimension of the twists: 3 (planar) or 6 (3-D)."""
    @property
    def labels(self) -> list[str]:
        """The contacts' labels, in order."""
    def solve_forward(self, pusher_twist: ArrayLike) -> dict[str, Any]:
        """Forward problem: the pusher twist `pusher_twist` (m/s, rad/s) given; returns the solution
        as a dict (twists in m/s and rad/s, forces in N)."""
    def solve_inverse(self, twist: ArrayLike) -> dict[str, Any]:
        """Inverse problem: the object twist `twist` (m/s, rad/s) given; returns the pusher motion
        (m/s, rad/s) and the forces (N) as a dict."""
    def residuals(
        self, twist: ArrayLike, pusher_twist: ArrayLike, normal_forces: ArrayLike, friction_forces: Sequence[ArrayLike]
    ) -> dict[str, float]:
        """Scaled violation of every constraint for a candidate solution (e.g. the reference's):
        twists (m/s, rad/s), normal and friction forces (N)."""
    def data(self) -> dict[str, Any]:
        """The problem's data (for the reference solver and for inspection)."""

@final
class Scene3D:
    """A validated 3-D scene (box or convex mesh object)."""

    @staticmethod
    def from_toml(text: str, base: str | None = None) -> Scene3D:
        """Parse and validate a 3-D scene; `base` is the folder mesh paths are relative to."""
    @property
    def name(self) -> str:
        """The scene's name."""
    @property
    def pusher_names(self) -> list[str]:
        """Names of the pushers, in file order."""
    @property
    def notes(self) -> list[str]:
        """What the loader changed in the file's values (pusher points snapped onto the surface)."""
    @property
    def length(self) -> float:
        """Characteristic length L [m] weighing rotation against translation."""
    @property
    def mass(self) -> float:
        """Mass of the object [kg]."""
    @property
    def inertia(self) -> _Floats:
        """Inertia about the centre of mass, object frame [kg·m²], shape (3, 3)."""
    @property
    def task(self) -> tuple[list[float], list[float], list[float]]:
        """(start, goal, tolerance): poses `[x, y, z, qw, qx, qy, qz]` (m, unit quaternion) and the
        tolerance `[x, y, z, angle]` (m, m, m, rad)."""
    @property
    def com(self) -> list[float]:
        """Centre of mass in the object frame [m]."""
    @property
    def grip_force(self) -> float:
        """Grip force per finger [N]."""
    @property
    def grip_friction(self) -> float:
        """Friction coefficient of the finger pads."""
    @property
    def gravity(self) -> list[float]:
        """Gravity vector in the gripper frame [m/s²]."""
    def pusher_spec(self, name: str, pose: ArrayLike | None = None) -> tuple[list[list[float]], list[float], float]:
        """Pusher `name` brought against the object at `pose` (default: the task's start): (contact
        points and normal in the object frame, friction). A rigid pusher's points do not depend
        on the pose; a plane's are where the object is lowest along its normal."""
    def pusher_normal(self, name: str) -> list[float]:
        """Pusher `name`'s normal as the scene gives it (object frame; a plane's: gripper frame)."""
    def is_plane(self, name: str) -> bool:
        """Whether pusher `name` is a plane (its normal fixed in the gripper frame)."""
    def goal_error(self, pose: ArrayLike, goal: ArrayLike | None = None) -> tuple[list[float], bool]:
        """The error of `pose` `[x, y, z, qw, qx, qy, qz]` to `goal` (default: the task's),
        `[dx, dy, dz, angle]` (m, m, m, rad), and whether it is within the task's tolerance."""
    @property
    def sphere(self) -> float | None:
        """The sphere's radius, for a spherical object (else None)."""
    def plan(
        self, start: ArrayLike | None = None, goal: ArrayLike | None = None, settings: dict[str, Any] | None = None
    ) -> dict[str, Any]:
        """T-RRT* over SE(3) with inverse-dynamics unit steps (`regrasp::planning::spatial`):
        `settings` overrides the defaults of `planner_defaults(3)`. Returns a dict like the
        planar plan (poses as [x, y, z, qw, qx, qy, qz]) plus the number of solves."""
    def validate_path(self, poses: ArrayLike, pushers: _Names, twists: ArrayLike | None = None) -> list[bool]:
        """Whether each step of a path (poses (m, unit quaternion), pusher names, optional pusher
        `twists` (m/s, rad/s)) can be taken by its pusher (inverse
        dynamics at 8 poses along it, pads on the object)."""
    def pusher_points(self, name: str, pose: ArrayLike | None = None) -> list[list[float]]:
        """Contact points (object frame) of pusher `name` at `pose` (default: the task's start)."""
    @property
    def pad_radius(self) -> float:
        """Radius of the finger pads [m]."""
    def mesh(self) -> tuple[_Floats, NDArray[np.uint32]]:
        """Vertices (n, 3) and triangles (m, 3) of the object's mesh (a non-convex object's convex
        hull)."""
    def parts(self) -> list[tuple[_Floats, NDArray[np.uint32]]]:
        """The object's convex parts, each its vertices (n, 3) and triangles (m, 3): the mesh alone
        for a convex object."""
    def pad_contacts(self, pose: ArrayLike) -> list[list[list[float]]]:
        """Contact points (object frame, m) of the two finger pads at `pose` `[x, y, z, qw, qx, qy, qz]`
        (m, unit quaternion)."""
    def quasistatic_problem(self, pose: ArrayLike, pusher: str, h: float | None = None) -> MncpProblem:
        """The quasi-static problem of `pusher` in contact at its points, at `pose`, with time
        step `h` (default: the quasi-static model's, `quasistatic_defaults()["h"]`)."""
    def simulate_push(self, pose: ArrayLike, pusher: str, twist: ArrayLike, duration: float, dt: float) -> dict[str, Any]:
        """Time stepping of one push from `pose` (m, unit quaternion): pusher body `twist` `[v, ω]`
        (m/s, rad/s) constant (object frame at t = 0) for `duration` [s] in steps of `dt` [s]."""

@final
class Mpc:
    """The MPC controller (Rust `regrasp::control::mpc`): a plan's reference, the scene's cones.
    Its state is behind a mutex: any thread may use it, one at a time (a call while another
    thread's is running is an `ArgumentError`, never a wait that could hold the GIL)."""

    def __new__(
        cls,
        scene: Scene,
        poses: ArrayLike,
        pushers: _Names,
        goal: ArrayLike | None = None,
        dt: float | None = None,
        horizon: int | None = None,
        speed: float | None = None,
        stage_weight: float | None = None,
        terminal_weight: float | None = None,
        effort_weight: float | None = None,
        margin: float | None = None,
        stall_steps: int | None = None,
        max_replans: int | None = None,
        replan_time_limit: float | None = None,
        seed: int | None = None,
        **settings: Any,
    ) -> Mpc: ...
    def step(self, pose: ArrayLike) -> dict[str, Any]:
        """One control step from the measured pose `pose` `[x, z, theta]` (m, m, rad): a dict with
        status, pusher, twist (m/s, m/s, rad/s), knot, tracking_error, projected, solve_time_s and
        replan_time_s (s)."""
    def solve_qp(self, pose: ArrayLike, knot: int) -> tuple[list[dict[str, Any]], bool]:
        """The QP at pose `pose` `[x, z, theta]` (m, m, rad) with the reference after knot `knot`: per horizon step a dict with
        the pusher, generators (k, 3) and weights (k,); and whether clarabel solved it."""
    @property
    def knots(self) -> _Floats:
        """Reference knots (n, 3)."""
    @property
    def knot_pushers(self) -> list[str | None]:
        """The pusher reaching each knot."""
    @property
    def replans(self) -> int:
        """Re-plans made so far."""
    @property
    def replan_error(self) -> str | None:
        """Why the last re-planning failed (None if it did not)."""

def planner_defaults(dimension: int) -> dict[str, Any]:
    """The planner's default settings for scenes of `dimension` 2 or 3 (the Rust `Default`s)."""

def mpc_defaults() -> dict[str, Any]:
    """The MPC's default settings (`regrasp::control::mpc::MpcSettings::default()`): the keywords
    `_core.Mpc` takes, `replan_time_limit` and `seed` being those of its re-planning."""

def limit_surface_default() -> str:
    """The limit surface a scene's motion cones use when its file does not say
(`regrasp::mechanics::limit_surface::SurfaceModel::default()`): "true" or "ellipsoid"."""
def quasistatic_defaults() -> dict[str, Any]:
    """The quasi-static model's default options (`regrasp::dynamics::planar::Options::default()`):
    the keywords of the planar `quasistatic_problem`, `push_outcomes` and `simulate_push`."""

def validation_rings() -> int:
    """Rings of the point-set pads that `regrasp validate` simulates unless told
    (`regrasp::dynamics::planar::VALIDATION_RINGS`)."""

def se3_log(a: ArrayLike, b: ArrayLike) -> list[float]:
    """The constant body twist taking pose `a` to pose `b` in unit time (SE(3) log)."""

def se3_integrate(pose: ArrayLike, twist: ArrayLike, t: float) -> list[float]:
    """`pose ∘ exp(t · twist)`: `pose` `[x, y, z, qw, qx, qy, qz]` (m, unit quaternion), body
    `twist` `[vx, vy, vz, wx, wy, wz]` (m/s, rad/s), `t` [s] (SE(3) exp)."""

def se3_compose(a: ArrayLike, b: ArrayLike) -> list[float]:
    """`a ∘ b` of two poses."""

def se3_inverse(a: ArrayLike) -> list[float]:
    """`a⁻¹`."""
