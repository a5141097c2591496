//! Robust motion cones, fixtureless fixturing and the MPC's QP.

mod common;

use proptest::prelude::*;
use regrasp::mechanics::geometry::Vec3;
use regrasp::control::mpc::{Mpc, MpcSettings, Status};
use regrasp::cones::robust::{self, ConeMode, Uncertainty};
use regrasp::scene::perturb;
use regrasp::Scene;

fn example(name: &str) -> Scene {
    let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples").join(format!("{name}.toml"));
    Scene::load(&p).expect("bundled example")
}

const SPREAD: Uncertainty = Uncertainty { pusher_friction: 0.2, finger_friction: 0.2, grip_force: 0.2, mass: 0.2 };

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    /// Every generator of the robust cone sticks for every sampled value in the ranges
    /// (friction, grip force, mass, pusher friction): the robust cone is inside every nominal
    /// cone of the range.
    #[test]
    fn robust_cone_is_inside_every_sampled_nominal_cone(
        case in common::block_case(),
        draws in proptest::collection::vec((0.0f64..1.0, 0.0f64..1.0, 0.0f64..1.0, 0.0f64..1.0), 8),
    ) {
        let scene = common::scene(&case);
        prop_assume!(scene.is_some());
        let scene = scene.unwrap();
        let worst = perturb::worst_case(&scene, &SPREAD).unwrap();
        let q = case.pose;
        let fw = worst.frame(&q);
        prop_assume!(fw.hold_ratio < 0.95);
        let gens = robust::generators(&fw, &worst.pushers[0].model);
        prop_assume!(!gens.is_empty());
        for (a, b, c, d) in draws {
            let s = perturb::scaled(&scene, 0.8 + 0.4 * a, 0.8 + 0.4 * b, 0.8 + 0.4 * c, 0.8 + 0.4 * d, ConeMode::Nominal).unwrap();
            let f = s.frame(&q);
            for g in &gens {
                let m = f.classify(&s.pushers[0].model, g).margin;
                prop_assert!(m >= -1e-7, "robust generator {g:?} slips at scales {a} {b} {c} {d} (margin {m})");
            }
        }
    }
}

#[test]
fn invariant_case_is_detected_for_a_pusher_below() {
    let s = example("block-low-friction");
    let q = [0.0, 0.0, 0.0];
    let f = s.frame(&q);
    let idx = |n: &str| s.pusher_index(n).unwrap();
    assert!(robust::carries_weight(&f, &s.pushers[idx("bottom")].model));
    assert!(!robust::carries_weight(&f, &s.pushers[idx("left")].model));
    assert!(!robust::carries_weight(&f, &s.pushers[idx("top")].model));
    // the robust cone of the bottom pusher is its gravity-free cone; fixtureless pushes exist
    // only for it
    let fx = perturb::fixtureless(&s);
    let ff = fx.frame(&q);
    assert!(robust::generators(&ff, &fx.pushers[idx("left")].model).is_empty());
    let gb = robust::generators(&ff, &fx.pushers[idx("bottom")].model);
    assert!(!gb.is_empty());
    // a fixtureless push sticks for any grip force, finger friction and mass
    for g in &gb {
        for (fr, grip, mass) in [(0.3, 0.3, 3.0), (1.0, 1.0, 1.0), (3.0, 5.0, 0.2)] {
            let w = perturb::scaled(&s, fr, grip, mass, 1.0, ConeMode::Nominal).unwrap();
            let m = w.frame(&q).classify(&w.pushers[idx("bottom")].model, g).margin;
            assert!(m >= -1e-7, "fixtureless generator slips at {fr} {grip} {mass}: {m}");
        }
    }
}

#[test]
fn robust_cone_found_where_the_two_cones_cross() {
    // μ_p = 0.25 side pushers move the block mostly by letting it slide down under gravity: with
    // ±20% on everything, no ray of V(ρ_min) lies in V_gf and no ray of V_gf in V(ρ_min), yet
    // the two cones cross (pivoting pushes); the robust cone is found on the chords between
    // outside rays, and its generators stick in every sampled world
    let s = example("block-low-friction");
    let w = perturb::worst_case(&s, &SPREAD).unwrap();
    let q = [0.002, -0.004, 0.05];
    let f = w.frame(&q);
    let p = s.pusher_index("left").unwrap();
    let model = &w.pushers[p].model;
    let m = model.metric;
    let rays: Vec<Vec3> = model.edges.iter().filter_map(|e| f.ray(&e.wrench, &m)).collect();
    let gf: Vec<Vec3> = model.edges.iter().map(|e| f.gravity_free_ray(&e.wrench, &m)).collect();
    assert!(rays.iter().chain(&gf).all(|v| f.classify(model, v).margin < 0.0), "not the crossing case");
    let gens = robust::generators(&f, model);
    assert!(gens.len() >= 2);
    for (a, b, c, d) in [(0.8, 0.8, 1.2, 0.8), (1.2, 1.2, 0.8, 1.2), (0.8, 1.2, 1.0, 1.0), (1.0, 1.0, 1.0, 1.0)] {
        let sc = perturb::scaled(&s, a, b, c, d, ConeMode::Nominal).unwrap();
        for g in &gens {
            assert!(sc.frame(&q).classify(&sc.pushers[p].model, g).margin >= -1e-7);
        }
    }
}

#[test]
fn robust_cone_shrinks_the_nominal_one() {
    let s = example("block-high-friction");
    let w = perturb::worst_case(&s, &SPREAD).unwrap();
    let q = [0.002, -0.004, 0.05];
    let p = s.pusher_index("left").unwrap();
    let (fs, fw) = (s.frame(&q), w.frame(&q));
    let gw = robust::generators(&fw, &w.pushers[p].model);
    assert!(gw.len() >= 2);
    for g in &gw {
        assert!(fs.classify(&s.pushers[p].model, g).margin >= -1e-7);
    }
    // some nominal generator is outside the robust cone
    let gn = robust::generators(&fs, &s.pushers[p].model);
    assert!(gn.iter().any(|g| fw.classify(&w.pushers[p].model, g).margin < 0.0));
}

#[test]
fn mpc_qp_respects_its_cone_constraints_and_tracks() {
    let s = example("block-low-friction");
    let r = regrasp::planning::planar::plan(&s, None, None, &regrasp::planning::planar::PlanarSettings::default()).unwrap();
    assert!(r.found);
    let mut mpc = Mpc::new(&s, &r.poses(), None, MpcSettings::default()).unwrap();
    let q = [0.0005, -0.0003, 0.01];
    let sol = mpc.solve_qp(&q, 0).unwrap();
    assert!(sol.status_ok);
    for (_, gens, w) in &sol.steps {
        assert_eq!(gens.len(), w.len());
        assert!(w.iter().all(|&x| x >= 0.0));
        let v = gens.iter().zip(w).fold(Vec3::zeros(), |a, (g, &x)| a + g * x);
        assert!(s.metric().twist_norm(&v) <= 0.01 * (1.0 + 1e-5));
    }
    let c = mpc.step(&q).unwrap();
    assert_eq!(c.status, Status::Tracking);
    let p = c.pusher.unwrap();
    let m = s.frame(&q).classify(&s.pushers[p].model, &c.twist).margin;
    assert!(m >= 0.01 - 1e-9, "executed twist outside the exact cone (margin {m})");
    assert!(s.metric().twist_norm(&c.twist) <= 0.01 * (1.0 + 1e-6));
    // at the goal it stops
    let g = s.task.unwrap().goal;
    assert_eq!(mpc.step(&g).unwrap().status, Status::AtGoal);
    // just inside the tolerance it keeps pushing while it makes progress
    let tol = s.task.unwrap().tolerance;
    let edge = [g[0] - 0.9 * tol[0], g[1], g[2]];
    let mut fresh = Mpc::new(&s, &r.poses(), None, MpcSettings::default()).unwrap();
    assert_ne!(fresh.step(&edge).unwrap().status, Status::AtGoal);
}

#[test]
fn mpc_closed_loop_on_the_cone_model_reaches_the_goal_after_a_poke() {
    // the plant moves exactly as commanded (the motion-cone model): the loop must converge
    for name in ["block-low-friction", "t-shape", "block-xztheta"] {
        let s = example(name);
        let r = regrasp::planning::planar::plan(&s, None, None, &regrasp::planning::planar::PlanarSettings::default()).unwrap();
        let mut mpc = Mpc::new(&s, &r.poses(), None, MpcSettings::default()).unwrap();
        let mut q = s.task.unwrap().start;
        let mut done = false;
        for k in 0..400 {
            if k == 15 {
                q = [q[0] + 0.002, q[1] - 0.002, q[2] + 0.03];
            }
            let c = mpc.step(&q).unwrap();
            if c.status == Status::AtGoal {
                done = true;
                break;
            }
            if c.status == Status::Stuck {
                continue;
            }
            q = regrasp::dynamics::planar::integrate(&q, &c.twist, 0.1);
        }
        assert!(done, "{name}: did not reach the goal ({q:?}, {} replans)", mpc.replans);
    }
}

/// A heavy block pushed up along the pads from below by a line pusher (hard example
/// heavy-low-friction, 76 % of the pads' friction taken by gravity), the MPC's reference a
/// slide up with a slight turn: the exact cone holds a twist close to it, but the edges' rays all
/// turn the block, so the projection on their span is a feasible turn far from it (the MPC,
/// given only that, rocked the block in place, "stuck" 3 mm short); the exact projection is close.
#[test]
fn the_exact_projection_finds_a_slide_that_the_edges_span_misses() {
    use regrasp::cones::motion_cone::{project_exact_with_margin, project_with_margin_on};
    let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/hard/heavy-low-friction.toml");
    let s = Scene::load(&p).expect("hard example");
    let q = [0.00725, 0.00128, 0.01859];
    let want = regrasp::pose::planar::body_twist(&q, &[0.00746, 0.00185, 0.01239]);
    let f = s.frame(&q);
    let model = &s.pushers[s.pusher_index("bottom").unwrap()].model;
    let m = s.metric();
    let gens = robust::generators(&f, model);
    let cos = |v: &Vec3| m.twist(v).dot(&m.twist(&want)) / (m.twist_norm(v) * m.twist_norm(&want));
    let up = Vec3::new(0.0, 1.0, 0.0);
    assert!(f.classify(model, &up).margin > 0.1, "sliding straight up is inside the exact cone");
    let poly = project_with_margin_on(&f, model, &gens, &want, 0.01).unwrap();
    let exact = project_exact_with_margin(&f, model, &gens, &want, 0.01).unwrap();
    println!("cos: span {} exact {}", cos(&poly), cos(&exact));
    assert!(f.classify(model, &exact).margin >= 0.01 - 1e-9);
    assert!(cos(&exact) > 0.9 && cos(&exact) > cos(&poly) + 0.3, "exact {} span {}", cos(&exact), cos(&poly));
}
