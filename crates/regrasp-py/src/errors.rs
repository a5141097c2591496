//! Core errors as the closed set of Python exceptions in `regrasp.errors`: `SceneError`,
//! `ArgumentError` and `GraspError`, each with the `field` at fault; a Rust panic as an
//! `InternalError` ([`guard`]); an interrupted computation as the exception the Python signal
//! handler raised (KeyboardInterrupt on Ctrl-C; [`interruptible`]).

use pyo3::exceptions::PyKeyboardInterrupt;
use pyo3::prelude::*;
use regrasp::Error;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::Mutex;

/// The message and location of the last panic in this extension (set by [`quiet_panic_hook`]).
static LAST_PANIC: Mutex<Option<String>> = Mutex::new(None);

/// Installs a panic hook that records the panic's message and location for [`guard`] instead
/// of printing them: the `InternalError` carries them to Python once (a printed copy would
/// only duplicate it, on stderr, around a clean error). The hook is this extension's own (its
/// Rust runtime is linked into it), so it affects no other library.
pub fn quiet_panic_hook() {
    std::panic::set_hook(Box::new(|info| {
        if let Ok(mut last) = LAST_PANIC.lock() {
            *last = Some(info.to_string());
        }
    }));
}

/// The body of a binding entry point, run so that a panic in it (or in the core under it)
/// becomes `regrasp.errors.InternalError` with the panic's message, never a crash nor a
/// `pyo3_runtime.PanicException`.
pub fn guard<T>(f: impl FnOnce() -> PyResult<T>) -> PyResult<T> {
    catch_unwind(AssertUnwindSafe(f)).unwrap_or_else(|payload| {
        let recorded = LAST_PANIC.lock().ok().and_then(|mut l| l.take());
        let message = recorded.unwrap_or_else(|| match payload.downcast_ref::<&str>() {
            Some(s) => s.to_string(),
            None => payload.downcast_ref::<String>().cloned().unwrap_or_else(|| "a Rust panic".into()),
        });
        Err(internal(&message))
    })
}

/// `regrasp.errors.InternalError` with `message`.
fn internal(message: &str) -> PyErr {
    let text = format!("internal error in regrasp (a bug: please report it with the input): {message}");
    Python::with_gil(|py| match py.import("regrasp.errors").and_then(|m| m.getattr("InternalError")).and_then(|c| c.call1((text.clone(),))) {
        Ok(exc) => PyErr::from_value(exc),
        Err(_) => pyo3::exceptions::PyRuntimeError::new_err(text),
    })
}

/// Runs the core computation `f` without the GIL, interruptible: its long loops poll
/// (through `regrasp::interrupt`) Python's signal handlers, at most every 20 ms; when a
/// handler raises (KeyboardInterrupt on Ctrl-C) the computation stops with
/// `Error::Interrupted` and that exception is returned. Other errors convert by [`to_py`].
pub fn interruptible<T: Send>(py: Python<'_>, f: impl FnOnce() -> regrasp::Result<T> + Send) -> PyResult<T> {
    let raised: Mutex<Option<PyErr>> = Mutex::new(None);
    let r = py.allow_threads(|| {
        let stop = || match Python::with_gil(|py| py.check_signals()) {
            Ok(()) => false,
            Err(e) => {
                if let Ok(mut r) = raised.lock() {
                    *r = Some(e);
                }
                true
            }
        };
        regrasp::interrupt::within(&stop, f)
    });
    r.map_err(|e| match e {
        Error::Interrupted => raised.into_inner().ok().flatten().unwrap_or_else(|| PyKeyboardInterrupt::new_err("interrupted")),
        e => to_py(e),
    })
}

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
            Error::Interrupted => return PyKeyboardInterrupt::new_err("interrupted"),
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
