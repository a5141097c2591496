//! Criterion benchmarks of the motion-cone hot paths: building one cone through the public API,
//! the fast frame + rays path of the batch API, the exact membership test, the projection, and
//! the batch generator computation over many poses; on the scenes' default (exact) limit surface,
//! and the frame, exact test and projection also on the ellipsoid (`*_ellipsoid`); and the exact
//! surface's own lookups (load and gauge) on a disc's profile and on a polygon's cube maps.
//!
//! Run with `cargo bench -p regrasp-core --bench cones`.

use std::hint::black_box;
use std::path::Path;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion};
use regrasp::cones::batch::{generators_into, Status};
use regrasp::mechanics::geometry::Vec3;
use regrasp::mechanics::limit_surface::SurfaceModel;
use regrasp::Scene;

const POSE: [f64; 3] = [0.003, 0.004, 0.1];

fn load(name: &str) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples").join(name);
    Scene::load(&path).unwrap_or_else(|e| panic!("cannot load {}: {e}", path.display()))
}

/// The block-low-friction scene and the index of its left line pusher.
fn scene_and_left() -> (Scene, usize) {
    let scene = load("block-low-friction.toml");
    let i = scene.pusher_index("left").expect("block-low-friction has a `left` pusher");
    (scene, i)
}

/// A twist inside the cone (straight right, along the pusher normal) and one outside it
/// (straight up along the left face: a low-friction pusher cannot drag the object along itself).
/// (Not the mean of the generators: with gravity the exact cone is not convex and that mean
/// falls outside it here.)
fn twists(scene: &Scene, pusher: usize) -> (Vec3, Vec3) {
    let push = scene.push(&POSE, pusher).unwrap();
    let inside = Vec3::new(1.0, 0.0, 0.0);
    let outside = Vec3::new(0.0, 1.0, 0.0);
    assert!(push.contains(&inside).unwrap(), "bench setup: `inside` twist is not in the cone");
    assert!(!push.contains(&outside).unwrap(), "bench setup: `outside` twist is in the cone");
    (inside, outside)
}

/// Deterministic xorshift64* generator.
struct XorShift(u64);

impl XorShift {
    fn next_u64(&mut self) -> u64 {
        let mut x = self.0;
        x ^= x >> 12;
        x ^= x << 25;
        x ^= x >> 27;
        self.0 = x;
        x.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    /// Uniform in [lo, hi).
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        let u = (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
        lo + (hi - lo) * u
    }
}

/// `n` admissible poses of `scene` by rejection sampling (pose components bounded by the
/// object's size).
fn random_admissible_poses(scene: &Scene, n: usize, seed: u64) -> Vec<[f64; 3]> {
    let mut rng = XorShift(seed);
    let mut out = Vec::with_capacity(n);
    while out.len() < n {
        let q = [rng.uniform(-0.025, 0.025), rng.uniform(-0.04, 0.04), rng.uniform(-0.6, 0.6)];
        if scene.admissible(&q) {
            out.push(q);
        }
    }
    out
}

fn bench_cone(c: &mut Criterion) {
    let (scene, i) = scene_and_left();
    let mut g = c.benchmark_group("cone");
    g.measurement_time(Duration::from_secs(3)).warm_up_time(Duration::from_secs(1));

    g.bench_function("build+generators", |b| {
        b.iter(|| {
            let push = scene.push(black_box(&POSE), black_box(i)).unwrap();
            black_box(push.generators().unwrap())
        })
    });

    let model = &scene.pushers[i].model;
    let ellipsoid = scene.with_surface_model(SurfaceModel::Ellipsoid);
    for (name, sc) in [("frame+rays_ellipsoid", &ellipsoid), ("frame+rays", &scene)] {
        g.bench_function(name, |b| {
            b.iter(|| {
                let frame = sc.frame(black_box(&POSE));
                let mut acc = Vec3::zeros();
                for e in &model.edges {
                    if let Some(v) = frame.ray(&e.wrench, &sc.metric()) {
                        acc += v;
                    }
                }
                black_box(acc)
            })
        });
    }
    g.finish();
}

fn bench_membership(c: &mut Criterion) {
    let (scene, i) = scene_and_left();
    let (inside, outside) = twists(&scene, i);
    let model = &scene.pushers[i].model;
    let frame = scene.frame(&POSE);
    let push = scene.push(&POSE, i).unwrap();

    // the same test on the ellipsoidal limit surface (the scenes' default is the exact one)
    let ellipsoid = scene.with_surface_model(SurfaceModel::Ellipsoid);
    let frame_e = ellipsoid.frame(&POSE);

    let mut g = c.benchmark_group("membership");
    g.measurement_time(Duration::from_secs(3)).warm_up_time(Duration::from_secs(1));
    // two exact tests per iteration (one twist inside, one outside)
    g.bench_function("exact", |b| {
        b.iter(|| {
            let a = frame.classify(model, black_box(&inside));
            let o = frame.classify(model, black_box(&outside));
            black_box((a, o))
        })
    });
    g.bench_function("exact_ellipsoid", |b| {
        b.iter(|| {
            let a = frame_e.classify(model, black_box(&inside));
            let o = frame_e.classify(model, black_box(&outside));
            black_box((a, o))
        })
    });
    g.bench_function("full", |b| {
        b.iter(|| {
            let a = push.classify(black_box(&inside)).unwrap();
            let o = push.classify(black_box(&outside)).unwrap();
            black_box((a, o))
        })
    });
    g.finish();

    let push_e = ellipsoid.push(&POSE, i).unwrap();
    let mut g = c.benchmark_group("project");
    g.measurement_time(Duration::from_secs(3)).warm_up_time(Duration::from_secs(1));
    g.bench_function("exact", |b| b.iter(|| black_box(push.project(black_box(&outside)).unwrap())));
    g.bench_function("exact_ellipsoid", |b| b.iter(|| black_box(push_e.project(black_box(&outside)).unwrap())));
    g.finish();
}

fn bench_batch(c: &mut Criterion) {
    const N: usize = 100_000;
    let (scene, i) = scene_and_left();
    let poses = random_admissible_poses(&scene, N, 0x9E37_79B9_7F4A_7C15);
    let k = scene.pushers[i].model.edges.len();
    let mut out = vec![0.0; N * k * 3];
    let mut status = vec![Status::Ok; N];

    let mut g = c.benchmark_group("batch");
    g.sample_size(10);
    g.bench_function("generators_100k", |b| {
        b.iter(|| {
            generators_into(&scene, black_box(&poses), i, false, &mut out, &mut status);
            black_box((&out, &status));
        })
    });
    g.finish();
    assert!(status.iter().all(|s| *s == Status::Ok), "batch: some sampled pose failed");
}

fn bench_surface(c: &mut Criterion) {
    use regrasp::mechanics::exact_surface::{ExactSurface, Region};
    use regrasp::mechanics::geometry::Vec2;
    use regrasp::mechanics::limit_surface::Pressure;
    let rect = vec![Vec2::new(-0.02, -0.01), Vec2::new(0.02, -0.01), Vec2::new(0.02, 0.01), Vec2::new(-0.02, 0.01)];
    let surfaces = [("disc", ExactSurface::new(&Region::Disc { radius: 0.006, pressure: Pressure::Uniform })), ("polygon", ExactSurface::new(&Region::Polygon { vertices: rect }))];
    let mut g = c.benchmark_group("surface");
    g.measurement_time(Duration::from_secs(2)).warm_up_time(Duration::from_secs(1));
    for (name, s) in &surfaces {
        let l = s.length();
        // 64 directions spread over the sphere of scaled twists / wrenches
        let dirs: Vec<Vec3> = (0..64).map(|k| (k as f64 * 2.399963, 1.0 - (k as f64 + 0.5) / 32.0)).map(|(a, z)| Vec3::new(a.cos() * (1.0 - z * z).sqrt(), a.sin() * (1.0 - z * z).sqrt(), z)).collect();
        let twists: Vec<Vec3> = dirs.iter().map(|d| Vec3::new(d.x, d.y, d.z / l)).collect();
        let wrenches: Vec<Vec3> = dirs.iter().map(|d| Vec3::new(d.x, d.y, d.z * l)).collect();
        g.bench_function(format!("load_{name}_x64"), |b| b.iter(|| twists.iter().map(|v| s.wrench(black_box(v)).x).sum::<f64>()));
        g.bench_function(format!("gauge_{name}_x64"), |b| b.iter(|| wrenches.iter().map(|w| s.gauge(black_box(w))).sum::<f64>()));
    }
    g.finish();
}

criterion_group!(benches, bench_cone, bench_membership, bench_batch, bench_surface);
criterion_main!(benches);
