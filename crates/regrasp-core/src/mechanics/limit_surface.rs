//! Ellipsoidal limit surfaces (thesis §3.1.3, eqs 3.7–3.11; Howe & Cutkosky 1996, Xydas & Kao 1999).
//!
//! A limit surface is stored as its *unit* matrix `B` (for `μ N = 1`): the friction wrench
//! `w = [fx, fz, τ]` in the support frame lies on `wᵀ A w = 1` with `A = B / (μ N)²` (eq 3.7),
//! the sliding twist is normal to it, `v ∝ A w` (eq 3.8), and conversely
//! `w = A⁻¹ v / √(vᵀ A⁻¹ v)` (eq 3.10). `w` is the *load* wrench: the friction the support
//! resists with is `−w`.
//!
//! * Circular pad, uniform pressure: `B = diag(1, 1, 1/k²)`, `k = 0.6 r` (thesis, [99, 86]).
//! * Any other pad shape or pressure: the wrench of a numerically integrated pad is computed for
//!   many sliding twists and an ellipsoid `wᵀ B w = 1` is fitted to them by least squares.

use crate::mechanics::geometry::{cross2, perp, Mat3, Polygon, Vec2, Vec3};
use nalgebra::{DMatrix, DVector};

/// Largest normal (grip) force a support may press with [N]: far beyond any gripper, and where
/// the cones' computations (squares of forces, `A = B / (μ N)²`) stay finite.
pub const MAX_NORMAL_FORCE: f64 = 1e6;

/// The integration constant `k` for a circular pad of radius `r` under uniform pressure.
pub fn circular_pad_k(radius: f64) -> f64 {
    0.6 * radius
}

/// Unit ellipsoidal limit surface (`μ N = 1`) in the support frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LimitSurface {
    /// `B`, symmetric positive definite.
    pub b: Mat3,
    /// `B⁻¹`.
    pub b_inv: Mat3,
}

impl LimitSurface {
    /// Circular pad of radius `r`, uniform pressure: `B = diag(1, 1, 1/(0.6 r)²)` (eq 3.7).
    pub fn circular(radius: f64) -> Self {
        let k = circular_pad_k(radius);
        Self::from_matrix(Mat3::from_diagonal(&Vec3::new(1.0, 1.0, 1.0 / (k * k))))
            .expect("a positive radius gives a positive definite surface")
    }

    /// From a symmetric positive definite `B`; `None` otherwise.
    pub fn from_matrix(b: Mat3) -> Option<Self> {
        let sym = (b + b.transpose()) * 0.5;
        nalgebra::Cholesky::new(sym)?;
        Some(Self { b: sym, b_inv: sym.try_inverse()? })
    }

    /// `A⁻¹ = B⁻¹ (μN)²`.
    pub fn matrix_inv(&self, mu_n: f64) -> Mat3 {
        self.b_inv * (mu_n * mu_n)
    }

    /// `A = B / (μN)²` for friction coefficient × normal force `mu_n` (eq 3.7).
    pub fn matrix(&self, mu_n: f64) -> Mat3 {
        self.b / (mu_n * mu_n)
    }

    /// The load wrench on the surface for sliding twist `v` (eq 3.10), for `A` given.
    pub fn wrench_for_twist(a_inv: &Mat3, v: &Vec3) -> Vec3 {
        let av = a_inv * v;
        av / v.dot(&av).sqrt()
    }

    /// Fits an ellipsoid to the limit surface of a pressure distribution. Returns the surface
    /// and the fit's largest relative radial error over the sampled twists.
    pub fn fit(pad: &PressureDistribution) -> (Self, f64) {
        let (b, err) = Self::fit_matrix(pad);
        (Self::from_matrix(b).expect("the fitted limit surface is an ellipsoid"), err)
    }

    fn fit_matrix(pad: &PressureDistribution) -> (Mat3, f64) {
        let ell = pad.length_scale();
        let dirs = fibonacci_sphere(600);
        // samples in scaled wrench space [fx, fz, τ/ℓ]
        let ws: Vec<Vec3> = dirs
            .iter()
            .map(|d| {
                let w = pad.friction_wrench(&Vec3::new(d.x, d.y, d.z / ell));
                Vec3::new(w.x, w.y, w.z / ell)
            })
            .collect();
        let mut m = DMatrix::<f64>::zeros(ws.len(), 6);
        for (i, w) in ws.iter().enumerate() {
            let row = [w.x * w.x, w.y * w.y, w.z * w.z, 2.0 * w.x * w.y, 2.0 * w.x * w.z, 2.0 * w.y * w.z];
            for (j, r) in row.iter().enumerate() {
                m[(i, j)] = *r;
            }
        }
        let rhs = DVector::<f64>::from_element(ws.len(), 1.0);
        let q = m.svd(true, true).solve(&rhs, 1e-14).expect("least squares on a full-rank design");
        let qs = Mat3::new(q[0], q[3], q[4], q[3], q[1], q[5], q[4], q[5], q[2]);
        let s = Mat3::from_diagonal(&Vec3::new(1.0, 1.0, 1.0 / ell));
        let b = s * qs * s;
        let err = ws
            .iter()
            .map(|w| (w.dot(&(qs * w)).sqrt() - 1.0).abs())
            .fold(0.0, f64::max);
        (b, err)
    }

    /// Maximum moment (for `μN = 1`) on the fitted surface, `1/√B₃₃` for a diagonal `B`: the
    /// `k` of eq 3.7.
    pub fn k(&self) -> f64 {
        self.b_inv[(2, 2)].sqrt()
    }
}

/// Which limit surface a support's motion cones use (scene key `limit_surface`, CLI
/// `--limit-surface`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SurfaceModel {
    /// The ellipsoid of eq 3.7 (`k = 0.6 r` for a uniform disc; fitted otherwise): the thesis'
    /// model, whose rays are closed-form.
    Ellipsoid,
    /// The exact surface of the pad's or footprint's pressure
    /// ([`crate::mechanics::exact_surface`]).
    True,
}

impl Default for SurfaceModel {
    /// The exact surface: against the point-set simulator it agrees on 99.2–100% of the
    /// validation's pushes where the ellipsoid agrees on 86.7–97.2% (README, Table 3.2).
    fn default() -> Self {
        SurfaceModel::True
    }
}

impl SurfaceModel {
    /// From its name, `"ellipsoid"` or `"true"`.
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "ellipsoid" => Some(Self::Ellipsoid),
            "true" => Some(Self::True),
            _ => None,
        }
    }

    pub fn label(&self) -> &'static str {
        match self {
            Self::Ellipsoid => "ellipsoid",
            Self::True => "true",
        }
    }
}

/// Points spread evenly over the unit sphere.
pub fn fibonacci_sphere(n: usize) -> Vec<Vec3> {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..n)
        .map(|i| {
            let y = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
            let r = (1.0 - y * y).sqrt();
            let phi = golden * i as f64;
            Vec3::new(r * phi.cos(), y, r * phi.sin())
        })
        .collect()
}

/// Pressure profile over a pad.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pressure {
    Uniform,
    /// Hertzian contact of a circular pad: `p ∝ √(1 − (ρ/r)²)`.
    Hertzian,
}

/// A pressure distribution discretized into cells (position, share of the normal force).
#[derive(Clone, Debug)]
pub struct PressureDistribution {
    pub cells: Vec<(Vec2, f64)>,
}

impl PressureDistribution {
    fn from_grid(lo: Vec2, hi: Vec2, n: usize, weight: impl Fn(&Vec2) -> f64) -> Self {
        let (dx, dz) = ((hi.x - lo.x) / n as f64, (hi.y - lo.y) / n as f64);
        let mut cells = Vec::with_capacity(n * n);
        for i in 0..n {
            for j in 0..n {
                let p = Vec2::new(lo.x + (i as f64 + 0.5) * dx, lo.y + (j as f64 + 0.5) * dz);
                let w = weight(&p);
                if w > 0.0 {
                    cells.push((p, w));
                }
            }
        }
        let total: f64 = cells.iter().map(|c| c.1).sum();
        for c in &mut cells {
            c.1 /= total;
        }
        Self { cells }
    }

    /// Circular pad of radius `r` centred at the origin.
    pub fn circle(r: f64, pressure: Pressure, n: usize) -> Self {
        Self::from_grid(Vec2::new(-r, -r), Vec2::new(r, r), n, |p| {
            let rho2 = p.norm_squared() / (r * r);
            if rho2 >= 1.0 {
                0.0
            } else {
                match pressure {
                    Pressure::Uniform => 1.0,
                    Pressure::Hertzian => (1.0 - rho2).sqrt(),
                }
            }
        })
    }

    /// Rectangular pad `width × height` (gripper X × Z), uniform pressure.
    pub fn rectangle(width: f64, height: f64, n: usize) -> Self {
        Self::from_grid(Vec2::new(-width / 2.0, -height / 2.0), Vec2::new(width / 2.0, height / 2.0), n, |_| 1.0)
    }

    /// Uniform pressure over a polygon, expressed about `center` (e.g. the centre of pressure).
    pub fn polygon(poly: &Polygon, center: &Vec2, n: usize) -> Self {
        let (mut lo, mut hi) = (poly.vertices()[0], poly.vertices()[0]);
        for p in poly.vertices() {
            lo = lo.inf(p);
            hi = hi.sup(p);
        }
        let mut d = Self::from_grid(lo, hi, n, |p| if poly.contains(p) { 1.0 } else { 0.0 });
        for c in &mut d.cells {
            c.0 -= center;
        }
        d
    }

    /// Root-mean-square cell distance from the origin, weighted by pressure.
    pub fn length_scale(&self) -> f64 {
        self.cells.iter().map(|(p, w)| w * p.norm_squared()).sum::<f64>().sqrt().max(1e-12)
    }

    /// Load wrench (for `μN = 1`) of the pad sliding with twist `v = [vx, vz, ω]` about its
    /// origin: `Σ pᵢ uᵢ/|uᵢ|` and its moment, with `uᵢ = v + ω × rᵢ` (Coulomb at every cell).
    pub fn friction_wrench(&self, v: &Vec3) -> Vec3 {
        let lin = Vec2::new(v.x, v.y);
        let mut w = Vec3::zeros();
        for (r, p) in &self.cells {
            let u = lin + perp(r) * v.z;
            let n = u.norm();
            if n > 1e-300 {
                let f = u * (p / n);
                w += Vec3::new(f.x, f.y, cross2(r, &f));
            }
        }
        w
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn twist_is_normal_to_the_surface_and_roundtrips() {
        let ls = LimitSurface::circular(0.01);
        let a = ls.matrix(12.0);
        let a_inv = a.try_inverse().unwrap();
        let v = Vec3::new(0.01, -0.02, 1.5);
        let w = LimitSurface::wrench_for_twist(&a_inv, &v);
        assert!((w.dot(&(a * w)) - 1.0).abs() < 1e-12, "on the surface (eq 3.7)");
        let n = a * w;
        assert!(n.normalize().cross(&v.normalize()).norm() < 1e-12, "twist ∝ A w (eq 3.8)");
        assert!(w.dot(&v) > 0.0, "load wrench does positive work");
    }

    #[test]
    fn fitted_uniform_circle_is_close_to_k_06r() {
        let r = 0.01;
        let (ls, err) = LimitSurface::fit(&PressureDistribution::circle(r, Pressure::Uniform, 60));
        // pure translation: friction force magnitude μN = 1
        assert!((ls.b[(0, 0)] - 1.0).abs() < 0.05, "B00 = {}", ls.b[(0, 0)]);
        assert!((ls.b[(1, 1)] - 1.0).abs() < 0.05);
        // the least-squares ellipsoid's moment axis is near the published k ≈ 0.6 r
        let k = ls.k() / r;
        assert!((0.55..0.68).contains(&k), "k/r = {k}");
        assert!(err < 0.1, "fit error {err}");
        // symmetric pad: no coupling terms
        assert!(ls.b[(0, 1)].abs() < 1e-3 && ls.b[(0, 2)].abs() < 1e-3 / r);
    }

    #[test]
    fn integrated_pad_matches_closed_forms() {
        let r = 0.02;
        let pad = PressureDistribution::circle(r, Pressure::Uniform, 120);
        // pure rotation about the centre: moment 2/3 μ N r for a uniform disk
        let w = pad.friction_wrench(&Vec3::new(0.0, 0.0, 1.0));
        assert!((w.z - 2.0 / 3.0 * r).abs() < 2e-3 * r, "τ = {}", w.z);
        // pure translation: force μN along the motion
        let w = pad.friction_wrench(&Vec3::new(1.0, 0.0, 0.0));
        assert!((w.x - 1.0).abs() < 1e-9 && w.y.abs() < 1e-9);
        // Hertzian pressure concentrates load at the centre: smaller moment (3π/16 r)
        let h = PressureDistribution::circle(r, Pressure::Hertzian, 120);
        let wh = h.friction_wrench(&Vec3::new(0.0, 0.0, 1.0));
        assert!((wh.z - 3.0 * std::f64::consts::PI / 16.0 * r).abs() < 3e-3 * r, "τ = {}", wh.z);
    }

    #[test]
    fn rectangle_pad_is_anisotropic_only_in_moment() {
        let (ls, _) = LimitSurface::fit(&PressureDistribution::rectangle(0.03, 0.01, 60));
        let (sq, _) = LimitSurface::fit(&PressureDistribution::rectangle(0.01, 0.01, 60));
        assert!(ls.k() > sq.k(), "a longer pad resists more moment");
    }
}
