//! The planar `Scene` (`regrasp::scene::planar`): its fields, its admissible poses, its
//! variants (grip force, robust scaling), and the entry points of the later pipeline stages
//! (cones, dynamics, planning), whose conversion lives in their own modules.

use crate::cones::{self, Classified, Generated, MotionCone, Projected};
use crate::convert::{Arg, arg, array1, opt, pose3, positive, pusher, rows, rows_array};
use crate::dynamics::{self, MncpProblem, Outcomes, PushArgs};
use crate::errors::{arg_err, guard, to_py};
use crate::{planning, settings};
use numpy::{PyArray1, PyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use regrasp::cones::robust::ConeMode;
use regrasp::mechanics::geometry::Vec3;
use regrasp::mechanics::limit_surface::SurfaceModel;
use regrasp::scene::perturb;
use regrasp::scene::planar::{PadShape, Support};
use std::collections::HashMap;

/// A validated planar scene (immutable).
#[pyclass(module = "regrasp._core", frozen)]
pub struct Scene {
    pub inner: regrasp::Scene,
}

/// A planar pusher: its points (k, 2), its normal and its friction coefficient.
type PusherSpec<'py> = (Bound<'py, PyArray2<f64>>, (f64, f64), f64);

/// The support options among the arguments of the quasi-static entry points.
fn support<'a, 'py>(
    support: Option<&'a Arg<'py>>,
    rings: Option<&'a Arg<'py>>,
    points: Option<&'a Arg<'py>>,
    merge_fingers: Option<&'a Arg<'py>>,
) -> [(&'static str, Option<&'a Arg<'py>>); 4] {
    [("support", support), ("rings", rings), ("points", points), ("merge_fingers", merge_fingers)]
}

#[pymethods]
impl Scene {
    /// Parse and validate a scene from TOML text.
    #[staticmethod]
    fn from_toml(text: &Arg<'_>) -> PyResult<Self> {
        guard(move || {
            regrasp::Scene::from_toml_str(&arg::<String>("text", text)?).map(|inner| Self { inner }).map_err(to_py)
        })
    }

    /// Parse and validate a scene from JSON text (same layout as the TOML file).
    #[staticmethod]
    fn from_json(text: &Arg<'_>) -> PyResult<Self> {
        guard(move || {
            regrasp::Scene::from_json_str(&arg::<String>("text", text)?).map(|inner| Self { inner }).map_err(to_py)
        })
    }

    /// The scene's name.
    #[getter] fn name(&self) -> String { self.inner.name.clone() }
    /// "grasp" (object between finger pads) or "surface" (object on a plane).
    #[getter]
    fn kind(&self) -> &'static str {
        match self.inner.support {
            Support::Grasp(_) => "grasp",
            Support::Surface(_) => "surface",
        }
    }
    /// Names of the pushers, in file order.
    #[getter] fn pusher_names(&self) -> Vec<String> { self.inner.pushers.iter().map(|p| p.name.clone()).collect() }
    /// What the loader changed in the file's values (pusher points snapped onto the outline).
    #[getter] fn notes(&self) -> Vec<String> { self.inner.notes().to_vec() }
    /// Characteristic length L [m] weighing rotation against translation.
    #[getter] fn length(&self) -> f64 { self.inner.length }
    /// Mass of the object [kg].
    #[getter] fn mass(&self) -> f64 { self.inner.mass }
    /// Centre of mass `(x, z)` in the object frame [m].
    #[getter] fn com(&self) -> (f64, f64) { (self.inner.com.x, self.inner.com.y) }
    /// Gravity: `(dx, dz, g)`, its unit direction in the gripper frame and magnitude g [m/s²].
    #[getter] fn gravity(&self) -> (f64, f64, f64) { (self.inner.gravity_dir.x, self.inner.gravity_dir.y, self.inner.g) }
    /// Grip force per finger [N] (None on a surface).
    #[getter] fn grip_force(&self) -> Option<f64> { self.inner.grip_force() }
    /// The support's friction force capacity [N]: 2μN between the pads, μ·m·g·cos(incline) on
    /// a surface (what the motion cones scale the pushers' wrenches by).
    #[getter] fn friction_scale(&self) -> f64 { self.inner.friction_scale() }
    /// The finger pads' Coulomb coefficient μ (None on a surface).
    #[getter]
    fn pad_friction(&self) -> Option<f64> {
        match &self.inner.support {
            Support::Grasp(g) => Some(g.friction),
            Support::Surface(_) => None,
        }
    }
    /// Vertices of the outline in the object frame [m], shape (n, 2).
    #[getter]
    fn outline<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        rows_array(py, self.inner.outline.vertices().iter().map(|p| [p.x, p.y]).collect())
    }
    /// The `k` of the support's limit surface (its largest friction moment per unit μN).
    #[getter]
    fn pad_limit_surface_k(&self) -> f64 {
        match &self.inner.support {
            Support::Grasp(g) => g.limit_surface.k(),
            Support::Surface(s) => s.limit_surface.k(),
        }
    }
    /// Pad description: ("circle", radius, radius) or ("rectangle", width, height); None on a surface.
    #[getter]
    fn pad(&self) -> Option<(&'static str, f64, f64)> {
        match &self.inner.support {
            Support::Grasp(g) => Some(match g.pad {
                PadShape::Circle { radius } => ("circle", radius, radius),
                PadShape::Rectangle { width, height } => ("rectangle", width, height),
            }),
            Support::Surface(_) => None,
        }
    }
    /// Pusher `name`: (points (k, 2), normal (2,), friction).
    fn pusher<'py>(&self, py: Python<'py>, name: &Arg<'py>) -> PyResult<PusherSpec<'py>> {
        guard(move || {
            let c = &self.inner.pushers[pusher(name, |n| self.inner.pusher_index(n))?].contact;
            Ok((rows_array(py, c.points.iter().map(|p| [p.x, p.y]).collect()), (c.normal.x, c.normal.y), c.friction))
        })
    }
    /// (start, goal, tolerance) or None.
    #[getter] fn task(&self) -> Option<([f64; 3], [f64; 3], [f64; 3])> { self.inner.task.map(|t| (t.start, t.goal, t.tolerance)) }

    /// Whether the whole finger pad lies on the object at `pose` `[x, z, theta]` (m, m, rad).
    fn admissible(&self, pose: &Arg<'_>) -> PyResult<bool> {
        guard(move || {
            Ok(self.inner.admissible(&pose3("pose", pose)?))
        })
    }

    /// The error `pose − goal` `[x, z, theta]` (m, m, rad; theta wrapped into [−π, π)) and
    /// whether it is within the task's tolerance (the default tolerance without a task);
    /// `goal` defaults to the task's.
    #[pyo3(signature = (pose, goal=None))]
    fn goal_error(&self, pose: &Arg<'_>, goal: Option<&Arg<'_>>) -> PyResult<([f64; 3], bool)> {
        guard(move || {
            let q = pose3("pose", pose)?;
            let g = match goal {
                Some(g) => pose3("goal", g)?,
                None => self.inner.task.map(|t| t.goal).ok_or_else(|| arg_err("goal", "the scene has no task: give a goal"))?,
            };
            Ok(regrasp::scene::planar::goal_error(&q, &g, &self.inner.tolerance()))
        })
    }

    /// `admissible` at each row of `poses` (n, 3) (m, m, rad): a bool array.
    fn admissible_many<'py>(&self, py: Python<'py>, poses: &Arg<'py>) -> PyResult<Bound<'py, PyArray1<bool>>> {
        guard(move || {
            let q = rows::<3>("poses", poses)?;
            Ok(array1(py, py.allow_threads(|| q.iter().map(|p| self.inner.admissible(p)).collect())))
        })
    }

    /// Share of the support's friction that gravity alone uses at `pose` `[x, z, theta]` (m, m, rad)
    /// (< 1 holds).
    fn hold_ratio(&self, pose: &Arg<'_>) -> PyResult<f64> {
        guard(move || {
            let r = self.inner.hold_ratio(&pose3("pose", pose)?);
            if !r.is_finite() {
                return Err(arg_err("pose", format!("has no finite hold ratio (got {r}): the support cannot hold the object there at all")));
            }
            Ok(r)
        })
    }

    /// The share of the support's friction each object-frame wrench row of `wrenches` (n, 3) (N, N,
    /// N·m about the object's origin) uses at the pose row of `poses` (n, 3) (m, m, rad): (n,).
    fn load_ratios<'py>(&self, py: Python<'py>, poses: &Arg<'py>, wrenches: &Arg<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        guard(move || {
            let q = rows::<3>("poses", poses)?;
            let w = rows::<3>("wrenches", wrenches)?;
            if q.len() != w.len() {
                return Err(arg_err("wrenches", format!("one per pose: {} rows (got {})", q.len(), w.len())));
            }
            let out: Vec<f64> = py.allow_threads(|| {
                q.iter().zip(&w).map(|(p, x)| self.inner.load_ratio(p, &Vec3::new(x[0], x[1], x[2]))).collect()
            });
            if let Some(i) = out.iter().position(|r| !r.is_finite()) {
                return Err(arg_err(&format!("poses[{i}]"), "has no finite load ratio: the support cannot hold anything there"));
            }
            Ok(array1(py, out))
        })
    }

    /// The same scene with grip force `force` [N] per finger (grasp scenes).
    fn with_grip_force(&self, force: &Arg<'_>) -> PyResult<Self> {
        guard(move || {
            let force = positive("force", force)?;
            if self.inner.grip_force().is_none() {
                return Err(arg_err("force", "only a grasp scene has a grip force"));
            }
            Ok(Self { inner: self.inner.try_with_grip_force(force).map_err(to_py)? })
        })
    }

    /// A copy whose motion cones use limit surface `model`, "true" or "ellipsoid".
    fn with_limit_surface(&self, model: &Arg<'_>) -> PyResult<Self> {
        guard(move || {
            let name = arg::<String>("limit_surface", model)?;
            let m = SurfaceModel::parse(&name)
                .ok_or_else(|| arg_err("limit_surface", format!("must be \"true\" or \"ellipsoid\" (got {name:?})")))?;
            Ok(Self { inner: self.inner.with_surface_model(m) })
        })
    }

    /// The limit surface the motion cones use: "true" or "ellipsoid".
    #[getter]
    fn limit_surface(&self) -> &'static str {
        self.inner.surface_model().label()
    }

    /// The motion cone of pusher `pusher` at `pose` `[x, z, theta]` (m, m, rad) (raises GraspError if the grasp cannot
    /// hold, unless `check_hold` is False).
    #[pyo3(signature = (pose, pusher, check_hold=None))]
    fn motion_cone(&self, pose: &Arg<'_>, pusher: &Arg<'_>, check_hold: Option<&Arg<'_>>) -> PyResult<MotionCone> {
        guard(move || {
            let q = pose3("pose", pose)?;
            let name: String = arg("pusher", pusher)?;
            let i = self.inner.pusher_index(&name).map_err(to_py)?;
            let push = match opt("check_hold", check_hold)?.unwrap_or(true) {
                true => self.inner.push(&q, i),
                false => self.inner.push_unchecked(&q, i),
            };
            Ok(MotionCone::new(push.map_err(to_py)?, name))
        })
    }

    /// Polyhedral (or gravity-free) generators at many `poses` (n, 3) (m, m, rad): (generators (n, k, 3),
    /// status (n,) uint8; 0 = ok, see `status_messages`).
    fn generators_many<'py>(&self, py: Python<'py>, poses: &Arg<'py>, pusher: &Arg<'py>, gravity_free: &Arg<'py>) -> PyResult<Generated<'py>> {
        guard(move || {
            cones::generators_many(py, &self.inner, poses, pusher, gravity_free)
        })
    }

    /// Exact test of twist i (m/s, m/s, rad/s) at pose i (m, m, rad): (feasible, margin, active-limit codes, status).
    fn classify_many<'py>(&self, py: Python<'py>, poses: &Arg<'py>, twists: &Arg<'py>, pusher: &Arg<'py>) -> PyResult<Classified<'py>> {
        guard(move || {
            cones::classify_many(py, &self.inner, poses, twists, pusher)
        })
    }

    /// Closest feasible twist to twist i (m/s, m/s, rad/s) at pose i (m, m, rad): (projections (n, 3), status).
    fn project_many<'py>(&self, py: Python<'py>, poses: &Arg<'py>, twists: &Arg<'py>, pusher: &Arg<'py>) -> PyResult<Projected<'py>> {
        guard(move || {
            cones::project_many(py, &self.inner, poses, twists, pusher)
        })
    }

    /// Labels of the contact-limit codes returned by `classify_many`.
    #[staticmethod]
    fn limit_labels() -> Vec<String> {
        cones::limit_labels()
    }

    /// Messages of the batch status codes.
    #[staticmethod]
    fn status_messages() -> Vec<(u8, &'static str)> {
        cones::status_messages()
    }

    /// The quasi-static problem of `pusher` (or no pusher) at `pose` (m, m, rad), time step `h` [s],
    /// pusher `speed` [m/s]; the options default to
    /// `quasistatic_defaults()`.
    #[pyo3(signature = (pose, pusher=None, support=None, rings=None, points=None, merge_fingers=None, h=None, speed=None))]
    #[allow(clippy::too_many_arguments)]
    fn quasistatic_problem(
        &self, pose: &Arg<'_>, pusher: Option<&Arg<'_>>,
        support: Option<&Arg<'_>>, rings: Option<&Arg<'_>>, points: Option<&Arg<'_>>, merge_fingers: Option<&Arg<'_>>,
        h: Option<&Arg<'_>>, speed: Option<&Arg<'_>>,
    ) -> PyResult<MncpProblem> {
        guard(move || {
            let [a, b, c, d] = self::support(support, rings, points, merge_fingers);
            let opts = settings::quasistatic(&[a, b, c, d, ("h", h), ("speed", speed)])?;
            dynamics::planar_problem(&self.inner, pose, pusher, &opts)
        })
    }

    /// Instantaneous pushes: pusher `pusher` at pose i (m, m, rad) moving with twist i (m/s, m/s,
    /// rad/s; object frame).
    /// Returns (sticks (n,), object twists (n, 3), max residual (n,), errors (None if solved)).
    #[pyo3(signature = (poses, pusher, twists, support=None, rings=None, points=None, merge_fingers=None))]
    #[allow(clippy::too_many_arguments)]
    fn push_outcomes<'py>(
        &self, py: Python<'py>, poses: &Arg<'py>, pusher: &Arg<'py>, twists: &Arg<'py>,
        support: Option<&Arg<'py>>, rings: Option<&Arg<'py>>, points: Option<&Arg<'py>>, merge_fingers: Option<&Arg<'py>>,
    ) -> PyResult<Outcomes<'py>> {
        guard(move || {
            let opts = settings::quasistatic(&self::support(support, rings, points, merge_fingers))?;
            dynamics::push_outcomes(py, &self.inner, poses, pusher, twists, &opts)
        })
    }

    /// Explicit time stepping of one push from `pose` (m, m, rad): pusher body `twist` (m/s, m/s,
    /// rad/s) constant (object frame at t = 0) for `duration` [s] in steps of `dt` [s].
    #[pyo3(signature = (pose, pusher, twist, duration, dt, support=None, rings=None, points=None, merge_fingers=None))]
    #[allow(clippy::too_many_arguments)]
    fn simulate_push<'py>(
        &self, py: Python<'py>, pose: &Arg<'py>, pusher: &Arg<'py>, twist: &Arg<'py>, duration: &Arg<'py>, dt: &Arg<'py>,
        support: Option<&Arg<'py>>, rings: Option<&Arg<'py>>, points: Option<&Arg<'py>>, merge_fingers: Option<&Arg<'py>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        guard(move || {
            let opts = settings::quasistatic(&self::support(support, rings, points, merge_fingers))?;
            dynamics::simulate_planar(py, &self.inner, PushArgs { pose, pusher, twist, duration, dt }, &opts)
        })
    }

    /// T-RRT* regrasp plan (see `regrasp.plan`): `settings` overrides the defaults of
    /// `planner_defaults(2)`. Returns a dict.
    #[pyo3(signature = (start=None, goal=None, settings=None))]
    fn plan<'py>(&self, py: Python<'py>, start: Option<&Arg<'py>>, goal: Option<&Arg<'py>>, settings: Option<&Arg<'py>>) -> PyResult<Bound<'py, PyDict>> {
        guard(move || {
            planning::plan_planar(py, &self.inner, planning::Request { start, goal, settings })
        })
    }

    /// Smallest exact-test margin along each step of a path (poses, pusher names), checked at
    /// `checks` poses a step (default: the planner's `checks`).
    #[pyo3(signature = (poses, pushers, checks=None))]
    fn validate_path(&self, py: Python<'_>, poses: &Arg<'_>, pushers: &Arg<'_>, checks: Option<&Arg<'_>>) -> PyResult<Vec<f64>> {
        guard(move || {
            planning::validate_planar(py, &self.inner, poses, pushers, checks)
        })
    }

    /// The cone mode: "nominal", "robust" or "fixtureless".
    #[getter] fn mode(&self) -> &'static str { self.inner.mode.label() }

    /// The `[uncertainty]` table as a dict of relative spreads (None when absent).
    #[getter]
    fn uncertainty(&self) -> Option<HashMap<&'static str, f64>> {
        self.inner.uncertainty.map(|u| {
            HashMap::from([("pusher_friction", u.pusher_friction), ("finger_friction", u.finger_friction), ("grip_force", u.grip_force), ("mass", u.mass)])
        })
    }

    /// `ρ = μ_s N / (m g)` (grasp scenes).
    #[getter] fn rho(&self) -> Option<f64> { perturb::rho(&self.inner) }

    /// A copy with scaled parameters and a cone mode (see `regrasp.robust`; default: the
    /// nominal cone).
    #[pyo3(signature = (finger_friction=None, grip=None, mass=None, pusher_friction=None, mode=None))]
    fn scaled(
        &self,
        finger_friction: Option<&Arg<'_>>,
        grip: Option<&Arg<'_>>,
        mass: Option<&Arg<'_>>,
        pusher_friction: Option<&Arg<'_>>,
        mode: Option<&Arg<'_>>,
    ) -> PyResult<Self> {
        guard(move || {
            let factor = |name: &str, v: Option<&Arg<'_>>| opt::<f64>(name, v).map(|f| f.unwrap_or(1.0));
            let (f, g) = (factor("finger_friction", finger_friction)?, factor("grip", grip)?);
            let (m, p) = (factor("mass", mass)?, factor("pusher_friction", pusher_friction)?);
            let mode = opt::<String>("mode", mode)?.map(|m| ConeMode::parse(&m)).transpose().map_err(to_py)?.unwrap_or_default();
            Ok(Self { inner: perturb::scaled(&self.inner, f, g, m, p, mode).map_err(to_py)? })
        })
    }

    /// Whether pusher `pusher` alone can carry the object's weight at pose `q` (the invariant case).
    fn carries_weight(&self, q: &Arg<'_>, pusher: &Arg<'_>) -> PyResult<bool> {
        guard(move || {
            let (q, p) = (pose3("pose", q)?, self::pusher(pusher, |n| self.inner.pusher_index(n))?);
            Ok(self.inner.push_unchecked(&q, p).map_err(to_py)?.carries_weight())
        })
    }
}
