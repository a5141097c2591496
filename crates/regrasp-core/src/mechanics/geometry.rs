//! Planar geometry of the manipulation plane (the gripper's X-Z plane).
//!
//! Conventions (docs/scene-file.md): points are `[x, z]` with X to the right and Z up; angles and
//! moments are counter-clockwise positive in that drawing. A planar twist is `[vx, vz, omega]`
//! and a planar wrench `[fx, fz, tau]`, dual to each other (power = f·v + tau·omega).

pub use crate::pose::planar::{rot, Mat2, Mat3, Pose2, Vec2, Vec3};

/// Planar cross product `a × b` (the moment of force `b` applied at `a`).
#[inline]
pub fn cross2(a: &Vec2, b: &Vec2) -> f64 {
    a.x * b.y - a.y * b.x
}

/// `a` rotated by +90°: the tangent that completes a contact normal to a right-handed frame.
#[inline]
pub fn perp(a: &Vec2) -> Vec2 {
    Vec2::new(-a.y, a.x)
}

/// Wrench of force `f` applied at point `r` (both in the same frame), about that frame's origin.
#[inline]
pub fn point_wrench(r: &Vec2, f: &Vec2) -> Vec3 {
    Vec3::new(f.x, f.y, cross2(r, f))
}

/// Jacobian mapping a twist about the origin to the twist about point `r`, same axes:
/// `[v + omega × r, omega]`. Its transpose moves a wrench applied at `r` to the origin.
#[inline]
pub fn shift_jacobian(r: &Vec2) -> Mat3 {
    Mat3::new(1.0, 0.0, -r.y, 0.0, 1.0, r.x, 0.0, 0.0, 1.0)
}

/// A simple polygon (counter-clockwise vertex order), possibly non-convex.
#[derive(Clone, Debug)]
pub struct Polygon {
    pts: Vec<Vec2>,
}

/// What is wrong with a candidate outline.
#[derive(Clone, Debug, PartialEq)]
pub enum PolygonDefect {
    TooFewVertices,
    NotFinite,
    RepeatedVertex(usize),
    SelfIntersecting(usize, usize),
    Clockwise,
    ZeroArea,
}

impl std::fmt::Display for PolygonDefect {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            PolygonDefect::TooFewVertices => write!(f, "needs at least 3 vertices"),
            PolygonDefect::NotFinite => write!(f, "has a non-finite coordinate"),
            PolygonDefect::RepeatedVertex(i) => write!(f, "vertex {i} repeats the next vertex"),
            PolygonDefect::SelfIntersecting(i, j) => {
                write!(f, "is not simple: edge {i} crosses edge {j}")
            }
            PolygonDefect::Clockwise => write!(f, "is clockwise; list the vertices counter-clockwise"),
            PolygonDefect::ZeroArea => write!(f, "has zero area"),
        }
    }
}

fn segments_intersect(a: &Vec2, b: &Vec2, c: &Vec2, d: &Vec2) -> bool {
    let o = |p: &Vec2, q: &Vec2, r: &Vec2| cross2(&(q - p), &(r - p));
    let on_seg = |p: &Vec2, q: &Vec2, r: &Vec2| {
        r.x >= p.x.min(q.x) && r.x <= p.x.max(q.x) && r.y >= p.y.min(q.y) && r.y <= p.y.max(q.y)
    };
    let (d1, d2, d3, d4) = (o(c, d, a), o(c, d, b), o(a, b, c), o(a, b, d));
    if ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0)) && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0)) {
        return true;
    }
    (d1 == 0.0 && on_seg(c, d, a))
        || (d2 == 0.0 && on_seg(c, d, b))
        || (d3 == 0.0 && on_seg(a, b, c))
        || (d4 == 0.0 && on_seg(a, b, d))
}

/// A pair `(i, j)`, `i < j`, of non-adjacent edges of the closed outline `pts` that touch, if
/// any. A sweep along x: the edges sorted by their left end, each tested (exactly) only against
/// the edges still open at that x whose z-ranges overlap its own; O(n log n) when a vertical
/// line crosses few edges (any outline a scene describes), O(n²) at worst (a comb).
fn first_crossing(pts: &[Vec2]) -> Option<(usize, usize)> {
    let n = pts.len();
    let bbox = |i: usize| {
        let (a, b) = (pts[i], pts[(i + 1) % n]);
        (a.inf(&b), a.sup(&b))
    };
    let boxes: Vec<(Vec2, Vec2)> = (0..n).map(bbox).collect();
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&i, &j| boxes[i].0.x.total_cmp(&boxes[j].0.x));
    let mut open: Vec<usize> = Vec::new();
    for &i in &order {
        let (lo, hi) = boxes[i];
        open.retain(|&j| boxes[j].1.x >= lo.x);
        for &j in &open {
            let (a, b) = (i.min(j), i.max(j));
            let adjacent = b == a + 1 || (a == 0 && b == n - 1);
            if adjacent || boxes[j].1.y < lo.y || boxes[j].0.y > hi.y {
                continue;
            }
            if segments_intersect(&pts[a], &pts[(a + 1) % n], &pts[b], &pts[(b + 1) % n]) {
                return Some((a, b));
            }
        }
        open.push(i);
    }
    None
}

/// The point of segment `ab` nearest to `p`.
pub fn closest_on_segment(p: &Vec2, a: &Vec2, b: &Vec2) -> Vec2 {
    let ab = b - a;
    let l2 = ab.norm_squared();
    let t = if l2 > 0.0 { ((p - a).dot(&ab) / l2).clamp(0.0, 1.0) } else { 0.0 };
    a + ab * t
}

/// Distance from `p` to segment `ab`.
pub fn point_segment_distance(p: &Vec2, a: &Vec2, b: &Vec2) -> f64 {
    let ab = b - a;
    let l2 = ab.norm_squared();
    let t = if l2 > 0.0 { ((p - a).dot(&ab) / l2).clamp(0.0, 1.0) } else { 0.0 };
    (a + ab * t - p).norm()
}

impl Polygon {
    /// Validates and builds a polygon: at least 3 finite vertices, counter-clockwise, simple.
    pub fn new(pts: Vec<Vec2>) -> Result<Self, PolygonDefect> {
        let n = pts.len();
        if n < 3 {
            return Err(PolygonDefect::TooFewVertices);
        }
        if pts.iter().any(|p| !p.x.is_finite() || !p.y.is_finite()) {
            return Err(PolygonDefect::NotFinite);
        }
        for i in 0..n {
            if (pts[i] - pts[(i + 1) % n]).norm() == 0.0 {
                return Err(PolygonDefect::RepeatedVertex(i));
            }
        }
        if let Some((i, j)) = first_crossing(&pts) {
            return Err(PolygonDefect::SelfIntersecting(i, j));
        }
        // adjacent edges folding back onto each other also make the outline non-simple
        for i in 0..n {
            let (a, b, c) = (pts[i], pts[(i + 1) % n], pts[(i + 2) % n]);
            let (u, v) = (b - a, c - b);
            if cross2(&u, &v).abs() <= 1e-14 * u.norm() * v.norm() && u.dot(&v) < 0.0 {
                return Err(PolygonDefect::SelfIntersecting(i, (i + 1) % n));
            }
        }
        let poly = Polygon { pts };
        let a = poly.signed_area();
        let scale = poly.bbox_diagonal();
        if a.abs() <= 1e-12 * scale * scale {
            return Err(PolygonDefect::ZeroArea);
        }
        if a < 0.0 {
            return Err(PolygonDefect::Clockwise);
        }
        Ok(poly)
    }

    pub fn vertices(&self) -> &[Vec2] {
        &self.pts
    }

    pub fn edges(&self) -> impl Iterator<Item = (Vec2, Vec2)> + '_ {
        let n = self.pts.len();
        (0..n).map(move |i| (self.pts[i], self.pts[(i + 1) % n]))
    }

    pub fn signed_area(&self) -> f64 {
        0.5 * self.edges().map(|(a, b)| cross2(&a, &b)).sum::<f64>()
    }

    /// Area centroid (the default centre of mass).
    pub fn centroid(&self) -> Vec2 {
        let a = self.signed_area();
        let s = self.edges().fold(Vec2::zeros(), |acc, (p, q)| acc + (p + q) * cross2(&p, &q));
        s / (6.0 * a)
    }

    /// Polar second moment of area about point `c`, divided by the area: the squared radius of
    /// gyration of a uniform lamina with this outline.
    pub fn gyration_radius_sq(&self, c: &Vec2) -> f64 {
        let mut ixx = 0.0;
        let mut iyy = 0.0;
        for (p, q) in self.edges() {
            let (p, q) = (p - c, q - c);
            let cr = cross2(&p, &q);
            ixx += cr * (p.y * p.y + p.y * q.y + q.y * q.y);
            iyy += cr * (p.x * p.x + p.x * q.x + q.x * q.x);
        }
        (ixx + iyy) / 12.0 / self.signed_area()
    }

    pub fn bbox_diagonal(&self) -> f64 {
        let (mut lo, mut hi) = (self.pts[0], self.pts[0]);
        for p in &self.pts {
            lo = lo.inf(p);
            hi = hi.sup(p);
        }
        (hi - lo).norm()
    }

    /// Point-in-polygon by the winding number (boundary points may go either way).
    pub fn contains(&self, p: &Vec2) -> bool {
        let mut wn = 0i32;
        for (a, b) in self.edges() {
            if a.y <= p.y {
                if b.y > p.y && cross2(&(b - a), &(p - a)) > 0.0 {
                    wn += 1;
                }
            } else if b.y <= p.y && cross2(&(b - a), &(p - a)) < 0.0 {
                wn -= 1;
            }
        }
        wn != 0
    }

    /// Distance from `p` to the outline.
    pub fn boundary_distance(&self, p: &Vec2) -> f64 {
        self.edges().map(|(a, b)| point_segment_distance(p, &a, &b)).fold(f64::INFINITY, f64::min)
    }

    /// Signed distance: positive inside, negative outside.
    pub fn signed_distance(&self, p: &Vec2) -> f64 {
        let d = self.boundary_distance(p);
        if self.contains(p) {
            d
        } else {
            -d
        }
    }

    /// The outline point nearest to `p`, the index of its edge and its distance to `p` [m].
    pub fn closest_point(&self, p: &Vec2) -> (Vec2, usize, f64) {
        let mut best = (self.pts[0], 0, f64::INFINITY);
        for (i, (a, b)) in self.edges().enumerate() {
            let c = closest_on_segment(p, &a, &b);
            let d = (c - p).norm();
            if d < best.2 {
                best = (c, i, d);
            }
        }
        best
    }

    /// Index of the edge closest to `p`.
    pub fn closest_edge(&self, p: &Vec2) -> usize {
        let mut best = (0, f64::INFINITY);
        for (i, (a, b)) in self.edges().enumerate() {
            let d = point_segment_distance(p, &a, &b);
            if d < best.1 {
                best = (i, d);
            }
        }
        best.0
    }

    /// Whether a convex polygon (given by its vertices) lies entirely inside this polygon.
    pub fn contains_convex(&self, inner: &[Vec2]) -> bool {
        if !inner.iter().all(|p| self.contains(p)) {
            return false;
        }
        let m = inner.len();
        for i in 0..m {
            let (a, b) = (inner[i], inner[(i + 1) % m]);
            for (c, d) in self.edges() {
                if segments_intersect(&a, &b, &c, &d) {
                    return false;
                }
            }
        }
        // a reflex vertex of the outline could poke into the convex set without crossing edges
        // only if it lies strictly inside `inner`
        !self.pts.iter().any(|v| convex_contains_strict(inner, v))
    }

    /// The same outline moved by `pose`.
    pub fn transformed(&self, pose: &Pose2) -> Polygon {
        Polygon { pts: self.pts.iter().map(|p| pose.apply(p)).collect() }
    }
}

fn convex_contains_strict(poly: &[Vec2], p: &Vec2) -> bool {
    let m = poly.len();
    (0..m).all(|i| cross2(&(poly[(i + 1) % m] - poly[i]), &(p - poly[i])) > 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square() -> Polygon {
        Polygon::new(vec![Vec2::new(-1.0, -1.0), Vec2::new(1.0, -1.0), Vec2::new(1.0, 1.0), Vec2::new(-1.0, 1.0)])
            .unwrap()
    }

    #[test]
    fn area_centroid_gyration_of_rectangle() {
        let p = Polygon::new(vec![Vec2::new(0.0, 0.0), Vec2::new(4.0, 0.0), Vec2::new(4.0, 2.0), Vec2::new(0.0, 2.0)])
            .unwrap();
        assert!((p.signed_area() - 8.0).abs() < 1e-12);
        assert!((p.centroid() - Vec2::new(2.0, 1.0)).norm() < 1e-12);
        // (a² + b²)/12 for a 4×2 rectangle about its centre
        assert!((p.gyration_radius_sq(&Vec2::new(2.0, 1.0)) - 20.0 / 12.0).abs() < 1e-12);
    }

    #[test]
    fn rejects_bad_outlines() {
        let bowtie = vec![Vec2::new(0.0, 0.0), Vec2::new(1.0, 1.0), Vec2::new(1.0, 0.0), Vec2::new(0.0, 1.0)];
        assert!(matches!(Polygon::new(bowtie), Err(PolygonDefect::SelfIntersecting(..))));
        let cw = vec![Vec2::new(0.0, 0.0), Vec2::new(0.0, 1.0), Vec2::new(1.0, 1.0), Vec2::new(1.0, 0.0)];
        assert_eq!(Polygon::new(cw).unwrap_err(), PolygonDefect::Clockwise);
        assert_eq!(Polygon::new(vec![Vec2::zeros(), Vec2::x()]).unwrap_err(), PolygonDefect::TooFewVertices);
        let line = vec![Vec2::new(0.0, 0.0), Vec2::new(1.0, 0.0), Vec2::new(2.0, 0.0)];
        assert!(Polygon::new(line).is_err());
    }

    #[test]
    fn containment_and_distances() {
        let s = square();
        assert!(s.contains(&Vec2::new(0.5, 0.5)));
        assert!(!s.contains(&Vec2::new(1.5, 0.5)));
        assert!((s.signed_distance(&Vec2::new(0.5, 0.0)) - 0.5).abs() < 1e-12);
        assert!((s.signed_distance(&Vec2::new(2.0, 0.0)) + 1.0).abs() < 1e-12);
        let pad = [Vec2::new(-0.5, -0.5), Vec2::new(0.5, -0.5), Vec2::new(0.5, 0.5), Vec2::new(-0.5, 0.5)];
        assert!(s.contains_convex(&pad));
        let big: Vec<Vec2> = pad.iter().map(|p| p * 2.5).collect();
        assert!(!s.contains_convex(&big));
    }

    #[test]
    fn pose_inverse_and_adjoint() {
        let p = Pose2::new(0.3, -0.2, 0.7);
        let q = p.compose(&p.inverse());
        assert!(q.t.norm() < 1e-12 && q.theta.abs() < 1e-12);
        // adjoint maps a child-frame twist to the parent frame: check on a point velocity
        let v_child = Vec3::new(0.1, 0.2, 0.3);
        let v_parent = p.adjoint() * v_child;
        // velocity of the child origin, seen in the parent axes, is R v; the parent-origin
        // velocity adds omega × (0 − t)
        let r = rot(p.theta);
        let v_origin = r * Vec2::new(0.1, 0.2) + perp(&(-p.t)) * 0.3;
        assert!((Vec2::new(v_parent.x, v_parent.y) - v_origin).norm() < 1e-12);
    }
}
