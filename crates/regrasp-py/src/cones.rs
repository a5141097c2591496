//! Motion cones: the `MotionCone` of one push (`regrasp::cones::motion_cone`, its polyhedral
//! cones in `regrasp::cones::polyhedral`) and the planar scene's batch queries
//! (`regrasp::cones::batch`).

use crate::convert::{Arg, arg, array1, batch, dict, matrix, matrix_rows, numbers, one_or_array, opt, pusher, rows, rows_array, twist3, vector};
use crate::errors::{arg_err, guard, interruptible, to_py};
use numpy::ndarray::Array3;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use pyo3::IntoPyObjectExt;
use regrasp::cones::batch::{self as batches, Status};
use regrasp::cones::polyhedral::{self, Generators};
use regrasp::mechanics::friction_cone::{ConeShape, ContactLimit};
use regrasp::mechanics::geometry::{Vec2, Vec3};
use regrasp::{PlanarPush, Scene};

/// The motion cone of one pusher at one pose.
#[pyclass(module = "regrasp._core", frozen)]
pub struct MotionCone {
    push: PlanarPush,
    pusher: String,
}

impl MotionCone {
    pub fn new(push: PlanarPush, pusher: String) -> Self {
        Self { push, pusher }
    }
}

/// Argument `twist`: one twist (`false`) or an `(n, 3)` array of twists (`true`).
fn twists(t: &Arg<'_>) -> PyResult<(Vec<Vec3>, bool)> {
    if t.extract::<Vec<f64>>().is_ok() {
        return Ok((vec![twist3("twist", t)?], false));
    }
    Ok((rows::<3>("twist", t)?.into_iter().map(Vec3::from).collect(), true))
}

#[pymethods]
impl MotionCone {
    /// Name of the pusher.
    #[getter] fn pusher(&self) -> String { self.pusher.clone() }
    /// The pose `[x, z, theta]` (m, m, rad).
    #[getter] fn pose(&self) -> [f64; 3] { self.push.spec().pose }
    /// Characteristic length L [m] of the twist metric diag(1, 1, L²).
    #[getter] fn length(&self) -> f64 { self.push.metric().length }
    /// Share of the pads' friction that gravity alone uses (< 1 holds).
    #[getter] fn hold_ratio(&self) -> f64 { self.push.hold_ratio() }
    /// Whether the pusher is a line pusher (two rigidly connected points).
    #[getter] fn line(&self) -> bool { self.push.spec().pusher.is_line() }
    /// Generators of the polyhedral approximation, one unit twist a row.
    #[getter]
    fn generators<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        guard(move || {
            Ok(matrix_rows(py, &self.push.generators().map_err(to_py)?))
        })
    }
    /// Generators of the gravity-free cone, one unit twist (m/s, m/s, rad/s) a row.
    #[getter]
    fn gravity_free_generators<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        matrix_rows(py, &self.push.gravity_free_generators())
    }
    /// Edge wrenches of the pusher's generalized friction cone (unit normal force), one a row.
    #[getter]
    fn pusher_edges<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        matrix_rows(py, &self.push.pusher_edges().iter().map(|e| e.wrench).collect::<Vec<_>>())
    }
    /// Pairs of edge indices spanning the boundary fans of the pusher's friction cone.
    #[getter] fn boundary_segments(&self) -> Vec<(usize, usize)> { self.push.pusher_cone().boundary_segments() }
    /// The ellipsoidal limit-surface matrix A (eq 3.7, support frame; the cones use it only on
    /// the ellipsoid), J_s and the gravity wrench.
    #[getter]
    #[allow(clippy::type_complexity)]
    fn support_matrices<'py>(&self, py: Python<'py>) -> (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<f64>>, Bound<'py, PyArray1<f64>>) {
        let f = self.push.frame();
        (matrix(py, &f.a), matrix(py, &f.js), vector(py, &f.gravity))
    }

    /// Motion-cone ray (unit twist) produced by pusher wrench `wrench` `[fx, fz, tau]` (N, N, N·m),
    /// or None.
    fn ray<'py>(&self, py: Python<'py>, wrench: &Arg<'py>) -> PyResult<Option<Bound<'py, PyArray1<f64>>>> {
        guard(move || {
            let w = Vec3::from(numbers("wrench", wrench, "[fx, fz, τ]")?);
            Ok(self.push.ray(&w).map(|v| vector(py, &v)))
        })
    }

    /// Exact test of one twist `[vx, vz, omega]` (m/s, m/s, rad/s): dict(feasible, margin,
    /// active_limit, pusher_wrench, support_wrench), wrenches `[fx, fz, tau]` (N, N, N·m).
    fn classify<'py>(&self, py: Python<'py>, twist: &Arg<'py>) -> PyResult<Bound<'py, PyDict>> {
        guard(move || {
            let c = self.push.classify(&twist3("twist", twist)?).map_err(to_py)?;
            Ok(dict!(py; "feasible" => c.feasible, "margin" => c.margin, "active_limit" => c.limit.label(),
                         "pusher_wrench" => c.pusher_wrench.as_slice().to_vec(),
                         "support_wrench" => c.support_wrench.as_slice().to_vec()))
        })
    }

    /// Signed margins of one twist `[vx, vz, omega]` (m/s, m/s, rad/s) or of an (n, 3) array of twists.
    fn margin(&self, py: Python<'_>, twist: &Arg<'_>) -> PyResult<PyObject> {
        guard(move || {
            let (ts, many) = twists(twist)?;
            let m = ts.iter().map(|t| self.push.classify(t).map(|c| c.margin)).collect::<Result<_, _>>().map_err(to_py)?;
            one_or_array(py, m, many)
        })
    }

    /// Exact membership of one twist (m/s, m/s, rad/s) or of an (n, 3) array of twists.
    fn contains(&self, py: Python<'_>, twist: &Arg<'_>) -> PyResult<PyObject> {
        guard(move || {
            let (ts, many) = twists(twist)?;
            let m = ts.iter().map(|t| self.push.contains(t)).collect::<Result<_, _>>().map_err(to_py)?;
            one_or_array(py, m, many)
        })
    }

    /// Membership in the polyhedral approximation, of one twist (m/s, m/s, rad/s) or an (n, 3) array.
    fn contains_polyhedral(&self, py: Python<'_>, twist: &Arg<'_>) -> PyResult<PyObject> {
        guard(move || {
            let (ts, many) = twists(twist)?;
            one_or_array(py, polyhedral::contains(&self.push, &ts).map_err(to_py)?, many)
        })
    }

    /// Margin of a twist (m/s, m/s, rad/s) in the gravity-free cone (exact, polyhedral).
    fn gravity_free_margin(&self, twist: &Arg<'_>) -> PyResult<f64> {
        guard(move || {
            self.push.gravity_free_margin(&twist3("twist", twist)?).map_err(to_py)
        })
    }

    /// Closest feasible twist (m/s, m/s, rad/s; metric diag(1, 1, L²)), exact cone, to one twist
    /// or to each row of an (n, 3) array.
    fn project(&self, py: Python<'_>, twist: &Arg<'_>) -> PyResult<PyObject> {
        guard(move || {
            let (ts, many) = twists(twist)?;
            let p: Vec<Vec3> = ts.iter().map(|t| self.push.project(t)).collect::<Result<_, _>>().map_err(to_py)?;
            match p[..] {
                [one] if !many => vector(py, &one).into_py_any(py),
                _ => matrix_rows(py, &p).into_py_any(py),
            }
        })
    }

    /// Closest twist (m/s, m/s, rad/s) in a polyhedral cone: `which` "approx" (default) or
    /// "gravity_free".
    #[pyo3(signature = (twist, which=None))]
    fn project_polyhedral<'py>(&self, py: Python<'py>, twist: &Arg<'py>, which: Option<&Arg<'py>>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        guard(move || {
            let which = match opt::<String>("which", which)? {
                Some(w) => Generators::parse(&w).map_err(to_py)?,
                None => Generators::Approx,
            };
            Ok(vector(py, &polyhedral::project(&self.push, &twist3("twist", twist)?, which).map_err(to_py)?))
        })
    }

    /// Per-finger grip-force range (min, max) [N] for which the pusher motion of `twist`
    /// (m/s, m/s, rad/s) sticks, or None.
    fn grip_force_range(&self, twist: &Arg<'_>) -> PyResult<Option<(f64, f64)>> {
        guard(move || {
            let r = self.push.grip_force_range(&twist3("twist", twist)?).map_err(to_py)?;
            Ok(r.map(|r| (r.min, r.max)))
        })
    }

    /// Point pushers: object twist (m/s, m/s, rad/s) when the contact point moves with velocity
    /// `u` [m/s] (object frame), or None.
    fn point_pusher_twist<'py>(&self, py: Python<'py>, u: &Arg<'py>) -> PyResult<Option<Bound<'py, PyArray1<f64>>>> {
        guard(move || {
            let u = Vec2::from(numbers("u", u, "[ux, uz]")?);
            if self.push.spec().pusher.is_line() {
                return Err(arg_err("pusher", "point_pusher_twist needs a point pusher"));
            }
            Ok(self.push.point_pusher_twist(&u, self.push.spec().friction_scale).map(|v| vector(py, &v)))
        })
    }

    /// Shape of the pusher's friction cone: "solid", "fan", "ray" or "full".
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

fn status_array<'py>(py: Python<'py>, st: &[Status]) -> Bound<'py, PyArray1<u8>> {
    array1(py, st.iter().map(|s| *s as u8).collect())
}

/// `Scene.generators_many`'s result: generators (n, k, 3) and status (n,).
pub type Generated<'py> = (Bound<'py, PyArray3<f64>>, Bound<'py, PyArray1<u8>>);
/// `Scene.classify_many`'s result: feasible, margin, active-limit codes and status, each (n,).
pub type Classified<'py> = (Bound<'py, PyArray1<bool>>, Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<u8>>, Bound<'py, PyArray1<u8>>);
/// `Scene.project_many`'s result: projections (n, 3) and status (n,).
pub type Projected<'py> = (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray1<u8>>);

/// Entries of a batch computed between two interrupt checks (each chunk spread over the core's
/// threads in pieces of [`regrasp::cones::batch`]'s own chunk; a few ms of work at most).
const CHUNK: usize = 16_384;

/// `f` on the ranges of `0..n`, [`CHUNK`] entries each, checking for an interrupt before each.
fn chunked(n: usize, mut f: impl FnMut(std::ops::Range<usize>)) -> regrasp::Result<()> {
    for start in (0..n).step_by(CHUNK) {
        regrasp::interrupt::check()?;
        f(start..(start + CHUNK).min(n));
    }
    Ok(())
}

/// `Scene.generators_many`: the polyhedral (or gravity-free) generators of pusher `name` at
/// each pose.
pub fn generators_many<'py>(py: Python<'py>, scene: &Scene, poses: &Arg<'py>, name: &Arg<'py>, gravity_free: &Arg<'py>) -> PyResult<Generated<'py>> {
    let (q, i, gravity_free) = (rows::<3>("poses", poses)?, pusher(name, |n| scene.pusher_index(n))?, arg("gravity_free", gravity_free)?);
    let (n, k) = (q.len(), scene.pushers[i].model.edges.len());
    let mut out = vec![0.0; n * k * 3];
    let mut st = vec![Status::Ok; n];
    let (g, s) = (k * 3, &mut st);
    interruptible(py, || chunked(q.len(), |r| batches::generators_into(scene, &q[r.clone()], i, gravity_free, &mut out[r.start * g..r.end * g], &mut s[r])))?;
    // the buffer is the array's memory, row-major (n, k, 3): no copy
    let g = Array3::from_shape_vec((n, k, 3), out).map_err(|e| to_py(regrasp::Error::arg("poses", format!("generators: {e}"))))?;
    Ok((g.into_pyarray(py), status_array(py, &st)))
}

/// `Scene.classify_many`: the exact test of twist i at pose i.
pub fn classify_many<'py>(py: Python<'py>, scene: &Scene, poses: &Arg<'py>, twists: &Arg<'py>, name: &Arg<'py>) -> PyResult<Classified<'py>> {
    let (q, t, i) = batch(poses, twists, name, |n| scene.pusher_index(n))?;
    let n = q.len();
    let (mut fe, mut ma, mut li, mut st) = (vec![false; n], vec![0.0; n], vec![ContactLimit::Torque; n], vec![Status::Ok; n]);
    interruptible(py, || {
        chunked(n, |r| batches::classify_into(scene, &q[r.clone()], &t[r.clone()], i, &mut fe[r.clone()], &mut ma[r.clone()], &mut li[r.clone()], &mut st[r]))
    })?;
    let codes = li.iter().map(|l| l.code()).collect();
    Ok((array1(py, fe), array1(py, ma), array1(py, codes), status_array(py, &st)))
}

/// `Scene.project_many`: the closest feasible twist to twist i at pose i.
pub fn project_many<'py>(py: Python<'py>, scene: &Scene, poses: &Arg<'py>, twists: &Arg<'py>, name: &Arg<'py>) -> PyResult<Projected<'py>> {
    let (q, t, i) = batch(poses, twists, name, |n| scene.pusher_index(n))?;
    let (mut out, mut st) = (vec![0.0; 3 * q.len()], vec![Status::Ok; q.len()]);
    interruptible(py, || chunked(q.len(), |r| batches::project_into(scene, &q[r.clone()], &t[r.clone()], i, &mut out[3 * r.start..3 * r.end], &mut st[r])))?;
    Ok((rows_array(py, out.as_chunks::<3>().0.to_vec()), status_array(py, &st)))
}

/// Labels of the contact-limit codes of `classify_many`.
pub fn limit_labels() -> Vec<String> {
    ContactLimit::ALL.iter().map(|l| l.label()).collect()
}

/// Messages of the batch status codes.
pub fn status_messages() -> Vec<(u8, &'static str)> {
    use Status::*;
    [Ok, NonFinite, Inadmissible, CannotHold, ZeroTwist].iter().map(|s| (*s as u8, s.message())).collect()
}
