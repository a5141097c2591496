//! Conversion across the boundary, one helper family each way.
//!
//! In: every Python argument arrives as a `&Bound<PyAny>` and is converted here, so that any
//! failure (a wrong type, a negative count, a wrong-length pose, a non-finite number) is an
//! `ArgumentError` naming the argument. Out: numpy arrays from rows, vectors and matrices, and
//! dicts through [`dict!`].

use crate::errors::{arg_err, to_py};
use nalgebra::{Dim, Isometry3, Matrix, RawStorage};
use numpy::ndarray::Array2;
use numpy::{AllowTypeChange, Element, IntoPyArray, PyArray1, PyArray2, PyArrayLike2};
use pyo3::prelude::*;
use pyo3::IntoPyObjectExt;
use regrasp::mechanics::geometry::Vec3;
use regrasp::Error;

/// Largest magnitude of a number argument (a coordinate [m], an angle [rad], a velocity [m/s],
/// a time [s], ...): far beyond any physical value, and where squares and products of a few of
/// them stay finite.
pub const MAX_MAGNITUDE: f64 = 1e9;

/// `x` unless it is not finite or its magnitude exceeds [`MAX_MAGNITUDE`] (an error naming `name`).
fn bounded(name: &str, x: f64) -> PyResult<f64> {
    if !x.is_finite() {
        return Err(arg_err(name, format!("must be finite (got {x})")));
    }
    if x.abs() > MAX_MAGNITUDE {
        return Err(arg_err(name, format!("must be at most {MAX_MAGNITUDE:e} in magnitude (got {x:e})")));
    }
    Ok(x)
}

/// A Python argument, as every binding takes it (converted by the functions below).
pub type Arg<'py> = Bound<'py, PyAny>;

/// A Rust type a Python argument converts to, and how an error message describes it.
pub trait Kind<'py>: FromPyObject<'py> {
    const WHAT: &'static str;
}

macro_rules! kinds {
    ($($t:ty => $what:literal),* $(,)?) => {
        $(impl<'py> Kind<'py> for $t {
            const WHAT: &'static str = $what;
        })*
    };
}

kinds!(
    f64 => "a number",
    usize => "a whole number >= 0",
    u64 => "a whole number >= 0",
    bool => "True or False",
    String => "a string",
    Option<f64> => "a number or None",
    Vec<f64> => "a list of numbers",
    Vec<Option<String>> => "a list of pusher names (None for the start)",
    Vec<Arg<'py>> => "a list",
);

/// Argument `name` as a `T`.
pub fn arg<'py, T: Kind<'py>>(name: &str, v: &Arg<'py>) -> PyResult<T> {
    v.extract().map_err(|_| arg_err(name, format!("must be {} (got {v})", T::WHAT)))
}

/// An optional argument converted by `f`: `None` when absent or None.
pub fn optional<'py, T>(v: Option<&Arg<'py>>, f: impl FnOnce(&Arg<'py>) -> PyResult<T>) -> PyResult<Option<T>> {
    v.filter(|v| !v.is_none()).map(f).transpose()
}

/// Optional argument `name` as a `T`: `None` when absent or None.
pub fn opt<'py, T: Kind<'py>>(name: &str, v: Option<&Arg<'py>>) -> PyResult<Option<T>> {
    optional(v, |v| arg(name, v))
}

/// Argument `name`: `N` finite numbers laid out as `layout` (a list, tuple or 1-D array).
pub fn numbers<const N: usize>(name: &str, v: &Arg<'_>, layout: &str) -> PyResult<[f64; N]> {
    let bad = |got: String| arg_err(name, format!("must be {N} finite numbers {layout} (got {got})"));
    let xs: Vec<f64> = v.extract().map_err(|_| bad(v.to_string()))?;
    let a: [f64; N] = xs.try_into().map_err(|xs: Vec<f64>| bad(format!("{} numbers", xs.len())))?;
    if !a.iter().all(|x| x.is_finite()) {
        return Err(arg_err(name, "has a non-finite component"));
    }
    for x in a {
        bounded(name, x)?;
    }
    Ok(a)
}

/// A finite number of magnitude at most [`MAX_MAGNITUDE`].
pub fn finite(name: &str, v: &Arg<'_>) -> PyResult<f64> {
    bounded(name, arg(name, v)?)
}

/// Finite numbers, each of magnitude at most [`MAX_MAGNITUDE`].
pub fn finite_numbers(name: &str, v: &Arg<'_>) -> PyResult<Vec<f64>> {
    let xs: Vec<f64> = arg(name, v)?;
    xs.into_iter().map(|x| bounded(name, x)).collect()
}

/// A positive, finite number.
pub fn positive(name: &str, v: &Arg<'_>) -> PyResult<f64> {
    let x = finite(name, v)?;
    if x <= 0.0 {
        return Err(arg_err(name, format!("must be positive (got {x})")));
    }
    Ok(x)
}

/// A planar pose `[x, z, θ]`.
pub fn pose3(name: &str, v: &Arg<'_>) -> PyResult<[f64; 3]> {
    numbers(name, v, "[x, z, θ]")
}

/// A planar twist `[vx, vz, ω]`.
pub fn twist3(name: &str, v: &Arg<'_>) -> PyResult<Vec3> {
    numbers(name, v, "[vx, vz, ω]").map(Vec3::from)
}

/// A 3-D body twist `[vx, vy, vz, wx, wy, wz]`.
pub fn twist6(name: &str, v: &Arg<'_>) -> PyResult<[f64; 6]> {
    numbers(name, v, "[vx, vy, vz, wx, wy, wz]")
}

/// A 3-D pose `[x, y, z, qw, qx, qy, qz]` (the quaternion normalized).
pub fn pose7(name: &str, v: &Arg<'_>) -> PyResult<Isometry3<f64>> {
    let a = numbers::<7>(name, v, "[x, y, z, qw, qx, qy, qz]")?;
    regrasp::pose::spatial::from_array(name, &a).map_err(|e| match e {
        Error::Scene { message, .. } => arg_err(name, message),
        e => to_py(e),
    })
}

/// Argument `name` as an `(n, N)` array of numbers (any array-like), one row a `[f64; N]`.
pub fn rows<const N: usize>(name: &str, v: &Arg<'_>) -> PyResult<Vec<[f64; N]>> {
    let a: PyArrayLike2<'_, f64, AllowTypeChange> =
        v.extract().map_err(|_| arg_err(name, format!("must be an (n, {N}) array of numbers (got {v})")))?;
    let a = a.as_array();
    if a.ncols() != N {
        return Err(arg_err(name, format!("must have shape (n, {N}), got {:?}", a.shape())));
    }
    Ok(a.rows().into_iter().map(|r| std::array::from_fn(|j| r[j])).collect())
}

/// Argument `pusher` (a pusher's name) as its index by `index`.
pub fn pusher(v: &Arg<'_>, index: impl Fn(&str) -> regrasp::Result<usize>) -> PyResult<usize> {
    index(&arg::<String>("pusher", v)?).map_err(to_py)
}

/// A batch query's poses, twists and pusher index.
pub type Batch = (Vec<[f64; 3]>, Vec<[f64; 3]>, usize);

/// The arguments of a batch query: `poses` and `twists`, two `(n, 3)` arrays with as many rows,
/// and the `pusher`'s index by `index`.
pub fn batch(poses: &Arg<'_>, twists: &Arg<'_>, pusher: &Arg<'_>, index: impl Fn(&str) -> regrasp::Result<usize>) -> PyResult<Batch> {
    let (q, t) = (rows::<3>("poses", poses)?, rows::<3>("twists", twists)?);
    if q.len() != t.len() {
        return Err(arg_err("twists", format!("has {} rows but poses has {}", t.len(), q.len())));
    }
    Ok((q, t, self::pusher(pusher, index)?))
}

/// A path from argument lists `poses` and `pushers` (pusher names, None for the start): step
/// `i`'s pose converted by `pose`, its pusher by `index`; errors name `{prefix}[i].pose` or
/// `{prefix}[i].pusher`.
pub fn path<'py, Q>(
    prefix: &str,
    poses: &Arg<'py>,
    pushers: &Arg<'py>,
    pose: impl Fn(&str, &Arg<'py>) -> PyResult<Q>,
    index: impl Fn(&str) -> regrasp::Result<usize>,
) -> PyResult<Vec<(Q, Option<usize>)>> {
    let poses: Vec<Arg<'py>> = arg("poses", poses)?;
    let names: Vec<Option<String>> = arg("pushers", pushers)?;
    if poses.len() != names.len() {
        return Err(arg_err(prefix, format!("{} poses but {} pushers", poses.len(), names.len())));
    }
    let step = |i: usize, q: &Arg<'py>, p: &Option<String>| {
        let q = pose(&format!("{prefix}[{i}].pose"), q)?;
        let p = p.as_deref().map(|n| index(n).map_err(|_| arg_err(&format!("{prefix}[{i}].pusher"), format!("no pusher {n:?} in the scene"))));
        Ok((q, p.transpose()?))
    };
    poses.iter().zip(&names).enumerate().map(|(i, (q, p))| step(i, q, p)).collect()
}

/// A 1-D array.
pub fn array1<T: Element>(py: Python<'_>, v: Vec<T>) -> Bound<'_, PyArray1<T>> {
    PyArray1::from_vec(py, v)
}

/// An `(n, N)` array, one row an `[T; N]`.
pub fn rows_array<T: Element, const N: usize>(py: Python<'_>, rows: Vec<[T; N]>) -> Bound<'_, PyArray2<T>> {
    Array2::from(rows).into_pyarray(py)
}

/// An `(n, N)` array of rows that convert to `[f64; N]` (e.g. `Vec3`).
pub fn matrix_rows<'py, R: Copy + Into<[f64; N]>, const N: usize>(py: Python<'py>, rows: &[R]) -> Bound<'py, PyArray2<f64>> {
    rows_array(py, rows.iter().map(|&r| r.into()).collect())
}

/// A vector (any nalgebra vector) as a 1-D array.
pub fn vector<'py, R: Dim, C: Dim, S: RawStorage<f64, R, C>>(py: Python<'py>, m: &Matrix<f64, R, C, S>) -> Bound<'py, PyArray1<f64>> {
    array1(py, m.iter().copied().collect())
}

/// A matrix (any nalgebra matrix) as a 2-D array.
pub fn matrix<'py, R: Dim, C: Dim, S: RawStorage<f64, R, C>>(py: Python<'py>, m: &Matrix<f64, R, C, S>) -> Bound<'py, PyArray2<f64>> {
    Array2::from_shape_fn((m.nrows(), m.ncols()), |(i, j)| m[(i, j)]).into_pyarray(py)
}

/// The single value of `v` when `many` is false, else `v` as a 1-D array.
pub fn one_or_array<'py, T: Element + Copy + IntoPyObject<'py>>(py: Python<'py>, v: Vec<T>, many: bool) -> PyResult<PyObject> {
    match v[..] {
        [x] if !many => x.into_py_any(py),
        _ => Ok(array1(py, v).into_any().unbind()),
    }
}

/// A `PyDict` of `key => value` pairs (each value converted by PyO3), `?` on failure.
macro_rules! dict {
    ($py:expr; $($key:expr => $value:expr),* $(,)?) => {{
        let d = pyo3::types::PyDict::new($py);
        $(d.set_item($key, $value)?;)*
        d
    }};
}
pub(crate) use dict;
