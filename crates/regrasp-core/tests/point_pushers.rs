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
        let settings = PlanarSettings { search: SearchSettings { seed, time_limit: 3.0, ..SearchSettings::default() }, ..PlanarSettings::default() };
        let t = std::time::Instant::now();
        let r = plan(&s, None, None, &settings).unwrap();
        eprintln!("seed {seed}: found {} in {:.1} ms, {} nodes, {} steps, {} switch-overs", r.found, t.elapsed().as_secs_f64() * 1e3, r.nodes, r.path.len() - 1, r.switch_overs);
        assert!(r.found, "seed {seed}: {:?} after {} iterations", r.stop_reason, r.iterations);
        let margins = validate_path(&s, &r.poses(), 64).unwrap();
        assert!(margins.iter().all(|m| *m >= -1e-9), "seed {seed}: {margins:?}");
    }
}

#[test]
#[ignore]
fn survey() {
    let s = hard("point-pushers.toml");
    let mut t = vec![];
    for seed in 0..20 {
        let settings = PlanarSettings { search: SearchSettings { seed, time_limit: 10.0, ..SearchSettings::default() }, ..PlanarSettings::default() };
        let r = plan(&s, None, None, &settings).unwrap();
        t.push(r.planning_time_s * 1e3);
        eprintln!("seed {seed}: found {} {:.1} ms nodes {} switch {}", r.found, r.planning_time_s * 1e3, r.nodes, r.switch_overs);
    }
    t.sort_by(f64::total_cmp);
    eprintln!("median {:.1} ms p90 {:.1} ms", 0.5 * (t[9] + t[10]), t[18]);
}

#[test]
#[ignore]
fn debug_connect() {
    let s = hard("point-pushers.toml");
    let goal = s.task.unwrap().goal;
    let tol = s.task.unwrap().tolerance;
    for a in [[0.0, 0.0, 0.0], [0.004, 0.003, 0.0], [0.008, 0.005, 0.01]] {
        let t = std::time::Instant::now();
        let r = point_step::connect(&s, &[0, 1, 2, 3], &a, &goal, &tol, 16, 0.01, |f| f.first_margin >= 0.01 && f.margin >= 0.005);
        eprintln!("a {a:?}: {:?} {:.2} ms", r.map(|(ps, st)| (ps, st[1].2)), t.elapsed().as_secs_f64() * 1e3);
    }
}
