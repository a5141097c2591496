//! Quasi-static dynamics (`regrasp::dynamics`): the `MncpProblem` of one instant, and the
//! problems, pushes and simulated pushes of planar and 3-D scenes.

use crate::convert::{Arg, arg, array1, finite, finite_numbers, batch, dict, matrix, pose3, pose7, pusher, rows_array, twist3, twist6, vector};
use crate::errors::{arg_err, guard, interruptible, to_py};
use nalgebra::DVector;
use numpy::{PyArray1, PyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use regrasp::dynamics::mncp::{self, Contact, FrictionLaw, NormalLaw, Side};
use regrasp::dynamics::planar::{self as quasistatic, Options};
use regrasp::dynamics::spatial as quasistatic3d;
use regrasp::scene::spatial::Scene3;
use regrasp::Scene;

/// One instantaneous quasi-static problem (thesis §3.2): contacts, mass matrix, gravity.
#[pyclass(module = "regrasp._core", frozen)]
pub struct MncpProblem {
    inner: mncp::Problem,
}

/// Argument `name`: a list of `n` numbers.
fn sized(name: &str, v: &Arg<'_>, n: usize) -> PyResult<Vec<f64>> {
    let x = finite_numbers(name, v)?;
    if x.len() != n {
        return Err(arg_err(name, format!("must have {n} numbers (got {})", x.len())));
    }
    Ok(x)
}

/// Argument `friction_forces`: one list of numbers per contact, of its tangent dimension.
fn friction_forces(p: &mncp::Problem, v: &Arg<'_>) -> PyResult<Vec<DVector<f64>>> {
    let fs: Vec<Arg<'_>> = arg("friction_forces", v)?;
    if fs.len() != p.contacts.len() {
        return Err(arg_err("friction_forces", format!("must have one entry per contact ({})", p.contacts.len())));
    }
    let one = |(i, (c, f)): (usize, (&Contact, &Arg<'_>))| sized(&format!("friction_forces[{i}]"), f, c.tangent_dim());
    p.contacts.iter().zip(&fs).enumerate().map(|x| one(x).map(DVector::from_vec)).collect()
}

fn residuals_dict<'py>(py: Python<'py>, r: &mncp::Residuals) -> PyResult<Bound<'py, PyDict>> {
    Ok(dict!(py; "newton_euler" => r.newton_euler, "normal_feasibility" => r.normal_feasibility,
                 "normal_complementarity" => r.normal_complementarity, "cone" => r.cone,
                 "friction_complementarity" => r.friction_complementarity, "dissipation" => r.dissipation))
}

fn solution_dict<'py>(py: Python<'py>, p: &mncp::Problem, s: &mncp::Solution) -> PyResult<Bound<'py, PyDict>> {
    let vectors = |vs: &[DVector<f64>]| vs.iter().map(|v| vector(py, v)).collect::<Vec<_>>();
    Ok(dict!(py;
        "twist" => vector(py, &s.twist),
        "pusher_twist" => vector(py, &s.pusher_twist),
        "normal_forces" => array1(py, s.normal_forces.clone()),
        "friction_forces" => vectors(&s.friction_forces),
        "normal_velocities" => array1(py, s.normal_velocities.clone()),
        "tangent_velocities" => vectors(&s.tangent_velocities),
        "states" => s.states.iter().map(|x| x.label()).collect::<Vec<_>>(),
        "labels" => p.contacts.iter().map(|c| c.label.clone()).collect::<Vec<_>>(),
        "residuals" => residuals_dict(py, &s.residuals)?,
        "max_residual" => s.residuals.max(),
        "iterations" => s.iterations,
    ))
}

fn contact_dict<'py>(py: Python<'py>, c: &Contact) -> PyResult<Bound<'py, PyDict>> {
    let side = match c.side {
        Side::Finger => "finger",
        Side::Pusher => "pusher",
        Side::Fixed => "fixed",
    };
    let d = dict!(py; "label" => &c.label, "side" => side, "jn" => vector(py, &c.jn), "jt" => matrix(py, &c.jt),
                      "jn_other" => vector(py, &c.jn_other), "jt_other" => matrix(py, &c.jt_other), "gap" => c.gap);
    match c.normal {
        NormalLaw::Fixed(f) => d.update(dict!(py; "normal" => "fixed", "normal_force" => f).as_mapping())?,
        NormalLaw::Unilateral => d.set_item("normal", "unilateral")?,
    }
    match &c.friction {
        FrictionLaw::Coulomb(mu) => d.update(dict!(py; "friction" => "coulomb", "mu" => *mu).as_mapping())?,
        FrictionLaw::Ellipsoid(a) => d.update(dict!(py; "friction" => "ellipsoid", "A" => matrix(py, a)).as_mapping())?,
    }
    Ok(d)
}

#[pymethods]
impl MncpProblem {
    /// Dimension of the twists: 3 (planar) or 6 (3-D).
    #[getter] fn dim(&self) -> usize { self.inner.dim }
    /// The contacts' labels, in order.
    #[getter] fn labels(&self) -> Vec<String> { self.inner.contacts.iter().map(|c| c.label.clone()).collect() }

    /// Forward problem: the pusher twist `pusher_twist` (m/s, rad/s) given; returns the solution
    /// as a dict (twists in m/s and rad/s, forces in N).
    fn solve_forward<'py>(&self, py: Python<'py>, pusher_twist: &Arg<'py>) -> PyResult<Bound<'py, PyDict>> {
        guard(move || {
            let u = DVector::from_vec(finite_numbers("pusher_twist", pusher_twist)?);
            let s = py.allow_threads(|| mncp::solve_forward(&self.inner, &u, &mncp::Settings::default())).map_err(to_py)?;
            solution_dict(py, &self.inner, &s)
        })
    }

    /// Inverse problem: the object twist `twist` (m/s, rad/s) given; returns the pusher motion
    /// (m/s, rad/s) and the forces (N) as a dict.
    fn solve_inverse<'py>(&self, py: Python<'py>, twist: &Arg<'py>) -> PyResult<Bound<'py, PyDict>> {
        guard(move || {
            let v = DVector::from_vec(finite_numbers("twist", twist)?);
            let s = py.allow_threads(|| mncp::solve_inverse(&self.inner, &v, &mncp::Settings::default())).map_err(to_py)?;
            solution_dict(py, &self.inner, &s)
        })
    }

    /// Scaled violation of every constraint for a candidate solution (e.g. the reference's):
    /// twists (m/s, rad/s), normal and friction forces (N).
    fn residuals<'py>(
        &self, py: Python<'py>, twist: &Arg<'py>, pusher_twist: &Arg<'py>, normal_forces: &Arg<'py>, friction_forces: &Arg<'py>,
    ) -> PyResult<Bound<'py, PyDict>> {
        guard(move || {
            let p = &self.inner;
            let v = DVector::from_vec(sized("twist", twist, p.dim)?);
            let u = DVector::from_vec(sized("pusher_twist", pusher_twist, p.dim)?);
            let f_n = sized("normal_forces", normal_forces, p.contacts.len())?;
            let f_t = self::friction_forces(p, friction_forces)?;
            residuals_dict(py, &mncp::residuals(p, &v, &u, &f_n, &f_t))
        })
    }

    /// The problem's data (for the reference solver and for inspection).
    fn data<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        guard(move || {
            let p = &self.inner;
            let contacts = p.contacts.iter().map(|c| contact_dict(py, c)).collect::<PyResult<Vec<_>>>()?;
            Ok(dict!(py; "dim" => p.dim, "mass" => matrix(py, &p.mass), "wrench" => vector(py, &p.wrench), "h" => p.h,
                         "force_scale" => p.force_scale, "velocity_scale" => p.velocity_scale, "contacts" => contacts))
        })
    }
}

/// `Scene.quasistatic_problem`: the problem of pusher `name` (or of no pusher) at `pose`.
pub fn planar_problem(scene: &Scene, pose: &Arg<'_>, name: Option<&Arg<'_>>, opts: &Options) -> PyResult<MncpProblem> {
    let q = pose3("pose", pose)?;
    let inner = match name.filter(|n| !n.is_none()) {
        Some(n) => quasistatic::push_problem(scene, &q, pusher(n, |n| scene.pusher_index(n))?, opts),
        None => scene.check_pose(&q).and_then(|_| quasistatic::planar_problem(scene, &q, None, opts)),
    };
    Ok(MncpProblem { inner: inner.map_err(to_py)? })
}

/// `Scene3D.quasistatic_problem`: the problem of pusher `name` in contact at its points.
pub fn spatial_problem(scene: &Scene3, pose: &Arg<'_>, name: &Arg<'_>, h: f64) -> PyResult<MncpProblem> {
    let p = pose7("pose", pose)?;
    let i = pusher(name, |n| scene.pusher_index(n))?;
    Ok(MncpProblem { inner: quasistatic3d::push_problem(scene, &p, i, h).map_err(to_py)? })
}

/// The results of `Scene.push_outcomes`: sticks, object twists, max residuals, errors.
pub type Outcomes<'py> = (Bound<'py, PyArray1<bool>>, Bound<'py, PyArray2<f64>>, Bound<'py, PyArray1<f64>>, Vec<Option<String>>);

/// `Scene.push_outcomes`: instantaneous pushes of pusher `name`, twist i at pose i (zero twist
/// and residual where `errors[i]` is set).
pub fn push_outcomes<'py>(py: Python<'py>, scene: &Scene, poses: &Arg<'py>, name: &Arg<'py>, twists: &Arg<'py>, opts: &Options) -> PyResult<Outcomes<'py>> {
    let (q, t, i) = batch(poses, twists, name, |n| scene.pusher_index(n))?;
    let res = interruptible(py, || quasistatic::push_outcomes(scene, &q, i, &t, opts))?;
    let (mut sticks, mut tw, mut resid, mut errors) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for r in res {
        let (s, v, m, e) = match r {
            Ok(o) => (o.sticks, std::array::from_fn(|c| o.solution.twist.get(c).copied().unwrap_or(0.0)), o.solution.residuals.max(), None),
            Err(e) => (false, [0.0; 3], 0.0, Some(e.to_string())),
        };
        sticks.push(s);
        tw.push(v);
        resid.push(m);
        errors.push(e);
    }
    Ok((array1(py, sticks), rows_array(py, tw), array1(py, resid), errors))
}

/// The fields a planar and a 3-D trajectory share, as a dict.
macro_rules! trajectory_dict {
    ($py:expr, $tr:expr) => {{
        let counts = |v: &[usize]| array1($py, v.iter().map(|&x| x as u32).collect());
        dict!($py;
            "t" => array1($py, $tr.t.clone()),
            "pose" => rows_array($py, $tr.pose.clone()),
            "twist" => rows_array($py, $tr.twist.clone()),
            "pusher_slip" => array1($py, $tr.pusher_slip.clone()),
            "pusher_contacts" => counts(&$tr.pusher_contacts),
            "pusher_sticking" => counts(&$tr.pusher_sticking),
            "residual" => array1($py, $tr.residual.clone()),
        )
    }};
}

/// The arguments of `simulate_push`: the start pose, the pusher, its twist, the duration and the time step.
pub struct PushArgs<'a, 'py> {
    pub pose: &'a Arg<'py>,
    pub pusher: &'a Arg<'py>,
    pub twist: &'a Arg<'py>,
    pub duration: &'a Arg<'py>,
    pub dt: &'a Arg<'py>,
}

/// `Scene.simulate_push`: explicit time stepping of one push.
pub fn simulate_planar<'py>(py: Python<'py>, scene: &Scene, a: PushArgs<'_, 'py>, opts: &Options) -> PyResult<Bound<'py, PyDict>> {
    let (q, u) = (pose3("pose", a.pose)?, twist3("twist", a.twist)?);
    let i = pusher(a.pusher, |n| scene.pusher_index(n))?;
    let (duration, dt) = (finite("duration", a.duration)?, finite("dt", a.dt)?);
    let tr = interruptible(py, || quasistatic::simulate_push(scene, &q, i, &u, duration, dt, opts))?;
    let d = trajectory_dict!(py, tr);
    d.set_item("pusher_pose", rows_array(py, tr.pusher_pose))?;
    d.set_item("pusher_wrench", rows_array(py, tr.pusher_wrench))?;
    d.set_item("support_wrench", rows_array(py, tr.support_wrench))?;
    Ok(d)
}

/// `Scene3D.simulate_push`: time stepping of one push (pusher body twist [v, ω] constant).
pub fn simulate_spatial<'py>(py: Python<'py>, scene: &Scene3, a: PushArgs<'_, 'py>) -> PyResult<Bound<'py, PyDict>> {
    let (p, u) = (pose7("pose", a.pose)?, twist6("twist", a.twist)?);
    let i = pusher(a.pusher, |n| scene.pusher_index(n))?;
    let (duration, dt) = (finite("duration", a.duration)?, finite("dt", a.dt)?);
    let tr = interruptible(py, || quasistatic3d::simulate_push(scene, &p, i, &u, duration, dt, &mncp::Settings::default()))?;
    Ok(trajectory_dict!(py, tr))
}
