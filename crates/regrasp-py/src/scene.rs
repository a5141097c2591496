//! The planar `Scene` (`regrasp::scene::planar`): its fields, its admissible poses, its
//! variants (grip force, robust scaling), and the entry points of the later pipeline stages
//! (cones, dynamics, planning), whose conversion lives in their own modules.

use crate::cones::{self, MotionCone};
use crate::convert::{arg, array1, finite, opt, pose3, pusher, rows, rows_array};
use crate::dynamics::{self, MncpProblem, PushArgs};
use crate::errors::{arg_err, to_py};
use crate::{planning, settings};
use numpy::{PyArray1, PyArray2, PyArray3};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use regrasp::cones::robust::{self, ConeMode};
use regrasp::scene::planar::{PadShape, Support};
use std::collections::HashMap;

/// A validated planar scene (immutable).
#[pyclass(module = "regrasp._core", frozen)]
pub struct Scene {
    pub inner: regrasp::Scene,
}

/// The support options among the arguments of the quasi-static entry points.
fn support<'a, 'py>(
    support: Option<&'a Bound<'py, PyAny>>,
    rings: Option<&'a Bound<'py, PyAny>>,
    points: Option<&'a Bound<'py, PyAny>>,
    merge_fingers: Option<&'a Bound<'py, PyAny>>,
) -> [(&'static str, Option<&'a Bound<'py, PyAny>>); 4] {
    [("support", support), ("rings", rings), ("points", points), ("merge_fingers", merge_fingers)]
}

#[pymethods]
impl Scene {
    /// Parse and validate a scene from TOML text.
    #[staticmethod]
    fn from_toml(text: &Bound<'_, PyAny>) -> PyResult<Self> {
        regrasp::Scene::from_toml_str(&arg::<String>("text", text)?).map(|inner| Self { inner }).map_err(to_py)
    }

    /// Parse and validate a scene from JSON text (same layout as the TOML file).
    #[staticmethod]
    fn from_json(text: &Bound<'_, PyAny>) -> PyResult<Self> {
        regrasp::Scene::from_json_str(&arg::<String>("text", text)?).map(|inner| Self { inner }).map_err(to_py)
    }

    #[getter]
    fn name(&self) -> String {
        self.inner.name.clone()
    }
    #[getter]
    fn kind(&self) -> &'static str {
        match self.inner.support {
            Support::Grasp(_) => "grasp",
            Support::Surface(_) => "surface",
        }
    }
    #[getter]
    fn pusher_names(&self) -> Vec<String> {
        self.inner.pushers.iter().map(|p| p.name.clone()).collect()
    }
    #[getter]
    fn length(&self) -> f64 {
        self.inner.length
    }
    #[getter]
    fn mass(&self) -> f64 {
        self.inner.mass
    }
    #[getter]
    fn com(&self) -> (f64, f64) {
        (self.inner.com.x, self.inner.com.y)
    }
    #[getter]
    fn gravity(&self) -> (f64, f64, f64) {
        (self.inner.gravity_dir.x, self.inner.gravity_dir.y, self.inner.g)
    }
    #[getter]
    fn grip_force(&self) -> Option<f64> {
        self.inner.grip_force()
    }
    #[getter]
    fn friction_scale(&self) -> f64 {
        self.inner.friction_scale()
    }
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
    fn pusher<'py>(&self, py: Python<'py>, name: &Bound<'py, PyAny>) -> PyResult<(Bound<'py, PyArray2<f64>>, (f64, f64), f64)> {
        let c = &self.inner.pushers[pusher(name, |n| self.inner.pusher_index(n))?].contact;
        Ok((rows_array(py, c.points.iter().map(|p| [p.x, p.y]).collect()), (c.normal.x, c.normal.y), c.friction))
    }
    /// (start, goal, tolerance) or None.
    #[getter]
    fn task(&self) -> Option<([f64; 3], [f64; 3], [f64; 3])> {
        self.inner.task.map(|t| (t.start, t.goal, t.tolerance))
    }

    fn admissible(&self, pose: &Bound<'_, PyAny>) -> PyResult<bool> {
        Ok(self.inner.admissible(&pose3("pose", pose)?))
    }

    fn admissible_many<'py>(&self, py: Python<'py>, poses: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyArray1<bool>>> {
        let q = rows::<3>("poses", poses)?;
        Ok(array1(py, py.allow_threads(|| q.iter().map(|p| self.inner.admissible(p)).collect())))
    }

    fn hold_ratio(&self, pose: &Bound<'_, PyAny>) -> PyResult<f64> {
        Ok(self.inner.hold_ratio(&pose3("pose", pose)?))
    }

    fn with_grip_force(&self, force: &Bound<'_, PyAny>) -> PyResult<Self> {
        let force = finite("force", force)?;
        if !(force > 0.0) {
            return Err(arg_err("force", "must be a positive number"));
        }
        if self.inner.grip_force().is_none() {
            return Err(arg_err("force", "only a grasp scene has a grip force"));
        }
        Ok(Self { inner: self.inner.with_grip_force(force) })
    }

    /// The motion cone of pusher `pusher` at `pose` (raises GraspError if the grasp cannot
    /// hold, unless `check_hold` is False).
    #[pyo3(signature = (pose, pusher, check_hold=None))]
    fn motion_cone(&self, pose: &Bound<'_, PyAny>, pusher: &Bound<'_, PyAny>, check_hold: Option<&Bound<'_, PyAny>>) -> PyResult<MotionCone> {
        let q = pose3("pose", pose)?;
        let name: String = arg("pusher", pusher)?;
        let i = self.inner.pusher_index(&name).map_err(to_py)?;
        let push = match opt("check_hold", check_hold)?.unwrap_or(true) {
            true => self.inner.push(&q, i),
            false => self.inner.push_unchecked(&q, i),
        };
        Ok(MotionCone::new(push.map_err(to_py)?, name))
    }

    /// Polyhedral (or gravity-free) generators at many poses: (generators (n, k, 3),
    /// status (n,) uint8; 0 = ok, see `status_messages`).
    #[allow(clippy::type_complexity)]
    fn generators_many<'py>(
        &self,
        py: Python<'py>,
        poses: &Bound<'py, PyAny>,
        pusher: &Bound<'py, PyAny>,
        gravity_free: &Bound<'py, PyAny>,
    ) -> PyResult<(Bound<'py, PyArray3<f64>>, Bound<'py, PyArray1<u8>>)> {
        cones::generators_many(py, &self.inner, poses, pusher, arg("gravity_free", gravity_free)?)
    }

    /// Exact test of twist i at pose i: (feasible, margin, active-limit codes, status).
    #[allow(clippy::type_complexity)]
    fn classify_many<'py>(
        &self,
        py: Python<'py>,
        poses: &Bound<'py, PyAny>,
        twists: &Bound<'py, PyAny>,
        pusher: &Bound<'py, PyAny>,
    ) -> PyResult<(Bound<'py, PyArray1<bool>>, Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<u8>>, Bound<'py, PyArray1<u8>>)> {
        cones::classify_many(py, &self.inner, poses, twists, pusher)
    }

    /// Closest feasible twist to twist i at pose i: (projections (n, 3), status).
    fn project_many<'py>(
        &self,
        py: Python<'py>,
        poses: &Bound<'py, PyAny>,
        twists: &Bound<'py, PyAny>,
        pusher: &Bound<'py, PyAny>,
    ) -> PyResult<(Bound<'py, PyArray2<f64>>, Bound<'py, PyArray1<u8>>)> {
        cones::project_many(py, &self.inner, poses, twists, pusher)
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

    /// The quasi-static problem of `pusher` (or no pusher) at `pose`; the options default to
    /// `quasistatic_defaults()`.
    #[pyo3(signature = (pose, pusher=None, support=None, rings=None, points=None, merge_fingers=None, h=None, speed=None))]
    #[allow(clippy::too_many_arguments)]
    fn quasistatic_problem(
        &self,
        pose: &Bound<'_, PyAny>,
        pusher: Option<&Bound<'_, PyAny>>,
        support: Option<&Bound<'_, PyAny>>,
        rings: Option<&Bound<'_, PyAny>>,
        points: Option<&Bound<'_, PyAny>>,
        merge_fingers: Option<&Bound<'_, PyAny>>,
        h: Option<&Bound<'_, PyAny>>,
        speed: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<MncpProblem> {
        let [a, b, c, d] = self::support(support, rings, points, merge_fingers);
        let opts = settings::quasistatic(&[a, b, c, d, ("h", h), ("speed", speed)])?;
        dynamics::planar_problem(&self.inner, pose, pusher, &opts)
    }

    /// Instantaneous pushes: pusher `pusher` at pose i moving with twist i (object frame).
    /// Returns (sticks (n,), object twists (n, 3), max residual (n,), errors (None if solved)).
    #[pyo3(signature = (poses, pusher, twists, support=None, rings=None, points=None, merge_fingers=None))]
    #[allow(clippy::type_complexity, clippy::too_many_arguments)]
    fn push_outcomes<'py>(
        &self,
        py: Python<'py>,
        poses: &Bound<'py, PyAny>,
        pusher: &Bound<'py, PyAny>,
        twists: &Bound<'py, PyAny>,
        support: Option<&Bound<'py, PyAny>>,
        rings: Option<&Bound<'py, PyAny>>,
        points: Option<&Bound<'py, PyAny>>,
        merge_fingers: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<(Bound<'py, PyArray1<bool>>, Bound<'py, PyArray2<f64>>, Bound<'py, PyArray1<f64>>, Vec<Option<String>>)> {
        let opts = settings::quasistatic(&self::support(support, rings, points, merge_fingers))?;
        dynamics::push_outcomes(py, &self.inner, poses, pusher, twists, &opts)
    }

    /// Explicit time stepping of one push (pusher body twist constant, object frame at t = 0).
    #[pyo3(signature = (pose, pusher, twist, duration, dt, support=None, rings=None, points=None, merge_fingers=None))]
    #[allow(clippy::too_many_arguments)]
    fn simulate_push<'py>(
        &self,
        py: Python<'py>,
        pose: &Bound<'py, PyAny>,
        pusher: &Bound<'py, PyAny>,
        twist: &Bound<'py, PyAny>,
        duration: &Bound<'py, PyAny>,
        dt: &Bound<'py, PyAny>,
        support: Option<&Bound<'py, PyAny>>,
        rings: Option<&Bound<'py, PyAny>>,
        points: Option<&Bound<'py, PyAny>>,
        merge_fingers: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let opts = settings::quasistatic(&self::support(support, rings, points, merge_fingers))?;
        dynamics::simulate_planar(py, &self.inner, PushArgs { pose, pusher, twist, duration, dt }, &opts)
    }

    /// T-RRT* regrasp plan (see `regrasp.plan`): `settings` overrides the defaults of
    /// `planner_defaults(2)`. Returns a dict.
    #[pyo3(signature = (start=None, goal=None, settings=None))]
    fn plan<'py>(
        &self,
        py: Python<'py>,
        start: Option<&Bound<'py, PyAny>>,
        goal: Option<&Bound<'py, PyAny>>,
        settings: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        planning::plan_planar(py, &self.inner, start, goal, settings)
    }

    /// Smallest exact-test margin along each step of a path (poses, pusher names), checked at
    /// `checks` poses a step (default: the planner's `checks`).
    #[pyo3(signature = (poses, pushers, checks=None))]
    fn validate_path(&self, poses: &Bound<'_, PyAny>, pushers: &Bound<'_, PyAny>, checks: Option<&Bound<'_, PyAny>>) -> PyResult<Vec<f64>> {
        planning::validate_planar(&self.inner, poses, pushers, checks)
    }

    /// The cone mode: "nominal", "robust" or "fixtureless".
    #[getter]
    fn mode(&self) -> &'static str {
        self.inner.mode.label()
    }

    /// The `[uncertainty]` table as a dict of relative spreads (None when absent).
    #[getter]
    fn uncertainty(&self) -> Option<HashMap<&'static str, f64>> {
        self.inner.uncertainty.map(|u| {
            HashMap::from([("pusher_friction", u.pusher_friction), ("finger_friction", u.finger_friction), ("grip_force", u.grip_force), ("mass", u.mass)])
        })
    }

    /// `ρ = μ_s N / (m g)` (grasp scenes).
    #[getter]
    fn rho(&self) -> Option<f64> {
        robust::rho(&self.inner)
    }

    /// A copy with scaled parameters and a cone mode (see `regrasp.robust`; default: the
    /// nominal cone).
    #[pyo3(signature = (finger_friction=None, grip=None, mass=None, pusher_friction=None, mode=None))]
    fn scaled(
        &self,
        finger_friction: Option<&Bound<'_, PyAny>>,
        grip: Option<&Bound<'_, PyAny>>,
        mass: Option<&Bound<'_, PyAny>>,
        pusher_friction: Option<&Bound<'_, PyAny>>,
        mode: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let factor = |name: &str, v: Option<&Bound<'_, PyAny>>| opt::<f64>(name, v).map(|f| f.unwrap_or(1.0));
        let (f, g) = (factor("finger_friction", finger_friction)?, factor("grip", grip)?);
        let (m, p) = (factor("mass", mass)?, factor("pusher_friction", pusher_friction)?);
        let mode = opt::<String>("mode", mode)?.map(|m| ConeMode::parse(&m)).transpose().map_err(to_py)?.unwrap_or_default();
        robust::scaled(&self.inner, f, g, m, p, mode).map(|inner| Self { inner }).map_err(to_py)
    }

    /// Whether pusher `pusher` alone can carry the object's weight at pose `q` (the invariant case).
    fn carries_weight(&self, q: &Bound<'_, PyAny>, pusher: &Bound<'_, PyAny>) -> PyResult<bool> {
        let (q, p) = (pose3("pose", q)?, self::pusher(pusher, |n| self.inner.pusher_index(n))?);
        Ok(self.inner.push_unchecked(&q, p).map_err(to_py)?.carries_weight())
    }
}
