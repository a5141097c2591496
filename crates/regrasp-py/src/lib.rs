//! Python bindings of the regrasp core: conversion only, no mechanics here.

use numpy::ndarray::{Array1, Array2, Array3};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3, PyReadonlyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use regrasp::mechanics::friction_cone::{ConeShape, ContactLimit};
use regrasp::mechanics::geometry::{Vec2, Vec3};
use regrasp::cones::motion_cone::{project_onto_generators, Classification, PlanarPush};
use regrasp::dynamics::mncp::{self, FrictionLaw, NormalLaw, Side};
use regrasp::dynamics::planar::{self as quasistatic, Options, SupportModel};
use regrasp::dynamics::spatial as quasistatic3d;
use regrasp::scene::spatial::{self as scene3d, Scene3};
use regrasp::planning::planar as trrt;
use regrasp::cones::batch;
use regrasp::Error;
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;

mod settings;

/// Raise the Python exception (defined in `regrasp.errors`) matching a core error.
pub(crate) fn to_py(err: Error) -> PyErr {
    Python::with_gil(|py| {
        let module = match py.import("regrasp.errors") {
            Ok(m) => m,
            Err(e) => return e,
        };
        let (cls, args): (&str, (String, Option<String>)) = match &err {
            Error::Scene { field, .. } => ("SceneError", (err.to_string(), Some(field.clone()))),
            Error::InvalidArgument { name, .. } => ("ArgumentError", (err.to_string(), Some(name.clone()))),
            Error::GraspCannotHold { .. } => ("GraspError", (err.to_string(), Some("grasp.force".into()))),
        };
        match module.getattr(cls).and_then(|c| c.call1(args)) {
            Ok(exc) => PyErr::from_value(exc),
            Err(e) => e,
        }
    })
}

/// The fields a plan dict shares between the planar and the 3-D planners.
fn plan_summary<'py, Q, E>(py: Python<'py>, scene: &str, r: &regrasp::planning::trrt::Plan<Q, E>, propagation: &str, seed: u64) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("scene", scene)?;
    d.set_item("found", r.found)?;
    d.set_item("stop_reason", r.stop_reason.label())?;
    d.set_item("planning_time_s", r.planning_time_s)?;
    d.set_item("nodes", r.nodes)?;
    d.set_item("iterations", r.iterations)?;
    d.set_item("switch_overs", r.switch_overs)?;
    d.set_item("cost", r.cost)?;
    d.set_item("goal_distance", r.goal_distance)?;
    d.set_item("propagation", propagation)?;
    d.set_item("seed", seed)?;
    Ok(d)
}

/// Pusher indices of a path's pusher names (None for the start), errors naming the step.
fn path_pushers(names: &[Option<String>], index: impl Fn(&str) -> regrasp::Result<usize>) -> PyResult<Vec<Option<usize>>> {
    names
        .iter()
        .enumerate()
        .map(|(i, p)| match p {
            None => Ok(None),
            Some(n) => index(n).map(Some).map_err(|_| arg_err(&format!("path[{i}].pusher"), format!("no pusher {n:?}"))),
        })
        .collect()
}

pub(crate) fn arg_err(name: &str, msg: impl Into<String>) -> PyErr {
    to_py(Error::arg(name, msg))
}

fn vec3(name: &str, v: &[f64]) -> PyResult<Vec3> {
    if v.len() != 3 {
        return Err(arg_err(name, format!("must have 3 components, got {}", v.len())));
    }
    if !v.iter().all(|x| x.is_finite()) {
        return Err(arg_err(name, "has a non-finite component"));
    }
    Ok(Vec3::new(v[0], v[1], v[2]))
}

fn pose3(v: &[f64]) -> PyResult<[f64; 3]> {
    let p = vec3("pose", v)?;
    Ok([p.x, p.y, p.z])
}

/// Rows of an (n, 3) float64 array, without a copy when it is C-contiguous.
fn rows3<'a>(name: &str, a: &'a PyReadonlyArray2<'_, f64>) -> PyResult<std::borrow::Cow<'a, [[f64; 3]]>> {
    let v = a.as_array();
    if v.ncols() != 3 {
        return Err(arg_err(name, format!("must have shape (n, 3), got (n, {})", v.ncols())));
    }
    Ok(match a.as_slice() {
        Ok(flat) => std::borrow::Cow::Borrowed(flat.as_chunks::<3>().0),
        Err(_) => std::borrow::Cow::Owned(v.rows().into_iter().map(|r| [r[0], r[1], r[2]]).collect()),
    })
}

fn mat_from_rows(rows: &[Vec3]) -> Array2<f64> {
    let mut m = Array2::zeros((rows.len(), 3));
    for (i, r) in rows.iter().enumerate() {
        for j in 0..3 {
            m[(i, j)] = r[j];
        }
    }
    m
}

fn classification_dict<'py>(py: Python<'py>, c: &Classification) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("feasible", c.feasible)?;
    d.set_item("margin", c.margin)?;
    d.set_item("active_limit", c.limit.label())?;
    d.set_item("pusher_wrench", c.pusher_wrench.as_slice().to_vec())?;
    d.set_item("support_wrench", c.support_wrench.as_slice().to_vec())?;
    Ok(d)
}


fn dvec<'py>(py: Python<'py>, v: &DVector<f64>) -> Bound<'py, PyArray1<f64>> {
    Array1::from(v.as_slice().to_vec()).into_pyarray(py)
}

fn dmat<'py>(py: Python<'py>, m: &DMatrix<f64>) -> Bound<'py, PyArray2<f64>> {
    Array2::from_shape_fn((m.nrows(), m.ncols()), |(i, j)| m[(i, j)]).into_pyarray(py)
}

fn residuals_dict<'py>(py: Python<'py>, r: &mncp::Residuals) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("newton_euler", r.newton_euler)?;
    d.set_item("normal_feasibility", r.normal_feasibility)?;
    d.set_item("normal_complementarity", r.normal_complementarity)?;
    d.set_item("cone", r.cone)?;
    d.set_item("friction_complementarity", r.friction_complementarity)?;
    d.set_item("dissipation", r.dissipation)?;
    Ok(d)
}

fn solution_dict<'py>(py: Python<'py>, p: &mncp::Problem, s: &mncp::Solution) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("twist", dvec(py, &s.twist))?;
    d.set_item("pusher_twist", dvec(py, &s.pusher_twist))?;
    d.set_item("normal_forces", Array1::from(s.normal_forces.clone()).into_pyarray(py))?;
    d.set_item("friction_forces", s.friction_forces.iter().map(|f| dvec(py, f)).collect::<Vec<_>>())?;
    d.set_item("normal_velocities", Array1::from(s.normal_velocities.clone()).into_pyarray(py))?;
    d.set_item("tangent_velocities", s.tangent_velocities.iter().map(|f| dvec(py, f)).collect::<Vec<_>>())?;
    d.set_item("states", s.states.iter().map(|x| x.label()).collect::<Vec<_>>())?;
    d.set_item("labels", p.contacts.iter().map(|c| c.label.clone()).collect::<Vec<_>>())?;
    d.set_item("residuals", residuals_dict(py, &s.residuals)?)?;
    d.set_item("max_residual", s.residuals.max())?;
    d.set_item("iterations", s.iterations)?;
    Ok(d)
}

fn options(support: &str, rings: usize, points: usize, merge_fingers: bool, h: f64, speed: f64) -> PyResult<Options> {
    let support = match support {
        "points" => SupportModel::Points { rings, points, merge_fingers },
        "limit_surface" => SupportModel::LimitSurface,
        other => return Err(arg_err("support", format!("must be \"points\" or \"limit_surface\", got {other:?}"))),
    };
    if !(h > 0.0) || !(speed > 0.0) {
        return Err(arg_err("h", "time step and speed must be positive"));
    }
    if rings == 0 && points == 0 {
        return Err(arg_err("points", "give rings > 0 or points > 0"));
    }
    Ok(Options { support, h, speed, ..Options::default() })
}

/// One instantaneous quasi-static problem (thesis §3.2): contacts, mass matrix, gravity.
#[pyclass(module = "regrasp._core", frozen)]
struct MncpProblem {
    inner: mncp::Problem,
}

#[pymethods]
impl MncpProblem {
    #[getter]
    fn dim(&self) -> usize {
        self.inner.dim
    }
    #[getter]
    fn labels(&self) -> Vec<String> {
        self.inner.contacts.iter().map(|c| c.label.clone()).collect()
    }

    /// Forward problem: pusher twist given; returns the solution as a dict.
    fn solve_forward<'py>(&self, py: Python<'py>, pusher_twist: Vec<f64>) -> PyResult<Bound<'py, PyDict>> {
        let u = DVector::from_vec(pusher_twist);
        let s = py.allow_threads(|| mncp::solve_forward(&self.inner, &u, &mncp::Settings::default())).map_err(to_py)?;
        solution_dict(py, &self.inner, &s)
    }

    /// Inverse problem: object twist given; returns the pusher motion and forces.
    fn solve_inverse<'py>(&self, py: Python<'py>, twist: Vec<f64>) -> PyResult<Bound<'py, PyDict>> {
        let v = DVector::from_vec(twist);
        let s = py.allow_threads(|| mncp::solve_inverse(&self.inner, &v, &mncp::Settings::default())).map_err(to_py)?;
        solution_dict(py, &self.inner, &s)
    }

    /// Scaled violation of every constraint for a candidate solution (e.g. the reference's).
    fn residuals<'py>(
        &self,
        py: Python<'py>,
        twist: Vec<f64>,
        pusher_twist: Vec<f64>,
        normal_forces: Vec<f64>,
        friction_forces: Vec<Vec<f64>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let n = self.inner.contacts.len();
        if twist.len() != self.inner.dim || pusher_twist.len() != self.inner.dim || normal_forces.len() != n || friction_forces.len() != n {
            return Err(arg_err("solution", "sizes do not match the problem"));
        }
        let ft: Vec<DVector<f64>> = friction_forces.into_iter().map(DVector::from_vec).collect();
        for (c, f) in self.inner.contacts.iter().zip(&ft) {
            if f.len() != c.tangent_dim() {
                return Err(arg_err("friction_forces", format!("contact {} needs {} components", c.label, c.tangent_dim())));
            }
        }
        let r = mncp::residuals(&self.inner, &DVector::from_vec(twist), &DVector::from_vec(pusher_twist), &normal_forces, &ft);
        residuals_dict(py, &r)
    }

    /// The problem's data (for the reference solver and for inspection).
    fn data<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let p = &self.inner;
        let d = PyDict::new(py);
        d.set_item("dim", p.dim)?;
        d.set_item("mass", dmat(py, &p.mass))?;
        d.set_item("wrench", dvec(py, &p.wrench))?;
        d.set_item("h", p.h)?;
        d.set_item("force_scale", p.force_scale)?;
        d.set_item("velocity_scale", p.velocity_scale)?;
        let mut cs = Vec::new();
        for c in &p.contacts {
            let e = PyDict::new(py);
            e.set_item("label", &c.label)?;
            e.set_item("side", match c.side { Side::Finger => "finger", Side::Pusher => "pusher", Side::Fixed => "fixed" })?;
            match c.normal {
                NormalLaw::Fixed(f) => {
                    e.set_item("normal", "fixed")?;
                    e.set_item("normal_force", f)?;
                }
                NormalLaw::Unilateral => e.set_item("normal", "unilateral")?,
            }
            match &c.friction {
                FrictionLaw::Coulomb(mu) => {
                    e.set_item("friction", "coulomb")?;
                    e.set_item("mu", *mu)?;
                }
                FrictionLaw::Ellipsoid(a) => {
                    e.set_item("friction", "ellipsoid")?;
                    e.set_item("A", dmat(py, a))?;
                }
            }
            e.set_item("jn", dvec(py, &c.jn))?;
            e.set_item("jt", dmat(py, &c.jt))?;
            e.set_item("jn_other", dvec(py, &c.jn_other))?;
            e.set_item("jt_other", dmat(py, &c.jt_other))?;
            e.set_item("gap", c.gap)?;
            cs.push(e);
        }
        d.set_item("contacts", cs)?;
        Ok(d)
    }
}

/// A validated planar scene (immutable).
#[pyclass(module = "regrasp._core", frozen)]
struct Scene {
    inner: regrasp::Scene,
}

#[pymethods]
impl Scene {
    /// Parse and validate a scene from TOML text.
    #[staticmethod]
    fn from_toml(text: &str) -> PyResult<Self> {
        regrasp::Scene::from_toml_str(text).map(|inner| Self { inner }).map_err(to_py)
    }

    /// Parse and validate a scene from JSON text (same layout as the TOML file).
    #[staticmethod]
    fn from_json(text: &str) -> PyResult<Self> {
        regrasp::Scene::from_json_str(text).map(|inner| Self { inner }).map_err(to_py)
    }

    #[getter]
    fn name(&self) -> String {
        self.inner.name.clone()
    }
    #[getter]
    fn kind(&self) -> &'static str {
        match self.inner.support {
            regrasp::scene::planar::Support::Grasp(_) => "grasp",
            regrasp::scene::planar::Support::Surface(_) => "surface",
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
        let v = self.inner.outline.vertices();
        let mut m = Array2::zeros((v.len(), 2));
        for (i, p) in v.iter().enumerate() {
            m[(i, 0)] = p.x;
            m[(i, 1)] = p.y;
        }
        m.into_pyarray(py)
    }
    /// The `k` of the support's limit surface (its largest friction moment per unit μN).
    #[getter]
    fn pad_limit_surface_k(&self) -> f64 {
        match &self.inner.support {
            regrasp::scene::planar::Support::Grasp(g) => g.limit_surface.k(),
            regrasp::scene::planar::Support::Surface(s) => s.limit_surface.k(),
        }
    }

    /// Pad description: ("circle", radius) or ("rectangle", width, height); None on a surface.
    #[getter]
    fn pad(&self) -> Option<(String, f64, f64)> {
        match &self.inner.support {
            regrasp::scene::planar::Support::Grasp(g) => Some(match g.pad {
                regrasp::scene::planar::PadShape::Circle { radius } => ("circle".into(), radius, radius),
                regrasp::scene::planar::PadShape::Rectangle { width, height } => ("rectangle".into(), width, height),
            }),
            _ => None,
        }
    }
    /// Pusher `name`: (points (k, 2), normal (2,), friction).
    fn pusher<'py>(&self, py: Python<'py>, name: &str) -> PyResult<(Bound<'py, PyArray2<f64>>, (f64, f64), f64)> {
        let i = self.inner.pusher_index(name).map_err(to_py)?;
        let c = &self.inner.pushers[i].contact;
        let mut m = Array2::zeros((c.points.len(), 2));
        for (k, p) in c.points.iter().enumerate() {
            m[(k, 0)] = p.x;
            m[(k, 1)] = p.y;
        }
        Ok((m.into_pyarray(py), (c.normal.x, c.normal.y), c.friction))
    }
    /// (start, goal, tolerance) or None.
    #[getter]
    fn task(&self) -> Option<([f64; 3], [f64; 3], [f64; 3])> {
        self.inner.task.map(|t| (t.start, t.goal, t.tolerance))
    }

    fn admissible(&self, pose: Vec<f64>) -> PyResult<bool> {
        Ok(self.inner.admissible(&pose3(&pose)?))
    }

    fn admissible_many<'py>(&self, py: Python<'py>, poses: PyReadonlyArray2<f64>) -> PyResult<Bound<'py, PyArray1<bool>>> {
        let q = rows3("poses", &poses)?;
        let out: Vec<bool> = py.allow_threads(|| q.iter().map(|p| self.inner.admissible(p)).collect());
        Ok(Array1::from(out).into_pyarray(py))
    }

    fn hold_ratio(&self, pose: Vec<f64>) -> PyResult<f64> {
        Ok(self.inner.hold_ratio(&pose3(&pose)?))
    }

    fn with_grip_force(&self, force: f64) -> PyResult<Self> {
        if !(force > 0.0) || !force.is_finite() {
            return Err(arg_err("force", "must be a positive number"));
        }
        if self.inner.grip_force().is_none() {
            return Err(arg_err("force", "only a grasp scene has a grip force"));
        }
        Ok(Self { inner: self.inner.with_grip_force(force) })
    }

    /// The motion cone of pusher `pusher` at `pose` (raises GraspError if the grasp cannot hold).
    #[pyo3(signature = (pose, pusher, check_hold=true))]
    fn motion_cone(&self, pose: Vec<f64>, pusher: &str, check_hold: bool) -> PyResult<MotionCone> {
        let q = pose3(&pose)?;
        let i = self.inner.pusher_index(pusher).map_err(to_py)?;
        let push = if check_hold { self.inner.push(&q, i) } else { self.inner.push_unchecked(&q, i) };
        Ok(MotionCone { push: push.map_err(to_py)?, pusher: pusher.to_string() })
    }

    /// Polyhedral (or gravity-free) generators at many poses: (generators (n, k, 3),
    /// status (n,) uint8; 0 = ok, see `status_messages`).
    fn generators_many<'py>(
        &self,
        py: Python<'py>,
        poses: PyReadonlyArray2<f64>,
        pusher: &str,
        gravity_free: bool,
    ) -> PyResult<(Bound<'py, PyArray3<f64>>, Bound<'py, PyArray1<u8>>)> {
        let q = rows3("poses", &poses)?;
        let i = self.inner.pusher_index(pusher).map_err(to_py)?;
        let k = self.inner.pushers[i].model.edges.len();
        let mut out = vec![0.0; q.len() * k * 3];
        let mut st = vec![batch::Status::Ok; q.len()];
        py.allow_threads(|| batch::generators_into(&self.inner, &q, i, gravity_free, &mut out, &mut st));
        let g = Array3::from_shape_vec((q.len(), k, 3), out).expect("shape");
        Ok((g.into_pyarray(py), status_array(py, &st)))
    }

    /// Exact test of twist i at pose i: (feasible, margin, active-limit labels, status).
    /// Exact test of twist i at pose i: (feasible, margin, active-limit codes, status).
    #[allow(clippy::type_complexity)]
    fn classify_many<'py>(
        &self,
        py: Python<'py>,
        poses: PyReadonlyArray2<f64>,
        twists: PyReadonlyArray2<f64>,
        pusher: &str,
    ) -> PyResult<(Bound<'py, PyArray1<bool>>, Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<u8>>, Bound<'py, PyArray1<u8>>)> {
        let q = rows3("poses", &poses)?;
        let t = rows3("twists", &twists)?;
        if q.len() != t.len() {
            return Err(arg_err("twists", format!("has {} rows but poses has {}", t.len(), q.len())));
        }
        let i = self.inner.pusher_index(pusher).map_err(to_py)?;
        let n = q.len();
        let (mut fe, mut ma) = (vec![false; n], vec![0.0; n]);
        let mut li = vec![ContactLimit::Torque; n];
        let mut st = vec![batch::Status::Ok; n];
        py.allow_threads(|| batch::classify_into(&self.inner, &q, &t, i, &mut fe, &mut ma, &mut li, &mut st));
        let codes: Vec<u8> = li.iter().map(|l| l.code()).collect();
        Ok((
            Array1::from(fe).into_pyarray(py),
            Array1::from(ma).into_pyarray(py),
            Array1::from(codes).into_pyarray(py),
            status_array(py, &st),
        ))
    }

    /// Closest feasible twist to twist i at pose i: (projections (n, 3), status).
    fn project_many<'py>(
        &self,
        py: Python<'py>,
        poses: PyReadonlyArray2<f64>,
        twists: PyReadonlyArray2<f64>,
        pusher: &str,
    ) -> PyResult<(Bound<'py, PyArray2<f64>>, Bound<'py, PyArray1<u8>>)> {
        let q = rows3("poses", &poses)?;
        let t = rows3("twists", &twists)?;
        if q.len() != t.len() {
            return Err(arg_err("twists", format!("has {} rows but poses has {}", t.len(), q.len())));
        }
        let i = self.inner.pusher_index(pusher).map_err(to_py)?;
        let mut out = vec![0.0; 3 * q.len()];
        let mut st = vec![batch::Status::Ok; q.len()];
        py.allow_threads(|| batch::project_into(&self.inner, &q, &t, i, &mut out, &mut st));
        let o = Array2::from_shape_vec((q.len(), 3), out).expect("shape");
        Ok((o.into_pyarray(py), status_array(py, &st)))
    }

    /// Labels of the contact-limit codes returned by `classify_many`.
    #[staticmethod]
    fn limit_labels() -> Vec<String> {
        ContactLimit::ALL.iter().map(|l| l.label()).collect()
    }

    /// The quasi-static problem of `pusher` (or no pusher) at `pose`.
    #[pyo3(signature = (pose, pusher=None, support="points", rings=3, points=0, merge_fingers=true, h=1.0, speed=0.01))]
    #[allow(clippy::too_many_arguments)]
    fn quasistatic_problem(
        &self,
        pose: Vec<f64>,
        pusher: Option<&str>,
        support: &str,
        rings: usize,
        points: usize,
        merge_fingers: bool,
        h: f64,
        speed: f64,
    ) -> PyResult<MncpProblem> {
        let q = pose3(&pose)?;
        let opts = options(support, rings, points, merge_fingers, h, speed)?;
        let p = match pusher {
            Some(name) => {
                let i = self.inner.pusher_index(name).map_err(to_py)?;
                quasistatic::push_problem(&self.inner, &q, i, &opts)
            }
            None => {
                self.inner.check_pose(&q).map_err(to_py)?;
                quasistatic::planar_problem(&self.inner, &q, None, &opts)
            }
        }
        .map_err(to_py)?;
        Ok(MncpProblem { inner: p })
    }

    /// Instantaneous pushes: pusher `pusher` at pose i moving with twist i (object frame).
    /// Returns (sticks (n,), object twists (n, 3), max residual (n,), errors (None if solved)).
    #[pyo3(signature = (poses, pusher, twists, support="points", rings=3, points=0, merge_fingers=true))]
    #[allow(clippy::type_complexity, clippy::too_many_arguments)]
    fn push_outcomes<'py>(
        &self,
        py: Python<'py>,
        poses: PyReadonlyArray2<f64>,
        pusher: &str,
        twists: PyReadonlyArray2<f64>,
        support: &str,
        rings: usize,
        points: usize,
        merge_fingers: bool,
    ) -> PyResult<(Bound<'py, PyArray1<bool>>, Bound<'py, PyArray2<f64>>, Bound<'py, PyArray1<f64>>, Vec<Option<String>>)> {
        let q = rows3("poses", &poses)?;
        let t = rows3("twists", &twists)?;
        if q.len() != t.len() {
            return Err(arg_err("twists", format!("has {} rows but poses has {}", t.len(), q.len())));
        }
        let i = self.inner.pusher_index(pusher).map_err(to_py)?;
        let opts = options(support, rings, points, merge_fingers, 1.0, 0.01)?;
        let res: Vec<_> = py.allow_threads(|| {
            q.par_iter()
                .zip(t.par_iter())
                .with_min_len(4)
                .map(|(qq, tt)| quasistatic::push_outcome(&self.inner, qq, i, &Vec3::from(*tt), &opts))
                .collect()
        });
        let n = q.len();
        let mut sticks = Array1::from_elem(n, false);
        let mut tw = Array2::zeros((n, 3));
        let mut resid = Array1::from_elem(n, f64::NAN);
        let mut errors = Vec::with_capacity(n);
        for (k, r) in res.into_iter().enumerate() {
            match r {
                Ok(o) => {
                    sticks[k] = o.sticks;
                    for c in 0..3 {
                        tw[(k, c)] = o.solution.twist[c];
                    }
                    resid[k] = o.solution.residuals.max();
                    errors.push(None);
                }
                Err(e) => errors.push(Some(e.to_string())),
            }
        }
        Ok((sticks.into_pyarray(py), tw.into_pyarray(py), resid.into_pyarray(py), errors))
    }

    /// Explicit time stepping of one push (pusher body twist constant, object frame at t = 0).
    #[pyo3(signature = (pose, pusher, twist, duration, dt, support="points", rings=3, points=0, merge_fingers=true))]
    #[allow(clippy::too_many_arguments)]
    fn simulate_push<'py>(
        &self,
        py: Python<'py>,
        pose: Vec<f64>,
        pusher: &str,
        twist: Vec<f64>,
        duration: f64,
        dt: f64,
        support: &str,
        rings: usize,
        points: usize,
        merge_fingers: bool,
    ) -> PyResult<Bound<'py, PyDict>> {
        let q = pose3(&pose)?;
        let u = vec3("twist", &twist)?;
        let i = self.inner.pusher_index(pusher).map_err(to_py)?;
        let opts = options(support, rings, points, merge_fingers, dt, 0.01)?;
        let tr = py
            .allow_threads(|| quasistatic::simulate_push(&self.inner, &q, i, &u, duration, dt, &opts))
            .map_err(to_py)?;
        let rows = |v: &Vec<[f64; 3]>| Array2::from_shape_fn((v.len(), 3), |(i, j)| v[i][j]);
        let d = PyDict::new(py);
        d.set_item("t", Array1::from(tr.t.clone()).into_pyarray(py))?;
        d.set_item("pose", rows(&tr.pose).into_pyarray(py))?;
        d.set_item("pusher_pose", rows(&tr.pusher_pose).into_pyarray(py))?;
        d.set_item("twist", rows(&tr.twist).into_pyarray(py))?;
        d.set_item("pusher_wrench", rows(&tr.pusher_wrench).into_pyarray(py))?;
        d.set_item("support_wrench", rows(&tr.support_wrench).into_pyarray(py))?;
        d.set_item("pusher_slip", Array1::from(tr.pusher_slip.clone()).into_pyarray(py))?;
        d.set_item("pusher_contacts", Array1::from(tr.pusher_contacts.iter().map(|x| *x as u32).collect::<Vec<_>>()).into_pyarray(py))?;
        d.set_item("pusher_sticking", Array1::from(tr.pusher_sticking.iter().map(|x| *x as u32).collect::<Vec<_>>()).into_pyarray(py))?;
        d.set_item("residual", Array1::from(tr.residual.clone()).into_pyarray(py))?;
        Ok(d)
    }

    /// T-RRT* regrasp plan (see `regrasp.plan`): `settings` overrides the defaults of
    /// `planner_defaults(2)`. Returns a dict.
    #[pyo3(signature = (start=None, goal=None, settings=None))]
    fn plan<'py>(&self, py: Python<'py>, start: Option<Vec<f64>>, goal: Option<Vec<f64>>, settings: Option<&Bound<'py, PyDict>>) -> PyResult<Bound<'py, PyDict>> {
        let start = start.map(|v| pose3(&v)).transpose().map_err(|_| arg_err("start", "must be 3 finite numbers"))?;
        let goal = goal.map(|v| pose3(&v)).transpose().map_err(|_| arg_err("goal", "must be 3 finite numbers"))?;
        let settings = settings::planar(settings)?;
        let r = py.allow_threads(|| trrt::plan(&self.inner, start, goal, &settings)).map_err(to_py)?;
        let d = plan_summary(py, &self.inner.name, &r, settings.propagation.label(), settings.search.seed)?;
        let path = r
            .path
            .iter()
            .map(|(q, p, _)| -> PyResult<Bound<'py, PyDict>> {
                let k = PyDict::new(py);
                k.set_item("pose", q.to_vec())?;
                k.set_item("pusher", p.map(|i| self.inner.pushers[i].name.clone()))?;
                Ok(k)
            })
            .collect::<PyResult<Vec<_>>>()?;
        d.set_item("path", path)?;
        Ok(d)
    }

    /// Smallest exact-test margin along each step of a path (poses, pusher names).
    #[pyo3(signature = (poses, pushers, checks=16))]
    fn validate_path(&self, poses: Vec<Vec<f64>>, pushers: Vec<Option<String>>, checks: usize) -> PyResult<Vec<f64>> {
        if poses.len() != pushers.len() {
            return Err(arg_err("path", "poses and pushers differ in length"));
        }
        let idx = path_pushers(&pushers, |n| self.inner.pusher_index(n))?;
        let mut path = Vec::new();
        for (i, (q, p)) in poses.iter().zip(idx).enumerate() {
            path.push((pose3(q).map_err(|_| arg_err(&format!("path[{i}].pose"), "must be 3 finite numbers"))?, p));
        }
        trrt::validate_path(&self.inner, &path, checks).map_err(to_py)
    }

    /// The cone mode: "nominal", "robust" or "fixtureless".
    #[getter]
    fn mode(&self) -> &'static str {
        self.inner.mode.label()
    }

    /// The `[uncertainty]` table as a dict of relative spreads (None when absent).
    #[getter]
    fn uncertainty(&self) -> Option<std::collections::HashMap<&'static str, f64>> {
        self.inner.uncertainty.map(|u| {
            [("pusher_friction", u.pusher_friction), ("finger_friction", u.finger_friction), ("grip_force", u.grip_force), ("mass", u.mass)]
                .into_iter()
                .collect()
        })
    }

    /// `ρ = μ_s N / (m g)` (grasp scenes).
    #[getter]
    fn rho(&self) -> Option<f64> {
        regrasp::scene::perturb::rho(&self.inner)
    }

    /// A copy with scaled parameters and a cone mode (see `regrasp.robust`).
    #[pyo3(signature = (finger_friction=1.0, grip=1.0, mass=1.0, pusher_friction=1.0, mode="nominal"))]
    fn scaled(&self, finger_friction: f64, grip: f64, mass: f64, pusher_friction: f64, mode: &str) -> PyResult<Self> {
        let mode = regrasp::cones::robust::ConeMode::parse(mode).map_err(to_py)?;
        regrasp::scene::perturb::scaled(&self.inner, finger_friction, grip, mass, pusher_friction, mode).map(|inner| Self { inner }).map_err(to_py)
    }

    /// Whether pusher `pusher` alone can carry the object's weight at pose `q` (the invariant case).
    fn carries_weight(&self, q: Vec<f64>, pusher: &str) -> PyResult<bool> {
        let q = pose3(&q)?;
        let p = self.inner.pusher_index(pusher).map_err(to_py)?;
        self.inner.check_pose(&q).map_err(to_py)?;
        Ok(regrasp::cones::robust::carries_weight(&self.inner.frame(&q), &self.inner.pushers[p].model))
    }

    /// Messages of the batch status codes.
    #[staticmethod]
    fn status_messages() -> Vec<(u8, &'static str)> {
        use batch::Status::*;
        [Ok, NonFinite, Inadmissible, CannotHold, ZeroTwist].iter().map(|s| (*s as u8, s.message())).collect()
    }
}

fn status_array<'py>(py: Python<'py>, st: &[batch::Status]) -> Bound<'py, PyArray1<u8>> {
    Array1::from(st.iter().map(|s| *s as u8).collect::<Vec<u8>>()).into_pyarray(py)
}

/// A validated 3-D scene (box or convex mesh object).
#[pyclass(module = "regrasp._core", frozen)]
struct Scene3D {
    inner: Scene3,
}

/// A 3-D pose `[x, y, z, qw, qx, qy, qz]` from Python (the quaternion normalized); errors name
/// the argument `name`.
fn pose7(name: &str, v: &[f64]) -> PyResult<nalgebra::Isometry3<f64>> {
    if v.len() != 7 {
        return Err(arg_err(name, format!("must be [x, y, z, qw, qx, qy, qz] (got {} numbers)", v.len())));
    }
    let a: [f64; 7] = std::array::from_fn(|i| v[i]);
    scene3d::pose_from_array(name, &a).map_err(|e| match e {
        Error::Scene { message, .. } => arg_err(name, message),
        e => to_py(e),
    })
}

#[pymethods]
impl Scene3D {
    /// Parse and validate a 3-D scene; `base` is the folder mesh paths are relative to.
    #[staticmethod]
    #[pyo3(signature = (text, base=None))]
    fn from_toml(text: &str, base: Option<String>) -> PyResult<Self> {
        Scene3::from_toml_str(text, base.as_deref().map(std::path::Path::new)).map(|inner| Self { inner }).map_err(to_py)
    }
    #[getter]
    fn name(&self) -> String {
        self.inner.name.clone()
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
    fn inertia<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        Array2::from_shape_fn((3, 3), |(i, j)| self.inner.inertia[(i, j)]).into_pyarray(py)
    }
    #[getter]
    fn task(&self) -> ([f64; 7], [f64; 7], [f64; 4]) {
        (scene3d::pose_to_array(&self.inner.start), scene3d::pose_to_array(&self.inner.goal), self.inner.tolerance)
    }
    #[getter]
    fn com(&self) -> [f64; 3] {
        [self.inner.com.x, self.inner.com.y, self.inner.com.z]
    }
    #[getter]
    fn grip_force(&self) -> f64 {
        self.inner.grip_force
    }
    #[getter]
    fn grip_friction(&self) -> f64 {
        self.inner.grip_friction
    }
    #[getter]
    fn gravity(&self) -> [f64; 3] {
        [self.inner.gravity.x, self.inner.gravity.y, self.inner.gravity.z]
    }
    /// Pusher `name` brought against the object at `pose` (default: the task's start): (contact
    /// points and normal in the object frame, friction). A rigid pusher's points do not depend
    /// on the pose; a plane's are where the object is lowest along its normal.
    #[pyo3(signature = (name, pose=None))]
    fn pusher_spec(&self, name: &str, pose: Option<Vec<f64>>) -> PyResult<(Vec<[f64; 3]>, [f64; 3], f64)> {
        let i = self.inner.pusher_index(name).map_err(to_py)?;
        let q = match pose {
            Some(v) => pose7("pose", &v)?,
            None => self.inner.start,
        };
        let (pts, n) = self.inner.pusher_contacts(i, &q);
        Ok((pts.iter().map(|v| [v.x, v.y, v.z]).collect(), [n.x, n.y, n.z], self.inner.pushers[i].friction))
    }
    /// Pusher `name`'s normal as the scene gives it (object frame; a plane's: gripper frame).
    fn pusher_normal(&self, name: &str) -> PyResult<[f64; 3]> {
        let i = self.inner.pusher_index(name).map_err(to_py)?;
        let n = self.inner.pushers[i].normal;
        Ok([n.x, n.y, n.z])
    }
    /// Whether pusher `name` is a plane (its normal fixed in the gripper frame).
    fn is_plane(&self, name: &str) -> PyResult<bool> {
        let i = self.inner.pusher_index(name).map_err(to_py)?;
        Ok(self.inner.pushers[i].plane)
    }
    /// The sphere's radius, for a spherical object (else None).
    #[getter]
    fn sphere(&self) -> Option<f64> {
        self.inner.sphere
    }
    /// T-RRT* over SE(3) with inverse-dynamics unit steps (`regrasp::planning::spatial`):
    /// `settings` overrides the defaults of `planner_defaults(3)`. Returns a dict like the
    /// planar plan (poses as [x, y, z, qw, qx, qy, qz]) plus the number of solves.
    #[pyo3(signature = (start=None, goal=None, settings=None))]
    fn plan<'py>(&self, py: Python<'py>, start: Option<Vec<f64>>, goal: Option<Vec<f64>>, settings: Option<&Bound<'py, PyDict>>) -> PyResult<Bound<'py, PyDict>> {
        let start = start.map(|v| pose7("start", &v)).transpose()?;
        let goal = goal.map(|v| pose7("goal", &v)).transpose()?;
        let settings = settings::spatial(settings)?;
        let r = py.allow_threads(|| regrasp::planning::spatial::plan3(&self.inner, start, goal, &settings)).map_err(to_py)?;
        let d = plan_summary(py, &self.inner.name, &r.plan, "mncp_inverse", settings.search.seed)?;
        d.set_item("solves", r.solves)?;
        let path = r
            .plan
            .path
            .iter()
            .map(|(q, p, u)| -> PyResult<Bound<'py, PyDict>> {
                let k = PyDict::new(py);
                k.set_item("pose", scene3d::pose_to_array(q).to_vec())?;
                k.set_item("pusher", p.map(|i| self.inner.pushers[i].name.clone()))?;
                if p.is_some() {
                    k.set_item("pusher_twist", u.to_vec())?;
                }
                Ok(k)
            })
            .collect::<PyResult<Vec<_>>>()?;
        d.set_item("path", path)?;
        Ok(d)
    }

    /// Whether each step of a path (poses, pusher names) can be taken by its pusher (inverse
    /// dynamics at 8 poses along it, pads on the object).
    #[pyo3(signature = (poses, pushers, twists=None))]
    fn validate_path(&self, poses: Vec<Vec<f64>>, pushers: Vec<Option<String>>, twists: Option<Vec<Vec<f64>>>) -> PyResult<Vec<bool>> {
        let tw: Option<Vec<[f64; 6]>> = twists
            .map(|t| t.iter().enumerate().map(|(i, v)| twist6(&format!("path[{i}].pusher_twist"), v)).collect::<PyResult<Vec<_>>>())
            .transpose()?;
        if poses.len() != pushers.len() {
            return Err(arg_err("path", "poses and pushers differ in length"));
        }
        let idx = path_pushers(&pushers, |n| self.inner.pusher_index(n))?;
        let mut path = Vec::new();
        for (i, (q, p)) in poses.iter().zip(idx).enumerate() {
            path.push((pose7(&format!("path[{i}].pose"), q)?, p));
        }
        regrasp::planning::spatial::validate_path3(&self.inner, &path, tw.as_deref()).map_err(to_py)
    }

    /// Contact points (object frame) of pusher `name` at `pose` (default: the task's start).
    #[pyo3(signature = (name, pose=None))]
    fn pusher_points(&self, name: &str, pose: Option<Vec<f64>>) -> PyResult<Vec<[f64; 3]>> {
        Ok(self.pusher_spec(name, pose)?.0)
    }

    #[getter]
    fn pad_radius(&self) -> f64 {
        self.inner.pad_radius
    }

    /// Vertices (n, 3) and triangles (m, 3) of the object's mesh.
    fn mesh<'py>(&self, py: Python<'py>) -> (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<u32>>) {
        let v = &self.inner.mesh.vertices;
        let t = &self.inner.mesh.triangles;
        (
            Array2::from_shape_fn((v.len(), 3), |(i, j)| v[i][j]).into_pyarray(py),
            Array2::from_shape_fn((t.len(), 3), |(i, j)| t[i][j] as u32).into_pyarray(py),
        )
    }
    /// Contact points (object frame) of the two finger pads at `pose`.
    fn pad_contacts(&self, pose: Vec<f64>) -> PyResult<Vec<Vec<[f64; 3]>>> {
        let p = pose7("pose", &pose)?;
        Ok(self.inner.pad_contacts(&p).iter().map(|s| s.iter().map(|v| [v.x, v.y, v.z]).collect()).collect())
    }
    /// The quasi-static problem of `pusher` in contact at its points, at `pose`.
    #[pyo3(signature = (pose, pusher, h=1.0))]
    fn quasistatic_problem(&self, pose: Vec<f64>, pusher: &str, h: f64) -> PyResult<MncpProblem> {
        let p = pose7("pose", &pose)?;
        let i = self.inner.pusher_index(pusher).map_err(to_py)?;
        Ok(MncpProblem { inner: quasistatic3d::push_problem(&self.inner, &p, i, h).map_err(to_py)? })
    }
    /// Time stepping of one push (pusher body twist [v, ω] constant, object frame at t = 0).
    fn simulate_push<'py>(
        &self,
        py: Python<'py>,
        pose: Vec<f64>,
        pusher: &str,
        twist: Vec<f64>,
        duration: f64,
        dt: f64,
    ) -> PyResult<Bound<'py, PyDict>> {
        let p = pose7("pose", &pose)?;
        if twist.len() != 6 || !twist.iter().all(|x| x.is_finite()) {
            return Err(arg_err("twist", "must be 6 finite numbers [vx, vy, vz, wx, wy, wz]"));
        }
        let u: [f64; 6] = std::array::from_fn(|i| twist[i]);
        let i = self.inner.pusher_index(pusher).map_err(to_py)?;
        let tr = py
            .allow_threads(|| quasistatic3d::simulate_push(&self.inner, &p, i, &u, duration, dt, &mncp::Settings::default()))
            .map_err(to_py)?;
        let d = PyDict::new(py);
        d.set_item("t", Array1::from(tr.t.clone()).into_pyarray(py))?;
        d.set_item("pose", Array2::from_shape_fn((tr.pose.len(), 7), |(i, j)| tr.pose[i][j]).into_pyarray(py))?;
        d.set_item("twist", Array2::from_shape_fn((tr.twist.len(), 6), |(i, j)| tr.twist[i][j]).into_pyarray(py))?;
        d.set_item("pusher_slip", Array1::from(tr.pusher_slip.clone()).into_pyarray(py))?;
        d.set_item("pusher_contacts", Array1::from(tr.pusher_contacts.iter().map(|x| *x as u32).collect::<Vec<_>>()).into_pyarray(py))?;
        d.set_item("pusher_sticking", Array1::from(tr.pusher_sticking.iter().map(|x| *x as u32).collect::<Vec<_>>()).into_pyarray(py))?;
        d.set_item("residual", Array1::from(tr.residual.clone()).into_pyarray(py))?;
        Ok(d)
    }
}

/// The motion cone of one pusher at one pose.
#[pyclass(module = "regrasp._core", frozen)]
struct MotionCone {
    push: PlanarPush,
    pusher: String,
}

impl MotionCone {
    fn twists(&self, t: &Bound<'_, PyAny>) -> PyResult<(Vec<Vec3>, bool)> {
        if let Ok(a) = t.extract::<PyReadonlyArray2<f64>>() {
            let rows = rows3("twist", &a)?;
            return Ok((rows.iter().map(|v| Vec3::new(v[0], v[1], v[2])).collect(), true));
        }
        let v: Vec<f64> = t.extract().map_err(|_| arg_err("twist", "must be 3 numbers or an (n, 3) array"))?;
        Ok((vec![vec3("twist", &v)?], false))
    }
}

#[pymethods]
impl MotionCone {
    #[getter]
    fn pusher(&self) -> String {
        self.pusher.clone()
    }
    #[getter]
    fn pose(&self) -> [f64; 3] {
        self.push.spec().pose
    }
    #[getter]
    fn length(&self) -> f64 {
        self.push.metric().length
    }
    #[getter]
    fn hold_ratio(&self) -> f64 {
        self.push.hold_ratio()
    }
    /// Whether the pusher is a line pusher (two rigidly connected points).
    #[getter]
    fn line(&self) -> bool {
        self.push.spec().pusher.is_line()
    }
    /// Generators of the polyhedral approximation, one unit twist a row.
    #[getter]
    fn generators<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        Ok(mat_from_rows(&self.push.generators().map_err(to_py)?).into_pyarray(py))
    }
    #[getter]
    fn gravity_free_generators<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        mat_from_rows(&self.push.gravity_free_generators()).into_pyarray(py)
    }
    /// Edge wrenches of the pusher's generalized friction cone (unit normal force), one a row.
    #[getter]
    fn pusher_edges<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let e: Vec<Vec3> = self.push.pusher_edges().iter().map(|e| e.wrench).collect();
        mat_from_rows(&e).into_pyarray(py)
    }
    /// Pairs of edge indices spanning the boundary fans of the pusher's friction cone.
    #[getter]
    fn boundary_segments(&self) -> Vec<(usize, usize)> {
        self.push.pusher_cone().boundary_segments()
    }
    /// The limit-surface matrix A (support frame) and J_s.
    #[getter]
    fn support_matrices<'py>(&self, py: Python<'py>) -> (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<f64>>, Bound<'py, PyArray1<f64>>) {
        let s = self.push.spec();
        let a = s.limit_surface.matrix(s.friction_scale);
        let to = |m: &regrasp::mechanics::geometry::Mat3| {
            let mut o = Array2::zeros((3, 3));
            for i in 0..3 {
                for j in 0..3 {
                    o[(i, j)] = m[(i, j)];
                }
            }
            o
        };
        (to(&a).into_pyarray(py), to(&s.support_jacobian).into_pyarray(py), Array1::from(s.gravity.as_slice().to_vec()).into_pyarray(py))
    }

    /// Motion-cone ray (unit twist) produced by pusher wrench `wrench`, or None.
    fn ray<'py>(&self, py: Python<'py>, wrench: Vec<f64>) -> PyResult<Option<Bound<'py, PyArray1<f64>>>> {
        let w = vec3("wrench", &wrench)?;
        Ok(self.push.ray(&w).map(|v| Array1::from(v.as_slice().to_vec()).into_pyarray(py)))
    }

    /// Exact test of one twist: dict(feasible, margin, active_limit, pusher_wrench, support_wrench).
    fn classify<'py>(&self, py: Python<'py>, twist: Vec<f64>) -> PyResult<Bound<'py, PyDict>> {
        let c = self.push.classify(&vec3("twist", &twist)?).map_err(to_py)?;
        classification_dict(py, &c)
    }

    /// Signed margins of one twist or of an (n, 3) array of twists.
    fn margin(&self, py: Python<'_>, twist: &Bound<'_, PyAny>) -> PyResult<PyObject> {
        let (ts, many) = self.twists(twist)?;
        let m: Vec<f64> = ts.iter().map(|t| self.push.classify(t).map(|c| c.margin)).collect::<Result<_, _>>().map_err(to_py)?;
        Ok(if many { Array1::from(m).into_pyarray(py).into_any().unbind() } else { m[0].into_pyobject(py)?.into_any().unbind() })
    }

    /// Exact membership of one twist or of an (n, 3) array of twists.
    fn contains(&self, py: Python<'_>, twist: &Bound<'_, PyAny>) -> PyResult<PyObject> {
        let (ts, many) = self.twists(twist)?;
        let m: Vec<bool> = ts.iter().map(|t| self.push.contains(t)).collect::<Result<_, _>>().map_err(to_py)?;
        Ok(if many {
            Array1::from(m).into_pyarray(py).into_any().unbind()
        } else {
            pyo3::types::PyBool::new(py, m[0]).to_owned().into_any().unbind()
        })
    }

    /// Membership in the polyhedral approximation, of one twist or an (n, 3) array.
    fn contains_polyhedral(&self, py: Python<'_>, twist: &Bound<'_, PyAny>) -> PyResult<PyObject> {
        let (ts, many) = self.twists(twist)?;
        let cone = self.push.polyhedral_cone().map_err(to_py)?;
        let mt = self.push.metric();
        let m: Vec<bool> =
            ts.iter().map(|v| cone.contains(&mt.twist(v), regrasp::cones::motion_cone::MEMBERSHIP_TOL)).collect();
        Ok(if many {
            Array1::from(m).into_pyarray(py).into_any().unbind()
        } else {
            pyo3::types::PyBool::new(py, m[0]).to_owned().into_any().unbind()
        })
    }

    /// Margin of a twist in the gravity-free cone (exact, polyhedral).
    fn gravity_free_margin(&self, twist: Vec<f64>) -> PyResult<f64> {
        self.push.gravity_free_margin(&vec3("twist", &twist)?).map_err(to_py)
    }

    /// Closest feasible twist (metric diag(1, 1, L²)), exact cone.
    fn project<'py>(&self, py: Python<'py>, twist: &Bound<'_, PyAny>) -> PyResult<PyObject> {
        let (ts, many) = self.twists(twist)?;
        let p: Vec<Vec3> = ts.iter().map(|t| self.push.project(t)).collect::<Result<_, _>>().map_err(to_py)?;
        Ok(if many {
            mat_from_rows(&p).into_pyarray(py).into_any().unbind()
        } else {
            Array1::from(p[0].as_slice().to_vec()).into_pyarray(py).into_any().unbind()
        })
    }

    /// Closest twist in a polyhedral cone given by `generators` ("approx" or "gravity_free").
    #[pyo3(signature = (twist, which="approx"))]
    fn project_polyhedral<'py>(&self, py: Python<'py>, twist: Vec<f64>, which: &str) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let v = vec3("twist", &twist)?;
        let gens = match which {
            "approx" => self.push.generators().map_err(to_py)?,
            "gravity_free" => self.push.gravity_free_generators(),
            _ => return Err(PyValueError::new_err("which must be \"approx\" or \"gravity_free\"")),
        };
        let m = self.push.metric();
        let gs: Vec<Vec3> = gens.iter().map(|g| m.twist(g)).collect();
        let (p, _) = project_onto_generators(&gs, &m.twist(&v));
        Ok(Array1::from(m.twist_inv(&p).as_slice().to_vec()).into_pyarray(py))
    }

    /// Per-finger grip-force range [min, max] for which the pusher motion of `twist` sticks.
    fn grip_force_range(&self, twist: Vec<f64>) -> PyResult<Option<(f64, f64)>> {
        let r = self.push.grip_force_range(&vec3("twist", &twist)?).map_err(to_py)?;
        Ok(r.map(|r| (r.min, r.max)))
    }

    /// Point pushers: object twist when the contact point moves with velocity `u` (object frame).
    fn point_pusher_twist<'py>(&self, py: Python<'py>, u: Vec<f64>) -> PyResult<Option<Bound<'py, PyArray1<f64>>>> {
        if u.len() != 2 || !u.iter().all(|x| x.is_finite()) {
            return Err(arg_err("u", "must be 2 finite numbers"));
        }
        if self.push.spec().pusher.is_line() {
            return Err(arg_err("pusher", "point_pusher_twist needs a point pusher"));
        }
        let s = self.push.spec().friction_scale;
        Ok(self.push.point_pusher_twist(&Vec2::new(u[0], u[1]), s).map(|v| Array1::from(v.as_slice().to_vec()).into_pyarray(py)))
    }

    /// Shape of the pusher's friction cone: "solid", "fan" or "ray".
    #[getter]
    fn pusher_cone_shape(&self) -> &'static str {
        match self.push.pusher_cone().shape {
            ConeShape::Solid { .. } => "solid",
            ConeShape::Fan { .. } => "fan",
            ConeShape::Ray => "ray",
            ConeShape::Full => "full",
        }
    }
}

/// The MPC controller (Rust `regrasp::control::mpc`): a plan's reference, the scene's cones.
#[pyclass(module = "regrasp._core", unsendable)]
struct Mpc {
    inner: regrasp::control::mpc::Mpc,
    names: Vec<String>,
}

fn path_from(scene: &regrasp::Scene, poses: &[Vec<f64>], pushers: &[Option<String>]) -> PyResult<Vec<([f64; 3], Option<usize>)>> {
    if poses.len() != pushers.len() {
        return Err(arg_err("plan", "poses and pushers differ in length"));
    }
    let mut path = Vec::new();
    for (i, (q, p)) in poses.iter().zip(pushers).enumerate() {
        let q = pose3(q).map_err(|_| arg_err(&format!("plan.path[{i}].pose"), "must be 3 finite numbers"))?;
        let p = match p {
            None => None,
            Some(n) => Some(scene.pusher_index(n).map_err(|_| arg_err(&format!("plan.path[{i}].pusher"), format!("no pusher {n:?} in the scene")))?),
        };
        path.push((q, p));
    }
    Ok(path)
}

#[pymethods]
impl Mpc {
    #[new]
    #[pyo3(signature = (scene, poses, pushers, goal=None, dt=0.1, horizon=5, speed=0.01, stage_weight=1.0,
                        terminal_weight=5.0, effort_weight=1e-3, margin=0.01, stall_steps=10, max_replans=5,
                        replan_time_limit=2.0, seed=0))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        scene: &Scene,
        poses: Vec<Vec<f64>>,
        pushers: Vec<Option<String>>,
        goal: Option<Vec<f64>>,
        dt: f64,
        horizon: usize,
        speed: f64,
        stage_weight: f64,
        terminal_weight: f64,
        effort_weight: f64,
        margin: f64,
        stall_steps: usize,
        max_replans: usize,
        replan_time_limit: f64,
        seed: u64,
    ) -> PyResult<Self> {
        let path = path_from(&scene.inner, &poses, &pushers)?;
        let goal = goal.map(|g| pose3(&g)).transpose().map_err(|_| arg_err("goal", "must be 3 finite numbers"))?;
        let settings = regrasp::control::mpc::MpcSettings {
            dt,
            horizon,
            speed,
            stage_weight,
            terminal_weight,
            effort_weight,
            margin,
            stall_steps,
            max_replans,
            planner: {
                let mut p = trrt::PlanarSettings::default();
                p.search.time_limit = replan_time_limit;
                p.search.seed = seed;
                p
            },
            ..regrasp::control::mpc::MpcSettings::default()
        };
        let inner = regrasp::control::mpc::Mpc::new(&scene.inner, &path, goal, settings).map_err(to_py)?;
        Ok(Self { inner, names: scene.inner.pushers.iter().map(|p| p.name.clone()).collect() })
    }

    /// One control step from the measured pose: a dict with status, pusher, twist, knot,
    /// tracking_error, projected, solve_time_s, replan_time_s.
    fn step<'py>(&mut self, py: Python<'py>, pose: Vec<f64>) -> PyResult<Bound<'py, PyDict>> {
        let q = pose3(&pose)?;
        let inner = &mut self.inner;
        // a step may re-plan (up to the re-planning time limit): other Python threads run meanwhile
        let c = py.allow_threads(|| inner.step(&q)).map_err(to_py)?;
        let d = PyDict::new(py);
        d.set_item("status", c.status.label())?;
        d.set_item("pusher", c.pusher.map(|i| self.names[i].clone()))?;
        d.set_item("twist", vec![c.twist.x, c.twist.y, c.twist.z])?;
        d.set_item("knot", c.knot)?;
        d.set_item("tracking_error", c.tracking_error)?;
        d.set_item("projected", c.projected)?;
        d.set_item("solve_time_s", c.solve_time_s)?;
        d.set_item("replan_time_s", c.replan_time_s)?;
        Ok(d)
    }

    /// The QP at pose `pose` with the reference after knot `knot`: per horizon step a dict with
    /// the pusher, generators (k, 3) and weights (k,); and whether clarabel solved it.
    fn solve_qp<'py>(&self, py: Python<'py>, pose: Vec<f64>, knot: usize) -> PyResult<(Vec<Bound<'py, PyDict>>, bool)> {
        let q = pose3(&pose)?;
        let sol = self.inner.solve_qp(&q, knot.min(self.inner.knots().len() - 1)).map_err(to_py)?;
        let steps = sol
            .steps
            .iter()
            .map(|(p, g, w)| -> PyResult<Bound<'py, PyDict>> {
                let d = PyDict::new(py);
                d.set_item("pusher", self.names[*p].clone())?;
                let mut a = Array2::<f64>::zeros((g.len(), 3));
                for (i, v) in g.iter().enumerate() {
                    for k in 0..3 {
                        a[(i, k)] = v[k];
                    }
                }
                d.set_item("generators", a.into_pyarray(py))?;
                d.set_item("weights", w.clone())?;
                Ok(d)
            })
            .collect::<PyResult<Vec<_>>>()?;
        Ok((steps, sol.status_ok))
    }

    /// Reference knots (n, 3) and the pusher reaching each.
    #[getter]
    fn knots<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let k = self.inner.knots();
        let mut a = Array2::<f64>::zeros((k.len(), 3));
        for (i, q) in k.iter().enumerate() {
            for j in 0..3 {
                a[(i, j)] = q[j];
            }
        }
        a.into_pyarray(py)
    }
    #[getter]
    fn knot_pushers(&self) -> Vec<Option<String>> {
        self.inner.knot_pushers().iter().map(|p| p.map(|i| self.names[i].clone())).collect()
    }
    #[getter]
    fn replans(&self) -> usize {
        self.inner.replans
    }
    /// Why the last re-planning failed (None if it did not).
    #[getter]
    fn replan_error(&self) -> Option<String> {
        self.inner.last_replan_error.clone()
    }
}

fn twist6(name: &str, v: &[f64]) -> PyResult<[f64; 6]> {
    let a: [f64; 6] = v.try_into().map_err(|_| arg_err(name, format!("must have 6 numbers [vx, vy, vz, wx, wy, wz], got {}", v.len())))?;
    if !a.iter().all(|x| x.is_finite()) {
        return Err(arg_err(name, "has a non-finite component"));
    }
    Ok(a)
}

/// The constant body twist taking pose `a` to pose `b` in unit time (SE(3) log).
#[pyfunction]
fn se3_log(a: Vec<f64>, b: Vec<f64>) -> PyResult<[f64; 6]> {
    Ok(regrasp::pose::spatial::log(&pose7("a", &a)?, &pose7("b", &b)?))
}

/// `pose ∘ exp(t · twist)` (body twist; SE(3) exp).
#[pyfunction]
fn se3_integrate(pose: Vec<f64>, twist: Vec<f64>, t: f64) -> PyResult<[f64; 7]> {
    if !t.is_finite() {
        return Err(arg_err("t", "must be finite"));
    }
    Ok(scene3d::pose_to_array(&regrasp::pose::spatial::integrate(&pose7("pose", &pose)?, &twist6("twist", &twist)?, t)))
}

/// `a ∘ b` of two poses.
#[pyfunction]
fn se3_compose(a: Vec<f64>, b: Vec<f64>) -> PyResult<[f64; 7]> {
    Ok(scene3d::pose_to_array(&(pose7("a", &a)? * pose7("b", &b)?)))
}

/// `a⁻¹`.
#[pyfunction]
fn se3_inverse(a: Vec<f64>) -> PyResult<[f64; 7]> {
    Ok(scene3d::pose_to_array(&pose7("a", &a)?.inverse()))
}

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Scene>()?;
    m.add_class::<MotionCone>()?;
    m.add_class::<MncpProblem>()?;
    m.add_class::<Scene3D>()?;
    m.add_class::<Mpc>()?;
    m.add_function(wrap_pyfunction!(settings::planner_defaults, m)?)?;
    m.add_function(wrap_pyfunction!(se3_log, m)?)?;
    m.add_function(wrap_pyfunction!(se3_integrate, m)?)?;
    m.add_function(wrap_pyfunction!(se3_compose, m)?)?;
    m.add_function(wrap_pyfunction!(se3_inverse, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
