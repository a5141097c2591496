//! Projections onto motion cones: the closest feasible twist to a desired one, on the exact
//! cone (the image of the boundary of the pusher's cone searched by grid and Brent's method) or
//! on a polyhedral cone spanned by generators (non-negative least squares).

use crate::cones::frame::{ConeMode, PusherModel, SupportFrame};
use crate::cones::robust::generators;
use crate::mechanics::geometry::Vec3;


/// Closest feasible twist (see [`PlanarPush::project`]); the support must hold.
pub fn project_exact(frame: &SupportFrame, model: &PusherModel, d: &Vec3) -> Vec3 {
    let scale = d.amax();
    if scale == 0.0 {
        return Vec3::zeros();
    }
    let dd = d / scale;
    if frame.classify(model, &dd).feasible {
        return *d;
    }
    let dn = model.metric.twist_norm(&dd);
    let (cos, u) = nearest_boundary_ray(frame, model, &dd);
    if cos > 0.0 {
        u * (cos * dn * scale)
    } else {
        Vec3::zeros()
    }
}

/// Closest twist to `want` in the cone (of the frame's mode) with at least margin `margin`: the
/// projection on the polyhedral cone of its generators when the exact test accepts it, else the
/// exact projection, then moved towards the mean of the generators until the margin holds.
/// `None` when the cone is empty or the support cannot hold the object.
pub fn project_with_margin(frame: &SupportFrame, model: &PusherModel, want: &Vec3, margin_min: f64) -> Option<Vec3> {
    project_with_margin_on(frame, model, &generators(frame, model), want, margin_min)
}

/// [`project_with_margin`] with the cone's generators already computed (`gens`, unit twists).
pub fn project_with_margin_on(frame: &SupportFrame, model: &PusherModel, gens: &[Vec3], want: &Vec3, margin_min: f64) -> Option<Vec3> {
    let m = &model.metric;
    // (a nominal cone with fewer rays than W_p has edges: the support cannot hold the object)
    if gens.is_empty() || (frame.mode == ConeMode::Nominal && gens.len() < model.edges.len()) {
        return None;
    }
    let gs: Vec<Vec3> = gens.iter().map(|g| m.twist(g)).collect();
    let (pp, _) = project_onto_generators(&gs, &m.twist(want));
    let mut v = m.twist_inv(&pp);
    // (feasible to the membership tolerance: a generator's own ray is, up to rounding)
    if v.amax() == 0.0 || !frame.classify(model, &v).feasible {
        v = project_exact(frame, model, want);
        if v.amax() == 0.0 {
            return None;
        }
    }
    with_margin(frame, model, gens, v, margin_min)
}

/// The exact projection of `want` ([`project_exact`]: `want` itself when feasible, else the
/// closest boundary ray in angle), then moved into the margin as [`project_with_margin_on`]
/// does. Where gravity bends the cone so that the generators' span misses a direction of the
/// exact cone (a heavy object slid along the pads by a line pusher: the edges' rays all turn
/// it), the polyhedral projection is feasible yet far from `want`; this one is not.
pub fn project_exact_with_margin(frame: &SupportFrame, model: &PusherModel, gens: &[Vec3], want: &Vec3, margin_min: f64) -> Option<Vec3> {
    if gens.is_empty() || (frame.mode == ConeMode::Nominal && gens.len() < model.edges.len()) {
        return None;
    }
    let v = project_exact(frame, model, want);
    if v.amax() == 0.0 {
        return None;
    }
    with_margin(frame, model, gens, v, margin_min)
}

/// Feasible `v` moved towards the generators' centre until its margin is at least `margin_min`
/// (at `v`'s speed); `v` itself when it has the margin; `None` when neither reaches it and `v`
/// is outside the cone.
fn with_margin(frame: &SupportFrame, model: &PusherModel, gens: &[Vec3], v: Vec3, margin_min: f64) -> Option<Vec3> {
    let m = &model.metric;
    let margin = |x: &Vec3| frame.classify(model, x).margin;
    if margin(&v) >= margin_min {
        return Some(v);
    }
    let centre = centre(frame, model, gens, margin_min);
    if centre.amax() == 0.0 || margin(&centre) < margin_min {
        return (margin(&v) >= 0.0).then_some(v);
    }
    let (vn, cn) = (m.twist_norm(&v), m.twist_norm(&centre));
    let blend = |t: f64| v / vn * (1.0 - t) + centre / cn * t;
    // the least blend with the margin: the Illinois method (regula falsi that halves the stale
    // end's value), bracketed, to 1e-6 of the blend (as bisection's 20 halvings, in fewer tests)
    let (mut lo, mut hi) = (0.0, 1.0);
    let (mut g_lo, mut g_hi) = (margin(&v) - margin_min, margin(&centre) - margin_min);
    let mut side = 0;
    for _ in 0..60 {
        if hi - lo < 1e-6 {
            break;
        }
        let t = lo - g_lo * (hi - lo) / (g_hi - g_lo);
        let t = if t > lo && t < hi && t.is_finite() { t } else { 0.5 * (lo + hi) };
        let g = margin(&blend(t)) - margin_min;
        if g >= 0.0 {
            (hi, g_hi) = (t, g);
            if side == 1 {
                g_lo *= 0.5;
            }
            side = 1;
        } else {
            (lo, g_lo) = (t, g);
            if side == -1 {
                g_hi *= 0.5;
            }
            side = -1;
        }
    }
    // the blend of two unit directions is shorter than either: back to the projection's speed
    let x = blend(hi);
    Some(x * (vn / m.twist_norm(&x)))
}

/// A twist inside the cone with margin ≥ `margin_min` if one is found: the mean of its rays, else
/// (nominal cones) the ray of the mean of `W_p`'s edges (scaled metric). The exact cone is not
/// convex in the twist space (gravity bends it): with low pusher friction the mean of its rays
/// can lie far outside it (margin −0.15 to −0.59 for μ 0.05 line pushers, where twists of margin
/// 0.04 exist), while the central pusher wrench's ray has about `W_p`'s own best margin.
fn centre(frame: &SupportFrame, model: &PusherModel, gens: &[Vec3], margin_min: f64) -> Vec3 {
    let margin = |x: &Vec3| if x.amax() == 0.0 { f64::NEG_INFINITY } else { frame.classify(model, x).margin };
    let mean = gens.iter().fold(Vec3::zeros(), |a, g| a + g);
    if frame.mode != ConeMode::Nominal || margin(&mean) >= margin_min {
        return mean;
    }
    let m = &model.metric;
    let wrench = model.edges.iter().fold(Vec3::zeros(), |a, e| a + e.wrench / m.wrench(&e.wrench).norm());
    frame.ray(&wrench, m).filter(|ray| margin(ray) > margin(&mean)).unwrap_or(mean)
}

/// A sample of the exact cone's boundary: (parameter along the fan, cosine to the desired
/// direction, unit ray in the metric, ray, pusher wrench); the fans' rays from
/// [`SupportFrame::ray_guess`], Brent's search's exact (each from the best one so far).
type Sample = (f64, f64, Vec3, Vec3, Vec3);

/// The rays of the exact cone's boundary fans compared with one desired direction.
struct BoundaryRays<'a> {
    frame: &'a SupportFrame,
    model: &'a PusherModel,
    /// The desired direction, a unit vector in the metric.
    ds: Vec3,
}

impl BoundaryRays<'_> {
    const MAX_STEP: f64 = 0.07; // rad between consecutive samples
    const MAX_SAMPLES: usize = 4096;

    /// The boundary ray of pusher wrench direction `p` (`t`: its parameter on the fan).
    fn sample(&self, p: &Vec3, t: f64) -> Sample {
        self.sample_with::<false>(p, t)
    }

    /// [`Self::sample`] with its ray exact, found from the ray `near` of a nearby sample.
    fn sample_near(&self, p: &Vec3, t: f64, near: &Vec3) -> Sample {
        let m = &self.model.metric;
        let w = m.wrench_inv(p);
        match self.frame.ray_near(&w, m, near) {
            Some(v) => {
                let s = m.twist(&v);
                (t, s.dot(&self.ds), s, v, w)
            }
            None => (t, f64::NEG_INFINITY, Vec3::zeros(), Vec3::zeros(), w),
        }
    }

    /// [`Self::sample`], its ray exact (`POLISH`) or a guess ([`SupportFrame::ray_guess`]).
    fn sample_with<const POLISH: bool>(&self, p: &Vec3, t: f64) -> Sample {
        let m = &self.model.metric;
        let w = m.wrench_inv(p);
        let ray = if POLISH { self.frame.ray(&w, m) } else { self.frame.ray_guess(&w, m) };
        match ray {
            Some(v) => {
                let s = m.twist(&v);
                (t, s.dot(&self.ds), s, v, w)
            }
            None => (t, f64::NEG_INFINITY, Vec3::zeros(), Vec3::zeros(), w),
        }
    }

    /// The fan between edges `ea` and `eb` at five evenly spaced parameters (its coarse samples).
    fn coarse(&self, ea: Vec3, eb: Vec3) -> Vec<Sample> {
        (0..=4).map(|k| k as f64 / 4.0).map(|t| self.sample(&(ea * (1.0 - t) + eb * t), t)).collect()
    }

    /// Refines a fan's coarse samples by depth-first subdivision until consecutive rays are
    /// less than `MAX_STEP` apart, except between samples that cannot hold a ray with a larger
    /// cosine than `best` (the largest found so far, raised as samples come): by the triangle
    /// inequality on the sphere, the rays between two samples `γ` apart lie within `γ` of one
    /// of them if their path is at most twice as long as the arc between them, so no cosine
    /// there exceeds `cos(θ − γ)` (`θ` the smaller angle of the two to the desired direction).
    /// Only samples less than `PRUNE_GAP` apart are so bounded.
    fn refine(&self, ea: Vec3, eb: Vec3, coarse: Vec<Sample>, best: &mut f64) -> Vec<Sample> {
        let cos_step = Self::MAX_STEP.cos();
        let mut stack: Vec<Sample> = coarse;
        stack.reverse();
        let mut pts: Vec<Sample> = vec![stack.pop().expect("samples")];
        while let Some(right) = stack.pop() {
            let left = *pts.last().expect("samples");
            let gap = left.2.dot(&right.2);
            let split = gap < cos_step && right.0 - left.0 > 1e-9 && pts.len() + stack.len() < Self::MAX_SAMPLES;
            if split && !Self::bounded_below(&left, &right, gap, *best) {
                let t = 0.5 * (left.0 + right.0);
                let mid = self.sample(&(ea * (1.0 - t) + eb * t), t);
                *best = best.max(mid.1);
                stack.push(right);
                stack.push(mid);
            } else {
                pts.push(right);
            }
        }
        pts
    }

    const PRUNE_GAP: f64 = 0.5; // rad

    /// Whether no ray between samples `left` and `right` (`gap` the cosine between their rays)
    /// can have a cosine above `best` (see [`Self::refine`]).
    fn bounded_below(left: &Sample, right: &Sample, gap: f64, best: f64) -> bool {
        if !(left.1.is_finite() && right.1.is_finite()) {
            return false;
        }
        // cos(θ − γ) = cos θ cos γ + sin θ sin γ where θ ≥ γ, i.e. cos θ ≤ cos γ
        let (c, g) = (left.1.max(right.1).clamp(-1.0, 1.0), gap.clamp(-1.0, 1.0));
        g > Self::PRUNE_GAP.cos() && c <= g && c * g + ((1.0 - c * c) * (1.0 - g * g)).sqrt() < best
    }

    /// Brent's search (parabolic steps, golden sections where they fail; Brent 1973, ch. 5) for
    /// the largest cosine on the fan `ea`–`eb` within `[lo, hi]`, from the sample `start`
    /// inside; returns the best sample (its ray exact).
    fn brent(&self, ea: Vec3, eb: Vec3, mut lo: f64, mut hi: f64, start: Sample) -> Sample {
        const C: f64 = 0.381_966_011_250_105; // (3 − √5)/2
        let at = |t: f64| ea * (1.0 - t) + eb * t;
        // the search on exact rays (each from the best one so far)
        let start = self.sample_near(&at(start.0), start.0, &start.3);
        let tol = 1e-6 * (hi - lo);
        // a peak at an end of the bracket (where the nearest ray is a cone edge's, often):
        // the end itself when the cosine falls inwards
        if start.0 == lo || start.0 == hi {
            let t = if start.0 == lo { lo + 1e2 * tol } else { hi - 1e2 * tol };
            if self.sample_near(&at(t), t, &start.3).1 <= start.1 {
                return start;
            }
        }
        // minimize −cos
        let (mut x, mut w, mut v) = (start, start, start);
        let (mut d, mut e): (f64, f64) = (0.0, 0.0);
        for _ in 0..100 {
            let xm = 0.5 * (lo + hi);
            if (x.0 - xm).abs() <= 2.0 * tol - 0.5 * (hi - lo) {
                break;
            }
            let (fx, fw, fv) = (-x.1, -w.1, -v.1);
            let mut golden = true;
            if e.abs() > tol && fx.is_finite() && fw.is_finite() && fv.is_finite() {
                let r = (x.0 - w.0) * (fx - fv);
                let mut q = (x.0 - v.0) * (fx - fw);
                let mut p = (x.0 - v.0) * q - (x.0 - w.0) * r;
                q = 2.0 * (q - r);
                if q > 0.0 {
                    p = -p;
                }
                q = q.abs();
                let e_old = e;
                if p.abs() < (0.5 * q * e_old).abs() && p > q * (lo - x.0) && p < q * (hi - x.0) {
                    e = d;
                    d = p / q;
                    let u = x.0 + d;
                    if u - lo < 2.0 * tol || hi - u < 2.0 * tol {
                        d = tol.copysign(xm - x.0);
                    }
                    golden = false;
                }
            }
            if golden {
                e = if x.0 >= xm { lo - x.0 } else { hi - x.0 };
                d = C * e;
            }
            let u = if d.abs() >= tol { x.0 + d } else { x.0 + tol.copysign(d) };
            let fu = self.sample_near(&at(u), u, &x.3);
            if fu.1 >= x.1 {
                if u >= x.0 {
                    lo = x.0;
                } else {
                    hi = x.0;
                }
                (v, w, x) = (w, x, fu);
            } else {
                if u < x.0 {
                    lo = u;
                } else {
                    hi = u;
                }
                if fu.1 >= w.1 || w.0 == x.0 {
                    (v, w) = (w, fu);
                } else if fu.1 >= v.1 || v.0 == x.0 || v.0 == w.0 {
                    v = fu;
                }
            }
        }
        x
    }
}

/// Maximizes the cosine between `d` and the rays on the boundary of the exact cone (images of
/// the boundary fans of `W_p`). Each fan is sampled until consecutive rays are less than 4°
/// apart (the boundary can turn quickly where gravity matters most), except where a bound
/// shows no better ray can lie ([`BoundaryRays::refine`]), then every local maximum near the
/// best is refined by Brent's search. Returns the cosine and the unit ray.
fn nearest_boundary_ray(frame: &SupportFrame, model: &PusherModel, d: &Vec3) -> (f64, Vec3) {
    let rays = BoundaryRays { frame, model, ds: model.metric.twist(d).normalize() };
    let segments = model.cone.boundary_segments();
    let edges = |(i, j): (usize, usize)| (model.cone.edges[i], model.cone.edges[j]);
    // every fan's coarse samples first, so that each fan's refinement is bounded by the best
    let coarse: Vec<Vec<Sample>> = segments
        .iter()
        .map(|&(i, j)| if i == j { vec![rays.sample(&model.cone.edges[i], 0.0)] } else { rays.coarse(edges((i, j)).0, edges((i, j)).1) })
        .collect();
    let mut best_sample = coarse.iter().flatten().map(|s| s.1).fold(f64::NEG_INFINITY, f64::max);
    let sampled: Vec<Vec<Sample>> = coarse
        .into_iter()
        .zip(&segments)
        .map(|(c, &(i, j))| if i == j { c } else { rays.refine(edges((i, j)).0, edges((i, j)).1, c, &mut best_sample) })
        .collect();
    let top = sampled.iter().flatten().map(|s| s.1).fold(f64::NEG_INFINITY, f64::max);
    // between samples at most MAX_STEP apart the cosine can rise by about MAX_STEP²/2 above
    // the better sample: refine every local maximum within that of the best one
    let slack = BoundaryRays::MAX_STEP * BoundaryRays::MAX_STEP;
    let mut best = (f64::NEG_INFINITY, None);
    for (seg, pts) in sampled.iter().enumerate() {
        let (ea, eb) = edges(segments[seg]);
        for k in 0..pts.len() {
            let is_peak = (k == 0 || pts[k].1 >= pts[k - 1].1) && (k + 1 == pts.len() || pts[k].1 >= pts[k + 1].1);
            if !is_peak || pts[k].1 < top - slack {
                continue;
            }
            // (compared by exact rays only: a guess's cosine may exceed any ray's of its fan)
            let f = if pts.len() < 2 {
                rays.sample_with::<true>(&model.metric.wrench(&pts[k].4), pts[k].0)
            } else {
                // two samples either side: a guessed ray's error may shift the peak by one
                let (lo, hi) = (pts[k.saturating_sub(2)].0, pts[(k + 2).min(pts.len() - 1)].0);
                rays.brent(ea, eb, lo, hi, pts[k])
            };
            if f.1 > best.0 {
                best = (f.1, Some(f.4));
            }
        }
    }
    // the best sample's ray, exact
    let m = &model.metric;
    match best.1.and_then(|w| frame.ray(&w, m)) {
        Some(v) => (m.twist(&v).dot(&rays.ds), v),
        None => (f64::NEG_INFINITY, Vec3::zeros()),
    }
}

/// Euclidean projection of `d` onto the cone generated by `gens` (non-negative least squares,
/// exact by enumerating the faces: a projection lies in the relative interior of a face spanned
/// by at most 3 independent generators). Returns the projection and the weights.
pub fn project_onto_generators(gens: &[Vec3], d: &Vec3) -> (Vec3, Vec<f64>) {
    let k = gens.len();
    let mut best = (d.norm_squared(), Vec3::zeros(), vec![0.0; k]);
    // every face spanned by 1, 2 or 3 generators: O(k³) small fixed-size solves
    let mut consider = |idx: &[usize]| {
        let n = idx.len();
        let mut g = nalgebra::Matrix3::<f64>::zeros();
        for (j, &i) in idx.iter().enumerate() {
            g.set_column(j, &gens[i]);
        }
        let g = g.columns(0, n);
        let gtg = g.transpose() * g;
        if gtg.determinant().abs() < 1e-14 * gtg.norm().powi(n as i32) {
            return;
        }
        let Some(inv) = gtg.try_inverse() else { return };
        let alpha = inv * (g.transpose() * d);
        if alpha.iter().any(|&a| a < 0.0) {
            return;
        }
        let p: Vec3 = g * &alpha;
        let res = (d - p).norm_squared();
        if res < best.0 {
            let mut w = vec![0.0; k];
            for (j, &i) in idx.iter().enumerate() {
                w[i] = alpha[j];
            }
            best = (res, p, w);
        }
    };
    for a in 0..k {
        consider(&[a]);
        for b in a + 1..k {
            consider(&[a, b]);
            for c in b + 1..k {
                consider(&[a, b, c]);
            }
        }
    }
    (best.1, best.2)
}
