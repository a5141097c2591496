//! Point pushers (thesis §3.3, a pusher of one contact point): a point contact transmits no
//! moment, so its generalized friction cone is a fan and its motion cone a surface in twist
//! space. What such a pusher controls is its contact point's velocity `u`; the object's rotation
//! rate is the one for which the required pusher wrench passes through the contact point `r`.
//!
//! With `û = u/|u|` the object twists whose contact point moves along `û` are
//! `v(φ) = (û cos φ − r⊥ sin φ / L, sin φ / L)`, φ ∈ (−π/2, π/2). The moment about `r` of the
//! required pusher wrench `w(v)` is non-decreasing in φ (the load is the gradient of a convex
//! dissipation function, a monotone map), so its root is found by a safeguarded secant search.

use crate::cones::frame::SupportFrame;
use crate::mechanics::geometry::{cross2, perp, Vec2, Vec3};

/// The object twist (direction only: `v(φ)` above, of unit size in the metric of length `length`)
/// when contact point `r` (object frame) moves with velocity `u`, given the required pusher
/// wrench `wrench(v)` (object frame, N and N·m). `None` when no rotation rate balances the
/// moment about `r`. For `u = 0`, a pure rotation about `r` if either sense balances it.
pub fn contact_twist(r: &Vec2, u: &Vec2, length: f64, wrench: impl Fn(&Vec3) -> Vec3) -> Option<Vec3> {
    contact_twist_near(r, u, length, wrench, None).map(|(v, _)| v)
}

/// [`contact_twist`] and its angle φ, the search started from a bracket of ±0.01 rad about
/// `hint` when it holds the root (a warm start along a motion), else from (−π/2, π/2).
pub fn contact_twist_near(r: &Vec2, u: &Vec2, length: f64, wrench: impl Fn(&Vec3) -> Vec3, hint: Option<f64>) -> Option<(Vec3, f64)> {
    let un = u.norm();
    let uhat = if un > 0.0 { u / un } else { Vec2::zeros() };
    let pr = perp(r);
    let twist = |phi: f64| -> Vec3 {
        let (sp, cp) = phi.sin_cos();
        let w = sp / length;
        let lin = uhat * cp - pr * w;
        Vec3::new(lin.x, lin.y, w)
    };
    let h = |phi: f64| -> f64 {
        let w = wrench(&twist(phi));
        w.z - cross2(r, &Vec2::new(w.x, w.y))
    };
    let half = std::f64::consts::FRAC_PI_2;
    if un == 0.0 {
        let scale = |phi: f64| wrench(&twist(phi)).norm();
        return [half, -half].into_iter().find(|&phi| h(phi).abs() < 1e-12 * (1.0 + scale(phi))).map(|phi| (twist(phi), phi));
    }
    let near = hint.filter(|p| p.abs() < half - 0.01).and_then(|p| {
        let (a, b) = (p - 0.01, p + 0.01);
        let (ha, hb) = (h(a), h(b));
        (ha <= 0.0 && hb >= 0.0).then_some((a, b, ha, hb))
    });
    let (mut lo, mut hi, mut hlo, mut hhi) = match near {
        Some(bracket) => bracket,
        None => (-half, half, h(-half), h(half)),
    };
    if hlo > 0.0 || hhi < 0.0 {
        return None;
    }
    // Illinois (safeguarded regula falsi): the bracket always holds the root
    let mut side = 0i8;
    for _ in 0..200 {
        if hi - lo < 1e-15 {
            break;
        }
        let mut mid = if hhi > hlo { lo - hlo * (hi - lo) / (hhi - hlo) } else { 0.5 * (lo + hi) };
        if !(mid > lo && mid < hi) {
            mid = 0.5 * (lo + hi);
        }
        let hm = h(mid);
        if hm == 0.0 {
            lo = mid;
            hi = mid;
            break;
        }
        if hm < 0.0 {
            lo = mid;
            hlo = hm;
            if side == -1 {
                hhi *= 0.5;
            }
            side = -1;
        } else {
            hi = mid;
            hhi = hm;
            if side == 1 {
                hlo *= 0.5;
            }
            side = 1;
        }
    }
    let phi = 0.5 * (lo + hi);
    (phi.abs() < half - 1e-12).then(|| (twist(phi), phi))
}

impl SupportFrame {
    /// The object twist [m/s, m/s, rad/s] when point pusher contact `r` moves with velocity `u`
    /// [m/s] (object frame) and sticks: [`contact_twist`] at this pose, scaled so that the
    /// contact point's velocity is `u`. `None` when no rotation rate balances the moment or the
    /// motion is (nearly) a pure rotation about `r` (`u·û` of the unit twist under 1e-9).
    pub fn point_twist(&self, r: &Vec2, u: &Vec2, length: f64) -> Option<Vec3> {
        self.point_twist_near(r, u, length, None).map(|(v, _)| v)
    }

    /// [`Self::point_twist`] and its angle φ, warm-started at `hint` ([`contact_twist_near`]).
    pub fn point_twist_near(&self, r: &Vec2, u: &Vec2, length: f64, hint: Option<f64>) -> Option<(Vec3, f64)> {
        let un = u.norm();
        if !(un > 0.0) || !un.is_finite() {
            return None;
        }
        let (v, phi) = contact_twist_near(r, u, length, |v| self.support_load(v) - self.gravity, hint)?;
        let along = (Vec2::new(v.x, v.y) + perp(r) * v.z).dot(u) / un;
        (along > 1e-9).then(|| (v * (un / along), phi))
    }
}
