//! Exact limit surfaces of pressure distributions (Goyal, Ruina & Papadopoulos 1991; thesis
//! §3.1.3 before its ellipsoidal approximation).
//!
//! A support sliding with twist `v = [vx, vz, ω]` (about its origin) loads its surface with the
//! wrench `W(v) = ∫ p(x) [û(x); x × û(x)] dA`, `û = (v + ω ẑ × x)/|…|` (Coulomb at every point,
//! `μN = 1`, eq 3.5): the gradient of the dissipation `D(v) = ∫ p |u| dA`. `W` is computed by
//! integrating in polar coordinates about the instantaneous centre of rotation `c`. For a
//! polygon (uniform pressure) that is closed-form, edge by edge ([`polygon_rotation`]). For a
//! disc the integral along each ray from `c` is closed-form (uniform and Hertzian pressure) and
//! the integral over the ray's angle is the trapezoid rule on a whole turn (`c` inside the disc,
//! a smooth periodic integrand) or Gauss–Legendre after a substitution that removes the
//! square-root ends of the window the disc fills (`c` outside).
//!
//! For speed the surface is tabulated once per shape. A disc's depends on one variable
//! (axisymmetry): its 1-D profile ([`crate::mechanics::disc_profile`]) gives the load, the gauge
//! and the twists to about 1e-9 of the integral, each in a few flops. Any other shape's is
//! tabulated on two cube maps of directions (bicubic Catmull–Rom, a ghost row beyond each face's
//! edges):
//! * **forward**: the wrench `W(ṽ)` at twist directions `ṽ = [vx, vz, ωℓ]`;
//! * **inverse**: at wrench directions `w̃ = [fx, fz, τ/ℓ]`, the gauge `H(w̃)` (`= 1` on the
//!   surface, degree-1 homogeneous) and the unit twist whose wrench is along `w̃`, found by
//!   Newton's method on the forward table.
//!
//! `ℓ` is the pressure-weighted radius of gyration, so the scaled twist and wrench are of one
//! size. On cube maps the forward table defines the surface: twists from the inverse table are
//! polished by Newton's method on it ([`ExactSurface::ray`]), so that the motion cones' rays and
//! their exact test agree to rounding (a disc's profile is consistent by construction). Tables
//! are shared between supports of one shape (scaled to size).

use crate::mechanics::disc_profile::DiscProfile;
use crate::mechanics::geometry::{cross2, Polygon, Vec2, Vec3};
use crate::mechanics::limit_surface::Pressure;
use rayon::prelude::*;
use std::collections::HashMap;
use std::f64::consts::{FRAC_PI_2, PI};
use std::sync::{Arc, Mutex, OnceLock, Weak};

/// Cells along a cube-map face's edge; the interpolation error this gives is measured against
/// direct integration in the tests (`crates/regrasp-core/tests/exact_surface.rs`).
pub const TABLE_CELLS: usize = 96;

/// A support region with its pressure (normal force shares integrate to 1).
#[derive(Clone, Debug, PartialEq)]
pub enum Region {
    /// A disc of `radius` [m] centred at the origin.
    Disc { radius: f64, pressure: Pressure },
    /// Uniform pressure over a simple polygon (counter-clockwise vertices [m], any origin).
    Polygon { vertices: Vec<Vec2> },
}

impl Region {
    /// Pressure-weighted radius of gyration about the origin [m] (`√∫p|x|²dA`).
    pub fn length_scale(&self) -> f64 {
        match self {
            Region::Disc { radius, pressure: Pressure::Uniform } => radius / 2f64.sqrt(),
            Region::Disc { radius, pressure: Pressure::Hertzian } => radius * 0.4f64.sqrt(),
            Region::Polygon { vertices } => polygon(vertices).gyration_radius_sq(&Vec2::zeros()).sqrt(),
        }
    }

    /// Whether the pressure is symmetric about every line through the origin (a disc).
    pub fn axisymmetric(&self) -> bool {
        matches!(self, Region::Disc { .. })
    }

    /// The region scaled to unit length scale (a disc's radius exactly `1/√(its ratio)`).
    fn unit(&self) -> Region {
        match self {
            Region::Disc { pressure, .. } => {
                let one = Region::Disc { radius: 1.0, pressure: *pressure };
                Region::Disc { radius: 1.0 / one.length_scale(), pressure: *pressure }
            }
            Region::Polygon { .. } => self.scaled(1.0 / self.length_scale()),
        }
    }

    fn scaled(&self, k: f64) -> Region {
        match self {
            Region::Disc { radius, pressure } => Region::Disc { radius: radius * k, pressure: *pressure },
            Region::Polygon { vertices } => Region::Polygon { vertices: vertices.iter().map(|v| v * k).collect() },
        }
    }

    fn key(&self) -> Vec<u64> {
        match self {
            Region::Disc { pressure, .. } => vec![0, *pressure as u64],
            Region::Polygon { vertices } => {
                let mut k = vec![1];
                k.extend(vertices.iter().flat_map(|v| [v.x.to_bits(), v.y.to_bits()]));
                k
            }
        }
    }

    /// The load wrench `W(v)` (μN = 1) by integration (module notes); `v` finite, non-zero.
    pub fn wrench(&self, v: &Vec3) -> Vec3 {
        let lin = Vec2::new(v.x, v.y);
        if v.z == 0.0 {
            // translation: force along the motion, moment of the pressure centroid
            let f = lin / lin.norm();
            return Vec3::new(f.x, f.y, cross2(&self.centroid(), &f));
        }
        // u = v + ω ẑ × x vanishes at c = (−vz/ω, vx/ω)
        let c = Vec2::new(-v.y / v.z, v.x / v.z);
        self.rotation_wrench(&c) * v.z.signum()
    }

    fn centroid(&self) -> Vec2 {
        match self {
            Region::Disc { .. } => Vec2::zeros(),
            Region::Polygon { vertices } => polygon(vertices).centroid(),
        }
    }

    /// `W` of a counter-clockwise rotation about `c`: `∫dα [e⊥ I₁, (c·e) I₁ + I₂]` with
    /// `I_k = ∫ p s^k ds` over the ray `c + s e(α)` inside the region.
    fn rotation_wrench(&self, c: &Vec2) -> Vec3 {
        let mut w = Vec3::zeros();
        let mut add = |e: Vec2, weight: f64, i1: f64, i2: f64| {
            w += Vec3::new(-e.y * i1, e.x * i1, c.dot(&e) * i1 + i2) * weight;
        };
        match self {
            Region::Disc { radius, pressure } => disc_rays(*radius, *pressure, c, &mut add),
            Region::Polygon { vertices } => return polygon_rotation(vertices, c),
        }
        w
    }
}

fn polygon(vertices: &[Vec2]) -> Polygon {
    Polygon::new(vertices.to_vec()).expect("a region's polygon is checked when the scene is read")
}

/// Gauss–Legendre nodes and weights on [−1, 1].
fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    (0..n)
        .map(|i| {
            let mut x = (PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            let mut dp = 1.0;
            for _ in 0..100 {
                let (mut p0, mut p1) = (1.0, x);
                for k in 2..=n {
                    let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                    p0 = p1;
                    p1 = p2;
                }
                dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
                let dx = p1 / dp;
                x -= dx;
                if dx.abs() < 1e-16 {
                    break;
                }
            }
            (x, 2.0 / ((1.0 - x * x) * dp * dp))
        })
        .collect()
}

fn nodes(n: usize) -> &'static [(f64, f64)] {
    static GL: OnceLock<Mutex<HashMap<usize, &'static [(f64, f64)]>>> = OnceLock::new();
    let mut m = GL.get_or_init(Default::default).lock().unwrap_or_else(|e| e.into_inner());
    m.entry(n).or_insert_with(|| Box::leak(gauss_legendre(n).into_boxed_slice()))
}

/// The unit vectors of the trapezoid rule's `TURN` angles on a whole turn.
const TURN: usize = 512;
fn turn() -> &'static [Vec2] {
    static E: OnceLock<Vec<Vec2>> = OnceLock::new();
    E.get_or_init(|| (0..TURN).map(|k| 2.0 * PI * k as f64 / TURN as f64).map(|a| Vec2::new(a.cos(), a.sin())).collect())
}

/// Rays from `c` through a disc: `add(e(α), dα weight, I₁, I₂)`.
fn disc_rays(r: f64, pressure: Pressure, c: &Vec2, add: &mut impl FnMut(Vec2, f64, f64, f64)) {
    let d = c.norm();
    let chord = |e: &Vec2| -> (f64, f64) {
        let b = c.dot(e);
        let disc = b * b - d * d + r * r;
        if disc <= 0.0 {
            return (0.0, 0.0);
        }
        let h = disc.sqrt();
        let (lo, hi) = ((-b - h).max(0.0), -b + h);
        if hi <= lo {
            return (0.0, 0.0);
        }
        match pressure {
            Pressure::Uniform => {
                let p = 1.0 / (PI * r * r);
                (p * (hi * hi - lo * lo) / 2.0, p * (hi.powi(3) - lo.powi(3)) / 3.0)
            }
            Pressure::Hertzian => hertz_chord(r, b, h, lo),
        }
    };
    if d < r {
        // whole turn, periodic and smooth: trapezoid rule
        for e in turn() {
            let (i1, i2) = chord(e);
            add(*e, 2.0 * PI / TURN as f64, i1, i2);
        }
    } else {
        // window α₀ ± β, β = asin(r/d); α = α₀ + β sin φ removes the square-root ends
        let (a0, beta) = ((-c.y).atan2(-c.x), (r / d).min(1.0).asin());
        for &(x, wt) in nodes(64) {
            let phi = x * FRAC_PI_2;
            let (sa, ca) = (a0 + beta * phi.sin()).sin_cos();
            let e = Vec2::new(ca, sa);
            let (i1, i2) = chord(&e);
            add(e, wt * FRAC_PI_2 * beta * phi.cos(), i1, i2);
        }
    }
}

/// `∫ p s^k ds` (k = 1, 2) along a chord of a Hertzian disc: with `σ = s + b = h sin θ` the
/// pressure `p₀/r · √(h² − σ²)` becomes `p₀/r · h cos θ` and the integrals are elementary.
fn hertz_chord(r: f64, b: f64, h: f64, lo: f64) -> (f64, f64) {
    let p0 = 3.0 / (2.0 * PI * r * r);
    let sa = ((lo + b) / h).clamp(-1.0, 1.0);
    let (ta, ca) = (sa.asin(), (1.0 - sa * sa).max(0.0).sqrt());
    // antiderivatives of cos²θ, cos²θ sinθ, cos²θ sin²θ from ta to π/2 (sin 4θ = 4 s c (c² − s²))
    let j0 = FRAC_PI_2 / 2.0 - 0.5 * (ta + sa * ca);
    let j1 = ca * ca * ca / 3.0;
    let j2 = PI / 16.0 - (ta / 8.0 - sa * ca * (ca * ca - sa * sa) / 8.0);
    // s = h sinθ − b; ds √(h² − σ²) = h² cos²θ dθ
    let k = p0 / r * h * h;
    let i1 = k * (h * j1 - b * j0);
    let i2 = k * (h * h * j2 - 2.0 * h * b * j1 + b * b * j0);
    (i1, i2)
}

/// `W` of a counter-clockwise rotation about `c` of a uniform polygon, in closed form: the sum
/// over edges of the signed triangles `(c, pᵢ, pᵢ₊₁)`; in polar coordinates about `c` an edge at
/// distance `d` along its normal `n` is `s = d sec φ` (`φ` from `n`), and with `t = ẑ × n`,
/// `∫ e⊥ s²/2 = d²/2 [t L(φ) − n sec φ]`, `∫ (c·e) s²/2 = d²/2 [(c·n) L(φ) + (c·t) sec φ]`,
/// `∫ s³/3 = d³/6 [sec φ tan φ + L(φ)]`, `L = asinh(tan φ)`.
fn polygon_rotation(vertices: &[Vec2], c: &Vec2) -> Vec3 {
    let n = vertices.len();
    let area = 0.5 * (0..n).map(|i| cross2(&vertices[i], &vertices[(i + 1) % n])).sum::<f64>();
    let mut w = Vec3::zeros();
    for i in 0..n {
        let (a, b) = (vertices[i] - c, vertices[(i + 1) % n] - c);
        let e = b - a;
        let len = e.norm();
        // the edge's normal pointing away from c, and its distance from c
        let mut nrm = Vec2::new(e.y, -e.x) / len;
        let mut d = nrm.dot(&a);
        if d < 0.0 {
            nrm = -nrm;
            d = -d;
        }
        if !(d > 1e-15 * (a.norm() + b.norm())) {
            continue;
        }
        let t = Vec2::new(-nrm.y, nrm.x);
        // at an end point x: d² sec φ = d|x|, d² L = d² asinh(x·t/d), d³ sec φ tan φ = d |x| (x·t)
        let at = |x: &Vec2| {
            let (sec_d2, l_d2, xt) = (d * x.norm(), d * d * (x.dot(&t) / d).asinh(), x.dot(&t));
            let f = (t * l_d2 - nrm * sec_d2) * 0.5;
            let tau = 0.5 * (c.dot(&nrm) * l_d2 + c.dot(&t) * sec_d2) + (sec_d2 * xt + d * l_d2) / 6.0;
            Vec3::new(f.x, f.y, tau)
        };
        w += at(&b) - at(&a);
    }
    w / area
}

/// Values on the unit sphere of directions, tabulated on a cube map (module notes), stored in
/// single precision (far below the interpolation error) on the three positive faces: the
/// surface is symmetric, each value odd (`f(−d) = −f(d)`) or even as `ODD` says.
#[derive(Debug)]
struct CubeMap<const K: usize> {
    n: usize,
    /// `3 (n+3)²` nodes; face `f` has axis `f/2` (positive faces `f` even)
    values: Vec<[f32; K]>,
    odd: [bool; K],
}

impl<const K: usize> CubeMap<K> {
    /// The direction (not unit) of node `(i, j)` of positive face `2a`.
    fn node_dir(n: usize, a: usize, i: usize, j: usize) -> Vec3 {
        let h = 2.0 / n as f64;
        face_dir(2 * a, -1.0 + (i as f64 - 1.0) * h, -1.0 + (j as f64 - 1.0) * h)
    }

    fn build(n: usize, odd: [bool; K], value: impl Fn(&Vec3) -> [f64; K] + Sync) -> Self {
        let m = n + 3;
        let values = (0..3 * m * m)
            .into_par_iter()
            .map(|k| value(&Self::node_dir(n, k / (m * m), (k / m) % m, k % m)).map(|x| x as f32))
            .collect();
        Self { n, values, odd }
    }

    /// The face of `d` (non-zero) and its coordinates there: `d = |d_a| (±e_a + u e_b + w e_c)`.
    fn face(d: &Vec3) -> (usize, f64, f64, f64) {
        let a = d.iamax();
        let m = d[a].abs();
        let f = 2 * a + usize::from(d[a] < 0.0);
        let r = 1.0 / m;
        (f, d[(a + 1) % 3] * r, d[(a + 2) % 3] * r, m)
    }

    /// Bicubic (Catmull–Rom) interpolation at direction `d`; also returns `|d_a|`.
    #[inline]
    fn at(&self, d: &Vec3) -> ([f64; K], f64) {
        let (f, u, w, m) = Self::face(d);
        let (v, _, _) = self.at_face::<false>(f, u, w);
        (v, m)
    }

    /// The node index (ghost row 0) at or below face coordinate `x` and the fraction beyond it.
    #[inline]
    fn cell(&self, x: f64) -> (usize, f64) {
        let g = ((x + 1.0) * (0.5 * self.n as f64) + 1.0).max(0.0);
        let i = (g as usize).clamp(1, self.n);
        (i, g - i as f64)
    }

    /// Bilinear interpolation at direction `d` (cheaper, for guesses); also returns `|d_a|`.
    #[inline]
    fn at_linear(&self, d: &Vec3) -> ([f64; K], f64) {
        let (f, u, w, m) = Self::face(d);
        let (u, w) = if f % 2 == 1 { (-u, -w) } else { (u, w) };
        let stride = self.n + 3;
        let ((i, s), (j, t)) = (self.cell(u), self.cell(w));
        let base = (f / 2) * stride * stride + i * stride + j;
        let (a, b, c, e) = (&self.values[base], &self.values[base + 1], &self.values[base + stride], &self.values[base + stride + 1]);
        let mut out = [0.0; K];
        for k in 0..K {
            let v = (1.0 - s) * ((1.0 - t) * a[k] as f64 + t * b[k] as f64) + s * ((1.0 - t) * c[k] as f64 + t * e[k] as f64);
            out[k] = if f % 2 == 1 && self.odd[k] { -v } else { v };
        }
        (out, m)
    }

    /// The interpolated value at face coordinates `(u, w)` of face `f`, and (when `GRAD`) its
    /// derivatives along `u` and `w`.
    #[inline]
    fn at_face<const GRAD: bool>(&self, f: usize, u: f64, w: f64) -> ([f64; K], [f64; K], [f64; K]) {
        // a negative face: the positive one at (−u, −w)
        let neg = f % 2 == 1;
        let (u, w) = if neg { (-u, -w) } else { (u, w) };
        let (stride, k) = (self.n + 3, 0.25 * self.n as f64); // k = 1/(2h)
        let ((i, s), (j, t)) = (self.cell(u), self.cell(w));
        let cr = |t: f64| {
            let (t2, t3) = (t * t, t * t * t);
            [(-t3 + 2.0 * t2 - t) * 0.5, (3.0 * t3 - 5.0 * t2 + 2.0) * 0.5, (-3.0 * t3 + 4.0 * t2 + t) * 0.5, (t3 - t2) * 0.5]
        };
        let dcr = |t: f64| {
            let t2 = t * t;
            [(-3.0 * t2 + 4.0 * t - 1.0) * k, (9.0 * t2 - 10.0 * t) * k, (-9.0 * t2 + 8.0 * t + 1.0) * k, (3.0 * t2 - 2.0 * t) * k]
        };
        let (wi, wj) = (cr(s), cr(t));
        let dj = if GRAD { dcr(t) } else { [0.0; 4] };
        let base = (f / 2) * stride * stride;
        // separable: each of the 4 rows interpolated along w (and differentiated), then along u
        let (mut out, mut du, mut dw) = ([0.0; K], [0.0; K], [0.0; K]);
        let di = if GRAD { dcr(s) } else { [0.0; 4] };
        for a in 0..4 {
            let start = base + (i + a - 1) * stride + j - 1;
            let row: &[[f32; K]; 4] = self.values[start..start + 4].try_into().expect("4 nodes");
            let (mut r, mut rd) = ([0.0; K], [0.0; K]);
            for (b, v) in row.iter().enumerate() {
                for c in 0..K {
                    r[c] += wj[b] * v[c] as f64;
                    if GRAD {
                        rd[c] += dj[b] * v[c] as f64;
                    }
                }
            }
            for c in 0..K {
                out[c] += wi[a] * r[c];
                if GRAD {
                    du[c] += di[a] * r[c];
                    dw[c] += wi[a] * rd[c];
                }
            }
        }
        if neg {
            // f(d) = ±f(−d): an odd value flips, and d/du of f(−u) flips once more
            for c in 0..K {
                if self.odd[c] {
                    out[c] = -out[c];
                } else {
                    du[c] = -du[c];
                    dw[c] = -dw[c];
                }
            }
        }
        (out, du, dw)
    }
}

/// The direction of face coordinates `(u, w)` on face `f` (not unit).
#[inline]
fn face_dir(f: usize, u: f64, w: f64) -> Vec3 {
    let a = f / 2;
    let mut d = Vec3::zeros();
    d[a] = if f % 2 == 0 { 1.0 } else { -1.0 };
    d[(a + 1) % 3] = u;
    d[(a + 2) % 3] = w;
    d
}

/// The surface of one shape, in units where its length scale is 1: a disc's 1-D profile, or
/// (any other shape) two cube maps.
#[derive(Debug)]
struct Tables {
    region: Region,
    kind: Kind,
}

#[derive(Debug)]
enum Kind {
    Profile(DiscProfile),
    Maps(Maps),
}

/// A general shape's surface on cube maps (module notes).
#[derive(Debug)]
struct Maps {
    /// `W(ṽ)` at twist directions
    forward: CubeMap<3>,
    /// `[H(face vector), unit twist]` at wrench directions
    inverse: CubeMap<4>,
}

/// Tables kept alive for reuse besides those that scenes hold: the most recently used shapes.
const KEEP: usize = 6;

/// Shares tables between supports of the same shape (a disc's by its pressure alone).
fn shared_tables(unit: Region) -> Arc<Tables> {
    type Cache = (HashMap<Vec<u64>, Weak<Tables>>, Vec<Arc<Tables>>);
    static CACHE: OnceLock<Mutex<Cache>> = OnceLock::new();
    let key = unit.key();
    let cache = CACHE.get_or_init(Default::default);
    let hit = cache.lock().unwrap_or_else(|e| e.into_inner()).0.get(&key).and_then(Weak::upgrade);
    let t = hit.unwrap_or_else(|| Arc::new(Tables::build(unit)));
    let mut m = cache.lock().unwrap_or_else(|e| e.into_inner());
    m.1.retain(|x| !Arc::ptr_eq(x, &t));
    m.1.push(t.clone());
    if m.1.len() > KEEP {
        m.1.remove(0);
    }
    m.0.retain(|_, w| w.strong_count() > 0);
    m.0.insert(key, Arc::downgrade(&t));
    t
}

impl Tables {
    fn build(region: Region) -> Self {
        let kind = match &region {
            Region::Disc { radius, .. } => Kind::Profile(DiscProfile::build(*radius, |v| region.wrench(v))),
            Region::Polygon { .. } => Kind::Maps(Maps::build(&region)),
        };
        Tables { region, kind }
    }

    fn wrench(&self, v: &Vec3) -> Vec3 {
        match &self.kind {
            Kind::Profile(p) => p.wrench(v),
            Kind::Maps(m) => m.wrench(v),
        }
    }

    /// Gauge and twist at wrench `w` ([`Maps::gauge_with`], unit; a profile's twist is not unit,
    /// and its gauge exact with `CUBIC`, else [`DiscProfile::gauge_guess`]).
    #[inline]
    fn gauge_with<const CUBIC: bool>(&self, w: &Vec3) -> (f64, Vec3) {
        match &self.kind {
            Kind::Profile(p) if CUBIC => p.gauge(w),
            Kind::Profile(p) => p.gauge_guess(w),
            Kind::Maps(m) => m.gauge_with::<CUBIC>(w),
        }
    }
}

impl Maps {
    fn build(region: &Region) -> Self {
        let n = TABLE_CELLS;
        let forward = CubeMap::<3>::build(n, [true; 3], |d| {
            let w = region.wrench(d);
            [w.x, w.y, w.z]
        });
        let mut t = Maps { forward, inverse: CubeMap { n, values: Vec::new(), odd: [false, true, true, true] } };
        let inverse = CubeMap::<4>::build(n / 2, [false, true, true, true], |d| {
            // from the direction itself, else from the axes and diagonals; else the best iterate
            // (the inverse table only starts the rays' Newton's method on the forward one)
            let starts = std::iter::once(*d).chain((0..27).map(|k| Vec3::new((k % 3) as f64 - 1.0, ((k / 3) % 3) as f64 - 1.0, (k / 9) as f64 - 1.0)));
            let mut last = *d;
            let mut found = None;
            for g in starts.filter(|g| g.amax() > 0.0) {
                match t.newton(d, &Vec3::zeros(), Some(g)) {
                    Ok(v) => {
                        found = Some(v);
                        break;
                    }
                    Err(v) => last = v,
                }
            }
            let v = found.unwrap_or(last);
            let w = t.wrench(&v);
            // H(d) = |d| / |W(v)| with W(v) ∥ d
            [d.norm() / w.norm(), v.x, v.y, v.z]
        });
        t.inverse = inverse;
        t
    }

    fn wrench(&self, v: &Vec3) -> Vec3 {
        let (w, _) = self.forward.at(v);
        Vec3::new(w[0], w[1], w[2])
    }

    /// Gauge `H(w)` and the unit twist at direction `w` from the inverse table (bilinear
    /// unless `CUBIC`).
    fn gauge_with<const CUBIC: bool>(&self, w: &Vec3) -> (f64, Vec3) {
        let (g, m) = if CUBIC { self.inverse.at(w) } else { self.inverse.at_linear(w) };
        let v = Vec3::new(g[1], g[2], g[3]);
        (g[0] * m, v / v.norm())
    }

    /// The unit twist `v` with `W(v) − o` along `dir` (positively), by Newton's method on the
    /// face coordinates of the forward table (its interpolant's exact derivatives) from `guess`
    /// (or from the direction itself). None if it fails.
    fn solve(&self, dir: &Vec3, o: &Vec3, guess: Option<Vec3>) -> Option<Vec3> {
        self.newton(dir, o, guess).ok()
    }

    /// One undamped step of [`Self::solve`]'s Newton's method from `v` (at most half a face).
    fn newton_step(&self, dir: &Vec3, o: &Vec3, v: &Vec3) -> Vec3 {
        let dir = dir * (1.0 / dir.norm());
        let (e1, e2) = basis(&dir);
        let proj = |x: &[f64; 3]| nalgebra::Vector2::new(e1.x * x[0] + e1.y * x[1] + e1.z * x[2], e2.x * x[0] + e2.y * x[1] + e2.z * x[2]);
        let (f, u, w, _) = CubeMap::<3>::face(v);
        let (x, du, dw) = self.forward.at_face::<true>(f, u, w);
        let r = proj(&x) - nalgebra::Vector2::new(e1.dot(o), e2.dot(o));
        match solve2(&proj(&du), &proj(&dw), &(-r)) {
            Some(step) if step.amax() < 0.5 => unit(&face_dir(f, u + step.x, w + step.y)),
            _ => *v,
        }
    }

    /// [`Self::solve`]'s Newton's method: the solution, or the last iterate when it has not
    /// converged.
    fn newton(&self, dir: &Vec3, o: &Vec3, guess: Option<Vec3>) -> Result<Vec3, Vec3> {
        let dir = dir / dir.norm();
        let (e1, e2) = basis(&dir);
        let mut v = guess.unwrap_or(dir);
        let proj = |x: &[f64; 3]| nalgebra::Vector2::new(e1.x * x[0] + e1.y * x[1] + e1.z * x[2], e2.x * x[0] + e2.y * x[1] + e2.z * x[2]);
        let along = |x: &[f64; 3]| dir.x * (x[0] - o.x) + dir.y * (x[1] - o.y) + dir.z * (x[2] - o.z);
        let r_of = |x: &[f64; 3]| proj(x) - nalgebra::Vector2::new(e1.dot(o), e2.dot(o));
        let mut best = f64::INFINITY;
        for _ in 0..60 {
            let (f, u, w, _) = CubeMap::<3>::face(&v);
            let (x, du, dw) = self.forward.at_face::<true>(f, u, w);
            let r = r_of(&x);
            let rn = r.norm();
            if rn < 1e-12 && along(&x) > 0.0 {
                return Ok(v / v.norm());
            }
            if rn >= best && rn < 1e-10 && along(&x) > 0.0 {
                // at the interpolant's rounding floor
                return Ok(v / v.norm());
            }
            best = best.min(rn);
            let step = solve2(&proj(&du), &proj(&dw), &(-r)).unwrap_or(-r);
            if rn < 1e-4 && along(&x) > 0.0 && step.amax() < 1e-2 {
                // near: Newton's full step (quadratic convergence), checked at the next lookup
                v = face_dir(f, u + step.x, w + step.y);
                continue;
            }
            // damped: at most a quarter of the face per step, and along the positive side
            let scale = (0.5 / step.amax().max(1e-300)).min(1.0);
            let mut k = scale;
            let mut moved = false;
            for _ in 0..30 {
                let cand = face_dir(f, u + step.x * k, w + step.y * k);
                let xc = self.wrench(&cand);
                let xa = [xc.x, xc.y, xc.z];
                if r_of(&xa).norm() < rn || (along(&x) <= 0.0 && along(&xa) > along(&x)) {
                    v = cand;
                    moved = true;
                    break;
                }
                k *= 0.5;
            }
            if !moved {
                break;
            }
        }
        let x = self.wrench(&v);
        let xa = [x.x, x.y, x.z];
        if r_of(&xa).norm() < 1e-10 && along(&xa) > 0.0 {
            Ok(v / v.norm())
        } else {
            Err(v / v.norm())
        }
    }
}

/// `|H − 1|` at which a profile's rays stop (its gauge is exact: the load of the ray's twist
/// minus `o` is then along `u` to about this).
const PROFILE_RAY_TOL: f64 = 1e-12;

/// The twist (not unit) on a profile's surface with load `λu + o` (`u` unit, scaled units) by
/// Newton's method on `λ` from `l` (∇H = n H/(n·w), Euler's relation), unbracketed: None unless
/// `|H − 1| < tol` within 8 steps (then the caller's fallback: the bracketed search of
/// [`ExactSurface::ray_from`], or from [`ExactSurface::ray_near`] the frame's ray).
fn profile_newton<const EXACT: bool>(p: &DiscProfile, us: &Vec3, os: &Vec3, mut l: f64, tol: f64) -> Option<Vec3> {
    for _ in 0..8 {
        if !(l > 0.0) {
            return None;
        }
        let w = us * l + os;
        let (h, n) = if EXACT { p.gauge(&w) } else { p.gauge_guess(&w) };
        if (h - 1.0).abs() < tol {
            return Some(n);
        }
        // the step (h − 1)/slope, slope = h n·u/(n·w), in one division
        let (nu, nw) = (n.dot(us), n.dot(&w));
        if !(nu * nw > 0.0) {
            return None;
        }
        l -= (h - 1.0) * nw / (h * nu);
    }
    None
}

/// The solution `x` of `[a b] x = r` (Cramer's rule); None when singular.
#[inline]
fn solve2(a: &nalgebra::Vector2<f64>, b: &nalgebra::Vector2<f64>, r: &nalgebra::Vector2<f64>) -> Option<nalgebra::Vector2<f64>> {
    let det = a.x * b.y - a.y * b.x;
    let x = nalgebra::Vector2::new(r.x * b.y - r.y * b.x, a.x * r.y - a.y * r.x) * (1.0 / det);
    (det != 0.0 && x.x.is_finite() && x.y.is_finite()).then_some(x)
}

/// `v / |v|` with one division.
#[inline]
fn unit(v: &Vec3) -> Vec3 {
    v * (1.0 / v.norm())
}

/// Two unit vectors completing `d` (unit) to an orthonormal basis.
fn basis(d: &Vec3) -> (Vec3, Vec3) {
    let a = if d.x.abs() < 0.9 { Vec3::x() } else { Vec3::y() };
    let e1 = unit(&(a - d * d.dot(&a)));
    (e1, d.cross(&e1))
}

/// The exact limit surface of one support (μN = 1, support frame, physical units).
#[derive(Clone, Debug)]
pub struct ExactSurface {
    tables: Arc<Tables>,
    /// `ℓ` [m]
    length: f64,
}

impl ExactSurface {
    /// Builds (or shares) the tables of `region`; `region` must have positive size.
    pub fn new(region: &Region) -> Self {
        let length = region.length_scale();
        Self { tables: shared_tables(region.unit()), length }
    }

    /// `ℓ` [m], the pressure-weighted radius of gyration.
    pub fn length(&self) -> f64 {
        self.length
    }

    /// The region at its physical size.
    pub fn region(&self) -> Region {
        self.tables.region.scaled(self.length)
    }

    fn scale_twist(&self, v: &Vec3) -> Vec3 {
        Vec3::new(v.x, v.y, v.z * self.length)
    }

    fn unscale_twist(&self, v: &Vec3) -> Vec3 {
        Vec3::new(v.x, v.y, v.z / self.length)
    }

    /// A scaled twist in physical units, unit in the scaled metric; None unless finite.
    fn unit_twist(&self, vs: &Vec3) -> Option<Vec3> {
        let v = self.unscale_twist(vs);
        let v = v / self.scale_twist(&v).norm();
        v.iter().all(|x| x.is_finite()).then_some(v)
    }

    fn scale_wrench(&self, w: &Vec3) -> Vec3 {
        Vec3::new(w.x, w.y, w.z / self.length)
    }

    fn unscale_wrench(&self, w: &Vec3) -> Vec3 {
        Vec3::new(w.x, w.y, w.z * self.length)
    }

    /// Load wrench `W(v)` [N, N, N·m per unit μN] of sliding twist `v` (finite, non-zero), from
    /// the table.
    #[inline]
    pub fn wrench(&self, v: &Vec3) -> Vec3 {
        self.unscale_wrench(&self.tables.wrench(&self.scale_twist(v)))
    }

    /// `W(v)` by direct integration (the table's reference).
    pub fn wrench_direct(&self, v: &Vec3) -> Vec3 {
        self.region().wrench(v)
    }

    /// The gauge `H(w)` (< 1 inside the surface, 1 on it; degree-1 homogeneous), from the table.
    #[inline]
    pub fn gauge(&self, w: &Vec3) -> f64 {
        let ws = self.scale_wrench(w);
        if ws.amax() == 0.0 {
            return 0.0;
        }
        self.tables.gauge_with::<true>(&ws).0
    }

    /// The sliding twist (unit in the scaled metric) whose load wrench is along `w` (non-zero),
    /// consistent with [`Self::wrench`] to rounding.
    pub fn twist_for(&self, w: &Vec3) -> Option<Vec3> {
        self.ray(w, &Vec3::zeros())
    }

    /// [`Self::ray`] by Newton's method from `near`, a twist close to the ray (e.g. the ray of a
    /// nearby `u`); None when that does not converge (then [`Self::ray`] from the tables).
    pub fn ray_near(&self, u: &Vec3, o: &Vec3, near: &Vec3) -> Option<Vec3> {
        let (us, os) = (self.scale_wrench(u), self.scale_wrench(o));
        let v = match &self.tables.kind {
            Kind::Maps(m) => m.solve(&(us / us.norm()), &os, Some(self.scale_twist(near)))?,
            Kind::Profile(p) => {
                // λ from the load of `near`: W(near) ≈ λu + o
                let us = us / us.norm();
                let l = (p.wrench(&self.scale_twist(near)) - os).dot(&us);
                profile_newton::<true>(p, &us, &os, l, PROFILE_RAY_TOL)?
            }
        };
        self.unit_twist(&v)
    }

    /// The sliding twist whose load wrench is `λ u + o` for the `λ > 0` that puts it on the
    /// surface (`H(o) < 1`): with `o` the support-frame gravity load, the motion-cone ray of a
    /// pusher wrench along `u` (eq 3.10 on the exact surface). Twist unit in the scaled metric;
    /// None when `H(o) ≥ 1` or `u` is zero.
    pub fn ray(&self, u: &Vec3, o: &Vec3) -> Option<Vec3> {
        self.ray_from::<true>(u, o, self.gauge(o), None)
    }

    /// [`Self::ray`] with `H(o)` known and perhaps a guess of `λ` (e.g. the ellipsoid's);
    /// without `POLISH` a guess, for searches that polish their result: on cube maps the
    /// inverse table's twist after one Newton step on the forward table; on a disc's profile
    /// the twist of a `λ` within 1e-4 of the root (in `H`) on the inverse's starting table
    /// alone ([`DiscProfile::gauge_guess`], within 1e-7 of the exact gauge).
    pub fn ray_from<const POLISH: bool>(&self, u: &Vec3, o: &Vec3, h_o: f64, guess: Option<f64>) -> Option<Vec3> {
        let (us, os) = (self.scale_wrench(u), self.scale_wrench(o));
        let un = us.norm();
        if !(un > 0.0) || !(h_o < 1.0) {
            return None;
        }
        let us = us / un;
        // λ: H(λu + o) = 1. H is a norm (the surface is symmetric), so λH(u) − H(o) ≤
        // H(λu + o) ≤ λH(u) + H(o): the root lies in [(1 − H(o))/H(u), (1 + H(o))/H(u)], and
        // it is the only one there (H convex). Newton's method kept in that bracket; on a
        // profile first unbracketed from the guess (cheaper: no H(u)).
        let tol = match self.tables.kind {
            Kind::Profile(_) if POLISH => PROFILE_RAY_TOL,
            Kind::Profile(_) => 1e-4,
            Kind::Maps(_) if POLISH => 1e-6,
            Kind::Maps(_) => 1e-4,
        };
        let g = |l: f64| self.tables.gauge_with::<POLISH>(&(us * l + os));
        if let (Kind::Profile(p), Some(l)) = (&self.tables.kind, guess) {
            if let Some(v) = profile_newton::<POLISH>(p, &us, &os, l * un, tol) {
                return self.unit_twist(&v);
            }
        }
        let (h_u, n_u) = self.tables.gauge_with::<POLISH>(&us);
        let (mut lo, mut hi) = ((1.0 - h_o) / h_u, (1.0 + h_o) / h_u);
        // else the root of H's expansion to first order in o: λH(u) + ∇H(u)·o = 1
        let expansion = (1.0 - h_u * n_u.dot(&os) / n_u.dot(&us)) / h_u;
        let mut l = match guess {
            Some(l) if l * un > lo && l * un < hi => l * un,
            _ if expansion > lo && expansion < hi => expansion,
            _ => lo,
        };
        let (mut h, mut n) = g(l);
        for _ in 0..60 {
            // (a guess to 1e-4 on the bilinear inverse table, the Newton step on the forward
            // table below squaring its error; 1e-3 left guesses wrong enough near a disc's
            // pure rotation to mislead the projection's search)
            if (h - 1.0).abs() < tol {
                break;
            }
            if h < 1.0 {
                lo = l;
            } else {
                hi = l;
            }
            // ∇H = n H / (n·w) (Euler's relation)
            let slope = n.dot(&us) / n.dot(&(us * l + os)) * h;
            let next = l - (h - 1.0) / slope;
            l = if next.is_finite() && next > lo && next < hi { next } else { 0.5 * (lo + hi) };
            (h, n) = g(l);
        }
        // polished to rounding, or (a guess) one Newton step on the forward table from the
        // inverse table's twist: steep parts of the normal map (near a disc's pure rotation)
        // are poorly interpolated by the inverse table alone
        let v = match &self.tables.kind {
            Kind::Profile(_) => n,
            Kind::Maps(m) if POLISH => m.solve(&us, &os, Some(n))?,
            Kind::Maps(m) => m.newton_step(&us, &os, &n),
        };
        self.unit_twist(&v)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_legendre_integrates_polynomials() {
        let s: f64 = nodes(8).iter().map(|(x, w)| w * x.powi(14)).sum();
        assert!((s - 2.0 / 15.0).abs() < 1e-14);
    }

    #[test]
    fn disc_closed_forms() {
        let r = 0.02;
        let u = Region::Disc { radius: r, pressure: Pressure::Uniform };
        let w = u.wrench(&Vec3::new(0.0, 0.0, 1.0));
        assert!((w.z - 2.0 / 3.0 * r).abs() < 1e-12 * r && w.x.abs() < 1e-14, "{w}");
        let h = Region::Disc { radius: r, pressure: Pressure::Hertzian };
        let w = h.wrench(&Vec3::new(0.0, 0.0, 1.0));
        assert!((w.z - 3.0 * PI / 16.0 * r).abs() < 1e-12 * r, "{w}");
        let w = u.wrench(&Vec3::new(1.0, 0.0, 0.0));
        assert!((w - Vec3::new(1.0, 0.0, 0.0)).norm() < 1e-15);
    }
}
