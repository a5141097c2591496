//! SE(3) pose algebra (`regrasp::pose::spatial`) on poses `[x, y, z, qw, qx, qy, qz]` and body
//! twists `[vx, vy, vz, wx, wy, wz]`.

use crate::convert::{Arg, finite, pose7, twist6};
use crate::errors::guard;
use pyo3::prelude::*;
use regrasp::pose::spatial::{integrate, log, to_array};

/// The constant body twist taking pose `a` to pose `b` in unit time (SE(3) log).
#[pyfunction]
pub fn se3_log(a: &Arg<'_>, b: &Arg<'_>) -> PyResult<[f64; 6]> {
    guard(move || {
        Ok(log(&pose7("a", a)?, &pose7("b", b)?))
    })
}

/// `pose ∘ exp(t · twist)`: `pose` `[x, y, z, qw, qx, qy, qz]` (m, unit quaternion), body
/// `twist` `[vx, vy, vz, wx, wy, wz]` (m/s, rad/s), `t` [s] (SE(3) exp).
#[pyfunction]
pub fn se3_integrate(pose: &Arg<'_>, twist: &Arg<'_>, t: &Arg<'_>) -> PyResult<[f64; 7]> {
    guard(move || {
        Ok(to_array(&integrate(&pose7("pose", pose)?, &twist6("twist", twist)?, finite("t", t)?)))
    })
}

/// `a ∘ b` of two poses.
#[pyfunction]
pub fn se3_compose(a: &Arg<'_>, b: &Arg<'_>) -> PyResult<[f64; 7]> {
    guard(move || {
        Ok(to_array(&(pose7("a", a)? * pose7("b", b)?)))
    })
}

/// `a⁻¹`.
#[pyfunction]
pub fn se3_inverse(a: &Arg<'_>) -> PyResult<[f64; 7]> {
    guard(move || {
        Ok(to_array(&pose7("a", a)?.inverse()))
    })
}
