//! One instantaneous quasi-static solve: the block in a grasp of two finger patches (4 points
//! each) pushed by a line pusher, for a push that sticks, one that slides and one that
//! separates; and the inverse problem.
use criterion::{criterion_group, criterion_main, Criterion};
use nalgebra::DVector;
use regrasp::dynamics::mncp::{solve_forward, solve_inverse, Settings};
use regrasp::dynamics::planar::{push_problem, Options, SupportModel};
use regrasp::Scene;
use std::hint::black_box;
use std::path::Path;
use std::time::Duration;

fn bench(c: &mut Criterion) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/block-low-friction.toml");
    let scene = Scene::load(&path).unwrap();
    let opts = Options { support: SupportModel::Points { rings: 0, points: 4, merge_fingers: false }, ..Options::default() };
    let i = scene.pusher_index("left").unwrap();
    let p = push_problem(&scene, &[0.0, 0.0, 0.0], i, &opts).unwrap();
    let s = Settings::default();
    let mut g = c.benchmark_group("mncp");
    g.measurement_time(Duration::from_secs(3)).warm_up_time(Duration::from_secs(1));
    for (name, u) in [("forward/stick", [0.01, 0.0, 0.0]), ("forward/slide", [0.002, 0.01, 0.0]), ("forward/separate", [-0.01, 0.0, 0.2])] {
        let u = DVector::from_row_slice(&u);
        g.bench_function(name, |b| b.iter(|| solve_forward(black_box(&p), black_box(&u), &s).unwrap()));
    }
    let v = DVector::from_row_slice(&[0.01, 0.001, 0.05]);
    g.bench_function("inverse", |b| b.iter(|| solve_inverse(black_box(&p), black_box(&v), &s).unwrap()));
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
