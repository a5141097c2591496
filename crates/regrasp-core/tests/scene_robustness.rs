//! Hostile scene files (issue 13): exact array lengths in both loaders, physical bounds, no
//! panic from any value, a bounded and fast outline check, measured pusher points snapped onto
//! the outline with a note, and mutations of every bundled example that load or fail with an
//! error naming a field — never a panic, never a NaN in the loaded scene, always fast.

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use proptest::prelude::*;
use regrasp::mechanics::geometry::{Polygon, PolygonDefect, Vec2};
use regrasp::scene::bounds;
use regrasp::scene::spatial::{ConvexMesh, V3};
use regrasp::scene::Scene3;
use regrasp::{Error, Scene};

const BLOCK: &str = include_str!("../../../examples/block-low-friction.toml");
const BLOCK3: &str = include_str!("../../../examples/block-3d.toml");
const BALL3: &str = include_str!("../../../examples/ball-roll-3d.toml");

fn examples_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples")
}

fn edit(text: &str, old: &str, new: &str) -> String {
    assert_eq!(text.matches(old).count(), 1, "test setup: `{old}` must occur once");
    text.replacen(old, new, 1)
}

/// The field and message of a scene error, failing on anything else.
#[track_caller]
fn scene_err<T: std::fmt::Debug>(r: regrasp::Result<T>) -> (String, String) {
    match r {
        Err(Error::Scene { field, message }) => (field, message),
        other => panic!("expected a scene error, got {other:?}"),
    }
}

#[track_caller]
fn planar_err(text: &str) -> (String, String) {
    scene_err(Scene::from_toml_str(text))
}

#[track_caller]
fn spatial_err(text: &str) -> (String, String) {
    scene_err(Scene3::from_toml_str(text, Some(&examples_dir())))
}

/// The planar TOML text as the JSON of `from_dict` / `from_json`.
fn to_json(text: &str) -> String {
    let v: toml::Value = toml::from_str(text).unwrap();
    serde_json::to_string(&v).unwrap()
}

// ---------------------------------------------------------------------------------------------
// Exact lengths

#[test]
fn extra_and_missing_components_name_the_field_in_toml_and_json() {
    let goal = "goal = [0.012, 0.008, 0.0]";
    for (new, got) in [("goal = [0.012, 0.008, 0.0, 99.0]", 4), ("goal = [0.012, 0.008]", 2)] {
        let text = edit(BLOCK, goal, new);
        let (f, m) = planar_err(&text);
        assert_eq!(f, "task.goal", "{m}");
        assert!(m.contains(&format!("expected 3 numbers, got {got}")), "{m}");
        let (f, m) = scene_err(Scene::from_json_str(&to_json(&text)));
        assert_eq!(f, "task.goal", "{m}");
        assert!(m.contains(&format!("expected 3 numbers, got {got}")), "{m}");
    }
    let outline = "outline = [[-0.025, -0.04], [0.025, -0.04], [0.025, 0.04], [-0.025, 0.04]]";
    let text = edit(BLOCK, outline, "outline = [[-0.025, -0.04], [0.025, -0.04, 1.0], [0.025, 0.04], [-0.025, 0.04]]");
    assert_eq!(planar_err(&text).0, "object.outline[1]");
    assert_eq!(scene_err(Scene::from_json_str(&to_json(&text))).0, "object.outline[1]");
    let normal = "normal = [0.0, 1.0]";
    let text = edit(BLOCK, normal, "normal = [0.0, 1.0, 0.0]");
    assert_eq!(planar_err(&text).0, "pushers[0].normal");
    let text = edit(BLOCK, "direction = [0.0, -1.0]", "direction = [0.0, -1.0, 0.0]");
    assert_eq!(planar_err(&text).0, "gravity.direction");
}

#[test]
fn wrong_types_inside_arrays_name_the_field() {
    let (f, _) = planar_err(&edit(BLOCK, "goal = [0.012, 0.008, 0.0]", "goal = [0.012, \"x\", 0.0]"));
    assert!(f.starts_with("task.goal"), "{f}");
    let (f, _) = planar_err(&edit(BLOCK, "goal = [0.012, 0.008, 0.0]", "goal = 0.012"));
    assert!(f.starts_with("task.goal"), "{f}");
}

#[test]
fn spatial_arrays_have_exact_lengths() {
    let (f, m) = spatial_err(&edit(BLOCK3, "size = [0.05, 0.012, 0.08]", "size = [0.05, 0.012, 0.08, 1.0]"));
    assert_eq!(f, "object.size", "{m}");
    assert!(m.contains("expected 3 numbers, got 4"), "{m}");
    let (f, m) = spatial_err(&edit(BLOCK3, "tolerance = [0.001, 0.001, 0.001, 0.0175]", "tolerance = [0.001, 0.001, 0.001]"));
    assert_eq!(f, "task.tolerance", "{m}");
    assert!(m.contains("expected 4 numbers, got 3"), "{m}");
    let start = BLOCK3.lines().find(|l| l.starts_with("start =")).unwrap();
    let (f, m) = spatial_err(&edit(BLOCK3, start, "start = [0, 0, 0, 1, 0, 0, 0, 5]"));
    assert_eq!(f, "task.start", "{m}");
}

// ---------------------------------------------------------------------------------------------
// Bounds and panics

#[test]
fn absurd_sizes_are_errors_not_panics() {
    for r in ["1e300", "1e-30", "0.0", "-0.03", "nan", "inf"] {
        let text = BALL3.lines().map(|l| if l.starts_with("radius =") { format!("radius = {r}") } else { l.to_string() }).collect::<Vec<_>>().join("\n");
        let (f, m) = spatial_err(&text);
        assert_eq!(f, "object.radius", "radius {r}: {m}");
    }
    for s in ["1e300", "1e-300"] {
        let (f, m) = spatial_err(&edit(BLOCK3, "size = [0.05, 0.012, 0.08]", &format!("size = [{s}, 0.012, 0.08]")));
        assert_eq!(f, "object.size[0]", "side {s}: {m}");
        assert!(m.contains("[1e-4, 1e1] m"), "{m}");
    }
    for (v, ok) in [(1e300, false), (1e-300, false), (0.05, true)] {
        let r = catch_unwind(|| ConvexMesh::try_cuboid(&V3::new(v, 0.012, 0.08)).is_ok());
        assert_eq!(r.expect("try_cuboid must not panic"), ok, "side {v}");
        let r = catch_unwind(|| ConvexMesh::try_icosphere(v, 2).is_ok());
        assert_eq!(r.expect("try_icosphere must not panic"), ok, "radius {v}");
    }
}

#[test]
fn forces_masses_and_poses_are_within_physical_bounds() {
    assert_eq!(planar_err(&edit(BLOCK, "force = 20.0", "force = 1e200")).0, "grasp.force");
    assert_eq!(spatial_err(&edit(BLOCK3, "force = 20.0", "force = 1e300")).0, "grasp.force");
    assert_eq!(spatial_err(&edit(BLOCK3, "mass = 0.130", "mass = 1e300")).0, "object.mass");
    assert_eq!(planar_err(&edit(BLOCK, "goal = [0.012, 0.008, 0.0]", "goal = [0.012, 0.008, 1e300]")).0, "task.goal");
    assert_eq!(planar_err(&edit(BLOCK, "tolerance = [0.001, 0.001, 0.0175]", "tolerance = [0.001, 1e-300, 0.0175]")).0, "task.tolerance[1]");
    let (f, m) = planar_err(&edit(BLOCK, "normal = [0.0, 1.0]", "normal = [0.0, 1e300]"));
    assert_eq!(f, "pushers[0].normal", "{m}");
    // a 1 km object
    let big = edit(BLOCK, "outline = [[-0.025, -0.04], [0.025, -0.04], [0.025, 0.04], [-0.025, 0.04]]", "outline = [[-90, -90], [90, -90], [90, 90], [-90, 90]]");
    assert_eq!(planar_err(&big).0, "object.outline");
    assert!(bounds::FORCE.check("grasp.force", 20.0).is_ok());
}

#[test]
fn irrelevant_keys_and_blank_names_are_refused() {
    let (f, _) = planar_err(&edit(BLOCK, "pad_radius = 0.007", "pad_radius = 0.007\npad_size = [0.01, 0.01]"));
    assert_eq!(f, "grasp.pad_size");
    assert_eq!(spatial_err(&edit(BLOCK3, "size = [0.05, 0.012, 0.08]", "size = [0.05, 0.012, 0.08]\nmesh = \"x.obj\"")).0, "object.mesh");
    assert_eq!(spatial_err(&edit(BLOCK3, "name = \"block-3d\"", "name = \"  \"")).0, "name");
    let first = BLOCK3.lines().find(|l| l.starts_with("name = ") && !l.contains("block-3d")).unwrap();
    assert_eq!(spatial_err(&edit(BLOCK3, first, "name = \"\"")).0, "pushers[0].name");
    assert_eq!(spatial_err(&edit(BLOCK3, first, "name = \" \"")).0, "pushers[0].name");
}

#[test]
fn spatial_pusher_points_must_be_distinct() {
    let pts = BLOCK3.lines().find(|l| l.starts_with("points = ")).unwrap();
    let first: String = pts["points = [".len()..].split(']').next().unwrap().to_string() + "]";
    let (f, m) = spatial_err(&edit(BLOCK3, pts, &format!("points = [{first}, {first}]")));
    assert_eq!(f, "pushers[0].points[1]", "{m}");
    assert!(m.contains("coincides"), "{m}");
}

// ---------------------------------------------------------------------------------------------
// The outline: a cap and a fast simplicity test

/// `n` vertices on a circle of radius `r` [m], counter-clockwise.
fn circle(n: usize, r: f64) -> Vec<[f64; 2]> {
    (0..n).map(|k| {
        let a = std::f64::consts::TAU * k as f64 / n as f64;
        [r * a.cos(), r * a.sin()]
    }).collect()
}

/// A grasp scene on a circular outline of `n` vertices with a point pusher at vertex 0.
fn round_scene(n: usize) -> String {
    let pts: Vec<String> = circle(n, 0.05).iter().map(|p| format!("[{:.17e}, {:.17e}]", p[0], p[1])).collect();
    format!(
        "name = \"round\"\n[object]\noutline = [{}]\nmass = 0.1\n[grasp]\nforce = 20.0\nfriction = 0.8\npad_radius = 0.007\n\
         [[pushers]]\nname = \"p\"\nfriction = 0.3\npoints = [[0.05, 0.0]]\nnormal = [-1.0, 0.0]\n\
         [task]\nstart = [0.0, 0.0, 0.0]\ngoal = [0.001, 0.0, 0.0]\ntolerance = [0.001, 0.001, 0.0175]\n",
        pts.join(", ")
    )
}

#[test]
fn a_ten_thousand_vertex_outline_loads_in_well_under_a_second() {
    let text = round_scene(bounds::MAX_OUTLINE_VERTICES);
    let t = Instant::now();
    let s = Scene::from_toml_str(&text).expect("a 10,000-vertex circle is a valid outline");
    let dt = t.elapsed();
    assert_eq!(s.outline.vertices().len(), bounds::MAX_OUTLINE_VERTICES);
    assert!(dt < Duration::from_millis(500), "loading took {dt:?}");
    // the simplicity test alone, on a 100,000-vertex circle (83 s when it was quadratic)
    let pts: Vec<Vec2> = circle(100_000, 0.05).iter().map(|p| Vec2::new(p[0], p[1])).collect();
    let t = Instant::now();
    assert!(Polygon::new(pts.clone()).is_ok());
    assert!(t.elapsed() < Duration::from_millis(500), "Polygon::new took {:?}", t.elapsed());
    // and it still finds a crossing among them: two vertices swapped
    let mut bad = pts;
    bad.swap(500, 501);
    assert!(matches!(Polygon::new(bad), Err(PolygonDefect::SelfIntersecting(..))));
}

#[test]
fn more_vertices_than_the_cap_are_refused_by_name() {
    let (f, m) = planar_err(&round_scene(bounds::MAX_OUTLINE_VERTICES + 1));
    assert_eq!(f, "object.outline");
    assert!(m.contains("at most 10000"), "{m}");
}

/// Exact orientation test, for the brute-force reference below.
fn touches(a: Vec2, b: Vec2, c: Vec2, d: Vec2) -> bool {
    let o = |p: Vec2, q: Vec2, r: Vec2| (q - p).perp(&(r - p));
    let on = |p: Vec2, q: Vec2, r: Vec2| r.x >= p.x.min(q.x) && r.x <= p.x.max(q.x) && r.y >= p.y.min(q.y) && r.y <= p.y.max(q.y);
    let (d1, d2, d3, d4) = (o(c, d, a), o(c, d, b), o(a, b, c), o(a, b, d));
    (d1 * d2 < 0.0 && d3 * d4 < 0.0)
        || (d1 == 0.0 && on(c, d, a))
        || (d2 == 0.0 && on(c, d, b))
        || (d3 == 0.0 && on(a, b, c))
        || (d4 == 0.0 && on(a, b, d))
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 300, ..ProptestConfig::default() })]

    /// The sweep finds a crossing exactly when the all-pairs test does (small integer grids make
    /// touching and collinear edges common).
    #[test]
    fn sweep_agrees_with_all_pairs(raw in prop::collection::vec((0i32..6, 0i32..6), 4..12)) {
        let pts: Vec<Vec2> = raw.iter().map(|&(x, y)| Vec2::new(x as f64, y as f64)).collect();
        let n = pts.len();
        let repeated = (0..n).any(|i| pts[i] == pts[(i + 1) % n]);
        prop_assume!(!repeated);
        let mut crossing = false;
        for i in 0..n {
            for j in i + 1..n {
                if j == i + 1 || (i == 0 && j == n - 1) { continue; }
                crossing |= touches(pts[i], pts[(i + 1) % n], pts[j], pts[(j + 1) % n]);
            }
        }
        let got = Polygon::new(pts);
        if crossing {
            prop_assert!(matches!(got, Err(PolygonDefect::SelfIntersecting(..))), "{:?}", got);
        } else {
            prop_assert!(!matches!(got, Err(PolygonDefect::SelfIntersecting(i, j)) if j != (i + 1) % n), "{:?}", got);
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Measured pusher points

#[test]
fn a_point_rounded_off_the_outline_is_snapped_with_a_note() {
    // 8 µm above the bottom face
    let text = edit(BLOCK, "points = [[-0.02, -0.04], [0.02, -0.04]]", "points = [[-0.02, -0.039992], [0.02, -0.04]]");
    let s = Scene::from_toml_str(&text).expect("8 µm off is within the measurement tolerance");
    assert_eq!(s.notes().len(), 1, "{:?}", s.notes());
    let note = &s.notes()[0];
    assert!(note.contains("pushers[0].points[0]") && note.contains("8.0 µm") && note.contains("edge 0"), "{note}");
    let p = s.pushers[0].contact.points[0];
    assert!((p - Vec2::new(-0.02, -0.04)).norm() < 1e-12, "{p:?}");
    assert!(Scene::from_toml_str(BLOCK).unwrap().notes().is_empty());
}

#[test]
fn a_point_farther_than_the_tolerance_names_the_nearest_outline_point() {
    let text = edit(BLOCK, "points = [[-0.02, -0.04], [0.02, -0.04]]", "points = [[-0.02, -0.0397], [0.02, -0.04]]");
    let (f, m) = planar_err(&text);
    assert_eq!(f, "pushers[0].points[0]");
    assert!(m.contains("[-0.020000, -0.040000]") && m.contains("300.0 µm"), "{m}");
}

#[test]
fn a_spatial_point_rounded_off_the_surface_is_snapped_with_a_note() {
    let pts = BLOCK3.lines().find(|l| l.starts_with("points = ")).unwrap();
    let s0 = Scene3::from_toml_str(BLOCK3, None).unwrap();
    assert!(s0.notes().is_empty());
    let p0 = s0.pushers[0].points[0];
    let n = s0.pushers[0].normal;
    // 50 µm outside along the pusher's normal
    let q = p0 - n * 5e-5;
    let first = pts["points = [".len()..].split(']').next().unwrap().to_string() + "]";
    let text = edit(BLOCK3, pts, &pts.replacen(&first, &format!("[{}, {}, {}]", q.x, q.y, q.z), 1));
    let s = Scene3::from_toml_str(&text, None).expect("50 µm off is within the tolerance");
    assert_eq!(s.notes().len(), 1, "{:?}", s.notes());
    assert!((s.pushers[0].points[0] - p0).norm() < 1e-9);
    let q = p0 - n * 5e-4;
    let text = edit(BLOCK3, pts, &pts.replacen(&first, &format!("[{}, {}, {}]", q.x, q.y, q.z), 1));
    assert_eq!(spatial_err(&text).0, "pushers[0].points[0]");
}

// ---------------------------------------------------------------------------------------------
// Mutations of every bundled example

/// Every example scene: (file name, text, 3-D?).
fn examples() -> Vec<(String, String, bool)> {
    let mut out: Vec<_> = std::fs::read_dir(examples_dir())
        .unwrap()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .map(|p| {
            let text = std::fs::read_to_string(&p).unwrap();
            let three = text.lines().any(|l| l.trim_start().starts_with("dimension"));
            (p.file_name().unwrap().to_string_lossy().into_owned(), text, three)
        })
        .collect();
    out.sort();
    assert!(out.len() >= 10 && out.iter().any(|e| e.2) && out.iter().any(|e| !e.2));
    out
}

/// Paths (keys and indices) of every number and every array of numbers in `v`.
fn leaves(v: &toml::Value, at: &mut Vec<Step>, out: &mut Vec<Vec<Step>>) {
    match v {
        toml::Value::Table(t) => {
            for (k, x) in t {
                at.push(Step::Key(k.clone()));
                leaves(x, at, out);
                at.pop();
            }
        }
        toml::Value::Array(a) => {
            if a.iter().all(|x| x.is_float() || x.is_integer()) {
                out.push(at.clone());
            }
            for (i, x) in a.iter().enumerate() {
                at.push(Step::Index(i));
                leaves(x, at, out);
                at.pop();
            }
        }
        toml::Value::Float(_) | toml::Value::Integer(_) => out.push(at.clone()),
        _ => {}
    }
}

#[derive(Clone, Debug)]
enum Step {
    Key(String),
    Index(usize),
}

fn at_mut<'a>(v: &'a mut toml::Value, path: &[Step]) -> &'a mut toml::Value {
    path.iter().fold(v, |v, s| match s {
        Step::Key(k) => v.get_mut(k.as_str()).unwrap(),
        Step::Index(i) => v.get_mut(*i).unwrap(),
    })
}

const HOSTILE: [f64; 12] = [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 1e300, -1e300, 1e-300, -1e-300, 0.0, -1.0, 1e6, 1e-9, 0.5];

/// Applies mutation `kind` (with hostile value `h`) to the leaf at `path`.
fn mutate(v: &mut toml::Value, path: &[Step], kind: usize, h: f64) {
    let leaf = at_mut(v, path);
    match (kind, leaf) {
        (0, toml::Value::Array(a)) => a.push(toml::Value::Float(h)),
        (1, toml::Value::Array(a)) => {
            a.pop();
        }
        (2, leaf) => *leaf = toml::Value::String("x".into()),
        (3, leaf @ toml::Value::Array(_)) => *leaf = toml::Value::Array(vec![]),
        (_, toml::Value::Array(a)) => {
            let k = (h.to_bits() as usize) % a.len().max(1);
            if let Some(x) = a.get_mut(k) {
                *x = toml::Value::Float(h);
            }
        }
        (_, leaf) => *leaf = toml::Value::Float(h),
    }
}

/// Loads `text` and checks the outcome: no panic, fast, Ok with finite numbers or a scene
/// error naming a field.
fn check_load(what: &str, text: &str, three: bool, json: bool) {
    let t = Instant::now();
    let r = catch_unwind(AssertUnwindSafe(|| {
        if three {
            Scene3::from_toml_str(text, Some(&examples_dir())).map(|s| {
                assert!(s.length.is_finite() && s.mass.is_finite() && s.inertia.iter().all(|x| x.is_finite()), "{what}: non-finite scene");
                assert!(s.pushers.iter().all(|p| p.normal.iter().chain(p.points.iter().flatten()).all(|x| x.is_finite())));
            })
        } else {
            let s = if json { Scene::from_json_str(text) } else { Scene::from_toml_str(text) };
            s.map(|s| {
                assert!(s.length.is_finite() && s.length > 0.0 && s.mass.is_finite() && s.friction_scale().is_finite(), "{what}: non-finite scene");
                assert!(s.com.iter().all(|x| x.is_finite()));
            })
        }
    }));
    let dt = t.elapsed();
    assert!(dt < Duration::from_secs(2), "{what}: loading took {dt:?}");
    match r {
        Err(_) => panic!("{what}: the loader panicked on\n{text}"),
        Ok(Ok(())) => {}
        Ok(Err(e @ Error::Scene { .. })) => {
            let Error::Scene { field, message } = &e else { unreachable!() };
            assert!(!field.is_empty() && !message.is_empty(), "{what}: {e}");
            assert!(e.to_string().contains(field.as_str()), "{what}: {e}");
        }
        Ok(Err(e)) => panic!("{what}: expected a scene error, got {e:?}"),
    }
}

/// Cases of the mutation fuzz: 600 (the short, seeded profile of `make test`), or
/// `REGRASP_FUZZ_CASES` for a long exploration (e.g. 20000).
fn fuzz_cases() -> u32 {
    std::env::var("REGRASP_FUZZ_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(600)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: fuzz_cases(), ..ProptestConfig::default() })]

    /// A hostile value, an extra or missing component, a wrong type or an empty array at any
    /// numeric leaf of any bundled example (planar in TOML and JSON, 3-D in TOML).
    #[test]
    fn mutated_examples_load_or_name_a_field(ex in any::<prop::sample::Index>(), leaf in any::<prop::sample::Index>(), kind in 0usize..7, h in prop::sample::select(HOSTILE.to_vec())) {
        let all = examples();
        let (file, text, three) = &all[ex.index(all.len())];
        let mut v: toml::Value = toml::from_str(text).unwrap();
        let mut paths = Vec::new();
        leaves(&v, &mut Vec::new(), &mut paths);
        let path = &paths[leaf.index(paths.len())];
        mutate(&mut v, path, kind, h);
        let what = format!("{file} {path:?} kind {kind} value {h:e}");
        let mutated = toml::to_string(&v).unwrap();
        check_load(&what, &mutated, *three, false);
        if !*three && h.is_finite() {
            check_load(&format!("{what} (json)"), &serde_json::to_string(&v).unwrap(), false, true);
        }
    }
}

#[test]
fn every_example_loads_unchanged_through_the_mutation_round_trip() {
    for (file, text, three) in examples() {
        let v: toml::Value = toml::from_str(&text).unwrap();
        let again = toml::to_string(&v).unwrap();
        if three {
            Scene3::from_toml_str(&again, Some(&examples_dir())).unwrap_or_else(|e| panic!("{file}: {e}"));
        } else {
            Scene::from_toml_str(&again).unwrap_or_else(|e| panic!("{file}: {e}"));
            Scene::from_json_str(&serde_json::to_string(&v).unwrap()).unwrap_or_else(|e| panic!("{file} (json): {e}"));
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Copies with changed parameters stay within the bounds

#[test]
fn absurd_grip_forces_and_scales_are_argument_errors() {
    let s = Scene::from_toml_str(BLOCK).unwrap();
    for f in [1e200, 1e300, f64::NAN, -1.0, 0.0] {
        assert!(matches!(s.try_with_grip_force(f), Err(Error::InvalidArgument { ref name, .. }) if name == "force"), "force {f}");
    }
    assert_eq!(s.try_with_grip_force(40.0).unwrap().grip_force(), Some(40.0));
    use regrasp::cones::robust::ConeMode;
    use regrasp::scene::perturb::scaled;
    let e = scaled(&s, 1.0, 1e300, 1.0, 1.0, ConeMode::Nominal).unwrap_err();
    assert!(matches!(e, Error::InvalidArgument { ref name, .. } if name == "grip"), "{e:?}");
    let e = scaled(&s, 1.0, 1.0, 1e300, 1.0, ConeMode::Nominal).unwrap_err();
    assert!(matches!(e, Error::InvalidArgument { ref name, .. } if name == "mass"), "{e:?}");
    assert!(scaled(&s, 0.9, 1.1, 1.2, 0.8, ConeMode::Nominal).is_ok());
}

#[test]
fn a_ten_thousand_vertex_outline_on_a_surface_loads_fast() {
    let text = round_scene(bounds::MAX_OUTLINE_VERTICES);
    let at = text.find("[grasp]").unwrap();
    let (head, tail) = text.split_at(at);
    let pushers = &tail[tail.find("[[pushers]]").unwrap()..tail.find("[task]").unwrap()];
    let text = format!("{head}[surface]\nfriction = 0.5\n{pushers}");
    let t = Instant::now();
    Scene::from_toml_str(&text).expect("a round object on a surface");
    assert!(t.elapsed() < Duration::from_secs(1), "loading took {:?}", t.elapsed());
}
