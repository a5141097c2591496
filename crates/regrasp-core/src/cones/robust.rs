//! Robust motion cones (thesis §5.1) and fixtureless fixturing (Chavan-Dafle & Rodriguez,
//! CASE 2018).
//!
//! Mass `m`, grip force `N` and finger friction `μ_s` enter a planar motion cone only through
//! `ρ = μ_s N / (m g)`: with `n(v)` the unit limit-surface load of twist `v`, the pusher must
//! apply `w_p = m g (ρ n(v) − ĝ)`. If both `ρ_min n − ĝ ∈ W_p` and `n ∈ W_p`, then
//! `ρ n − ĝ = (ρ_min n − ĝ) + (ρ − ρ_min) n ∈ W_p` for every `ρ ≥ ρ_min` (a convex cone), so
//!
//! * **robust cone** = `V(ρ_min, μ_p,min) ∩ V_gf(μ_p,min)` (lower pusher friction only shrinks
//!   `W_p`);
//! * **invariant case**: when the pusher alone can carry the weight (`−w_g ∈ W_p`, e.g. pushing
//!   from below), `V_gf ⊂ V(ρ)` for every `ρ` and the robust cone is `V_gf`;
//! * **fixtureless fixturing**: pushes that work for *every* `ρ > 0` (any grip force, finger
//!   friction and mass) — the object stays put against the environment feature while the
//!   fingers slide over it. They need `−w_g ∈ W_p` (`ρ → 0`) and `n ∈ W_p` (`ρ → ∞`): the
//!   gravity-free cone of a pusher that carries the weight, a convex polyhedral set that depends
//!   only on the pusher's friction.

use crate::error::{Error, Result};
use crate::cones::frame::{PusherModel, SupportFrame};
pub use crate::cones::frame::{carries_weight, mode_margin, ConeMode, MEMBERSHIP_TOL};
use crate::mechanics::geometry::Vec3;

/// Relative spreads of the uncertain parameters (each value lies in `[x(1 − e), x(1 + e)]`),
/// the scene's optional `[uncertainty]` table.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Uncertainty {
    pub pusher_friction: f64,
    pub finger_friction: f64,
    pub grip_force: f64,
    pub mass: f64,
}

impl Uncertainty {
    /// Checks every spread is in `[0, 1)`; the error names the field.
    pub fn checked(self) -> Result<Self> {
        for (name, v) in [
            ("uncertainty.pusher_friction", self.pusher_friction),
            ("uncertainty.finger_friction", self.finger_friction),
            ("uncertainty.grip_force", self.grip_force),
            ("uncertainty.mass", self.mass),
        ] {
            if !v.is_finite() || !(0.0..1.0).contains(&v) {
                return Err(Error::scene(name, format!("must be a relative spread in [0, 1) (got {v})")));
            }
        }
        Ok(self)
    }

    /// `ρ_min / ρ`: the worst ratio of support friction to weight in the range.
    pub fn rho_factor(&self) -> f64 {
        (1.0 - self.finger_friction) * (1.0 - self.grip_force) / (1.0 + self.mass)
    }
}

/// Generators (unit twists) of a polyhedral cone inside the mode's cone: for the robust cone,
/// the rays of `V(ρ_min)` and of `V_gf` that pass the robust test and the crossings of the robust
/// boundary on the chords between them — an inside ray and an outside one, or two outside rays
/// whose chord passes through the robust cone (the two cones crossing like a star) — reduced to
/// the extreme rays (exact where both cones are polyhedral, an inner approximation otherwise);
/// for fixtureless fixturing the gravity-free rays (or none).
pub fn generators(frame: &SupportFrame, model: &PusherModel) -> Vec<Vec3> {
    let m = &model.metric;
    let gravity_free = || model.edges.iter().map(|e| frame.gravity_free_ray(&e.wrench, m)).collect::<Vec<Vec3>>();
    match frame.mode {
        ConeMode::Nominal => model.edges.iter().filter_map(|e| frame.ray(&e.wrench, m)).collect(),
        ConeMode::Fixtureless => {
            if carries_weight(frame, model) {
                gravity_free()
            } else {
                Vec::new()
            }
        }
        ConeMode::Robust => {
            let mut cands: Vec<Vec3> = model.edges.iter().filter_map(|e| frame.ray(&e.wrench, m)).collect();
            cands.extend(gravity_free());
            let inside_at = |v: &Vec3| frame.classify(model, v).margin >= 0.0;
            let inside: Vec<bool> = cands.iter().map(|v| frame.classify(model, v).margin >= -1e-9).collect();
            let mut out: Vec<Vec3> = cands.iter().zip(&inside).filter(|(_, &i)| i).map(|(v, _)| *v).collect();
            // the robust boundary between s_in (inside) and s_out on the chord a→b
            let cross = |a: &Vec3, b: &Vec3, mut s_in: f64, mut s_out: f64| -> Vec3 {
                let at = |s: f64| m.twist_inv(&(a * (1.0 - s) + b * s));
                for _ in 0..12 {
                    // 2^-12 of the chord (on its inside end): finer than the cones' own
                    // polyhedral approximation
                    let mid = 0.5 * (s_in + s_out);
                    if inside_at(&at(mid)) {
                        s_in = mid;
                    } else {
                        s_out = mid;
                    }
                }
                let v = at(s_in);
                v / m.twist_norm(&v)
            };
            for i in 0..cands.len() {
                for j in 0..cands.len() {
                    let (a, b) = (m.twist(&cands[i]), m.twist(&cands[j]));
                    if i == j || a.dot(&b) < -0.999 {
                        continue;
                    }
                    if inside[i] && !inside[j] {
                        out.push(cross(&a, &b, 0.0, 1.0));
                    } else if !inside[i] && !inside[j] && i < j {
                        // both outside: the chord may still pass through the robust cone
                        let at = |s: f64| m.twist_inv(&(a * (1.0 - s) + b * s));
                        // (a thin lens between two outside rays may be missed: fewer generators,
                        // a smaller cone, still robust)
                        if let Some(s) = [0.5, 0.25, 0.75].into_iter().find(|&s| inside_at(&at(s))) {
                            out.push(cross(&a, &b, s, 0.0));
                            out.push(cross(&a, &b, s, 1.0));
                        }
                    }
                }
            }
            extreme_rays(&out, m)
        }
    }
}

/// The extreme rays of the cone spanned by unit twists `rays` (a pointed cone): the vertices of
/// the convex hull of their central projection on the plane normal to their mean, in the
/// metric; near-duplicates dropped. Falls back to the de-duplicated set when the cone is not
/// pointed (some ray at 90° or more from the mean).
fn extreme_rays(rays: &[Vec3], m: &crate::mechanics::metric::Metric) -> Vec<Vec3> {
    let mut uniq: Vec<Vec3> = Vec::with_capacity(rays.len());
    for v in rays {
        let s = m.twist(v);
        if uniq.iter().all(|u| m.twist(u).dot(&s) < 1.0 - 1e-10) {
            uniq.push(*v);
        }
    }
    if uniq.len() <= 3 {
        return uniq;
    }
    let ts: Vec<Vec3> = uniq.iter().map(|v| m.twist(v).normalize()).collect();
    let c = ts.iter().fold(Vec3::zeros(), |a, t| a + t);
    if c.norm() < 1e-9 || ts.iter().any(|t| t.dot(&c) <= 1e-6 * c.norm()) {
        return uniq;
    }
    let c = c.normalize();
    let e1 = if c.x.abs() < 0.9 { Vec3::x() } else { Vec3::y() };
    let e1 = (e1 - c * c.dot(&e1)).normalize();
    let e2 = c.cross(&e1);
    let pts: Vec<(f64, f64)> = ts.iter().map(|t| (t.dot(&e1) / t.dot(&c), t.dot(&e2) / t.dot(&c))).collect();
    // monotone chain convex hull
    let mut idx: Vec<usize> = (0..pts.len()).collect();
    idx.sort_by(|&a, &b| pts[a].partial_cmp(&pts[b]).unwrap_or(std::cmp::Ordering::Equal));
    let cross = |o: usize, a: usize, b: usize| {
        (pts[a].0 - pts[o].0) * (pts[b].1 - pts[o].1) - (pts[a].1 - pts[o].1) * (pts[b].0 - pts[o].0)
    };
    let mut hull: Vec<usize> = Vec::with_capacity(2 * idx.len());
    for pass in 0..2 {
        let start = hull.len();
        let seq: Vec<usize> = if pass == 0 { idx.clone() } else { idx.iter().rev().copied().collect() };
        for &i in &seq {
            while hull.len() >= start + 2 && cross(hull[hull.len() - 2], hull[hull.len() - 1], i) <= 1e-12 {
                hull.pop();
            }
            hull.push(i);
        }
        hull.pop();
    }
    hull.iter().map(|&i| uniq[i]).collect()
}
