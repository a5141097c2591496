//! SE(3): poses of the object frame in the gripper frame as isometries (arrays
//! `[x, y, z, qw, qx, qy, qz]` at the boundary), body twists `[v, ω]` [m/s, rad/s].

use crate::error::{Error, Result};
use nalgebra::{Isometry3, Matrix3, Quaternion, Translation3, UnitQuaternion, Vector3};

pub type V3 = Vector3<f64>;
/// A body twist `[v, ω]` (unit time).
pub type Twist6 = [f64; 6];

/// The cross-product matrix `[r]×`.
pub fn skew(r: &V3) -> Matrix3<f64> {
    Matrix3::new(0.0, -r.z, r.y, r.z, 0.0, -r.x, -r.y, r.x, 0.0)
}

/// `V(ω) = I + (1 − cos θ)/θ² [ω]× + (θ − sin θ)/θ³ [ω]×²`: the left Jacobian mapping a twist's
/// linear part to the displacement of its exponential.
fn left_jacobian(w: &V3) -> Matrix3<f64> {
    let th = w.norm();
    let wx = skew(w);
    let (a, b) = if th < 1e-8 { (0.5 - th * th / 24.0, 1.0 / 6.0 - th * th / 120.0) } else {
        ((1.0 - th.cos()) / (th * th), (th - th.sin()) / (th * th * th))
    };
    Matrix3::identity() + wx * a + wx * wx * b
}

/// `exp` of a body twist `[v, ω]` applied over `dt` (right multiplication).
pub fn integrate(pose: &Isometry3<f64>, u: &Twist6, dt: f64) -> Isometry3<f64> {
    let v = V3::new(u[0], u[1], u[2]) * dt;
    let w = V3::new(u[3], u[4], u[5]) * dt;
    let step = Isometry3::from_parts(Translation3::from(left_jacobian(&w) * v), UnitQuaternion::from_scaled_axis(w));
    pose * step
}

/// The constant body twist taking `a` to `b` in unit time: `log(a⁻¹b)` (inverse of
/// [`integrate`]).
pub fn log(a: &Isometry3<f64>, b: &Isometry3<f64>) -> Twist6 {
    let rel = a.inverse() * b;
    let w = rel.rotation.scaled_axis();
    let v = left_jacobian(&w).try_inverse().unwrap_or_else(Matrix3::identity) * rel.translation.vector;
    [v.x, v.y, v.z, w.x, w.y, w.z]
}

/// Body twist of frame `b` expressed in frame `a` (`rel = a⁻¹ b`).
pub fn twist_in(rel: &Isometry3<f64>, u: &Twist6) -> Twist6 {
    let (v, w) = (V3::new(u[0], u[1], u[2]), V3::new(u[3], u[4], u[5]));
    let rw = rel.rotation * w;
    let rv = rel.rotation * v + rel.translation.vector.cross(&rw);
    [rv.x, rv.y, rv.z, rw.x, rw.y, rw.z]
}

/// The metric distance between two poses: `√(‖p‖² + (L θ)²)` of `a⁻¹b` [m].
pub fn distance(l: f64, a: &Isometry3<f64>, b: &Isometry3<f64>) -> f64 {
    let rel = a.inverse() * b;
    (rel.translation.vector.norm_squared() + (l * rel.rotation.angle()).powi(2)).sqrt()
}

/// Length of a body twist in the metric: `√(‖v‖² + (L‖ω‖)²)` [m] (for small steps, ≈ the
/// distance it travels).
pub fn twist_length(l: f64, u: &Twist6) -> f64 {
    (u[0] * u[0] + u[1] * u[1] + u[2] * u[2] + l * l * (u[3] * u[3] + u[4] * u[4] + u[5] * u[5])).sqrt()
}

/// `[x, y, z, qw, qx, qy, qz]` as an isometry (the quaternion is normalized; it must not be 0).
pub fn from_array(field: &str, a: &[f64; 7]) -> Result<Isometry3<f64>> {
    if !a.iter().all(|x| x.is_finite()) {
        return Err(Error::scene(field, "has a non-finite component"));
    }
    let q = Quaternion::new(a[3], a[4], a[5], a[6]);
    if q.norm() < 1e-9 {
        return Err(Error::scene(field, "the quaternion [qw, qx, qy, qz] is zero"));
    }
    Ok(Isometry3::from_parts(Translation3::new(a[0], a[1], a[2]), UnitQuaternion::from_quaternion(q)))
}

/// An isometry as `[x, y, z, qw, qx, qy, qz]`.
pub fn to_array(p: &Isometry3<f64>) -> [f64; 7] {
    let q = p.rotation.quaternion();
    [p.translation.x, p.translation.y, p.translation.z, q.w, q.i, q.j, q.k]
}
