//! Point pushers in the planar planner (issue 18, item 1): every plan's step is the object's
//! flow under the pusher's motion, sticking all along and landing on the next pose.

use regrasp::planning::planar::{plan, validate_path, PlanarSettings};
use regrasp::planning::point_step;
use regrasp::planning::trrt::SearchSettings;
use regrasp::scene::Scene;

fn hard(name: &str) -> Scene {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../python/regrasp/examples/hard").join(name);
    Scene::load(&path).unwrap()
}

#[test]
fn point_pushers_only_scene_is_planned_and_every_step_lands() {
    let s = hard("point-pushers.toml");
    for seed in 0..5 {
        let settings = PlanarSettings { search: SearchSettings { seed, time_limit: 10.0, ..SearchSettings::default() }, ..PlanarSettings::default() };
        let r = plan(&s, None, None, &settings).unwrap();
        assert!(r.found, "seed {seed}: {:?} after {} iterations", r.stop_reason, r.iterations);
        let margins = validate_path(&s, &r.poses(), 64).unwrap();
        assert!(margins.iter().all(|m| *m >= -1e-9), "seed {seed}: {margins:?}");
    }
}

/// A step of a point pusher lands where its flow ends: the flow integrated with 16 and with 256
/// RK4 steps (per tenth of L) ends within the landing tolerance, and the steered pusher twist's flow lands on
/// `a·exp(ξ)`; the object's contact point stays on the pusher's all along (sticking).
#[test]
fn steered_steps_land_and_the_contact_sticks() {
    use regrasp::mechanics::geometry::{rot, Vec2};
    use regrasp::pose::planar::{distance, integrate};
    let s = hard("point-pushers.toml");
    let a = [0.004, 0.002, 0.02];
    let mut steered = 0;
    for p in 0..4 {
        let r = point_step::contact_point(&s, p).unwrap();
        for k in 0..16 {
            let ang = k as f64 * std::f64::consts::PI / 8.0;
            let ub = Vec2::new(ang.cos(), ang.sin()) * 0.002;
            let Some((xi, fl)) = point_step::steer(&s, p, &a, &ub, 16) else { continue };
            steered += 1;
            let b = integrate(&a, &xi, 1.0);
            assert!(distance(s.length, &fl.end(), &b) <= point_step::LANDING_TOL * s.length);
            let fine = point_step::flow(&s, p, &a, &xi, 256).unwrap();
            assert!(distance(s.length, &fine.end(), &b) <= point_step::LANDING_TOL * s.length, "pusher {p} direction {k}");
            // the contact point in the grasp frame: the object's and the pusher's (constant twist)
            let m = (fine.poses.len() - 1) as f64;
            for (i, q) in fine.poses.iter().enumerate() {
                let pusher = integrate(&a, &xi, i as f64 / m);
                let (po, pp) = (rot(q[2]) * r + Vec2::new(q[0], q[1]), rot(pusher[2]) * r + Vec2::new(pusher[0], pusher[1]));
                assert!((po - pp).norm() < 1e-9, "pusher {p} direction {k}: the contact slides {:.2e} m", (po - pp).norm());
            }
        }
    }
    assert!(steered >= 16, "only {steered} of 64 contact directions steered");
}



proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig { cases: 200, ..Default::default() })]
    /// `SupportFrame::point_twist`: the object's contact point moves with the velocity asked for,
    /// and the pusher wrench the twist needs passes through the contact (no moment about it), at
    /// random admissible poses and contact velocities.
    #[test]
    fn point_twist_moves_the_contact_as_asked_and_needs_no_moment(
        x in -0.01f64..0.01, z in -0.02f64..0.02, th in -0.5f64..0.5, p in 0usize..4, ang in 0.0f64..6.283, speed in 1e-4f64..0.05,
    ) {
        use regrasp::mechanics::geometry::{cross2, perp, Vec2};
        let s = hard("point-pushers.toml");
        let q = [x, z, th];
        proptest::prop_assume!(s.admissible(&q));
        let f = s.frame(&q);
        proptest::prop_assume!(f.hold_ratio < 1.0);
        let r = point_step::contact_point(&s, p).unwrap();
        let u = Vec2::new(ang.cos(), ang.sin()) * speed;
        if let Some(v) = f.point_twist(&r, &u, s.length) {
            proptest::prop_assert!(v.iter().all(|c| c.is_finite()));
            let c = Vec2::new(v.x, v.y) + perp(&r) * v.z;
            proptest::prop_assert!((c - u).norm() <= 1e-9 * speed, "contact velocity {c:?} vs {u:?}");
            let w = f.support_load(&v) - f.gravity;
            let moment = w.z - cross2(&r, &Vec2::new(w.x, w.y));
            proptest::prop_assert!(moment.abs() <= 1e-9 * (w.norm() * s.length + w.z.abs()), "moment {moment:e} about the contact");
        }
    }
}
