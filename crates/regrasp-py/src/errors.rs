//! Core errors as the closed set of Python exceptions in `regrasp.errors`: `SceneError`,
//! `ArgumentError` and `GraspError`, each with the `field` at fault.

use pyo3::prelude::*;
use regrasp::Error;

/// The Python exception (from `regrasp.errors`) matching a core error.
pub fn to_py(err: Error) -> PyErr {
    Python::with_gil(|py| {
        let module = match py.import("regrasp.errors") {
            Ok(m) => m,
            Err(e) => return e,
        };
        let (class, field) = match &err {
            Error::Scene { field, .. } => ("SceneError", field.clone()),
            Error::InvalidArgument { name, .. } => ("ArgumentError", name.clone()),
            Error::GraspCannotHold { .. } => ("GraspError", "grasp.force".to_string()),
        };
        match module.getattr(class).and_then(|c| c.call1((err.to_string(), Some(field)))) {
            Ok(exc) => PyErr::from_value(exc),
            Err(e) => e,
        }
    })
}

/// An `ArgumentError` naming argument `name`.
pub fn arg_err(name: &str, msg: impl Into<String>) -> PyErr {
    to_py(Error::arg(name, msg))
}
