//! The pad's guide path (`planning::guide`) against a brute-force shortest path on a grid of the
//! pad centres where the whole pad lies on the object, and what it buys the planner on the U.

mod common;

use common::{outline_scene, star};
use proptest::prelude::*;
use regrasp::mechanics::geometry::Vec2;
use regrasp::planning::guide::Guide;
use regrasp::planning::planar::{plan, validate_path, PlanarSettings};
use regrasp::planning::trrt::SearchSettings;
use regrasp::Scene;
use std::collections::BinaryHeap;

fn bundled(name: &str) -> Scene {
    Scene::load(&std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("../../python/regrasp/examples/{name}.toml"))).unwrap()
}

/// Brute force: the shortest 8-connected path [m] between pad centres `a` and `b` through the
/// grid (spacing `h`) of the centres where the pad of radius `r` fits; None when none joins them.
fn grid_path(s: &Scene, r: f64, a: Vec2, b: Vec2, h: f64) -> Option<f64> {
    let v = s.outline.vertices();
    let (lo, hi) = v.iter().fold((v[0], v[0]), |(l, u), p| (l.inf(p), u.sup(p)));
    let (nx, nz) = (((hi.x - lo.x) / h) as i64 + 2, ((hi.y - lo.y) / h) as i64 + 2);
    let at = |i: i64, j: i64| Vec2::new(lo.x + i as f64 * h, lo.y + j as f64 * h);
    let fits = |i: i64, j: i64| (0..nx).contains(&i) && (0..nz).contains(&j) && s.outline.signed_distance(&at(i, j)) >= r;
    let cell = |p: Vec2| (((p.x - lo.x) / h).round() as i64, ((p.y - lo.y) / h).round() as i64);
    let ((ia, ja), (ib, jb)) = (cell(a), cell(b));
    let mut dist = vec![f64::INFINITY; (nx * nz) as usize];
    let idx = |i: i64, j: i64| (i * nz + j) as usize;
    let mut heap = BinaryHeap::new();
    dist[idx(ia, ja)] = (at(ia, ja) - a).norm();
    heap.push((std::cmp::Reverse((dist[idx(ia, ja)] * 1e9) as u64), ia, ja));
    while let Some((std::cmp::Reverse(_), i, j)) = heap.pop() {
        if (i, j) == (ib, jb) {
            return Some(dist[idx(i, j)] + (at(i, j) - b).norm());
        }
        for (di, dj) in [(1, 0), (-1, 0), (0, 1), (0, -1), (1, 1), (1, -1), (-1, 1), (-1, -1)] {
            let (u, w) = (i + di, j + dj);
            if fits(u, w) {
                let d = dist[idx(i, j)] + h * ((di * di + dj * dj) as f64).sqrt();
                if d < dist[idx(u, w)] - 1e-15 {
                    dist[idx(u, w)] = d;
                    heap.push((std::cmp::Reverse((d * 1e9) as u64), u, w));
                }
            }
        }
    }
    None
}

/// How close to the outline the region's segments may take the pad's centre: the erosion is
/// 0.96 r less the simplification's 0.01 r, and a bevel's chord across the arc about a reflex
/// corner that turns by φ passes at 0.96 r cos(φ/2) from it.
fn bevel_floor(outline: &[[f64; 2]], r: f64) -> f64 {
    let n = outline.len();
    let v = |i: usize| Vec2::new(outline[i % n][0], outline[i % n][1]);
    let turn = (0..n)
        .map(|i| {
            let (a, b, c) = (v(i + n - 1), v(i), v(i + 1));
            let (e, f) = (b - a, c - b);
            // CCW outline: a clockwise turn is a reflex corner
            if e.perp(&f) < 0.0 { e.angle(&f) } else { 0.0 }
        })
        .fold(0.0, f64::max);
    r * (0.96 * (0.5 * turn).cos() - 0.01) - 1e-9
}

/// The guide stays where a pad of radius `r` fits, sampled every 0.1 mm.
fn stays_on(s: &Scene, g: &Guide, r: f64) -> bool {
    let n = (g.length() / 1e-4).ceil() as usize;
    (0..=n).all(|k| s.outline.signed_distance(&g.at(g.length() * k as f64 / n as f64)) >= r)
}

#[test]
fn the_us_guide_goes_down_the_arm_across_the_base_and_up() {
    let s = bundled("hard/u-shape");
    let t = s.task.clone().unwrap();
    let (start, goal) = (t.start, t.goal);
    let g = Guide::new(&s, &start, &goal).expect("the straight path crosses the U's gap");
    let (a, b) = (s.pad_disc(&start).unwrap().0, s.pad_disc(&goal).unwrap().0);
    // the pad (5 mm) cannot rise above the base's inner edge (z = −15 mm) less its radius
    assert!(g.points().iter().any(|p| p.y < -0.0195 && p.x < 0.0) && g.points().iter().any(|p| p.y < -0.0195 && p.x > 0.0), "{:?}", g.points());
    let grid = grid_path(&s, 0.005, a, b, 2.5e-4).unwrap();
    assert!(g.length() <= grid && g.length() >= grid / 1.0824 - 1e-3, "guide {} grid {}", g.length(), grid);
    // the bevelled corners' chords (90° turns) keep the centre 0.96 cos 45° r = 0.68 r off them
    assert!(stays_on(&s, &g, 0.6 * 0.005) && !stays_on(&s, &g, 0.005));
    // a convex object needs no guide
    let block = bundled("block-low-friction");
    let t = block.task.clone().unwrap();
    assert!(Guide::new(&block, &t.start, &t.goal).is_none());
}

#[test]
fn across_a_thin_wall_the_distance_left_goes_round_it() {
    // a 60 mm square with a 2 mm slot cut from its right side to 8 mm from its left: the pad
    // (3 mm) goes from the upper right round the slot's end to the lower right
    let mm = |x: f64, z: f64| [x * 1e-3, z * 1e-3];
    let outline = vec![mm(-30.0, -30.0), mm(30.0, -30.0), mm(30.0, 1.0), mm(-22.0, 1.0), mm(-22.0, 3.0), mm(30.0, 3.0), mm(30.0, 30.0), mm(-30.0, 30.0)];
    let s = outline_scene(outline, 0.003, mm(24.0, 26.0), mm(24.0, -5.0)).unwrap();
    let t = s.task.clone().unwrap();
    let g = Guide::new(&s, &t.start, &t.goal).expect("the slot is in the way");
    let goal = Vec2::new(0.024, -0.005);
    for z in [6.5, 8.0, 12.0, 20.0] {
        // just above the slot the nearest guide point lies across its 2 mm wall
        let c = Vec2::new(0.024, z * 1e-3);
        let grid = grid_path(&s, 0.003, c, goal, 2.5e-4).unwrap();
        let cut = 1.2 * 0.003 * (g.points().len() - 2) as f64;
        assert!(g.to_go(&c) >= grid / 1.0824 - 1e-3 - cut, "z {z} mm: {} left against {grid}", g.to_go(&c));
    }
}

#[test]
fn the_guide_cuts_the_us_search_and_its_plans_stay_valid() {
    let s = bundled("hard/u-shape");
    let iterations = |guide: f64, seed: u64| {
        let search = SearchSettings { seed, refine: 0.0, time_limit: 60.0, ..SearchSettings::default() };
        let r = plan(&s, None, None, &PlanarSettings { search, guide, ..PlanarSettings::default() }).unwrap();
        assert!(r.found);
        let m = validate_path(&s, &r.poses(), 64).unwrap();
        assert!(m.iter().all(|m| *m >= -1e-9), "guide {guide}, seed {seed}: {m:?}");
        r.iterations
    };
    let (with, without): (Vec<_>, Vec<_>) = (0..3).map(|k| (iterations(0.7, k), iterations(0.0, k))).unzip();
    let (w, wo) = (with.iter().sum::<usize>(), without.iter().sum::<usize>());
    assert!(4 * w < wo, "iterations to the first plan with the guide {with:?}, without {without:?}");
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]
    /// On random star-shaped outlines, between random pad centres that the grid joins: the guide
    /// keeps its centre on the object, is no longer than the grid's path and shorter than it by
    /// at most the 8-connected grid's excess (8.24 %), a millimetre and, at each bend, what a
    /// bevel's chord cuts from a pad's arc (below 1.2 r).
    #[test]
    fn the_guide_is_the_shortest_path_the_grid_confirms(
        radii in prop::collection::vec(0.008f64..0.045, 5..16),
        pad in 0.001f64..0.003,
        ends in ((0.5f64..0.95, 0.0f64..6.3), (0.5f64..0.95, 1.0f64..2.5)),
    ) {
        let outline = star(&radii);
        let centre = |(u, a): (f64, f64)| {
            // along a ray, a share of the way to the outline's edge it crosses
            let k = ((a.rem_euclid(std::f64::consts::TAU) / std::f64::consts::TAU) * radii.len() as f64).floor() as usize % radii.len();
            let (p, q) = (outline[k], outline[(k + 1) % radii.len()]);
            let (e, d) = ([q[0] - p[0], q[1] - p[1]], [a.cos(), a.sin()]);
            let r = (p[0] * e[1] - p[1] * e[0]) / (d[0] * e[1] - d[1] * e[0]);
            [u * r * d[0], u * r * d[1]]
        };
        // the ends out in lobes a turn of 1 to 2.5 rad apart
        let (a, b) = (centre(ends.0), centre((ends.1 .0, ends.0 .1 + ends.1 .1)));
        let s = outline_scene(outline.clone(), pad, a, b);
        prop_assume!(s.is_some());
        let s = s.unwrap();
        let (va, vb) = (Vec2::new(a[0], a[1]), Vec2::new(b[0], b[1]));
        let grid = grid_path(&s, pad, va, vb, 2.5e-4);
        prop_assume!(grid.is_some());
        let grid = grid.unwrap();
        let t = s.task.clone().unwrap();
        match Guide::new(&s, &t.start, &t.goal) {
            // no guide: the straight segment keeps the pad's centre as far from the outline as
            // the region's bevelled corners allow
            None => {
                let d = vb - va;
                let floor = bevel_floor(&outline, pad);
                prop_assert!((0..=200).all(|k| s.outline.signed_distance(&(va + d * (k as f64 / 200.0))) >= floor), "floor {floor}");
            }
            Some(g) => {
                prop_assert!(stays_on(&s, &g, bevel_floor(&outline, pad)), "{:?}", g.points());
                let cut = 1.2 * pad * (g.points().len() - 2) as f64;
                prop_assert!(g.length() <= grid + 1e-9 && g.length() >= grid / 1.0824 - 1e-3 - cut, "guide {} grid {}", g.length(), grid);
            }
        }
    }
}
