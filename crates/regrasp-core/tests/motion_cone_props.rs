//! Property tests of the motion cone against independent checks (force balance solved as an
//! LP over the contact forces with clarabel, limits, invariances).

mod common;

use clarabel::algebra::CscMatrix;
use clarabel::solver::{DefaultSettings, DefaultSolver, IPSolver, SolverStatus, SupportedConeT};
use common::*;
use proptest::prelude::*;
use regrasp::mechanics::exact_surface::Region;
use regrasp::mechanics::geometry::{perp, rot, Vec2, Vec3};
use regrasp::mechanics::limit_surface::Pressure;
use regrasp::scene::planar_file::{RawGravity, RawScene};
use regrasp::Scene;

fn twist_from_angles(a: f64, b: f64, l: f64) -> Vec3 {
    // uniform-ish direction in the scaled twist space, returned unscaled
    let d = Vec3::new(a.cos() * b.cos(), a.sin() * b.cos(), b.sin());
    Vec3::new(d.x, d.y, d.z / l)
}

/// Independent force balance: the load wrench of the finger pads is recomputed from the pose
/// and the pad's limit surface (eq 3.10), then an LP asks for contact forces at the pusher
/// points, inside their Coulomb cones, that balance it with gravity. Returns feasibility.
/// The pad's load is on the ellipsoid (`k = 0.6 r`) or, when `exact`, integrated over the
/// uniform disc directly ([`Region::wrench`], eq 3.5).
fn brute_force_sticks_on(raw: &RawScene, q: &[f64; 3], v: &Vec3, exact: bool) -> bool {
    let obj = raw.object.as_ref().unwrap();
    let grasp = raw.grasp.as_ref().unwrap();
    let grav = raw.gravity.clone().unwrap_or(RawGravity { direction: None, g: None });
    let p = &raw.pushers.as_ref().unwrap()[0];
    let (mass, com) = (obj.mass.unwrap(), obj.com.unwrap());
    let s = 2.0 * grasp.force.unwrap() * grasp.friction.unwrap();
    let k = 0.6 * grasp.pad_radius.unwrap();
    // pad centre in the object frame, and the object's velocity there, in gripper axes
    let r = rot(q[2]);
    let c = r.transpose() * -Vec2::new(q[0], q[1]);
    let vel_obj = Vec2::new(v.x, v.y) + perp(&c) * v.z;
    let vel = r * vel_obj;
    // eq 3.10 with A = diag(1, 1, 1/k²)/s²: w = s [vx, vz, k² ω]/√(vx² + vz² + k² ω²)
    let den = (vel.x * vel.x + vel.y * vel.y + k * k * v.z * v.z).sqrt();
    let (f_pad, tau_pad) = if exact {
        let disc = Region::Disc { radius: grasp.pad_radius.unwrap(), pressure: Pressure::Uniform };
        let w = disc.wrench(&Vec3::new(vel.x, vel.y, v.z)) * s;
        (r.transpose() * Vec2::new(w.x, w.y), w.z)
    } else {
        (r.transpose() * Vec2::new(vel.x, vel.y) * (s / den), s * k * k * v.z / den)
    };
    // required pusher wrench about the object origin = support load − gravity
    let d = grav.direction.unwrap_or([0.0, -1.0]);
    let g = grav.g.unwrap_or(9.81);
    let fg = r.transpose() * Vec2::new(d[0], d[1]) * (mass * g);
    let comv = Vec2::new(com[0], com[1]);
    let req = Vec3::new(
        f_pad.x - fg.x,
        f_pad.y - fg.y,
        tau_pad + (c.x * f_pad.y - c.y * f_pad.x) - (comv.x * fg.y - comv.y * fg.x),
    );
    // LP: variables (f_n, f_t) per point; J_pᵀ f = req; f_n ≥ 0, μ f_n ± f_t ≥ 0
    let pts = p.points.as_ref().unwrap();
    let n = Vec2::new(p.normal.unwrap()[0], p.normal.unwrap()[1]).normalize();
    let t = perp(&n);
    let mu = p.friction.unwrap();
    let m = 2 * pts.len();
    let mut cols: Vec<Vec<f64>> = Vec::new();
    for pt in pts {
        let pv = Vec2::new(pt[0], pt[1]);
        for dir in [n, t] {
            cols.push(vec![dir.x, dir.y, pv.x * dir.y - pv.y * dir.x]);
        }
    }
    // rows: 3 equalities (on the integrated surface: within 1e-4 of the load, the table's
    // error, as 6 inequalities), then 3 inequalities per point written as -G f + s = 0, s ≥ 0
    let eq = if exact { 6 } else { 3 };
    let mut dense = vec![vec![0.0; m]; eq + 3 * pts.len()];
    for j in 0..m {
        for i in 0..3 {
            dense[i][j] = cols[j][i];
            if exact {
                dense[3 + i][j] = -cols[j][i];
            }
        }
    }
    for i in 0..pts.len() {
        let (jn, jt) = (2 * i, 2 * i + 1);
        dense[eq + 3 * i][jn] = -1.0;
        dense[eq + 1 + 3 * i][jn] = -mu;
        dense[eq + 1 + 3 * i][jt] = -1.0;
        dense[eq + 2 + 3 * i][jn] = -mu;
        dense[eq + 2 + 3 * i][jt] = 1.0;
    }
    let a = CscMatrix::from(&dense);
    let mut b = vec![0.0; eq + 3 * pts.len()];
    b[..3].copy_from_slice(&[req.x, req.y, req.z]);
    if exact {
        let l = obj.outline.as_ref().map_or(0.05, |o| o.iter().map(|p| p[0].hypot(p[1])).fold(0.0, f64::max));
        let tol = 1e-4 * (req.x.hypot(req.y) + req.z.abs() / l);
        b[..3].iter_mut().for_each(|x| *x += tol);
        b[3..6].copy_from_slice(&[-req.x + tol, -req.y + tol, -req.z + tol * l]);
        b[2] += tol * (l - 1.0);
    }
    let pmat = CscMatrix::zeros((m, m));
    let qv = vec![0.0; m];
    let cones = if exact {
        vec![SupportedConeT::NonnegativeConeT(6 + 3 * pts.len())]
    } else {
        vec![SupportedConeT::ZeroConeT(3), SupportedConeT::NonnegativeConeT(3 * pts.len())]
    };
    let settings = DefaultSettings { verbose: false, ..DefaultSettings::default() };
    let mut solver = DefaultSolver::new(&pmat, &qv, &a, &b, &cones, settings).unwrap();
    solver.solve();
    matches!(solver.solution.status, SolverStatus::Solved | SolverStatus::AlmostSolved)
}

fn angle(a: &Vec3, b: &Vec3) -> f64 {
    let (a, b) = (a.normalize(), b.normalize());
    a.cross(&b).norm().atan2(a.dot(&b))
}

/// How far the projection may fall short of a sampled ray (in cosine, or in distance per unit
/// desired twist). The search is local within each bracket of its samples (4° apart in the
/// rays), and the cosine along a fan can have two local maxima inside one: a wiggle of the
/// boundary below the samples' spacing, e.g. where it turns sharply near the holding limit
/// (one case of 20,000: peaks 0.796396 and 0.796373 at fan parameters 0.300 and 0.330, a dip
/// to 0.796228 between). With discs on their 1-D profile (smooth to about 1e-9) two runs of
/// 20,000 cases gave largest shortfalls of 4.2e-6 and 2.3e-5 in cosine against the dense
/// scan, all but one case below 2e-12, and none in distance against the cone's rays; on the
/// earlier cube maps (ripple about 1e-4 of the load) 8.6e-6 in distance and 2.8e-6 in cosine.
const RIPPLE: f64 = 1e-4;

proptest! {
    #![proptest_config(ProptestConfig { cases: 200, .. ProptestConfig::default() })]

    /// Every generator's pusher wrench lies on an edge of the pusher's friction cone, and the
    /// support wrench is on the (ellipsoidal) limit surface, balancing pusher and gravity.
    #[test]
    fn generators_balance_forces(b in block_case()) {
        let Some(scene) = scene_ellipsoid(&b) else { return Ok(()) };
        let push = scene.push(&b.pose, 0).unwrap();
        let gens = push.generators().unwrap();
        let spec = push.spec().clone();
        let a = spec.limit_surface.matrix(spec.friction_scale);
        let js_inv_t = spec.support_jacobian.try_inverse().unwrap().transpose();
        for (g, e) in gens.iter().zip(push.pusher_edges()) {
            let c = push.classify(g).unwrap();
            // on the cone's boundary, pusher wrench along this edge
            prop_assert!(c.margin.abs() < 1e-7, "margin {}", c.margin);
            let ang = angle(&c.pusher_wrench, &e.wrench);
            prop_assert!(ang < 1e-6 || c.pusher_wrench.norm() < 1e-9 * spec.friction_scale, "edge angle {ang}");
            // support wrench on the limit surface and normal to it along the twist
            let ws = js_inv_t * c.support_wrench;
            prop_assert!((ws.dot(&(a * ws)) - 1.0).abs() < 1e-9);
            prop_assert!(angle(&(a * ws), &(spec.support_jacobian * g)) < 1e-7);
            // balance
            prop_assert!((c.support_wrench - c.pusher_wrench - spec.gravity).norm() < 1e-9 * spec.friction_scale);
        }
    }

    /// The projection with a margin delivers it whenever a line pusher's cone has room: when some twist (the
    /// ray of one of 64 random pusher wrenches inside W_p, brute force) has twice the margin asked,
    /// `project_with_margin` of any direction the cone has a part of returns a twist with at
    /// least the margin asked.
    #[test]
    fn the_projection_keeps_its_margin_when_the_cone_has_room(
        b in block_case(), ws in proptest::collection::vec(proptest::collection::vec(0.0f64..1.0, 4), 64),
        dir in (-3.1f64..3.1, -1.5f64..1.5), margin in 0.002f64..0.03,
    ) {
        // a point pusher's exact cone is a surface in twist space (no interior to keep a margin
        // in; the planner steps point pushers by their contact velocity instead)
        let b = BlockCase { line: true, ..b };
        let Some(scene) = scene(&b) else { return Ok(()) };
        let push = scene.push(&b.pose, 0).unwrap();
        let edges = push.pusher_edges();
        let room = ws.iter().filter_map(|w| {
            let p: Vec3 = edges.iter().zip(w).map(|(e, x)| e.wrench * *x).sum();
            push.ray(&p).map(|v| push.classify(&v).unwrap().margin)
        }).fold(f64::NEG_INFINITY, f64::max);
        prop_assume!(room >= 2.0 * margin);
        let want = twist_from_angles(dir.0, dir.1, scene.length);
        let frame = push.frame();
        let model = &scene.pushers[0].model;
        match regrasp::cones::motion_cone::project_with_margin(frame, model, &want, margin) {
            // only a direction the cone has no part of (its projection is zero)
            None => prop_assert!(regrasp::cones::motion_cone::project_exact(frame, model, &want).amax() == 0.0),
            Some(v) => {
                let m = frame.classify(model, &v).margin;
                prop_assert!(m >= margin - 1e-9, "margin {m} asked {margin}, room {room}");
            }
        }
    }

    /// `load_ratio` of a wrench on the object is, on the ellipsoid, the share of the pads' friction
    /// (`s = 2μN`, `k = 0.6 r`) its opposite takes at the pad's centre, recomputed by hand:
    /// `√(|f|²/s² + τ_c²/(s k)²)`; gravity's is `hold_ratio`; on the exact surface too, and there
    /// it grows linearly with the wrench.
    #[test]
    fn load_ratio_is_the_pads_share_of_the_wrench(b in block_case(), w in (-5.0f64..5.0, -5.0f64..5.0, -0.3f64..0.3), t in 0.1f64..3.0) {
        let w = Vec3::new(w.0, w.1, w.2);
        for (scene, exact) in [(scene_ellipsoid(&b), false), (scene(&b), true)] {
            let Some(scene) = scene else { continue };
            let q = b.pose;
            let hold = scene.hold_ratio(&q);
            prop_assert!((scene.load_ratio(&q, &scene.frame(&q).gravity) - hold).abs() <= 1e-12 * hold.max(1.0));
            let r = scene.load_ratio(&q, &w);
            prop_assert!((scene.load_ratio(&q, &(w * t)) - t * r).abs() <= 1e-9 * r.max(1e-9), "not linear: {r}");
            if !exact {
                let c = rot(q[2]).transpose() * -Vec2::new(q[0], q[1]); // pad centre, object frame
                let tau_c = w.z - (c.x * w.y - c.y * w.x);
                let (sf, k) = (2.0 * b.force * b.mu_s, 0.6 * b.pad);
                let want = ((w.x * w.x + w.y * w.y) / (sf * sf) + tau_c * tau_c / (sf * sf * k * k)).sqrt();
                prop_assert!((r - want).abs() <= 1e-9 * want.max(1e-9), "{r} vs {want}");
            }
        }
    }

    /// Rays from random wrenches inside W_p are feasible, with the pusher wrench along them.
    #[test]
    fn interior_rays_are_feasible(b in block_case(), w in proptest::collection::vec(0.01f64..1.0, 4)) {
        let Some(scene) = scene(&b) else { return Ok(()) };
        let push = scene.push(&b.pose, 0).unwrap();
        let p: Vec3 = push.pusher_edges().iter().zip(&w).map(|(e, x)| e.wrench * *x).sum();
        let v = push.ray(&p).unwrap();
        let c = push.classify(&v).unwrap();
        prop_assert!(c.feasible, "margin {}", c.margin);
        prop_assert!(angle(&c.pusher_wrench, &p) < 1e-6);
    }

    /// Projection returns a feasible twist no farther than any sampled feasible twist.
    #[test]
    fn projection_is_feasible_and_closest(b in block_case(), a1 in -3.2f64..3.2, a2 in -1.5f64..1.5) {
        let Some(scene) = scene(&b) else { return Ok(()) };
        let push = scene.push(&b.pose, 0).unwrap();
        let d = twist_from_angles(a1, a2, scene.length);
        let p = push.project(&d).unwrap();
        let dist = |x: &Vec3| push.twist_norm(&(d - x));
        if push.twist_norm(&p) > 0.0 {
            let c = push.classify(&p).unwrap();
            prop_assert!(c.margin > -1e-7, "projection infeasible: margin {}", c.margin);
        }
        let edges = push.pusher_edges();
        let mut rng = 0x9E3779B97F4A7C15u64;
        let mut next = || { rng ^= rng << 13; rng ^= rng >> 7; rng ^= rng << 17; (rng >> 11) as f64 / (1u64 << 53) as f64 };
        for _ in 0..300 {
            let wp: Vec3 = edges.iter().map(|e| e.wrench * next().powi(3)).sum();
            let Some(u) = push.ray(&wp) else { continue };
            let m = push.metric();
            let s = m.twist(&u).dot(&m.twist(&d)).max(0.0);
            prop_assert!(dist(&p) <= dist(&(u * s)) + RIPPLE * push.twist_norm(&d), "sampled ray closer: {} < {}", dist(&(u * s)), dist(&p));
        }
    }

    /// The projection's boundary ray is the best on the cone's boundary: against 2,000 exact
    /// rays evenly spaced along each boundary fan (brute force, no pruning, no local search),
    /// its cosine to the desired twist is never worse than a sampled ray's by more than
    /// [`RIPPLE`].
    #[test]
    fn projection_matches_a_dense_scan_of_the_boundary(b in block_case(), a1 in -3.2f64..3.2, a2 in -1.5f64..1.5) {
        let Some(scene) = scene(&b) else { return Ok(()) };
        let push = scene.push(&b.pose, 0).unwrap();
        let d = twist_from_angles(a1, a2, scene.length);
        if push.classify(&d).unwrap().feasible {
            return Ok(());
        }
        let m = push.metric();
        let ds = m.twist(&d).normalize();
        let p = push.project(&d).unwrap();
        let got = if p.amax() > 0.0 { m.twist(&p).normalize().dot(&ds) } else { 0.0 };
        let cone = push.pusher_cone();
        for (i, j) in cone.boundary_segments() {
            for k in 0..=2000 {
                let t = k as f64 / 2000.0;
                let w = m.wrench_inv(&(cone.edges[i] * (1.0 - t) + cone.edges[j] * t));
                let Some(u) = push.ray(&w) else { continue };
                let c = m.twist(&u).normalize().dot(&ds);
                prop_assert!(got >= c.min(1.0).max(0.0) - RIPPLE, "fan ({i}, {j}) at {t}: cosine {c} > the projection's {got}");
            }
        }
    }

    /// On the true limit surface too, every generator's pusher wrench lies on an edge of the
    /// pusher's friction cone and balances gravity with the support's load, and that load is the
    /// pad's friction integrated directly (not from the table) within the table's error.
    #[test]
    fn generators_balance_forces_on_the_true_surface(b in block_case()) {
        let Some(scene) = scene(&b) else { return Ok(()) };
        let push = scene.push(&b.pose, 0).unwrap();
        let gens = push.generators().unwrap();
        let spec = push.spec().clone();
        let exact = spec.exact.clone().expect("the true surface is the default");
        let js = spec.support_jacobian;
        let l = exact.length();
        for (g, e) in gens.iter().zip(push.pusher_edges()) {
            let c = push.classify(g).unwrap();
            prop_assert!(c.margin.abs() < 1e-7, "margin {}", c.margin);
            let ang = angle(&c.pusher_wrench, &e.wrench);
            prop_assert!(ang < 1e-6 || c.pusher_wrench.norm() < 1e-9 * spec.friction_scale, "edge angle {ang}");
            let direct = js.transpose() * exact.wrench_direct(&(js * g)) * spec.friction_scale;
            let d = js.try_inverse().unwrap().transpose() * (c.support_wrench - direct);
            let scaled = Vec3::new(d.x, d.y, d.z / l).norm() / spec.friction_scale;
            // (the pads are discs: their profile is within 1e-7 of the integral, tests/exact_surface.rs)
            prop_assert!(scaled < 1e-7, "load off the integrated surface by {scaled}");
            prop_assert!((c.support_wrench - c.pusher_wrench - spec.gravity).norm() < 1e-9 * spec.friction_scale);
        }
    }

    /// Without gravity the exact cone on the ellipsoid is the polyhedral cone (on the true
    /// surface the rays are still those of the gravity-free cone).
    #[test]
    fn zero_gravity_cone_is_polyhedral(mut b in block_case(), a1 in -3.2f64..3.2, a2 in -1.5f64..1.5) {
        b.g = 0.0;
        if let Some(scene) = scene(&b) {
            let push = scene.push(&b.pose, 0).unwrap();
            for (g, gf) in push.generators().unwrap().iter().zip(push.gravity_free_generators()) {
                prop_assert!(angle(g, &gf) < 1e-9);
            }
        }
        let Some(scene) = scene_ellipsoid(&b) else { return Ok(()) };
        let push = scene.push(&b.pose, 0).unwrap();
        for (g, gf) in push.generators().unwrap().iter().zip(push.gravity_free_generators()) {
            prop_assert!(angle(g, &gf) < 1e-9);
        }
        if b.line {
            let v = twist_from_angles(a1, a2, scene.length);
            let c = push.classify(&v).unwrap();
            let poly = push.polyhedral_cone().unwrap();
            let m = poly.membership(&scene.metric().twist(&v)).margin;
            if c.margin.abs() > 1e-7 && m.abs() > 1e-7 {
                prop_assert_eq!(c.feasible, m >= 0.0);
            }
        }
    }

    /// As the grip force grows the cone tends to the gravity-free cone, like 1/N (the cone
    /// depends on N only through ρ = μN/mg). Angles in the scaled twist metric.
    #[test]
    fn large_grip_force_tends_to_gravity_free(b in block_case()) {
        let Some(scene) = scene(&b) else { return Ok(()) };
        let metric = scene.metric();
        let sc = |v: &Vec3| metric.twist(v);
        let mut seq = Vec::new();
        for f in [1.0, 10.0, 100.0, 1000.0] {
            let s = scene.with_grip_force(b.force * f);
            let push = s.push(&b.pose, 0).unwrap();
            let worst = push.generators().unwrap().iter().zip(push.gravity_free_generators())
                .map(|(g, gf)| angle(&sc(g), &sc(&gf))).fold(0.0, f64::max);
            seq.push(worst);
        }
        prop_assert!(seq.windows(2).all(|w| w[1] <= w[0] * 1.0000001 + 1e-12), "not shrinking: {seq:?}");
        prop_assert!(seq[3] <= seq[2] * 0.2 + 1e-10, "not converging like 1/N: {seq:?}");
    }

    /// Results do not depend on where the object frame is put.
    #[test]
    fn invariant_under_change_of_object_frame(b in block_case(), tx in -0.05f64..0.05, tz in -0.05f64..0.05,
                                              phi in -3.0f64..3.0, a1 in -3.2f64..3.2, a2 in -1.5f64..1.5) {
        let raw = raw_scene(&b);
        let Ok(scene) = Scene::from_raw(raw.clone()) else { return Ok(()) };
        // new frame: p' = R_h p + t_h for every object-frame quantity
        let rh = rot(phi);
        let th = Vec2::new(tx, tz);
        let mv = |p: [f64; 2]| { let q = rh * Vec2::new(p[0], p[1]) + th; [q.x, q.y] };
        let mut raw2 = raw.clone();
        let obj = raw2.object.as_mut().unwrap();
        obj.outline = Some(obj.outline.as_ref().unwrap().iter().map(|p| mv(*p)).collect());
        obj.com = obj.com.map(mv);
        let pu = &mut raw2.pushers.as_mut().unwrap()[0];
        pu.points = Some(pu.points.as_ref().unwrap().iter().map(|p| mv(*p)).collect());
        let n = rh * Vec2::new(pu.normal.unwrap()[0], pu.normal.unwrap()[1]);
        pu.normal = Some([n.x, n.y]);
        // pose of the new frame: P' = P ∘ H⁻¹
        let q = b.pose;
        let r = rot(q[2]);
        let t2 = Vec2::new(q[0], q[1]) - r * rh.transpose() * th;
        let q2 = [t2.x, t2.y, q[2] - phi];
        let task = raw2.task.as_mut().unwrap();
        task.start = Some(q2);
        task.goal = Some(q2);
        let scene2 = Scene::from_raw(raw2).unwrap();
        let to2 = |v: &Vec3| { let l = rh * Vec2::new(v.x, v.y) - perp(&th) * v.z; Vec3::new(l.x, l.y, v.z) };
        let (p1, p2) = (scene.push(&q, 0).unwrap(), scene2.push(&q2, 0).unwrap());
        for (g1, g2) in p1.generators().unwrap().iter().zip(p2.generators().unwrap()) {
            prop_assert!(angle(&to2(g1), &g2) < 1e-7);
        }
        let v = twist_from_angles(a1, a2, scene.length);
        let (c1, c2) = (p1.classify(&v).unwrap(), p2.classify(&to2(&v)).unwrap());
        if c1.margin.abs() > 1e-6 {
            prop_assert_eq!(c1.feasible, c2.feasible);
        }
        // margins and projections are frame-invariant too (metrics about the centre of mass)
        prop_assert!((c1.margin - c2.margin).abs() < 1e-8, "margins {} vs {}", c1.margin, c2.margin);
        let (j1, j2) = (p1.project(&v).unwrap(), p2.project(&to2(&v)).unwrap());
        // the same distance to rounding; the same point to the search's tolerance (Brent's, 1e-6
        // of its bracket on a fan: near the peak the distance is flat, so two frames' rounding
        // can stop it 1e-6 apart with distances equal to 1e-16)
        let dist = |j: &Vec3| p2.twist_norm(&(j - to2(&v)));
        prop_assert!((dist(&to2(&j1)) - dist(&j2)).abs() < 1e-9 * (1.0 + p2.twist_norm(&to2(&v))), "distances differ");
        prop_assert!(p2.twist_norm(&(to2(&j1) - j2)) < 1e-5 * (1.0 + p2.twist_norm(&j2)), "projections differ");
    }

    /// Inside the grip-force range the twist sticks; outside it does not (line pushers).
    #[test]
    fn grip_force_range_is_tight(mut b in block_case(), a1 in -3.2f64..3.2, a2 in -1.5f64..1.5) {
        b.line = true;
        let Some(scene) = scene(&b) else { return Ok(()) };
        let push = scene.push_unchecked(&b.pose, 0).unwrap();
        let v = twist_from_angles(a1, a2, scene.length);
        let range = push.grip_force_range(&v).unwrap();
        let sticks = |f: f64| scene.with_grip_force(f).push(&b.pose, 0).map(|p| p.classify(&v).unwrap().feasible).unwrap_or(false);
        match range {
            Some(r) => {
                // inside by 0.1%, or by a quarter of a narrower range (a nearly frictionless
                // pusher's can be 2e-4 wide); its middle always
                let width = r.max / r.min - 1.0;
                let eps = 1e-3f64.min(0.25 * width);
                if r.max.is_finite() {
                    prop_assert!(sticks(0.5 * (r.min + r.max)));
                }
                if eps > 1e-9 {
                    // (no weight to hold: from any positive grip force)
                    let above_min = if r.min > 0.0 { r.min * (1.0 + eps) } else { 1e-3 };
                    prop_assert!(sticks(above_min));
                }
                prop_assert!(!sticks(r.min * 0.999));
                if r.max.is_finite() {
                    prop_assert!(eps <= 1e-9 || sticks(r.max * (1.0 - eps)));
                    prop_assert!(!sticks(r.max * 1.001));
                } else {
                    prop_assert!(sticks(r.min * 1e4));
                }
            }
            None => {
                for f in [1.0, 3.0, 10.0, 30.0, 100.0, 1000.0] {
                    prop_assert!(!sticks(f));
                }
            }
        }
    }
}

#[test]
fn zero_pusher_friction_collapses_the_cone() {
    let b = BlockCase {
        w: 0.05, h: 0.08, mass: 0.13, force: 20.0, mu_s: 0.6, pad: 0.007, mu_p: 0.0, face: 3, line: true,
        at: 0.0, gdir: 0.0, g: 9.81, pose: [0.0, 0.0, 0.0], com: [0.0, 0.0],
    };
    let scene = scene(&b).unwrap();
    let push = scene.push(&b.pose, 0).unwrap();
    let g = push.generators().unwrap();
    // the two edges of each contact point coincide: two distinct generators
    assert!(angle(&g[0], &g[1]) < 1e-12 && angle(&g[2], &g[3]) < 1e-12);
    assert!(!push.pusher_cone().is_solid());
    // a push straight along the normal needs friction to carry the weight: infeasible
    let c = push.classify(&Vec3::new(1.0, 0.0, 0.0)).unwrap();
    assert!(!c.feasible);
    // the cone has no interior: random twists are never inside it
    let mut inside = 0;
    for i in 0..2000 {
        let a = i as f64 * 0.618;
        let v = twist_from_angles(a * 7.0, (a * 3.0).sin() * 1.5, scene.length);
        if push.classify(&v).unwrap().feasible {
            inside += 1;
        }
    }
    assert_eq!(inside, 0);
    // with some friction, the same cone has an interior
    let b2 = BlockCase { mu_p: 0.3, ..b };
    let push2 = common::scene(&b2).unwrap().push(&b2.pose, 0).unwrap();
    assert!(push2.pusher_cone().is_solid());
}

#[test]
fn cannot_hold_is_an_error_not_a_nan() {
    let b = BlockCase {
        w: 0.05, h: 0.08, mass: 3.0, force: 20.0, mu_s: 0.6, pad: 0.007, mu_p: 0.3, face: 0, line: true,
        at: 0.0, gdir: 0.0, g: 9.81, pose: [0.0, 0.0, 0.0], com: [0.0, 0.0],
    };
    // 3 kg: the scene itself is rejected, naming grasp.force
    let err = Scene::from_raw(raw_scene(&b)).unwrap_err();
    assert!(err.to_string().contains("grasp.force"), "{err}");
    // a scene that holds at its start but not with a weaker grip
    let ok = BlockCase { mass: 0.13, ..b };
    let s = scene(&ok).unwrap().with_grip_force(0.5);
    let e = s.push(&ok.pose, 0).unwrap_err();
    assert!(matches!(e, regrasp::Error::GraspCannotHold { .. }), "{e}");
    // unchecked: gravity-free cone and grip-force range still work, and are finite
    let p = s.push_unchecked(&ok.pose, 0).unwrap();
    assert!(p.gravity_free_generators().iter().all(|g| g.iter().all(|x| x.is_finite())));
    assert!(p.classify(&Vec3::new(0.0, 1.0, 0.0)).is_err());
    let r = p.grip_force_range(&Vec3::new(0.0, 1.0, 0.0)).unwrap().unwrap();
    assert!(r.min > 0.5 && r.min.is_finite());
}

/// The exact test agrees with an LP over contact forces built from the raw scene values, on
/// 3000 random scenes, poses and twists (twists drawn near the cone half of the time), with
/// both outcomes well represented.
#[test]
fn exact_test_matches_brute_force_lp() {
    exact_test_matches_lp(false);
}

/// The same on the true limit surface, against the pad's friction integrated directly; twists
/// whose margin is within the table's error (1e-3) are left out.
#[test]
fn exact_test_on_the_true_surface_matches_brute_force_lp() {
    exact_test_matches_lp(true);
}

fn exact_test_matches_lp(exact: bool) {
    use proptest::strategy::ValueTree;
    use proptest::test_runner::TestRunner;
    let mut runner = TestRunner::deterministic();
    let strat = (block_case(), -3.2f64..3.2, -1.5f64..1.5, proptest::collection::vec(0.0f64..1.0, 4), any::<bool>());
    let (mut checked, mut disagree) = ([0usize; 2], Vec::new());
    let mut inside = [0usize; 2];
    for _ in 0..3000 {
        let (b, a1, a2, w, near) = strat.new_tree(&mut runner).unwrap().current();
        let raw = if exact { raw_scene(&b) } else { raw_scene_ellipsoid(&b) };
        let Ok(scene) = Scene::from_raw(raw.clone()) else { continue };
        let push = scene.push(&b.pose, 0).unwrap();
        let mut v = twist_from_angles(a1, a2, scene.length);
        let kind = b.line as usize;
        if near {
            if b.line {
                // a ray of the cone plus a perturbation of ~20% of its size
                let p: Vec3 = push.pusher_edges().iter().zip(&w).map(|(e, x)| e.wrench * *x).sum();
                if let Some(r) = push.ray(&p) {
                    v = r + v * 0.2;
                }
            } else {
                // a point pusher: the twist its contact point's motion produces
                let u = regrasp::mechanics::geometry::Vec2::new(a1.cos(), a1.sin());
                if let Some(t) = push.point_pusher_twist(&u, push.spec().friction_scale) {
                    v = t;
                }
            }
        }
        let c = push.classify(&v).unwrap();
        if c.margin.abs() < if exact { 1e-3 } else { 1e-6 } {
            continue;
        }
        checked[kind] += 1;
        inside[kind] += c.feasible as usize;
        if c.feasible != brute_force_sticks_on(&raw, &b.pose, &v, exact) {
            disagree.push((b, v, c.margin));
        }
    }
    assert!(disagree.is_empty(), "{} disagreements, first: {:?}", disagree.len(), disagree.first());
    // [point, line]: enough cases of each kind, feasible and not
    assert!(checked[0] > 500 && checked[1] > 1000, "checked {checked:?}");
    assert!(inside[1] > 200 && checked[1] - inside[1] > 200, "line pushers: inside {inside:?} of {checked:?}");
    assert!(inside[0] > 100 && checked[0] - inside[0] > 100, "point pushers: inside {inside:?} of {checked:?}");
}

/// A μ 0.05 side pusher on the block of the low-friction diagonal: the mean of its cone's rays
/// lies far outside the cone (gravity bends it), yet the projection keeps the margin asked.
#[test]
fn a_thin_bent_cone_still_gives_a_margin() {
    let s = Scene::from_toml_str(include_str!("../../../python/regrasp/examples/hard/diagonal-mu005.toml")).unwrap();
    let q = [0.02, 0.0265, 0.0];
    let frame = s.frame(&q);
    let want = Vec3::new(-0.04, -0.053, 0.0); // the diagonal to the goal
    for p in [1, 2] {
        let model = &s.pushers[p].model;
        let gens = regrasp::cones::robust::generators(&frame, model);
        let mean: Vec3 = gens.iter().sum();
        assert!(frame.classify(model, &mean).margin < -0.1, "pusher {p}: the mean of the rays is outside");
        let v = regrasp::cones::motion_cone::project_with_margin(&frame, model, &want, 0.01).unwrap();
        assert!(frame.classify(model, &v).margin >= 0.01 - 1e-12, "pusher {p}");
    }
}

fn low_friction_block() -> Scene {
    Scene::from_toml_str(include_str!("../../../examples/block-low-friction.toml")).unwrap()
}

/// A frictionless line pusher is still a line pusher: its grip-force range is an exact
/// interval (here a single force: the plane of its fan must contain the required wrench).
#[test]
fn frictionless_line_pusher_grip_range_matches_a_scan() {
    let text = include_str!("../../../examples/block-low-friction.toml").replace("friction = 0.25", "friction = 0.0");
    let scene = Scene::from_toml_str(&text).unwrap();
    let i = scene.pusher_index("bottom").unwrap();
    let q = [0.002, -0.003, 0.1];
    let push = scene.push_unchecked(&q, i).unwrap();
    // a twist from a feasible pusher wrench at 9 N per finger
    let s9 = scene.with_grip_force(9.0);
    let p9 = s9.push(&q, i).unwrap();
    let w: Vec3 = p9.pusher_edges().iter().map(|e| e.wrench).sum::<Vec3>() * 0.5;
    let v = p9.ray(&w).unwrap();
    assert!(p9.classify(&v).unwrap().feasible);
    let r = push.grip_force_range(&v).unwrap().expect("the twist sticks at 9 N");
    assert!((r.min - 9.0).abs() < 1e-6 && (r.max - 9.0).abs() < 1e-6, "{r:?}");
    for f in [5.0, 8.9, 9.1, 20.0] {
        assert!(!scene.with_grip_force(f).push(&q, i).unwrap().classify(&v).unwrap().feasible, "{f} N");
    }
}

/// Only the direction of a twist matters, however large or small its numbers.
#[test]
fn huge_and_tiny_twists_give_the_same_answers() {
    let scene = low_friction_block();
    for name in ["bottom", "left"] {
        let push = scene.push(&[0.003, 0.002, 0.2], scene.pusher_index(name).unwrap()).unwrap();
        for v in [Vec3::new(0.0, 0.0, 1.0), Vec3::new(1.0, 1.0, 0.0), Vec3::new(0.01, 0.002, -0.3), Vec3::new(0.0, 1.0, 0.0)] {
            let c = push.classify(&v).unwrap();
            for k in [1e160, 1e-200] {
                let ck = push.classify(&(v * k)).unwrap();
                assert_eq!(c.feasible, ck.feasible, "{name} {v:?} x {k}");
                assert!((c.margin - ck.margin).abs() < 1e-12);
                let (p, pk) = (push.project(&v).unwrap(), push.project(&(v * k)).unwrap());
                assert!((pk / k - p).amax() <= 1e-6 * p.amax().max(1e-300), "projection of {v:?} x {k}");
            }
        }
    }
}

/// A grip too weak or too strong to represent is an error, never NaN.
#[test]
fn absurd_grip_forces_are_errors() {
    let scene = low_friction_block();
    let i = scene.pusher_index("left").unwrap();
    for f in [1e-300, 1e-30] {
        assert!(scene.with_grip_force(f).push(&[0.0, 0.0, 0.0], i).is_err(), "{f}");
    }
    let text = include_str!("../../../examples/block-low-friction.toml").replace("force = 20.0", "force = 1e300");
    let e = Scene::from_toml_str(&text).unwrap_err();
    assert!(e.to_string().contains("grasp.force"), "{e}");
}


