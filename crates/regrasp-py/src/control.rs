//! Control (`regrasp::control::mpc`): the MPC that tracks a plan's reference within the
//! scene's motion cones, re-planning when it stalls.

use crate::convert::{Arg, arg, dict, matrix_rows, optional, path, pose3, rows_array};
use crate::errors::{arg_err, guard, interruptible, to_py};
use crate::scene::Scene;
use crate::settings;
use numpy::PyArray2;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use std::sync::{Mutex, MutexGuard, TryLockError};

/// The MPC controller (Rust `regrasp::control::mpc`): a plan's reference, the scene's cones.
/// Its state is behind a mutex: any thread may use it, one at a time (a call while another
/// thread's is running is an `ArgumentError`, never a wait that could hold the GIL).
#[pyclass(module = "regrasp._core", frozen)]
pub struct Mpc {
    inner: Mutex<regrasp::control::mpc::Mpc>,
    names: Vec<String>,
}

impl Mpc {
    fn name(&self, i: Option<usize>) -> Option<String> {
        i.and_then(|i| self.names.get(i)).cloned()
    }

    /// The controller's state, or an error when another thread is using it.
    fn state(&self) -> PyResult<MutexGuard<'_, regrasp::control::mpc::Mpc>> {
        self.inner.try_lock().map_err(|e| match e {
            TryLockError::WouldBlock => arg_err("self", "the controller is in use by another thread"),
            TryLockError::Poisoned(_) => arg_err("self", "the controller failed in an earlier call (make a new one)"),
        })
    }
}

#[pymethods]
impl Mpc {
    /// The controller of the plan (`poses` (n, 3) in (m, m, rad), `pushers`) in `scene`, towards
    /// `goal` (default: the task's); `dt` [s], `speed` [m/s], `replan_time_limit` [s]. Every other keyword is a setting of `mpc_defaults()` (None: its default).
    #[new]
    #[pyo3(signature = (scene, poses, pushers, goal=None, dt=None, horizon=None, speed=None, stage_weight=None,
                        terminal_weight=None, effort_weight=None, margin=None, stall_steps=None, max_replans=None,
                        replan_time_limit=None, seed=None, **settings))]
    #[allow(clippy::too_many_arguments)]
    fn new<'py>(
        scene: &Arg<'py>,
        poses: &Arg<'py>,
        pushers: &Arg<'py>,
        goal: Option<&Arg<'py>>,
        dt: Option<Arg<'py>>,
        horizon: Option<Arg<'py>>,
        speed: Option<Arg<'py>>,
        stage_weight: Option<Arg<'py>>,
        terminal_weight: Option<Arg<'py>>,
        effort_weight: Option<Arg<'py>>,
        margin: Option<Arg<'py>>,
        stall_steps: Option<Arg<'py>>,
        max_replans: Option<Arg<'py>>,
        replan_time_limit: Option<Arg<'py>>,
        seed: Option<Arg<'py>>,
        settings: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Self> {
        guard(move || {
            let named = [("dt", dt), ("horizon", horizon), ("speed", speed), ("stage_weight", stage_weight),
                         ("terminal_weight", terminal_weight), ("effort_weight", effort_weight), ("margin", margin),
                         ("stall_steps", stall_steps), ("max_replans", max_replans),
                         ("replan_time_limit", replan_time_limit), ("seed", seed)];
            let mut given: Vec<(String, Arg<'py>)> =
                named.into_iter().filter_map(|(k, v)| v.map(|v| (k.to_string(), v))).collect();
            given.extend(settings::items(settings.map(|d| d.as_any()))?);
            let scene = scene.downcast::<Scene>().map_err(|_| arg_err("scene", "must be a regrasp._core.Scene"))?.get();
            let path = path("plan.path", poses, pushers, pose3, |n| scene.inner.pusher_index(n))?;
            let goal = optional(goal, |g| pose3("goal", g))?;
            let inner = regrasp::control::mpc::Mpc::new(&scene.inner, &path, goal, settings::mpc(&given)?).map_err(to_py)?;
            Ok(Self { inner: Mutex::new(inner), names: scene.inner.pushers.iter().map(|p| p.name.clone()).collect() })
        })
    }

    /// One control step from the measured pose `pose` `[x, z, theta]` (m, m, rad): a dict with
    /// status, pusher, twist (m/s, m/s, rad/s), knot, tracking_error, projected, solve_time_s and
    /// replan_time_s (s).
    fn step<'py>(&self, py: Python<'py>, pose: &Arg<'py>) -> PyResult<Bound<'py, PyDict>> {
        guard(move || {
            let q = pose3("pose", pose)?;
            let mut state = self.state()?;
            let inner = &mut *state;
            // a step may re-plan (up to the re-planning time limit): other Python threads run meanwhile
            let c = interruptible(py, || inner.step(&q))?;
            Ok(dict!(py;
                "status" => c.status.label(), "pusher" => self.name(c.pusher), "twist" => c.twist.as_slice().to_vec(),
                "knot" => c.knot, "tracking_error" => c.tracking_error, "projected" => c.projected,
                "solve_time_s" => c.solve_time_s, "replan_time_s" => c.replan_time_s,
            ))
        })
    }

    /// The QP at pose `pose` `[x, z, theta]` (m, m, rad) with the reference after knot `knot`: per horizon step a dict with
    /// the pusher, generators (k, 3) and weights (k,); and whether clarabel solved it.
    fn solve_qp<'py>(&self, py: Python<'py>, pose: &Arg<'py>, knot: &Arg<'py>) -> PyResult<Bound<'py, PyTuple>> {
        guard(move || {
            let sol = self.state()?.solve_qp(&pose3("pose", pose)?, arg("knot", knot)?).map_err(to_py)?;
            let step = |(p, g, w): &(usize, Vec<_>, Vec<f64>)| -> PyResult<_> {
                Ok(dict!(py; "pusher" => self.name(Some(*p)), "generators" => matrix_rows(py, g), "weights" => w.clone()))
            };
            let steps = sol.steps.iter().map(step).collect::<PyResult<Vec<_>>>()?;
            (steps, sol.status_ok).into_pyobject(py)
        })
    }

    /// Reference knots (n, 3).
    #[getter] fn knots<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> { Ok(rows_array(py, self.state()?.knots().to_vec())) }
    /// The pusher reaching each knot.
    #[getter] fn knot_pushers(&self) -> PyResult<Vec<Option<String>>> { Ok(self.state()?.knot_pushers().iter().map(|&p| self.name(p)).collect()) }
    /// Re-plans made so far.
    #[getter] fn replans(&self) -> PyResult<usize> { Ok(self.state()?.replans) }
    /// Why the last re-planning failed (None if it did not).
    #[getter] fn replan_error(&self) -> PyResult<Option<String>> { Ok(self.state()?.last_replan_error.clone()) }
}
