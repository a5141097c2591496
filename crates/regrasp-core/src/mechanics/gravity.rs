//! Gravity wrench on the object (the `m g` term of eq 3.12, restricted to the plane).

use crate::mechanics::geometry::{point_wrench, rot, Vec2, Vec3};

/// Gravity wrench `[fx, fz, τ]` in the object frame, about the object-frame origin: the force
/// `Rᵀ(θ) m g d` (d: unit direction in the gripper/world frame) applied at the centre of mass
/// `com` (object frame).
pub fn gravity_wrench(mass: f64, g: f64, direction: &Vec2, theta: f64, com: &Vec2) -> Vec3 {
    let f = rot(-theta) * direction * (mass * g);
    point_wrench(com, &f)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gravity_rotates_with_the_object() {
        let w = gravity_wrench(1.0, 10.0, &Vec2::new(0.0, -1.0), std::f64::consts::FRAC_PI_2, &Vec2::zeros());
        // object turned +90°: world down is object +x
        assert!((w.x + 10.0).abs() < 1e-12, "world -Z is object -X after +90° turn: got {w}");
        let w = gravity_wrench(1.0, 10.0, &Vec2::new(0.0, -1.0), 0.0, &Vec2::new(0.1, 0.0));
        assert!((w.z + 1.0).abs() < 1e-12, "COM right of origin: clockwise moment");
    }
}
