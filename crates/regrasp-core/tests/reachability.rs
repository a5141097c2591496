//! Infeasibility certificates (`planning::reachability`) against a brute-force flood fill of the
//! pad centres where the whole pad lies on the object, and never on a reachable task.

mod common;

use common::{outline_scene, pad_pose, star};
use proptest::prelude::*;
use regrasp::mechanics::geometry::Vec2;
use regrasp::planning::planar::{plan, PlanarSettings, StopReason};
use regrasp::planning::reachability::{blocked, one_way, unreachable};
use regrasp::Scene;
use std::time::Instant;

const TOL: [f64; 3] = [1e-3, 1e-3, 0.0175];

/// A scene of `outline` (CCW) held by a disc pad of radius `pad`, the pad centre at `at` for the
/// task's start and goal; one line pusher on the first edge.
fn scene(outline: Vec<[f64; 2]>, pad: f64, at: [f64; 2]) -> Scene {
    try_scene(outline, pad, at).unwrap()
}

/// [`scene`], or None when the loader refuses it (the pad off the object at `at`).
fn try_scene(outline: Vec<[f64; 2]>, pad: f64, at: [f64; 2]) -> Option<Scene> {
    outline_scene(outline, pad, at, at)
}

/// Two 30 × 30 mm lobes joined by a neck `neck` [m] wide and 20 mm long.
fn dumbbell(neck: f64) -> Vec<[f64; 2]> {
    let n = neck / 2.0;
    vec![
        [-0.04, -0.015], [-0.01, -0.015], [-0.01, -n], [0.01, -n], [0.01, -0.015], [0.04, -0.015],
        [0.04, 0.015], [0.01, 0.015], [0.01, n], [-0.01, n], [-0.01, 0.015], [-0.04, 0.015],
    ]
}

/// Brute force: whether pad centres `a` and `b` are joined through the grid (spacing `h` [m]) of
/// the centres where the pad fits (signed distance ≥ its radius).
fn connected(s: &Scene, r: f64, a: Vec2, b: Vec2, h: f64) -> bool {
    let v = s.outline.vertices();
    let (lo, hi) = v.iter().fold((v[0], v[0]), |(l, u), p| (l.inf(p), u.sup(p)));
    let (nx, nz) = (((hi.x - lo.x) / h) as usize + 1, ((hi.y - lo.y) / h) as usize + 1);
    let fits = |i: usize, j: usize| s.outline.signed_distance(&Vec2::new(lo.x + i as f64 * h, lo.y + j as f64 * h)) >= r;
    let cell = |p: Vec2| (((p.x - lo.x) / h).round() as usize, ((p.y - lo.y) / h).round() as usize);
    let (start, goal) = (cell(a), cell(b));
    let mut seen = vec![false; nx * nz];
    let mut stack = vec![start];
    while let Some((i, j)) = stack.pop() {
        if (i, j) == goal {
            return true;
        }
        if i >= nx || j >= nz || seen[i * nz + j] || !fits(i, j) {
            continue;
        }
        seen[i * nz + j] = true;
        stack.extend([(i + 1, j), (i.wrapping_sub(1), j), (i, j + 1), (i, j.wrapping_sub(1))]);
    }
    false
}

#[test]
fn a_neck_narrower_than_the_pad_is_unreachable_at_once() {
    let (pad, a, b) = (0.006, [-0.025, 0.0], [0.025, 0.0]);
    let s = scene(dumbbell(0.008), pad, a);
    assert!(!connected(&s, pad, Vec2::new(a[0], a[1]), Vec2::new(b[0], b[1]), 2e-4));
    let t0 = Instant::now();
    let r = plan(&s, None, Some(pad_pose(b[0], b[1], 0.3)), &PlanarSettings::default()).unwrap();
    assert!(t0.elapsed().as_secs_f64() < 1.0);
    assert!(!r.found && r.stop_reason == StopReason::Unreachable && r.path.len() == 1);
    let why = r.reason.unwrap();
    assert!(why.contains("different parts") && why.contains("12.00 mm across"), "{why}");
}

#[test]
fn a_densely_sampled_outline_is_simplified_before_it_is_eroded() {
    // the dumbbell's edges cut into 9,600 vertices (the buffer alone would take seconds): the
    // simplified outline decides it the same
    let d = dumbbell(0.008);
    let mut dense = vec![];
    for (i, a) in d.iter().enumerate() {
        let b = d[(i + 1) % d.len()];
        dense.extend((0..800).map(|k| {
            let t = k as f64 / 800.0;
            [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]
        }));
    }
    let (a, b) = ([-0.025, 0.0], [0.025, 0.0]);
    let s = scene(dense, 0.006, a);
    assert!(unreachable(&s, &pad_pose(a[0], a[1], 0.0), &pad_pose(b[0], b[1], 0.0), &TOL).is_some());
}

#[test]
fn a_neck_wider_than_the_pad_is_left_to_the_search() {
    let (pad, a, b) = (0.006, [-0.025, 0.0], [0.025, 0.0]);
    let s = scene(dumbbell(0.016), pad, a);
    assert!(connected(&s, pad, Vec2::new(a[0], a[1]), Vec2::new(b[0], b[1]), 2e-4));
    assert_eq!(unreachable(&s, &pad_pose(a[0], a[1], 0.0), &pad_pose(b[0], b[1], 0.0), &TOL), None);
    // exactly as wide as the pad: the pad passes (touching both sides), so it must not be refused
    let s = scene(dumbbell(0.012), pad, a);
    assert_eq!(unreachable(&s, &pad_pose(a[0], a[1], 0.0), &pad_pose(b[0], b[1], 0.0), &TOL), None);
}

#[test]
fn a_goal_within_tolerance_of_the_start_part_is_not_refused() {
    // the goal's pad centre just across a thin wall, within the tolerance's reach of the start's part
    let (pad, a) = (0.006, [-0.025, 0.0]);
    let s = scene(dumbbell(0.008), pad, a);
    let goal = pad_pose(-0.0095, 0.0, 0.0); // in the neck, 2.3 mm off the start's part as eroded
    let start = pad_pose(a[0], a[1], 0.0);
    assert_eq!(unreachable(&s, &start, &goal, &[1.7e-3, 1.7e-3, 0.0]), None); // reaches 2.40 mm
    assert!(unreachable(&s, &start, &goal, &[1.5e-3, 1.5e-3, 0.0]).is_some()); // reaches 2.12 mm
}

/// The low-friction block held by a weak grip (3.6 N): it holds the task's poses, not a pad far
/// from the centre of mass.
fn weak_block() -> Scene {
    let text = include_str!("../../../examples/block-low-friction.toml").replace("force = 20.0", "force = 3.6");
    Scene::from_toml_str(&text).unwrap()
}

/// Brute force: whether some pose of a 21³ grid of the goal's box holds.
fn holds_somewhere(s: &Scene, goal: &[f64; 3], tol: &[f64; 3]) -> bool {
    let at = |k: usize, i: usize| goal[k] + tol[k] * (i as f64 / 10.0 - 1.0);
    (0..21).any(|i| (0..21).any(|j| (0..21).any(|k| s.hold_ratio(&[at(0, i), at(1, j), at(2, k)]) < 1.0)))
}

#[test]
fn a_goal_the_grasp_cannot_hold_is_unreachable_at_once() {
    let s = weak_block();
    let goal = [0.0175, 0.0, 0.0];
    assert!(s.hold_ratio(&goal) > 1.0 && !holds_somewhere(&s, &goal, &TOL));
    let t0 = Instant::now();
    let r = plan(&s, None, Some(goal), &PlanarSettings::default()).unwrap();
    assert!(t0.elapsed().as_secs_f64() < 1.0);
    assert!(!r.found && r.stop_reason == StopReason::Unreachable && r.path.len() == 1);
    let why = r.reason.unwrap();
    assert!(why.contains("cannot hold") && why.contains("tolerance"), "{why}");
    // of the goals on a 9 x 9 grid over the block (1 mm, 1°) whose boxes hold nowhere, the
    // certificate refuses nearly all (it leaves to the search only those near the limit)
    let (mut nowhere, mut refused) = (0, 0);
    for i in 0..9 {
        for j in 0..9 {
            let g = [-0.018 + 0.0045 * i as f64, -0.033 + 0.00825 * j as f64, 0.0];
            if s.admissible(&g) && !holds_somewhere(&s, &g, &TOL) {
                nowhere += 1;
                refused += regrasp::planning::reachability::cannot_hold(&s, &g, &TOL).is_some() as usize;
            }
        }
    }
    assert!(nowhere >= 10 && 10 * refused >= 9 * nowhere, "{refused} of {nowhere} refused");
    // a start the grasp cannot hold is a bad request, not a question for the planner
    assert!(plan(&s, Some(goal), None, &PlanarSettings::default()).is_err());
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]
    /// On the weak grip, across the block: a goal declared unreachable for holding has no
    /// holding pose in its tolerance box (21³ grid).
    #[test]
    fn a_goal_refused_for_holding_holds_nowhere(x in -0.02f64..0.02, z in -0.03f64..0.03, th in -1.0f64..1.0, t in 0.0005f64..0.004) {
        let s = weak_block();
        let (goal, tol) = ([x, z, th], [t, t, 10.0 * t]);
        prop_assume!(s.admissible(&goal));
        let refused = regrasp::planning::reachability::cannot_hold(&s, &goal, &tol).is_some();
        let holds = holds_somewhere(&s, &goal, &tol);
        prop_assert!(!(refused && holds), "refused a goal whose box holds somewhere");
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(250))]
    /// A goal that a chain of short admissible pad moves reaches from the start is never declared
    /// unreachable (random star-shaped outlines, pads, walks and turns).
    #[test]
    fn a_reachable_goal_is_never_declared_unreachable(
        radii in prop::collection::vec(0.01f64..0.04, 5..150),
        pad in 0.001f64..0.006,
        walk in prop::collection::vec((-1.0f64..1.0, -1.0f64..1.0), 1..60),
        turns in (-3.0f64..3.0, -3.0f64..3.0),
    ) {
        let outline = star(&radii);
        let probe = try_scene(outline, pad, [0.0, 0.0]);
        prop_assume!(probe.is_some());
        let s = probe.unwrap();
        let fits = |c: Vec2| s.outline.signed_distance(&c) >= pad;
        let mut c = Vec2::new(0.0, 0.0);
        prop_assume!(fits(c));
        let start = c;
        for (dx, dz) in walk {
            let next = c + Vec2::new(dx, dz) * 0.002;
            // the whole move admissible (sampled every 0.1 mm)
            if (0..=20).all(|k| fits(c + (next - c) * (k as f64 / 20.0))) {
                c = next;
            }
        }
        let q0 = pad_pose(start.x, start.y, turns.0);
        let q1 = pad_pose(c.x, c.y, turns.1);
        prop_assert_eq!(unreachable(&s, &q0, &q1, &[1e-4, 1e-4, 1e-3]), None);
    }
}

/// The low-friction block with only its top pusher (it pushes down): the object can only move
/// down in the grasp, so the pad's centre only up in the object's frame.
fn top_only() -> Scene {
    let text = include_str!("../../../examples/block-low-friction.toml");
    let kept: String = text
        .split("[[pushers]]")
        .enumerate()
        .filter(|(i, p)| *i == 0 || p.contains("name = \"top\""))
        .map(|(i, p)| if i == 0 { p.to_string() } else { format!("[[pushers]]{p}") })
        .collect();
    let s = Scene::from_toml_str(&kept).unwrap();
    assert_eq!(s.pushers.len(), 1);
    s
}

#[test]
fn a_goal_no_push_can_move_towards_is_unreachable_at_once() {
    let s = top_only();
    let t0 = Instant::now();
    let r = plan(&s, None, Some([0.0, 0.01, 0.0]), &PlanarSettings::default()).unwrap(); // the object 10 mm up
    assert!(t0.elapsed().as_secs_f64() < 1.0);
    assert!(!r.found && r.stop_reason == StopReason::Unreachable && r.path.len() == 1, "{r:?}");
    let why = r.reason.unwrap();
    assert!(why.contains("no push can move the pad's centre") && why.contains("10.00 mm"), "{why}");
    // down is the pusher's way: left to the search, which finds it
    let r = plan(&s, None, Some([0.0, -0.01, 0.0]), &PlanarSettings::default()).unwrap();
    assert!(r.found, "{r:?}");
    // sideways by less than the friction cone's bend allows is not decided either
    let turn = [-0.5, 0.5];
    assert_eq!(one_way(&s, &[0.0; 3], &[0.005, -0.01, 0.0], &TOL, turn), None);
    // every pusher of the example together: nothing blocked
    let all = Scene::from_toml_str(include_str!("../../../examples/block-low-friction.toml")).unwrap();
    assert_eq!(blocked(&all, turn), None);
}

/// Brute force for [`blocked`]: at random poses within the turn range, the pad's centre moved by
/// a short step along random non-negative combinations of each pusher's motion-cone generators
/// (the planner's own model) never has a component along a blocked direction.
fn check_blocked(s: &Scene, turn: [f64; 2], mid: f64, half: f64, rng: &mut impl rand::Rng) -> Result<usize, TestCaseError> {
    let ends = [Vec2::new((mid - half).cos(), (mid - half).sin()), Vec2::new((mid + half).cos(), (mid + half).sin())];
    let pad = |q: &[f64; 3]| s.pad_disc(q).unwrap().0;
    let mut moves = 0;
    for _ in 0..20 {
        let th = turn[0] + (turn[1] - turn[0]) * rng.random::<f64>();
        let q = pad_pose(0.01 * (rng.random::<f64>() - 0.5), 0.01 * (rng.random::<f64>() - 0.5), th);
        for p in 0..s.pushers.len() {
            let Ok(push) = s.push(&q, p) else { continue };
            let Ok(gens) = push.generators() else { continue };
            for _ in 0..4 {
                let tw = gens.iter().fold(regrasp::mechanics::geometry::Vec3::zeros(), |a, g| a + g * rng.random::<f64>());
                let step = tw * (1e-4 / tw.norm().max(1e-12));
                let u = pad(&regrasp::pose::planar::integrate(&q, &step, 1.0)) - pad(&q);
                for d in &ends {
                    prop_assert!(d.dot(&u) <= 1e-9 * (1.0 + u.norm()) + 1e-12, "pad moved {:?} along blocked {:?}", u, d);
                }
                moves += 1;
            }
        }
    }
    Ok(moves)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]
    /// On random blocks with one pusher (any face, line or point, any friction and gravity), the
    /// blocked directions are never moved along by the motion cones at any turn of the range.
    #[test]
    fn blocked_directions_are_never_moved_along(b in common::block_case(), seed in 0u64..1000) {
        let s = common::scene(&b);
        prop_assume!(s.is_some());
        let s = s.unwrap();
        let turn = [b.pose[2] - 0.5, b.pose[2] + 0.5];
        let Some((mid, half)) = blocked(&s, turn) else { return Ok(()) };
        prop_assert!(half > 0.0 && half <= std::f64::consts::FRAC_PI_2);
        let mut rng = <rand_chacha::ChaCha8Rng as rand::SeedableRng>::seed_from_u64(seed);
        check_blocked(&s, turn, mid, half, &mut rng)?;
    }
}

#[test]
fn one_pusher_blocks_directions_on_most_random_blocks() {
    // the property above is not vacuous: one pusher of friction < 1 with gravity over a turn
    // range of 1 rad leaves blocked directions on many blocks, whose cones move the pad
    use proptest::strategy::ValueTree;
    let mut runner = proptest::test_runner::TestRunner::deterministic();
    let (mut scenes, mut some, mut moves) = (0, 0, 0);
    let mut rng = <rand_chacha::ChaCha8Rng as rand::SeedableRng>::seed_from_u64(7);
    for _ in 0..300 {
        let b = common::block_case().new_tree(&mut runner).unwrap().current();
        let Some(s) = common::scene(&b) else { continue };
        scenes += 1;
        let turn = [b.pose[2] - 0.5, b.pose[2] + 0.5];
        if let Some((mid, half)) = blocked(&s, turn) {
            some += 1;
            moves += check_blocked(&s, turn, mid, half, &mut rng).unwrap();
        }
    }
    assert!(scenes >= 100 && 4 * some >= scenes && moves >= 1000, "{some} of {scenes} blocked, {moves} moves checked");
}

#[test]
fn the_bundled_one_way_scene_is_unreachable_and_its_full_example_is_not() {
    let s = Scene::from_toml_str(include_str!("../../../python/regrasp/examples/hard/one-way-unreachable.toml")).unwrap();
    let t0 = Instant::now();
    let r = plan(&s, None, None, &PlanarSettings::default()).unwrap();
    assert!(t0.elapsed().as_secs_f64() < 1.0 && r.stop_reason == StopReason::Unreachable, "{r:?}");
    assert!(r.reason.unwrap().contains("no push can move the pad's centre"));
    // with the bottom and left pushers too (the bundled example), the same task is planned
    let full = Scene::from_toml_str(include_str!("../../../examples/block-low-friction.toml")).unwrap();
    assert!(plan(&full, None, None, &PlanarSettings::default()).unwrap().found);
    // and with the left pusher alone added, nothing is blocked any more
    let text = include_str!("../../../python/regrasp/examples/hard/one-way-unreachable.toml").replace(
        "[[pushers]]\nname = \"top\"",
        "[[pushers]]\nname = \"left\"\nfriction = 0.25\npoints = [[-0.025, -0.03], [-0.025, 0.03]]\nnormal = [1.0, 0.0]\n\n[[pushers]]\nname = \"top\"",
    );
    let three = Scene::from_toml_str(&text).unwrap();
    assert_eq!(three.pushers.len(), 3);
    let (start, goal, tol) = (s.task.unwrap().start, s.task.unwrap().goal, s.task.unwrap().tolerance);
    assert_eq!(one_way(&three, &start, &goal, &tol, [-0.5, 0.5]), None);
}

/// The 3-D block held by a weak grip (`force` N per finger).
fn weak_block3(force: f64) -> regrasp::scene::spatial::Scene3 {
    let text = include_str!("../../../python/regrasp/examples/block-3d.toml").replace("force = 20.0", &format!("force = {force}"));
    regrasp::scene::spatial::Scene3::from_toml_str(&text, None).unwrap()
}

#[test]
fn a_3d_goal_the_pads_cannot_hold_is_unreachable_at_once() {
    use nalgebra::{Isometry3, UnitQuaternion, Vector3};
    use regrasp::planning::reachability::{cannot_hold3, hold_ratio3};
    use regrasp::planning::spatial::{plan3, SpatialSettings};
    let s = weak_block3(2.0);
    // independent: with the centre of mass on the pads' axis the weight is a pure force, carried
    // by both pads' discs at once, m g / (2 μ N)
    let pure = s.mass * 9.81 / (2.0 * 0.6 * 2.0);
    let start = hold_ratio3(&s, &Isometry3::identity()).unwrap();
    assert!((start - pure).abs() < 2e-3 * pure, "{start} vs {pure}");
    // 18 mm off the centre of mass the weight's moment is too much for 2 N
    let goal = Isometry3::translation(0.018, 0.0, 0.0);
    let t0 = Instant::now();
    let r = plan3(&s, None, Some(goal), &SpatialSettings::default()).unwrap().plan;
    assert!(t0.elapsed().as_secs_f64() < 1.0);
    assert!(!r.found && r.stop_reason == StopReason::Unreachable && r.path.len() == 1, "{:?}", r.stop_reason);
    assert!(r.reason.unwrap().contains("cannot hold"));
    // brute force: no pose of a finer grid of the tolerance region holds (5³ translations, the
    // rotation turned about 6 axes by 0.5 and 1 times the angle)
    let tol = s.tolerance;
    let mut turns = vec![UnitQuaternion::identity()];
    for axis in [Vector3::x(), Vector3::y(), Vector3::z(), Vector3::new(1.0, 1.0, 0.0), Vector3::new(0.0, 1.0, 1.0), Vector3::new(1.0, 0.0, 1.0)] {
        for k in [-1.0, -0.5, 0.5, 1.0] {
            turns.push(UnitQuaternion::from_scaled_axis(axis.normalize() * (k * tol[3])));
        }
    }
    for turn in &turns {
        for c in 0..125 {
            let d = Vector3::new((c % 5) as f64 / 2.0 - 1.0, ((c / 5) % 5) as f64 / 2.0 - 1.0, (c / 25) as f64 / 2.0 - 1.0);
            let at = Isometry3::from_parts((goal.translation.vector + d.component_mul(&Vector3::new(tol[0], tol[1], tol[2]))).into(), *turn * goal.rotation);
            assert!(hold_ratio3(&s, &at).is_none_or(|h| h >= 1.0), "{at:?} holds");
        }
    }
    // a goal that holds is left to the search, and the strong grip holds the same goal
    assert_eq!(cannot_hold3(&s, &Isometry3::identity(), &Isometry3::translation(0.0, 0.0, 0.01), &tol), None);
    let strong = weak_block3(20.0);
    assert_eq!(cannot_hold3(&strong, &Isometry3::identity(), &goal, &tol), None);
    // a start that cannot hold either: not the certificate's question
    assert_eq!(cannot_hold3(&weak_block3(1.0), &Isometry3::identity(), &goal, &tol), None);
    // near the limit: where the ratio crosses 1 along x, a goal 0.5 mm beyond it (its box reaches
    // back over the limit: some pose there holds) is left to the search; 3 mm beyond is refused
    let x1 = (0..400).map(|i| i as f64 * 5e-5).find(|&x| hold_ratio3(&s, &Isometry3::translation(x, 0.0, 0.0)).unwrap() >= 1.0).unwrap();
    let near = Isometry3::translation(x1 + 5e-4, 0.0, 0.0);
    assert!(hold_ratio3(&s, &near).unwrap() > 1.0 && hold_ratio3(&s, &Isometry3::translation(x1 - 5e-4, 0.0, 0.0)).unwrap() < 1.0);
    assert_eq!(cannot_hold3(&s, &Isometry3::identity(), &near, &tol), None);
    assert!(cannot_hold3(&s, &Isometry3::identity(), &Isometry3::translation(x1 + 3e-3, 0.0, 0.0), &tol).is_some());
}
