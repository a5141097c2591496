//! The exact limit surface of a disc from its one-dimensional profile (axisymmetry).
//!
//! A disc's load wrench depends on the scaled twist `ṽ = [vx, vz, ωℓ]` only through
//! `p = t/(t + |ω|R)` (`t = |(vx, vz)|`, `R` the radius in units of `ℓ`; `p = 0` is a rotation
//! about the centre, `p = 1` a translation): `W = [F(p) v̂, sign(ω) M(p)]`, `F` rising from 0 to
//! 1 and `M` falling from `M₀` (`2R/3` for uniform pressure) to 0. The profile is integrated once
//! at `PROFILE_NODES + 1` values of `p` and interpolated by cubic Hermite polynomials with
//! finite-difference slopes (C¹; error of order `h³` where the profile is smooth).
//!
//! The inverse is exact to rounding on that interpolant: a wrench `[f, τ]` (`a = |f|`,
//! `b = |τ|`) points at the profile where `c(p) = F(p) q − M(p)(1 − q) = 0`, `q = b/(a + b)`,
//! a root increasing in `p`, started from a table of `p(q)` and finished by Newton's method on
//! the interpolant. The gauge is then `H = (a + b)/(F + M)` and the twist `[p f̂, sign(τ)(1 − p)/R]`,
//! so that the forward map, the gauge and the twists agree to rounding. Against the two cube
//! maps that general shapes need ([`super::exact_surface`]), a lookup is a few flops on a
//! 1-D table and the surface is smooth to the table's precision.

use crate::mechanics::geometry::Vec3;
use rayon::prelude::*;

/// Intervals of the profile's table in `p`.
pub const PROFILE_NODES: usize = 8192;
/// Intervals of the inverse's starting table in `q`.
const INVERSE_NODES: usize = 4096;
/// Relative error of [`DiscProfile::gauge_guess`] (8.1e-9 at worst in its test).
pub const GUESS_TOLERANCE: f64 = 1e-7;

/// A disc's surface in units where its length scale is 1 (module notes).
#[derive(Debug)]
pub struct DiscProfile {
    /// `R` in units of the length scale
    radius: f64,
    /// `1/R`
    inv_radius: f64,
    /// `[F, M, dF/dp, dM/dp]` at `p = i / PROFILE_NODES`
    nodes: Vec<[f64; 4]>,
    /// at `q = j / INVERSE_NODES`: the root `p` (decreasing), `dp/dq`, `F + M` there and its
    /// derivative in `q`
    starts: Vec<[f64; 4]>,
}

impl DiscProfile {
    /// The profile of a disc of radius `radius` whose load wrench at a scaled twist is `wrench`
    /// (direct integration).
    pub fn build(radius: f64, wrench: impl Fn(&Vec3) -> Vec3 + Sync) -> Self {
        let n = PROFILE_NODES;
        let values: Vec<[f64; 2]> = (0..=n)
            .into_par_iter()
            .map(|i| {
                let p = i as f64 / n as f64;
                let w = wrench(&Vec3::new(p, 0.0, (1.0 - p) / radius));
                [w.x, w.z]
            })
            .collect();
        let h = 1.0 / n as f64;
        let slope = |i: usize, k: usize| match i {
            0 => (-3.0 * values[0][k] + 4.0 * values[1][k] - values[2][k]) / (2.0 * h),
            i if i == n => (3.0 * values[n][k] - 4.0 * values[n - 1][k] + values[n - 2][k]) / (2.0 * h),
            i => (values[i + 1][k] - values[i - 1][k]) / (2.0 * h),
        };
        let nodes = (0..=n).map(|i| [values[i][0], values[i][1], slope(i, 0), slope(i, 1)]).collect();
        let mut profile = Self { radius, inv_radius: 1.0 / radius, nodes, starts: Vec::new() };
        profile.starts = (0..=INVERSE_NODES)
            .map(|j| {
                let q = j as f64 / INVERSE_NODES as f64;
                let p = profile.bisect(q);
                // c(p(q), q) = 0: dp/dq = −∂c/∂q / ∂c/∂p
                let v = profile.at(p);
                let dp = -(v[0] + v[1]) / (v[2] * q - v[3] * (1.0 - q));
                [p, dp, v[0] + v[1], (v[2] + v[3]) * dp]
            })
            .collect();
        profile
    }

    /// `[F, M, dF/dp, dM/dp]` at `p` (clamped to [0, 1]).
    #[inline]
    fn at(&self, p: f64) -> [f64; 4] {
        let n = PROFILE_NODES;
        let x = p.clamp(0.0, 1.0) * n as f64;
        let i = (x as usize).min(n - 1);
        let s = x - i as f64;
        let (a, b) = (&self.nodes[i], &self.nodes[i + 1]);
        let h = 1.0 / n as f64;
        let (s2, s3) = (s * s, s * s * s);
        let (h00, h10, h01, h11) = (2.0 * s3 - 3.0 * s2 + 1.0, s3 - 2.0 * s2 + s, 3.0 * s2 - 2.0 * s3, s3 - s2);
        let (d00, d10, d11) = ((6.0 * s2 - 6.0 * s) * n as f64, 3.0 * s2 - 4.0 * s + 1.0, 3.0 * s2 - 2.0 * s);
        let value = |k: usize| h00 * a[k] + h10 * h * a[k + 2] + h01 * b[k] + h11 * h * b[k + 2];
        let deriv = |k: usize| d00 * (a[k] - b[k]) + d10 * a[k + 2] + d11 * b[k + 2];
        [value(0), value(1), deriv(0), deriv(1)]
    }

    /// The root of `c(p) = F q − M (1 − q)` by bisection (for the starting table).
    fn bisect(&self, q: f64) -> f64 {
        let (mut lo, mut hi) = (0.0, 1.0);
        for _ in 0..80 {
            let mid = 0.5 * (lo + hi);
            let v = self.at(mid);
            if v[0] * q - v[1] * (1.0 - q) > 0.0 {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        0.5 * (lo + hi)
    }

    /// The root `p` of `c(p)` (module notes) and `[F, M]` there: Newton's method from the
    /// starting table (cubic Hermite), kept inside the bracket of its two neighbouring entries
    /// (widened to the start when the Hermite guess falls outside it).
    /// A step `δ` below `SMALL_STEP` is the last: the profile at `p + δ` is then taken to first
    /// order (its error `F'' δ²/2`, below 1e-15).
    #[inline]
    fn root(&self, q: f64) -> (f64, [f64; 2]) {
        const SMALL_STEP: f64 = 1e-8;
        let x = q.clamp(0.0, 1.0) * INVERSE_NODES as f64;
        let j = (x as usize).min(INVERSE_NODES - 1);
        let s = x - j as f64;
        let (a, b) = (self.starts[j], self.starts[j + 1]);
        let (mut lo, mut hi) = ((b[0] - 1e-12).max(0.0), (a[0] + 1e-12).min(1.0));
        let h = 1.0 / INVERSE_NODES as f64;
        let (s2, s3) = (s * s, s * s * s);
        let mut p = (2.0 * s3 - 3.0 * s2 + 1.0) * a[0] + (s3 - 2.0 * s2 + s) * h * a[1] + (3.0 * s2 - 2.0 * s3) * b[0] + (s3 - s2) * h * b[1];
        for _ in 0..40 {
            let v = self.at(p);
            let c = v[0] * q - v[1] * (1.0 - q);
            let step = -c / (v[2] * q - v[3] * (1.0 - q));
            if step.abs() < SMALL_STEP && p + step >= 0.0 && p + step <= 1.0 {
                return (p + step, [v[0] + v[2] * step, v[1] + v[3] * step]);
            }
            if c > 0.0 {
                hi = p;
            } else {
                lo = p;
            }
            let next = p + step;
            p = if next > lo && next < hi { next } else { 0.5 * (lo + hi) };
            if hi - lo < 1e-15 {
                break;
            }
        }
        let v = self.at(p);
        (p, [v[0], v[1]])
    }

    /// The load wrench `W(ṽ)` of a scaled twist (non-zero; degree 0 in it).
    #[inline]
    pub fn wrench(&self, v: &Vec3) -> Vec3 {
        if out_of_range(v) {
            return self.wrench_scaled(v);
        }
        self.wrench_in_range(v)
    }

    /// [`Self::wrench`] of a huge or tiny twist: of its direction (off the hot path).
    #[cold]
    #[inline(never)]
    fn wrench_scaled(&self, v: &Vec3) -> Vec3 {
        match largest(v) {
            m if m > 0.0 && m.is_finite() => self.wrench_in_range(&(v / m)),
            _ => self.wrench_in_range(v),
        }
    }

    /// [`Self::wrench`] of a twist whose squares neither overflow nor underflow.
    #[inline]
    fn wrench_in_range(&self, v: &Vec3) -> Vec3 {
        let t = (v.x * v.x + v.y * v.y).sqrt();
        let p = t / (t + v.z.abs() * self.radius);
        let f = self.at(p);
        let k = if t > 0.0 { f[0] / t } else { 0.0 };
        Vec3::new(v.x * k, v.y * k, f[1].copysign(v.z))
    }

    /// The gauge `H(w)` of a scaled wrench and a twist (not unit) whose load is along `w` (a
    /// zero wrench: gauge 0, the zero twist).
    #[inline]
    pub fn gauge(&self, w: &Vec3) -> (f64, Vec3) {
        self.gauge_by::<true>(w)
    }

    /// [`Self::gauge`] on the starting table alone (cubic Hermite in `q` of the root and of
    /// `F + M`; no Newton step on the profile; within `GUESS_TOLERANCE` of the gauge and its
    /// twist's direction): for searches whose result is then found exactly.
    #[inline]
    pub fn gauge_guess(&self, w: &Vec3) -> (f64, Vec3) {
        self.gauge_by::<false>(w)
    }

    /// [`Self::gauge`] (`EXACT`) or [`Self::gauge_guess`].
    #[inline]
    fn gauge_by<const EXACT: bool>(&self, w: &Vec3) -> (f64, Vec3) {
        // (degree 1: H(w) = s H(w/s); a NaN wrench gives a NaN gauge)
        if out_of_range(w) {
            return self.gauge_scaled(w);
        }
        let a = (w.x * w.x + w.y * w.y).sqrt();
        let b = w.z.abs();
        if a + b == 0.0 {
            return (0.0, Vec3::zeros());
        }
        let (p, g) = if EXACT {
            let (p, f) = self.root(b / (a + b));
            (p, f[0] + f[1])
        } else {
            self.start(b / (a + b))
        };
        // [p f̂, ±(1 − p)/R] times a (one division fewer), unless a = 0 (then p = 0)
        let v = if a > 0.0 { Vec3::new(w.x * p, w.y * p, (a * (1.0 - p) * self.inv_radius).copysign(w.z)) } else { Vec3::new(0.0, 0.0, 1.0f64.copysign(w.z)) };
        ((a + b) / g, v)
    }

    /// The starting table at `q ∈ [0, 1]` (cubic Hermite): the root `p` and `F + M` there.
    #[inline]
    fn start(&self, q: f64) -> (f64, f64) {
        let x = q * INVERSE_NODES as f64;
        let j = (x as usize).min(INVERSE_NODES - 1);
        let s = x - j as f64;
        let (l, r) = (&self.starts[j], &self.starts[j + 1]);
        let h = 1.0 / INVERSE_NODES as f64;
        let (s2, s3) = (s * s, s * s * s);
        let (h00, h10, h01, h11) = (2.0 * s3 - 3.0 * s2 + 1.0, (s3 - 2.0 * s2 + s) * h, 3.0 * s2 - 2.0 * s3, (s3 - s2) * h);
        let p = (h00 * l[0] + h10 * l[1] + h01 * r[0] + h11 * r[1]).clamp(0.0, 1.0);
        (p, h00 * l[2] + h10 * l[3] + h01 * r[2] + h11 * r[3])
    }

    /// [`Self::gauge`] of a huge or tiny wrench (degree 1: `H(w) = m H(w/m)`; zero, NaN and
    /// infinite wrenches as they are: gauge 0, NaN, NaN). Off the hot path.
    #[cold]
    #[inline(never)]
    fn gauge_scaled(&self, w: &Vec3) -> (f64, Vec3) {
        let m = largest(w);
        if !(m > 0.0 && m.is_finite()) {
            return if m == 0.0 { (0.0, Vec3::zeros()) } else { (f64::NAN, Vec3::zeros()) };
        }
        let (h, v) = self.gauge(&(w / m));
        (m * h, v)
    }
}

/// `|x|∞`.
#[inline]
fn largest(x: &Vec3) -> f64 {
    x.x.abs().max(x.y.abs()).max(x.z.abs())
}

/// Whether `x` is so large or small (or not finite) that its squares could overflow or
/// underflow: then it is scaled by [`largest`] first, off the hot path.
#[inline]
fn out_of_range(x: &Vec3) -> bool {
    let m = largest(x);
    !(m > 1e-100 && m < 1e100)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mechanics::exact_surface::Region;
    use crate::mechanics::limit_surface::Pressure;

    fn profiles() -> Vec<DiscProfile> {
        [(2f64.sqrt(), Pressure::Uniform), (2.5f64.sqrt(), Pressure::Hertzian)]
            .into_iter()
            .map(|(r, pressure)| {
                let region = Region::Disc { radius: r, pressure };
                DiscProfile::build(r, |v| region.wrench(v))
            })
            .collect()
    }

    #[test]
    fn the_profile_is_monotone_and_ends_at_rotation_and_translation() {
        for d in profiles() {
            assert!(d.nodes[0][0].abs() < 1e-15 && d.nodes[PROFILE_NODES][1].abs() < 1e-15);
            assert!((d.nodes[PROFILE_NODES][0] - 1.0).abs() < 1e-15);
            // M falls everywhere; F rises but flattens at translation (F = 1 − O((1 − p)²)),
            // where the integration's error (~4e-9) shows: the inverse's root needs F to rise
            // only where q is near 1, i.e. p near 0
            for (i, w) in d.nodes.windows(2).enumerate() {
                assert!(w[1][1] < w[0][1], "{w:?}");
                assert!(w[1][0] > w[0][0] || i > PROFILE_NODES * 99 / 100, "{i}: {w:?}");
                assert!(w[1][0] < 1.0 + 1e-8, "{w:?}");
            }
        }
    }

    /// Huge and tiny inputs give the loads and gauges of their directions (no overflow), a NaN
    /// wrench a NaN gauge (never "holds").
    #[test]
    fn extreme_inputs_are_scaled_and_nan_propagates() {
        let d = &profiles()[0];
        for v in [Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.3, -0.2, 0.7), Vec3::new(0.0, 0.0, -1.0)] {
            for k in [1e-170, 1e200] {
                assert!((d.wrench(&(v * k)) - d.wrench(&v)).norm() < 1e-14, "{v} × {k}");
                let (h, _) = d.gauge(&(v * k));
                assert!((h / k - d.gauge(&v).0).abs() < 1e-13 * d.gauge(&v).0, "{v} × {k}: {h}");
            }
        }
        assert!(d.gauge(&Vec3::new(f64::NAN, 0.0, 1.0)).0.is_nan());
        assert_eq!(d.gauge(&Vec3::zeros()).0, 0.0);
    }

    /// The gauge's twist loads the surface along the wrench, to rounding, at every direction
    /// (the ends of `q` and wrenches nearly pure force or pure moment included).
    #[test]
    fn the_inverse_agrees_with_the_forward_map_to_rounding() {
        for d in profiles() {
            let mut ws: Vec<Vec3> = (0..=2000).map(|k| k as f64 / 2000.0 * std::f64::consts::PI).map(|a| Vec3::new(a.sin(), 0.3 * a.sin(), a.cos())).collect();
            ws.extend([Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 0.0, -2.0), Vec3::new(1.0, -1.0, 1e-13), Vec3::new(1e-13, 0.0, 1.0)]);
            for w in ws {
                let (h, v) = d.gauge(&w);
                let load = d.wrench(&v);
                assert!((load.normalize() - w.normalize()).norm() < 1e-12, "{w}: {load}");
                assert!((load.norm() * h - w.norm()).abs() < 1e-12 * w.norm(), "{w}: H = {h}");
            }
        }
    }

    /// The guess (the starting table alone) is as close to the exact gauge as the searches that
    /// use it need: their guesses stop at `|H − 1| < 1e-4`.
    #[test]
    fn the_guess_is_close_to_the_exact_gauge() {
        let mut worst = (0.0f64, 0.0f64);
        for d in profiles() {
            for k in 0..=20000 {
                let a = k as f64 / 20000.0 * std::f64::consts::PI;
                let w = Vec3::new(a.sin(), -0.4 * a.sin(), 0.8 * a.cos());
                let ((h, v), (hg, vg)) = (d.gauge(&w), d.gauge_guess(&w));
                worst.0 = worst.0.max((hg / h - 1.0).abs());
                worst.1 = worst.1.max((vg.normalize() - v.normalize()).norm());
            }
        }
        assert!(worst.0 < GUESS_TOLERANCE && worst.1 < GUESS_TOLERANCE, "{worst:?}");
        assert!(worst.0 > GUESS_TOLERANCE * 1e-3, "the bound is loose: {worst:?}");
    }
}
