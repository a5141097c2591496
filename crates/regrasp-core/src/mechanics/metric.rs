//! Frame-invariant metrics on planar twists and wrenches.
//!
//! A twist is measured by the velocity of the centre of mass and `L ω`, a wrench by its force
//! and its moment about the centre of mass divided by `L` (L: a characteristic length, the
//! radius of gyration of the outline). The two are dual, `⟨W(w), T(v)⟩ = w·v` (power), and
//! neither depends on where the object frame is put, so margins, projections and distances
//! are the same in any object frame.

use crate::mechanics::geometry::{cross2, perp, Vec2, Vec3};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Metric {
    /// Centre of mass, object frame [m].
    pub com: Vec2,
    /// Characteristic length L [m].
    pub length: f64,
}

impl Metric {
    pub fn new(com: Vec2, length: f64) -> Self {
        Self { com, length }
    }

    /// `[v_com, L ω]`: the velocity of the centre of mass and the scaled rotation rate.
    #[inline]
    pub fn twist(&self, v: &Vec3) -> Vec3 {
        let c = perp(&self.com) * v.z;
        Vec3::new(v.x + c.x, v.y + c.y, v.z * self.length)
    }

    /// Inverse of [`Self::twist`].
    #[inline]
    pub fn twist_inv(&self, s: &Vec3) -> Vec3 {
        let w = s.z / self.length;
        let c = perp(&self.com) * w;
        Vec3::new(s.x - c.x, s.y - c.y, w)
    }

    /// `[f, τ_com / L]`: the force and the moment about the centre of mass, scaled.
    #[inline]
    pub fn wrench(&self, w: &Vec3) -> Vec3 {
        Vec3::new(w.x, w.y, (w.z - cross2(&self.com, &Vec2::new(w.x, w.y))) / self.length)
    }

    /// Inverse of [`Self::wrench`].
    #[inline]
    pub fn wrench_inv(&self, s: &Vec3) -> Vec3 {
        Vec3::new(s.x, s.y, s.z * self.length + cross2(&self.com, &Vec2::new(s.x, s.y)))
    }

    #[inline]
    pub fn twist_norm(&self, v: &Vec3) -> f64 {
        self.twist(v).norm()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn metrics_are_dual_and_invertible() {
        let m = Metric::new(Vec2::new(0.01, -0.02), 0.03);
        let (v, w) = (Vec3::new(0.1, -0.2, 3.0), Vec3::new(4.0, 5.0, -0.06));
        assert!((m.wrench(&w).dot(&m.twist(&v)) - w.dot(&v)).abs() < 1e-12);
        assert!((m.twist_inv(&m.twist(&v)) - v).norm() < 1e-14);
        assert!((m.wrench_inv(&m.wrench(&w)) - w).norm() < 1e-14);
    }
}
