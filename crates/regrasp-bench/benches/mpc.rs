//! One MPC step (closest knot, motion cones of the horizon, the QP with clarabel, the exact
//! check of the executed twist): horizon 5 on the block and the T-shape, nominal and robust
//! cones. Target: median under 1 ms (a 125 Hz pushing MPC is the published reference).
use criterion::{criterion_group, criterion_main, Criterion};
use regrasp::control::mpc::{Mpc, MpcSettings};
use regrasp::cones::robust::Uncertainty;
use regrasp::scene::perturb::worst_case;
use regrasp::planning::planar::{plan, PlanarSettings};
use regrasp::Scene;
use std::hint::black_box;
use std::path::Path;
use std::time::Duration;

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("mpc");
    g.measurement_time(Duration::from_secs(3)).warm_up_time(Duration::from_secs(1));
    let u = Uncertainty { pusher_friction: 0.2, finger_friction: 0.2, grip_force: 0.2, mass: 0.2 };
    for name in ["block-high-friction", "t-shape"] {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("../../examples/{name}.toml"));
        let scene = Scene::load(&path).unwrap();
        for (label, s) in [("nominal", scene.clone()), ("robust", worst_case(&scene, &u).unwrap())] {
            let r = plan(&s, None, None, &PlanarSettings::default()).unwrap();
            // a missing plan is a regression, never a silently shorter benchmark
            assert!(r.found, "no {label} plan for {name}: {}", r.stop_reason.label());
            let q0 = r.path[0].0;
            let q = [q0[0] + 0.0005, q0[1] - 0.0005, q0[2] + 0.01];
            g.bench_function(format!("step/{name}/{label}"), |b| {
                b.iter_batched(
                    || Mpc::new(&s, &r.poses(), None, MpcSettings::default()).unwrap(),
                    |mut m| black_box(m.step(black_box(&q)).unwrap()),
                    criterion::BatchSize::SmallInput,
                )
            });
        }
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
