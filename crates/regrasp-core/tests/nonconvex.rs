//! A non-convex 3-D object given as convex parts (issue 18, item 5): the bundled L-bracket's mass
//! properties against the boxes' closed forms, its surface (the union, not the hull), its pads
//! and pushers, the file's errors, and the 3-D planner on it.

use regrasp::planning::spatial::{plan3, validate_path3, SpatialSettings};
use regrasp::planning::trrt::SearchSettings;
use regrasp::scene::spatial::{ConvexMesh, Scene3, V3};
use regrasp::Error;
use nalgebra::{Isometry3, Matrix3, Translation3, UnitQuaternion};

fn examples() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../python/regrasp/examples")
}

fn bracket() -> Scene3 {
    Scene3::load(&examples().join("bracket-pivot-3d.toml")).unwrap()
}

/// Volume, centroid and inertia about the centroid per unit volume of an axis-aligned box.
fn boxed(lo: [f64; 3], hi: [f64; 3]) -> (f64, V3, Matrix3<f64>) {
    let s = V3::new(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
    let c = V3::new(hi[0] + lo[0], hi[1] + lo[1], hi[2] + lo[2]) / 2.0;
    let i = Matrix3::from_diagonal(&V3::new(s.y * s.y + s.z * s.z, s.x * s.x + s.z * s.z, s.x * s.x + s.y * s.y)) / 12.0;
    (s.x * s.y * s.z, c, i)
}

#[test]
fn the_brackets_mass_properties_are_the_two_boxes() {
    let s = bracket();
    assert_eq!(s.parts.len(), 2);
    let (up, foot) = (boxed([-0.012, -0.006, -0.02], [0.012, 0.006, 0.04]), boxed([-0.012, -0.006, -0.04], [0.04, 0.006, -0.02]));
    let vol = up.0 + foot.0;
    let c = (up.1 * up.0 + foot.1 * foot.0) / vol;
    let mut i = Matrix3::zeros();
    for (v, ci, ii) in [up, foot] {
        let d = ci - c;
        i += (ii + Matrix3::identity() * d.norm_squared() - d * d.transpose()) * v;
    }
    let i = i / vol * s.mass;
    assert!((s.com - c).norm() < 1e-12, "{:?} vs {:?}", s.com, c);
    assert!((s.com - V3::new(0.014 * 12.48 / 29.76, 0.0, (0.01 * 17.28 - 0.03 * 12.48) / 29.76)).norm() < 1e-9);
    assert!((s.inertia - i).norm() < 1e-12 * s.mass, "{} vs {}", s.inertia, i);
    // the hull is not the object: its centroid lies elsewhere
    let (hv, hc, _) = s.mesh.mass_properties();
    assert!(hv > vol * 1.2 && (hc - c).norm() > 1e-3);
}

#[test]
fn the_surface_is_the_union_of_the_parts_not_their_hull() {
    let s = bracket();
    assert_eq!(s.mesh.vertices.len(), 10); // the L's five outer corners, at ±6 mm
    let notch = V3::new(0.026, 0.0, -0.005); // inside the hull, outside the L
    assert!(s.mesh.signed_distance(&notch) < 0.0 && s.signed_distance(&notch) > 0.01 - 1e-12);
    for p in [V3::new(0.0, 0.0, 0.0), V3::new(0.03, 0.0, -0.03)] {
        assert!(s.signed_distance(&p) < 0.0);
    }
    // on the foot's top face (inside the notch's corner) and on the upright's right face
    assert!(s.signed_distance(&V3::new(0.03, 0.0, -0.02)).abs() < 1e-12);
    assert!(s.signed_distance(&V3::new(0.012, 0.0, 0.01)).abs() < 1e-12);
}

#[test]
fn pads_touch_the_ls_faces_and_not_the_notch() {
    let s = bracket();
    // the pad's centre over the notch's corner (object point (12, 0, −15) mm: the gripper's
    // origin there): its ring points over the notch are dropped
    let at = |c: V3| Isometry3::from_parts(Translation3::from(-c), UnitQuaternion::identity());
    let pads = s.pad_contacts(&at(V3::new(0.016, 0.0, -0.016)));
    for pad in &pads {
        assert!(!pad.is_empty() && pad.len() < 8, "{}", pad.len());
        assert!(pad.iter().all(|p| s.signed_distance(p).abs() < 1e-9 && !(p.x > 0.012 + 1e-9 && p.z > -0.02 + 1e-9)));
    }
    assert!(s.pad_contacts(&at(V3::zeros())).iter().all(|p| p.len() == 8));
}

/// The bracket's scene with its OBJ replaced by `obj` (written next to a copy of the scene).
fn with_obj(obj: &str, tag: &str) -> regrasp::Result<Scene3> {
    // a folder of its own per call: the tests run in parallel threads of one process
    static CALLS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let call = CALLS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let dir = std::env::temp_dir().join(format!("regrasp-nonconvex-{tag}-{}-{call}", std::process::id()));
    std::fs::create_dir_all(dir.join("meshes")).unwrap();
    std::fs::write(dir.join("meshes/bracket.obj"), obj).unwrap();
    let text = std::fs::read_to_string(examples().join("bracket-pivot-3d.toml")).unwrap();
    Scene3::from_toml_str(&text, Some(&dir))
}

#[track_caller]
fn mesh_error(r: regrasp::Result<Scene3>) -> String {
    match r {
        Err(Error::Scene { field, message }) if field == "object.mesh" => message,
        other => panic!("expected an object.mesh error, got {other:?}"),
    }
}

/// An OBJ group `o name` of the box `[lo, hi]` (outward quads), its vertices numbered from `first`.
fn box_obj(name: &str, lo: [f64; 3], hi: [f64; 3], first: usize) -> String {
    let mut out = format!("o {name}\n");
    for i in 0..8 {
        let p = [if i & 1 > 0 { hi[0] } else { lo[0] }, if i & 2 > 0 { hi[1] } else { lo[1] }, if i & 4 > 0 { hi[2] } else { lo[2] }];
        out += &format!("v {} {} {}\n", p[0], p[1], p[2]);
    }
    for q in [[0, 4, 6, 2], [1, 3, 7, 5], [0, 1, 5, 4], [2, 6, 7, 3], [0, 2, 3, 1], [4, 5, 7, 6]] {
        out += &format!("f {} {} {} {}\n", q[0] + first, q[1] + first, q[2] + first, q[3] + first);
    }
    out
}

#[test]
fn bad_parts_are_errors_naming_the_field() {
    let up = box_obj("upright", [-0.012, -0.006, -0.02], [0.012, 0.006, 0.04], 1);
    let foot = |top: f64| box_obj("foot", [-0.012, -0.006, -0.04], [0.04, 0.006, top], 9);
    // the box helper writes the bundled bracket's two parts
    let same = with_obj(&(up.clone() + &foot(-0.02)), "same").unwrap();
    assert!((same.com - bracket().com).norm() < 1e-12);
    // the parts overlap: the foot 10 mm taller, into the upright
    let m = mesh_error(with_obj(&(up.clone() + &foot(-0.01)), "overlap"));
    assert!(m.contains("parts 0 and 1 overlap"), "{m}");
    // one group of both boxes' faces: one mesh, not convex (the hint says how to give it)
    let merged: String = (up.clone() + &foot(-0.02)).lines().filter(|l| !l.starts_with("o ")).map(|l| format!("{l}\n")).collect();
    let m = mesh_error(with_obj(&merged, "merged"));
    assert!(m.contains("not convex") && m.contains("`o` group"), "{m}");
    // a part that is not closed names the part
    let open = up.replace("f 5 6 8 7\n", "") + &foot(-0.02);
    let m = mesh_error(with_obj(&open, "open"));
    assert!(m.contains("part 0 (`o upright`): the mesh is not closed"), "{m}");
    // a coordinate that is not finite, or too far, and more vertices than a mesh may have: named
    for (bad, what) in [("nan", "finite"), ("inf", "finite"), ("1e300", "within 100 m")] {
        let m = mesh_error(with_obj(&(up.replacen("v -0.012", &format!("v {bad}"), 1) + &foot(-0.02)), "coordinate"));
        assert!(m.contains(what) && m.contains("line 2"), "{m}");
    }
    let unused: String = (0..regrasp::scene::bounds::MAX_MESH_VERTICES).map(|k| format!("v 0 0 {}\n", k as f64 * 1e-6)).collect();
    let m = mesh_error(with_obj(&(up.clone() + &foot(-0.02) + &unused), "many"));
    assert!(m.contains("more than 5000 vertices"), "{m}");
    // a pusher point in the notch's air is not on the surface
    let text = std::fs::read_to_string(examples().join("bracket-pivot-3d.toml")).unwrap();
    let bad = text.replace("points = [[-0.008, -0.005, -0.04], [0.036, -0.005, -0.04]", "points = [[0.026, 0.0, -0.005], [0.036, -0.005, -0.04]");
    assert_ne!(bad, text);
    match Scene3::from_toml_str(&bad, Some(&examples())) {
        Err(Error::Scene { field, message }) => assert!(field == "pushers[1].points[0]" && message.contains("not on the object's surface"), "{field}: {message}"),
        other => panic!("{other:?}"),
    }
}

#[test]
fn the_hull_of_points_is_convex_and_holds_them_all() {
    let s = bracket();
    let all: Vec<V3> = s.parts.iter().flat_map(|m| m.vertices.iter().copied()).collect();
    let h = ConvexMesh::hull(&all).unwrap();
    assert!(all.iter().all(|p| h.signed_distance(p) <= 1e-12));
    let (v, _, _) = h.mass_properties();
    // the L's outline (x–z) hull: the L (2,480 mm²) and the notch's triangle under the hull's
    // slanted edge (28 mm × 60 mm), 12 mm thick
    let l_area = 24.0 * 60.0 + 52.0 * 20.0;
    let tri = 0.5 * 28.0 * 60.0;
    assert!((v - (l_area + tri) * 12.0 * 1e-9).abs() < 1e-15, "{v}");
}

#[test]
fn the_bracket_is_planned_and_every_step_checks() {
    let s = bracket();
    // ~5 s a seed on an idle machine; the limit only bounds a failure (a loaded machine, pytest
    // beside it, took over 20 s for seed 0)
    for seed in 0..3 {
        let st = SpatialSettings { search: SearchSettings { seed, time_limit: 90.0, ..SearchSettings::default() }, ..SpatialSettings::default() };
        let r = plan3(&s, None, None, &st).unwrap();
        assert!(r.plan.found, "seed {seed}: {:?}", r.plan.stop_reason);
        let path: Vec<_> = r.plan.path.iter().map(|(q, p, _)| (*q, *p)).collect();
        let twists: Vec<_> = r.plan.path.iter().map(|(_, _, e)| *e).collect();
        assert!(validate_path3(&s, &path, Some(&twists)).unwrap().iter().all(|b| *b));
    }
}

#[test]
fn parts_are_bounded_together() {
    // 40 copies of a 200-vertex prism side by side: 8,000 vertices in all, each part within a
    // mesh's bounds; refused, naming the field, before any overlap test
    let mut obj = String::new();
    let mut first = 1;
    for p in 0..40 {
        obj += &format!("o p{p}\n");
        let x0 = -0.02 + 0.001 * p as f64;
        for y in [-0.006, 0.006] {
            for k in 0..100 {
                let a = std::f64::consts::TAU * k as f64 / 100.0;
                obj += &format!("v {} {} {}\n", x0 + 0.0004 * (1.0 + a.cos()), y, 0.01 * a.sin());
            }
        }
        // the two caps fanned, the sides as quads, outward
        obj += &format!("f {}\n", (0..100).map(|k| (first + k).to_string()).collect::<Vec<_>>().join(" "));
        obj += &format!("f {}\n", (0..100).rev().map(|k| (first + 100 + k).to_string()).collect::<Vec<_>>().join(" "));
        for k in 0..100 {
            let (a, b) = (first + k, first + (k + 1) % 100);
            obj += &format!("f {a} {} {} {b}\n", a + 100, b + 100);
        }
        first += 200;
    }
    let m = mesh_error(with_obj(&obj, "parts"));
    assert!(m.contains("more than 5000 vertices"), "{m}");
}
