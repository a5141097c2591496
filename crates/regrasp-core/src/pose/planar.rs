//! SE(2): poses `q = [x, z, θ]` of the object frame in the gripper frame (a point `p` of the
//! object is at `R(θ) p + [x, z]`), body twists `[vx, vz, ω]` in the object frame [m/s, rad/s].

use nalgebra::{Matrix2, Matrix3, Vector2, Vector3};

pub type Vec2 = Vector2<f64>;
pub type Vec3 = Vector3<f64>;
pub type Mat2 = Matrix2<f64>;
pub type Mat3 = Matrix3<f64>;

/// Rotation by `theta` (counter-clockwise).
#[inline]
pub fn rot(theta: f64) -> Mat2 {
    let (s, c) = theta.sin_cos();
    Mat2::new(c, -s, s, c)
}

/// A planar rigid transform `p ↦ R(theta) p + t`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pose2 {
    pub t: Vec2,
    pub theta: f64,
}

impl Pose2 {
    pub fn new(x: f64, z: f64, theta: f64) -> Self {
        Self { t: Vec2::new(x, z), theta }
    }
    pub fn from_array(q: &[f64; 3]) -> Self {
        Self::new(q[0], q[1], q[2])
    }
    pub fn to_array(&self) -> [f64; 3] {
        [self.t.x, self.t.y, self.theta]
    }
    pub fn apply(&self, p: &Vec2) -> Vec2 {
        rot(self.theta) * p + self.t
    }
    pub fn inverse(&self) -> Pose2 {
        let r = rot(-self.theta);
        Pose2 { t: -(r * self.t), theta: -self.theta }
    }
    pub fn compose(&self, other: &Pose2) -> Pose2 {
        Pose2 { t: rot(self.theta) * other.t + self.t, theta: self.theta + other.theta }
    }
    /// Adjoint: maps twists `[v, ω]` expressed in the child frame to the parent frame.
    pub fn adjoint(&self) -> Mat3 {
        let r = rot(self.theta);
        let mut m = Mat3::zeros();
        m.fixed_view_mut::<2, 2>(0, 0).copy_from(&r);
        m[(0, 2)] = self.t.y;
        m[(1, 2)] = -self.t.x;
        m[(2, 2)] = 1.0;
        m
    }
}

/// Exponential of a body twist applied over `dt` to a pose (exact for constant twists).
pub fn integrate(q: &[f64; 3], v: &Vec3, dt: f64) -> [f64; 3] {
    let w = v.z * dt;
    let lin = Vec2::new(v.x, v.y) * dt;
    // displacement in the body frame: V(w) lin with V = [[sin w / w, −(1−cos w)/w], [(1−cos w)/w, sin w / w]]
    let (a, b) = if w.abs() < 1e-9 { (1.0 - w * w / 6.0, w / 2.0) } else { (w.sin() / w, (1.0 - w.cos()) / w) };
    let disp = Vec2::new(a * lin.x - b * lin.y, b * lin.x + a * lin.y);
    let world = rot(q[2]) * disp;
    [q[0] + world.x, q[1] + world.y, q[2] + w]
}

/// Logarithm: the constant body twist taking `a` to `b` in unit time (inverse of [`integrate`]).
pub fn body_twist(a: &[f64; 3], b: &[f64; 3]) -> Vec3 {
    let d = rot(-a[2]) * Vec2::new(b[0] - a[0], b[1] - a[1]);
    let w = b[2] - a[2];
    if w.abs() < 1e-9 {
        return Vec3::new(d.x, d.y, w);
    }
    let (s, c) = (w.sin() / w, (1.0 - w.cos()) / w);
    let det = s * s + c * c;
    Vec3::new((s * d.x + c * d.y) / det, (-c * d.x + s * d.y) / det, w)
}

/// Relative pose `a⁻¹ b`.
pub fn relative(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    let d = rot(-a[2]) * Vec2::new(b[0] - a[0], b[1] - a[1]);
    [d.x, d.y, b[2] - a[2]]
}

/// Body twist `[v, ω]` of frame `b` expressed in frame `a` (`rel = a⁻¹ b`).
pub fn twist_in(rel: &[f64; 3], u: &Vec3) -> Vec3 {
    let r = rot(rel[2]);
    let lin = r * Vec2::new(u.x, u.y) - Vec2::new(-rel[1], rel[0]) * u.z;
    Vec3::new(lin.x, lin.y, u.z)
}

/// The planners' metric: `√(Δx² + Δz² + (L Δθ)²)` [m] (L: the object's radius of gyration).
pub fn distance(l: f64, a: &[f64; 3], b: &[f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (l * (a[2] - b[2])).powi(2)).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_and_exp_are_inverse() {
        for (a, b) in [([0.0, 0.0, 0.0], [0.01, -0.02, 0.3]), ([0.005, 0.002, -0.4], [-0.003, 0.01, 0.2])] {
            let tw = body_twist(&a, &b);
            let c = integrate(&a, &tw, 1.0);
            for k in 0..3 {
                assert!((c[k] - b[k]).abs() < 1e-12, "{c:?} vs {b:?}");
            }
        }
    }

    #[test]
    fn relative_composes_back() {
        let (a, b) = ([0.01, -0.02, 0.3], [-0.004, 0.03, -0.7]);
        let r = relative(&a, &b);
        let back = Pose2::from_array(&a).compose(&Pose2::from_array(&r)).to_array();
        for k in 0..3 {
            assert!((back[k] - b[k]).abs() < 1e-12);
        }
    }
}
