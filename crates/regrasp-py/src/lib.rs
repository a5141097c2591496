//! Python bindings of the regrasp core (`regrasp._core`): conversion only, no mechanics here.
//!
//! One module per pipeline stage — [`scene`] and [`scene3d`] (the scenes), [`cones`],
//! [`dynamics`], [`planning`], [`control`], [`pose`] — over [`convert`] (arguments in, arrays
//! and dicts out), [`errors`] (core errors as `regrasp.errors` exceptions) and [`settings`]
//! (the Rust defaults and their overrides).

mod cones;
mod control;
mod convert;
mod dynamics;
mod errors;
mod planning;
mod pose;
mod scene;
mod scene3d;
mod settings;

use pyo3::prelude::*;

/// The compiled core of regrasp: scenes, motion cones, quasi-static dynamics, planning, control
/// and SE(3) pose algebra (the Python API wraps it: `regrasp.Scene`, `regrasp.plan`, ...).
/// Units are SI (m, rad, N, kg, s).
#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    errors::quiet_panic_hook();
    m.add_class::<scene::Scene>()?;
    m.add_class::<cones::MotionCone>()?;
    m.add_class::<dynamics::MncpProblem>()?;
    m.add_class::<scene3d::Scene3D>()?;
    m.add_class::<control::Mpc>()?;
    m.add_function(wrap_pyfunction!(settings::planner_defaults, m)?)?;
    m.add_function(wrap_pyfunction!(settings::mpc_defaults, m)?)?;
    m.add_function(wrap_pyfunction!(settings::quasistatic_defaults, m)?)?;
    m.add_function(wrap_pyfunction!(settings::validation_rings, m)?)?;
    m.add_function(wrap_pyfunction!(settings::limit_surface_default, m)?)?;
    m.add_function(wrap_pyfunction!(pose::se3_log, m)?)?;
    m.add_function(wrap_pyfunction!(pose::se3_integrate, m)?)?;
    m.add_function(wrap_pyfunction!(pose::se3_compose, m)?)?;
    m.add_function(wrap_pyfunction!(pose::se3_inverse, m)?)?;
    m.add("MAX_MAGNITUDE", convert::MAX_MAGNITUDE)?;
    let limits = pyo3::types::PyDict::new(m.py());
    for (name, v) in regrasp::scene::bounds::LIMITS {
        limits.set_item(name, v)?;
    }
    m.add("LIMITS", limits)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
