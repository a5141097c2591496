//! The anytime refinement on a hard scene: goal connections reach the very same goal pose many
//! times; the search must keep going (a k-d leaf of identical keys once panicked here).

use regrasp::planning::planar::{plan, validate_path, PlanarSettings};
use regrasp::planning::trrt::SearchSettings;
use regrasp::mechanics::limit_surface::SurfaceModel;
use regrasp::scene::Scene;

#[test]
fn refining_long_past_the_first_plan_keeps_the_plan_valid_and_no_costlier() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../python/regrasp/examples/hard/u-shape.toml");
    // on the ellipsoid, whose cones cost less: the test is about the search's long refinement
    let s = Scene::load(&path).unwrap().with_surface_model(SurfaceModel::Ellipsoid);
    // (refine 20: ten times the first plan's iterations and more, whatever the first plan takes)
    let search = SearchSettings { seed: 0, refine: 20.0, time_limit: 60.0, ..SearchSettings::default() };
    let r = plan(&s, None, None, &PlanarSettings { search, ..PlanarSettings::default() }).unwrap();
    let f = r.first.expect("a first plan");
    assert!(r.found && r.iterations > f.iterations + 10_000 && r.cost <= f.cost + 1e-12, "{} iterations, first {f:?}", r.iterations);
    let margins = validate_path(&s, &r.poses(), 64).unwrap();
    assert!(margins.iter().all(|m| *m >= -1e-9), "{margins:?}");
}
