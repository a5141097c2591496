//! The inner goal tolerance (`SearchSettings::goal_share`): plans end within that share of the
//! task's tolerance, so execution has room; a search that reaches only the whole tolerance ends
//! there (found), and a share outside (0, 1] is refused naming the setting.

use regrasp::planning::planar::{plan, PlanarSettings};
use regrasp::planning::spatial::{plan3, SpatialSettings};
use regrasp::planning::trrt::SearchSettings;
use regrasp::scene::spatial::goal_error;
use regrasp::scene::spatial::Scene3;
use regrasp::Scene;
use std::path::{Path, PathBuf};

fn examples() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../python/regrasp/examples")
}

fn planar(share: f64, seed: u64) -> PlanarSettings {
    // no straight connection to the goal: the plan ends where a grown step lands
    let search = SearchSettings { seed, goal_share: share, connect: false, time_limit: 30.0, ..SearchSettings::default() };
    PlanarSettings { search, ..PlanarSettings::default() }
}

/// The largest share of the tolerance that the end's error takes, over the components.
fn share_of(end: &[f64; 3], goal: &[f64; 3], tol: &[f64; 3]) -> f64 {
    (0..3).map(|k| (end[k] - goal[k]).abs() / tol[k]).fold(0.0, f64::max)
}

#[test]
fn planar_plans_end_within_the_inner_share_of_the_tolerance() {
    let mut wider = 0; // plans with the whole tolerance that end beyond half of it
    for name in ["block-low-friction", "t-shape", "block-xztheta"] {
        let s = Scene::load(&examples().join(format!("{name}.toml"))).unwrap();
        let task = s.task.unwrap();
        for seed in 0..4 {
            let half = plan(&s, None, None, &planar(0.5, seed)).unwrap();
            assert!(half.found, "{name} seed {seed}: {:?}", half.stop_reason);
            let e = share_of(&half.path.last().unwrap().0, &task.goal, &task.tolerance);
            assert!(e <= 0.5 + 1e-12, "{name} seed {seed}: ends at {e:.3} of the tolerance");
            let whole = plan(&s, None, None, &planar(1.0, seed)).unwrap();
            assert!(whole.found);
            let e = share_of(&whole.path.last().unwrap().0, &task.goal, &task.tolerance);
            assert!(e <= 1.0 + 1e-12);
            wider += (e > 0.5) as usize;
        }
    }
    // the setting changes something: with the whole tolerance some plans end beyond its half
    assert!(wider > 0, "no plan with the whole tolerance ended beyond half of it");
}

#[test]
fn a_search_that_reaches_only_the_whole_tolerance_ends_there() {
    // the ball rolled on the floor: rolling moves its centre as a side effect, so the plan ends
    // 0.62 of the position tolerance off, within the task's but not its half
    let s = Scene3::load(&examples().join("ball-roll-3d.toml")).unwrap();
    let at = |share: f64| {
        let settings = SpatialSettings { search: SearchSettings { goal_share: share, ..SearchSettings::default() } };
        plan3(&s, None, None, &settings).unwrap().plan
    };
    let half = at(0.5);
    assert!(half.found, "{:?}", half.stop_reason);
    let end = half.path.last().unwrap().0;
    let (e, within) = goal_error(&end, &s.goal, &s.tolerance);
    assert!(within, "{e:?}");
    let share = (0..4).map(|k| e[k].abs() / s.tolerance[k]).fold(0.0, f64::max);
    assert!(share > 0.5, "{share}: the fallback is not exercised");
    assert_eq!(at(1.0).path.len(), half.path.len());
}

#[test]
fn a_share_outside_zero_to_one_is_refused_naming_it() {
    let s = Scene::load(&examples().join("block-low-friction.toml")).unwrap();
    for bad in [0.0, -0.5, 1.5, f64::NAN, f64::INFINITY] {
        let e = plan(&s, None, None, &planar(bad, 0)).unwrap_err();
        assert!(e.to_string().contains("goal_share"), "{bad}: {e}");
    }
}
