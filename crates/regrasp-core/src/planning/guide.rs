//! The pad's guide path: where the pad's centre must go, on the object, from the start's grasp to
//! the goal's.
//!
//! The pad's centre (object frame) stays in the outline eroded by the pad's inscribed radius
//! ([`super::reachability`]; the same region, whose bevelled reflex corners let the guide cut
//! each corner's arc by its chord: at most 0.57 r shorter per 90° turn). When the straight segment between the start's and the goal's pad
//! centres leaves that region (a U, an L, a hole in the way), the search's Euclidean cost-to-go
//! points into walls: T-RRT's transition test rejects the detour the pad must take, and the
//! nearest nodes to the goal are dead ends. The guide is the shortest path of the pad's centre
//! inside the region: a visibility graph of the region's reflex corners (where a shortest path in
//! a polygonal domain bends), each pair joined when the segment between them is covered by the
//! region (`geo`'s DE-9IM covers), searched by A* (`petgraph`) with the straight distance as the
//! heuristic. The cost-to-go becomes the distance left along it, and a share of the samples
//! (the planner's `guide` setting) lies just ahead of the tree's node closest to the goal along
//! it: uniform samples over a U mostly pull the nearest nodes into its walls.

use super::reachability::pad_region;
use super::trrt::gauss;
use crate::mechanics::geometry::{rot, Vec2};
use crate::scene::Scene;
use geo::algorithm::buffer::LineJoin;
use geo::{Contains, Line, Point, Polygon, PreparedGeometry, Relate};
use petgraph::graph::UnGraph;
use rand::Rng;

/// The most corners a region may have for a guide to be built (the visibility graph is cubic in
/// them).
pub const MAX_CORNERS: usize = 200;
/// A guided sample's arc length: from this many unit steps behind the closest node's projection…
pub const BEHIND: f64 = 1.0;
/// …to this many ahead of it.
pub const AHEAD: f64 = 2.0;
/// The spread of a guided sample's pad centre about the guide (standard deviation per axis, a
/// share of L): about the half-width of a pad-wide corridor.
pub const SPREAD: f64 = 0.12;
/// The spread of a guided sample's turn about the goal's [rad].
pub const TURN: f64 = 0.1;

/// A polyline of pad centres [m], object frame, from the start's to the goal's, with the walls
/// of the region it runs in.
#[derive(Clone, Debug)]
pub struct Guide {
    points: Vec<Vec2>,
    /// Arc length at each point [m].
    along: Vec<f64>,
    /// The region's boundary edges: a pad centre is matched only to guide points it sees.
    walls: Vec<(Vec2, Vec2)>,
}

impl Guide {
    /// The guide between the start's and the goal's pad centres (poses `[x, z, θ]`), when the
    /// straight segment between them leaves the pad's region; None when it does not (or on a
    /// surface, or when the region is too large, or the goal lies outside the start's part).
    pub fn new(scene: &Scene, start: &[f64; 3], goal: &[f64; 3]) -> Option<Self> {
        let (cs, r) = scene.pad_disc(start)?;
        let (cg, _) = scene.pad_disc(goal)?;
        let region = pad_region(scene, r, LineJoin::Bevel)?;
        let part = region.0.into_iter().find(|p| p.contains(&point(&cs)))?;
        let corners = reflex_corners(&part);
        if corners.len() > MAX_CORNERS {
            return None;
        }
        // the part indexed once (an R-tree of its edges) for the many segment tests
        let prepared = PreparedGeometry::from(&part);
        let sees = |a: &Vec2, b: &Vec2| prepared.relate(&line(a, b)).is_covers();
        if sees(&cs, &cg) {
            return None;
        }
        let points: Vec<Vec2> = [cs, cg].into_iter().chain(corners).collect();
        let mut graph = UnGraph::<Vec2, f64>::new_undirected();
        let ids: Vec<_> = points.iter().map(|p| graph.add_node(*p)).collect();
        for i in 0..points.len() {
            for j in i + 1..points.len() {
                if sees(&points[i], &points[j]) {
                    graph.add_edge(ids[i], ids[j], (points[i] - points[j]).norm());
                }
            }
        }
        let (_, route) = petgraph::algo::astar(&graph, ids[0], |n| n == ids[1], |e| *e.weight(), |n| (graph[n] - cg).norm())?;
        let walls = std::iter::once(part.exterior())
            .chain(part.interiors())
            .flat_map(|ring| ring.lines().map(|l| (Vec2::new(l.start.x, l.start.y), Vec2::new(l.end.x, l.end.y))))
            .collect();
        Some(Self { walls, ..Self::through(route.iter().map(|&n| graph[n]).collect()) })
    }

    /// The polyline through `points` (at least two), with no walls.
    fn through(points: Vec<Vec2>) -> Self {
        assert!(points.len() >= 2, "a guide joins two points at least");
        let along = std::iter::once(0.0)
            .chain(points.windows(2).scan(0.0, |s, w| {
                *s += (w[1] - w[0]).norm();
                Some(*s)
            }))
            .collect();
        Self { points, along, walls: Vec::new() }
    }

    pub fn points(&self) -> &[Vec2] {
        &self.points
    }

    /// The guide's length [m].
    pub fn length(&self) -> f64 {
        *self.along.last().unwrap_or(&0.0)
    }

    /// The arc length of the guide's point nearest to `c` among those `c` sees (no wall between
    /// them; else the nearest of all), and the distance to it [m]. Across a thin wall the nearest
    /// guide point can lie far further along the guide than the pad can get to directly.
    pub fn project(&self, c: &Vec2) -> (f64, f64) {
        let mut near: Vec<(f64, f64, Vec2)> = self
            .points
            .windows(2)
            .enumerate()
            .map(|(k, w)| {
                let d = w[1] - w[0];
                let n2 = d.norm_squared();
                let u = if n2 > 0.0 { ((c - w[0]).dot(&d) / n2).clamp(0.0, 1.0) } else { 0.0 };
                let p = w[0] + u * d;
                (self.along[k] + u * n2.sqrt(), (p - c).norm(), p)
            })
            .collect();
        near.sort_by(|a, b| a.1.total_cmp(&b.1));
        let seen = near.iter().find(|(_, _, p)| self.sees(c, p)).unwrap_or(&near[0]);
        (seen.0, seen.1)
    }

    /// Whether no wall properly crosses the segment from `a` to `b`.
    fn sees(&self, a: &Vec2, b: &Vec2) -> bool {
        let side = |p: &Vec2, q: &Vec2, x: &Vec2| (q - p).perp(&(x - p));
        !self.walls.iter().any(|(p, q)| side(p, q, a) * side(p, q, b) < 0.0 && side(a, b, p) * side(a, b, q) < 0.0)
    }

    /// The distance left to the goal's pad centre from `c` [m]: to the guide point it sees, then
    /// along the guide.
    pub fn to_go(&self, c: &Vec2) -> f64 {
        let (s, d) = self.project(c);
        self.length() - s + d
    }

    /// A pose `[x, z, θ]` to grow towards, just ahead of arc length `from` along the guide (from
    /// [`BEHIND`] to [`AHEAD`] unit steps `step` [m]), its pad centre spread about the guide by
    /// [`SPREAD`]·`length` and its turn about `theta` by [`TURN`]; the pose puts the pad's centre
    /// there, `t = −R(θ) c`.
    pub fn sample<R: Rng>(&self, rng: &mut R, from: f64, step: f64, length: f64, theta: f64) -> [f64; 3] {
        let th = theta + TURN * gauss(rng);
        let s = from + step * rng.random_range(-BEHIND..=AHEAD);
        let c = self.at(s) + SPREAD * length * Vec2::new(gauss(rng), gauss(rng));
        let t = -(rot(th) * c);
        [t.x, t.y, th]
    }

    /// The guide's point at arc length `s` (clamped to the guide) [m].
    pub fn at(&self, s: f64) -> Vec2 {
        let k = self.along.partition_point(|&a| a <= s).clamp(1, self.points.len().max(2) - 1);
        let (a, b) = (self.along[k - 1], self.along[k]);
        let u = if b > a { ((s - a) / (b - a)).clamp(0.0, 1.0) } else { 0.0 };
        self.points[k - 1] + u * (self.points[k] - self.points[k - 1])
    }
}

fn point(c: &Vec2) -> Point<f64> {
    Point::new(c.x, c.y)
}

fn line(a: &Vec2, b: &Vec2) -> Line<f64> {
    Line::new((a.x, a.y), (b.x, b.y))
}

/// The corners of `part` where it is not locally convex: reflex corners of its outer ring, convex
/// corners of its holes.
fn reflex_corners(part: &Polygon<f64>) -> Vec<Vec2> {
    let ring = |ls: &geo::LineString<f64>, outer: bool| -> Vec<Vec2> {
        let mut v: Vec<Vec2> = ls.0.iter().map(|c| Vec2::new(c.x, c.y)).collect();
        if v.len() > 1 && v.first() == v.last() {
            v.pop();
        }
        let n = v.len();
        let area: f64 = (0..n).map(|i| v[i].perp(&v[(i + 1) % n])).sum();
        // a corner turns against the ring's orientation where the region is locally non-convex
        // (outer ring); a hole's corners that turn with its own orientation bulge into the region
        let sign = if outer { area.signum() } else { -area.signum() };
        (0..n)
            .filter(|&i| {
                let (a, b, c) = (v[(i + n - 1) % n], v[i], v[(i + 1) % n]);
                sign * (b - a).perp(&(c - b)) < 0.0
            })
            .map(|i| v[i])
            .collect()
    };
    let mut out = ring(part.exterior(), true);
    for hole in part.interiors() {
        out.extend(ring(hole, false));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn polyline_measures() {
        let g = Guide::through(vec![Vec2::new(0.0, 0.0), Vec2::new(1.0, 0.0), Vec2::new(1.0, 2.0)]);
        assert!((g.length() - 3.0).abs() < 1e-12);
        assert!((g.at(2.0) - Vec2::new(1.0, 1.0)).norm() < 1e-12);
        assert!((g.at(-1.0) - Vec2::new(0.0, 0.0)).norm() < 1e-12);
        assert!((g.at(9.0) - Vec2::new(1.0, 2.0)).norm() < 1e-12);
        let (s, d) = g.project(&Vec2::new(0.5, -0.25));
        assert!((s - 0.5).abs() < 1e-12 && (d - 0.25).abs() < 1e-12);
        assert!((g.to_go(&Vec2::new(2.0, 1.5)) - (0.5 + 1.0)).abs() < 1e-12);
    }
}
