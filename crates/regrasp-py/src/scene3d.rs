//! The 3-D `Scene3D` (`regrasp::scene::spatial`): a box, sphere or convex-mesh object between
//! two finger pads, its pushers, and the entry points of dynamics and planning.

use crate::convert::{Arg, arg, matrix, optional, pose7, pusher, rows_array};
use crate::dynamics::{self, MncpProblem, PushArgs};
use crate::errors::{guard, to_py};
use crate::planning;
use numpy::PyArray2;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use regrasp::dynamics::planar::Options;
use regrasp::pose::spatial::to_array;
use regrasp::scene::spatial::Scene3;

/// A validated 3-D scene (box or convex mesh object).
#[pyclass(module = "regrasp._core", frozen)]
pub struct Scene3D {
    inner: Scene3,
}

impl Scene3D {
    fn index(&self, name: &Arg<'_>) -> PyResult<usize> {
        pusher(name, |n| self.inner.pusher_index(n))
    }
}

#[pymethods]
impl Scene3D {
    /// Parse and validate a 3-D scene; `base` is the folder mesh paths are relative to.
    #[staticmethod]
    #[pyo3(signature = (text, base=None))]
    fn from_toml(text: &Arg<'_>, base: Option<&Arg<'_>>) -> PyResult<Self> {
        guard(move || {
            let base: Option<String> = optional(base, |b| arg("base", b))?;
            Scene3::from_toml_str(&arg::<String>("text", text)?, base.as_deref().map(std::path::Path::new))
                .map(|inner| Self { inner })
                .map_err(to_py)
        })
    }
    /// The scene's name.
    #[getter] fn name(&self) -> String { self.inner.name.clone() }
    /// Names of the pushers, in file order.
    #[getter] fn pusher_names(&self) -> Vec<String> { self.inner.pushers.iter().map(|p| p.name.clone()).collect() }
    /// What the loader changed in the file's values (pusher points snapped onto the surface).
    #[getter] fn notes(&self) -> Vec<String> { self.inner.notes().to_vec() }
    /// Characteristic length L [m] weighing rotation against translation.
    #[getter] fn length(&self) -> f64 { self.inner.length }
    /// Mass of the object [kg].
    #[getter] fn mass(&self) -> f64 { self.inner.mass }
    /// Inertia about the centre of mass, object frame [kg·m²], shape (3, 3).
    #[getter] fn inertia<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> { matrix(py, &self.inner.inertia) }
    /// (start, goal, tolerance): poses `[x, y, z, qw, qx, qy, qz]` (m, unit quaternion) and the
    /// tolerance `[x, y, z, angle]` (m, m, m, rad).
    #[getter]
    fn task(&self) -> ([f64; 7], [f64; 7], [f64; 4]) {
        (to_array(&self.inner.start), to_array(&self.inner.goal), self.inner.tolerance)
    }
    /// Centre of mass in the object frame [m].
    #[getter] fn com(&self) -> [f64; 3] { self.inner.com.into() }
    /// Grip force per finger [N].
    #[getter] fn grip_force(&self) -> f64 { self.inner.grip_force }
    /// Friction coefficient of the finger pads.
    #[getter] fn grip_friction(&self) -> f64 { self.inner.grip_friction }
    /// Gravity vector in the gripper frame [m/s²].
    #[getter] fn gravity(&self) -> [f64; 3] { self.inner.gravity.into() }
    /// Pusher `name` brought against the object at `pose` (default: the task's start): (contact
    /// points and normal in the object frame, friction). A rigid pusher's points do not depend
    /// on the pose; a plane's are where the object is lowest along its normal.
    #[pyo3(signature = (name, pose=None))]
    #[allow(clippy::type_complexity)]
    fn pusher_spec(&self, name: &Arg<'_>, pose: Option<&Arg<'_>>) -> PyResult<(Vec<[f64; 3]>, [f64; 3], f64)> {
        guard(move || {
            let i = self.index(name)?;
            let q = optional(pose, |v| pose7("pose", v))?.unwrap_or(self.inner.start);
            let (pts, n) = self.inner.pusher_contacts(i, &q);
            Ok((pts.into_iter().map(Into::into).collect(), n.into(), self.inner.pushers[i].friction))
        })
    }
    /// Pusher `name`'s normal as the scene gives it (object frame; a plane's: gripper frame).
    fn pusher_normal(&self, name: &Arg<'_>) -> PyResult<[f64; 3]> {
        guard(move || {
            Ok(self.inner.pushers[self.index(name)?].normal.into())
        })
    }
    /// Whether pusher `name` is a plane (its normal fixed in the gripper frame).
    fn is_plane(&self, name: &Arg<'_>) -> PyResult<bool> {
        guard(move || {
            Ok(self.inner.pushers[self.index(name)?].plane)
        })
    }
    /// The error of `pose` `[x, y, z, qw, qx, qy, qz]` to `goal` (default: the task's),
    /// `[dx, dy, dz, angle]` (m, m, m, rad), and whether it is within the task's tolerance.
    #[pyo3(signature = (pose, goal=None))]
    fn goal_error(&self, pose: &Arg<'_>, goal: Option<&Arg<'_>>) -> PyResult<([f64; 4], bool)> {
        guard(move || {
            let g = optional(goal, |v| pose7("goal", v))?.unwrap_or(self.inner.goal);
            Ok(regrasp::scene::spatial::goal_error(&pose7("pose", pose)?, &g, &self.inner.tolerance))
        })
    }
    /// The sphere's radius, for a spherical object (else None).
    #[getter] fn sphere(&self) -> Option<f64> { self.inner.sphere }
    /// T-RRT* over SE(3) with inverse-dynamics unit steps (`regrasp::planning::spatial`):
    /// `settings` overrides the defaults of `planner_defaults(3)`. Returns a dict like the
    /// planar plan (poses as [x, y, z, qw, qx, qy, qz]) plus the number of solves.
    #[pyo3(signature = (start=None, goal=None, settings=None))]
    fn plan<'py>(&self, py: Python<'py>, start: Option<&Arg<'py>>, goal: Option<&Arg<'py>>, settings: Option<&Arg<'py>>) -> PyResult<Bound<'py, PyDict>> {
        guard(move || {
            planning::plan_spatial(py, &self.inner, planning::Request { start, goal, settings })
        })
    }

    /// Whether each step of a path (poses (m, unit quaternion), pusher names, optional pusher
    /// `twists` (m/s, rad/s)) can be taken by its pusher (inverse
    /// dynamics at 8 poses along it, pads on the object).
    #[pyo3(signature = (poses, pushers, twists=None))]
    fn validate_path(&self, py: Python<'_>, poses: &Arg<'_>, pushers: &Arg<'_>, twists: Option<&Arg<'_>>) -> PyResult<Vec<bool>> {
        guard(move || {
            planning::validate_spatial(py, &self.inner, poses, pushers, twists)
        })
    }

    /// Contact points (object frame) of pusher `name` at `pose` (default: the task's start).
    #[pyo3(signature = (name, pose=None))]
    fn pusher_points(&self, name: &Arg<'_>, pose: Option<&Arg<'_>>) -> PyResult<Vec<[f64; 3]>> {
        guard(move || {
            Ok(self.pusher_spec(name, pose)?.0)
        })
    }

    /// Radius of the finger pads [m].
    #[getter] fn pad_radius(&self) -> f64 { self.inner.pad_radius }

    /// Vertices (n, 3) and triangles (m, 3) of the object's mesh (a non-convex object's convex
    /// hull).
    fn mesh<'py>(&self, py: Python<'py>) -> (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<u32>>) {
        mesh_arrays(py, &self.inner.mesh)
    }
    /// The object's convex parts, each its vertices (n, 3) and triangles (m, 3): the mesh alone
    /// for a convex object.
    fn parts<'py>(&self, py: Python<'py>) -> Vec<(Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<u32>>)> {
        if self.inner.parts.is_empty() {
            return vec![mesh_arrays(py, &self.inner.mesh)];
        }
        self.inner.parts.iter().map(|m| mesh_arrays(py, m)).collect()
    }
    /// Contact points (object frame, m) of the two finger pads at `pose` `[x, y, z, qw, qx, qy, qz]`
    /// (m, unit quaternion).
    fn pad_contacts(&self, pose: &Arg<'_>) -> PyResult<Vec<Vec<[f64; 3]>>> {
        guard(move || {
            let pads = self.inner.pad_contacts(&pose7("pose", pose)?);
            Ok(pads.iter().map(|s| s.iter().map(|&v| v.into()).collect()).collect())
        })
    }
    /// The quasi-static problem of `pusher` in contact at its points, at `pose`, with time
    /// step `h` (default: the quasi-static model's, `quasistatic_defaults()["h"]`).
    #[pyo3(signature = (pose, pusher, h=None))]
    fn quasistatic_problem(&self, pose: &Arg<'_>, pusher: &Arg<'_>, h: Option<&Arg<'_>>) -> PyResult<MncpProblem> {
        guard(move || {
            let h = optional(h, |v| arg("h", v))?.unwrap_or(Options::default().h);
            dynamics::spatial_problem(&self.inner, pose, pusher, h)
        })
    }
    /// Time stepping of one push from `pose` (m, unit quaternion): pusher body `twist` `[v, ω]`
    /// (m/s, rad/s) constant (object frame at t = 0) for `duration` [s] in steps of `dt` [s].
    fn simulate_push<'py>(
        &self,
        py: Python<'py>,
        pose: &Arg<'py>,
        pusher: &Arg<'py>,
        twist: &Arg<'py>,
        duration: &Arg<'py>,
        dt: &Arg<'py>,
    ) -> PyResult<Bound<'py, PyDict>> {
        guard(move || {
            dynamics::simulate_spatial(py, &self.inner, PushArgs { pose, pusher, twist, duration, dt })
        })
    }
}

/// A mesh's vertices and triangles as numpy arrays.
fn mesh_arrays<'py>(py: Python<'py>, m: &regrasp::scene::spatial::ConvexMesh) -> (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<u32>>) {
    (rows_array(py, m.vertices.iter().map(|&v| v.into()).collect()), rows_array(py, m.triangles.iter().map(|t| t.map(|i| i as u32)).collect()))
}
