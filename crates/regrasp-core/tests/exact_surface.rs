//! The exact limit surface against independent references: its integration against a fine
//! grid of cells (the point-set model) and closed forms, its tables against its integration at
//! random twists (the stated tolerance), and its rays against their definition.

use proptest::prelude::*;
use regrasp::mechanics::exact_surface::{ExactSurface, Region};
use regrasp::mechanics::geometry::{Polygon, Vec2, Vec3};
use regrasp::mechanics::limit_surface::{Pressure, PressureDistribution};
use std::f64::consts::PI;

/// Tables against direct integration: the largest error of the load wrench, relative to its
/// size, in the scaled metric (`τ/ℓ`), over random twists: a general shape's cube maps.
const TABLE_TOLERANCE: f64 = 5e-4;
/// The same for a disc's 1-D profile (`mechanics::disc_profile`).
const PROFILE_TOLERANCE: f64 = 1e-7;

/// The stated tolerance of a region's tables.
fn tolerance(region: &Region) -> f64 {
    if region.axisymmetric() {
        PROFILE_TOLERANCE
    } else {
        TABLE_TOLERANCE
    }
}

fn rect(w: f64, h: f64) -> Vec<Vec2> {
    vec![Vec2::new(-w / 2.0, -h / 2.0), Vec2::new(w / 2.0, -h / 2.0), Vec2::new(w / 2.0, h / 2.0), Vec2::new(-w / 2.0, h / 2.0)]
}

/// A T-shaped outline (non-convex) about its centroid.
fn tee() -> Vec<Vec2> {
    let v = [[-0.01, -0.04], [0.01, -0.04], [0.01, 0.02], [0.03, 0.02], [0.03, 0.04], [-0.03, 0.04], [-0.03, 0.02], [-0.01, 0.02]];
    let p = Polygon::new(v.iter().map(|a| Vec2::new(a[0], a[1])).collect()).unwrap();
    let c = p.centroid();
    p.vertices().iter().map(|x| x - c).collect()
}

fn regions() -> Vec<(&'static str, Region)> {
    vec![
        ("uniform disc", Region::Disc { radius: 0.007, pressure: Pressure::Uniform }),
        ("hertzian disc", Region::Disc { radius: 0.01, pressure: Pressure::Hertzian }),
        ("3:1 rectangle", Region::Polygon { vertices: rect(0.03, 0.01) }),
        ("footprint", Region::Polygon { vertices: rect(0.05, 0.08) }),
        ("tee", Region::Polygon { vertices: tee() }),
    ]
}

fn scaled(w: &Vec3, l: f64) -> Vec3 {
    Vec3::new(w.x, w.y, w.z / l)
}

/// Twists spread over the sphere of scaled twists (Fibonacci points), unscaled.
fn twists(n: usize, l: f64) -> Vec<Vec3> {
    regrasp::mechanics::limit_surface::fibonacci_sphere(n).iter().map(|d| Vec3::new(d.x, d.y, d.z / l)).collect()
}

#[test]
fn integration_matches_a_fine_grid_of_cells() {
    let cases: Vec<(Region, PressureDistribution)> = vec![
        (Region::Disc { radius: 0.02, pressure: Pressure::Uniform }, PressureDistribution::circle(0.02, Pressure::Uniform, 900)),
        (Region::Disc { radius: 0.02, pressure: Pressure::Hertzian }, PressureDistribution::circle(0.02, Pressure::Hertzian, 900)),
        (Region::Polygon { vertices: rect(0.05, 0.08) }, PressureDistribution::polygon(&Polygon::new(rect(0.05, 0.08)).unwrap(), &Vec2::zeros(), 900)),
        (Region::Polygon { vertices: tee() }, PressureDistribution::polygon(&Polygon::new(tee()).unwrap(), &Vec2::zeros(), 900)),
    ];
    for (region, grid) in cases {
        let l = region.length_scale();
        let mut worst: f64 = 0.0;
        for v in twists(150, l) {
            let (a, b) = (region.wrench(&v), grid.friction_wrench(&v));
            worst = worst.max((scaled(&a, l) - scaled(&b, l)).norm());
        }
        // the grid's own error (cells of 1/900 of the size) bounds the agreement
        assert!(worst < 2e-5, "{region:?}: {worst}");
    }
}

#[test]
fn integration_matches_closed_forms() {
    let r = 0.013;
    let disc = Region::Disc { radius: r, pressure: Pressure::Uniform };
    // pure rotation: moment 2/3 μN r (uniform), 3π/16 μN r (Hertzian); translation: force μN
    assert!((disc.wrench(&Vec3::new(0.0, 0.0, 2.0)).z - 2.0 / 3.0 * r).abs() < 1e-12 * r);
    let hertz = Region::Disc { radius: r, pressure: Pressure::Hertzian };
    assert!((hertz.wrench(&Vec3::new(0.0, 0.0, -1.0)).z + 3.0 * PI / 16.0 * r).abs() < 1e-12 * r);
    let w = disc.wrench(&Vec3::new(0.0, -3.0, 0.0));
    assert!((w - Vec3::new(0.0, -1.0, 0.0)).norm() < 1e-15);
    // a rectangle a × b turning about its centre: μN/(ab) ∫|x| dA, by a fine 1-D quadrature
    let (a, b) = (0.04, 0.01);
    let rect_region = Region::Polygon { vertices: rect(a, b) };
    let n = 4000;
    let mut m = 0.0;
    for i in 0..n {
        for j in 0..n / 4 {
            let x = -a / 2.0 + a * (i as f64 + 0.5) / n as f64;
            let y = -b / 2.0 + b * (j as f64 + 0.5) / (n / 4) as f64;
            m += x.hypot(y);
        }
    }
    m /= (n * n / 4) as f64;
    assert!((rect_region.wrench(&Vec3::new(0.0, 0.0, 1.0)).z - m).abs() < 1e-6 * a);
}

#[test]
fn the_tables_agree_with_integration_within_the_stated_tolerance() {
    for (name, region) in regions() {
        let s = ExactSurface::new(&region);
        let l = s.length();
        let mut worst: f64 = 0.0;
        for v in twists(3000, l) {
            let (a, b) = (scaled(&s.wrench(&v), l), scaled(&s.wrench_direct(&v), l));
            worst = worst.max((a - b).norm() / b.norm());
        }
        println!("{name}: largest relative error of the table {worst:.2e}");
        assert!(worst < tolerance(&region), "{name}: {worst}");
        // the tolerance is not loose: the tables are not exact
        assert!(worst > tolerance(&region) * 1e-3, "{name}: {worst}");
    }
}

#[test]
fn the_gauge_is_one_on_the_surface_and_the_twist_is_its_normal() {
    for (name, region) in regions() {
        let s = ExactSurface::new(&region);
        let l = s.length();
        for v in twists(400, l) {
            let w = s.wrench(&v);
            let h = s.gauge(&w);
            // (a disc's profile: its gauge and load are one interpolant, consistent to rounding)
            let consistency = if region.axisymmetric() { 1e-12 } else { TABLE_TOLERANCE };
            assert!((h - 1.0).abs() < consistency, "{name}: H = {h}");
            assert!((s.gauge(&(w * 0.5)) - 0.5 * h).abs() < 1e-12, "{name}: homogeneous");
            let t = s.twist_for(&w).expect("every wrench direction has a twist");
            // scaled twists [vx, vz, ωℓ]
            let (ts, vs) = (Vec3::new(t.x, t.y, t.z * l), Vec3::new(v.x, v.y, v.z * l));
            // the twist whose load is along w is v itself (the table's inverse, polished)
            assert!((ts.normalize() - vs.normalize()).norm() < 1e-8, "{name}: {ts} vs {vs}");
        }
    }
}

#[test]
fn a_disc_is_axisymmetric_and_every_surface_is_symmetric() {
    let disc = Region::Disc { radius: 0.01, pressure: Pressure::Uniform };
    for v in twists(200, 0.01) {
        let w = disc.wrench(&v);
        // the force is along the velocity of the pad's centre (mirror symmetry)
        let (f, u) = (Vec2::new(w.x, w.y), Vec2::new(v.x, v.y));
        assert!((f.x * u.y - f.y * u.x).abs() < 1e-12 * u.norm().max(1e-300), "{f} vs {u}");
        assert!((disc.wrench(&-v) + w).norm() < 1e-12);
    }
    let s = ExactSurface::new(&Region::Polygon { vertices: tee() });
    for v in twists(200, s.length()) {
        assert!((s.wrench(&-v) + s.wrench(&v)).norm() < 1e-12);
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    /// A ray's twist loads the surface with `λu + o`, `λ > 0`, on the surface: its load minus
    /// `o` is along `u` (to rounding: the ray is polished on the same table) and its gauge is 1.
    #[test]
    fn rays_meet_their_definition(k in 0usize..5, a in -PI..PI, b in -1.5f64..1.5, oa in -PI..PI, ob in -1.5f64..1.5, h in 0.0f64..0.95) {
        let (_, region) = regions().swap_remove(k);
        let s = ExactSurface::new(&region);
        let l = s.length();
        let dir = |a: f64, b: f64| Vec3::new(a.cos() * b.cos(), a.sin() * b.cos(), b.sin() * l);
        let u = dir(a, b);
        let o0 = dir(oa, ob);
        let o = o0 * (h / s.gauge(&o0));
        let v = s.ray(&u, &o).expect("a ray from inside the surface");
        let w = s.wrench(&v) - o;
        let (ws, us) = (scaled(&w, l), scaled(&u, l));
        prop_assert!(ws.normalize().cross(&us.normalize()).norm() < 1e-9 && ws.dot(&us) > 0.0, "{ws} vs {us}");
        let consistency = if region.axisymmetric() { 1e-12 } else { TABLE_TOLERANCE };
        prop_assert!((s.gauge(&s.wrench(&v)) - 1.0).abs() < consistency);
        // from outside the surface there is no ray
        prop_assert!(s.ray(&u, &(o0 * (1.01 / s.gauge(&o0)))).is_none());
    }
}
