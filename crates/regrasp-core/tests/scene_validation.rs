//! Scene validation: every invalid variation of a bundled scene is rejected with an
//! `Error::Scene` naming the offending field; every bundled example loads (from TOML and from
//! the equivalent JSON); admissibility of poses at the edge of the object and in a notch.

use std::path::{Path, PathBuf};

use regrasp::{Error, Scene};

/// The base scene: a 50 x 80 mm block, pads of 7 mm radius, four line pushers.
const BASE: &str = include_str!("../../../examples/block-low-friction.toml");

fn examples_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples")
}

/// `BASE` with the single occurrence of `old` replaced by `new`.
fn edit(old: &str, new: &str) -> String {
    edit_text(BASE, old, new)
}

fn edit_text(text: &str, old: &str, new: &str) -> String {
    let n = text.matches(old).count();
    assert_eq!(n, 1, "test setup: `{old}` occurs {n} times in the base text (expected once)");
    text.replacen(old, new, 1)
}

/// `BASE` without its `[task]` table (the last table of the file).
fn without_task() -> String {
    let at = BASE.find("[task]").expect("the base scene has a [task] table");
    BASE[..at].to_string()
}

/// Asserts that `text` fails to load with `Error::Scene` on exactly `field`, and that the
/// error's Display names the field.
#[track_caller]
fn expect_field(case: &str, text: &str, field: &str) {
    match Scene::from_toml_str(text) {
        Ok(_) => panic!("{case}: the scene loaded, expected an error on `{field}`"),
        Err(e @ Error::Scene { .. }) => {
            let Error::Scene { field: got, message } = &e else { unreachable!() };
            assert_eq!(got, field, "{case}: wrong field (message: {message})");
            let shown = e.to_string();
            assert!(shown.contains(field), "{case}: Display `{shown}` does not name `{field}`");
            assert!(!message.is_empty(), "{case}: empty message");
        }
        Err(e) => panic!("{case}: expected Error::Scene on `{field}`, got {e:?}"),
    }
}

/// Asserts that `text` fails to load with an `Error::Scene` (any field); returns the field.
#[track_caller]
fn expect_scene_error(case: &str, text: &str) -> String {
    match Scene::from_toml_str(text) {
        Ok(_) => panic!("{case}: the scene loaded, expected an error"),
        Err(e @ Error::Scene { .. }) => {
            let Error::Scene { field, .. } = &e else { unreachable!() };
            assert!(e.to_string().contains(field.as_str()), "{case}: Display `{e}` does not name `{field}`");
            field.clone()
        }
        Err(e) => panic!("{case}: expected Error::Scene, got {e:?}"),
    }
}

/// Pose that puts the pad centre (gripper origin) at object point `c` with rotation `theta`:
/// `c = −R(θ)ᵀ t`  ⇔  `t = −R(θ) c`.
fn pad_at(cx: f64, cz: f64, theta: f64) -> [f64; 3] {
    let (s, c) = theta.sin_cos();
    [-(c * cx - s * cz), -(s * cx + c * cz), theta]
}

// ---------------------------------------------------------------------------------------------
// The base and the bundled examples

#[test]
fn base_scene_loads() {
    let s = Scene::from_toml_str(BASE).expect("block-low-friction.toml loads");
    assert_eq!(s.name, "block-low-friction");
    assert_eq!(s.pushers.len(), 4);
    assert!(s.task.is_some());
}

#[test]
fn every_bundled_example_loads() {
    let mut n = 0;
    for entry in std::fs::read_dir(examples_dir()).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().and_then(|e| e.to_str()) != Some("toml") {
            continue;
        }
        if std::fs::read_to_string(&path).unwrap().contains("dimension = 3") {
            let s3 = regrasp::scene::spatial::Scene3::load(&path).unwrap_or_else(|e| panic!("{} does not load: {e}", path.display()));
            assert!(!s3.pushers.is_empty());
            continue;
        }
        let scene = Scene::load(&path).unwrap_or_else(|e| panic!("{} does not load: {e}", path.display()));
        assert!(!scene.pushers.is_empty(), "{}: no pushers", path.display());
        assert!(scene.length > 0.0 && scene.length.is_finite(), "{}: bad length", path.display());
        n += 1;
    }
    assert!(n >= 6, "expected at least the 6 bundled examples, found {n}");
}

#[test]
fn load_reports_a_missing_file_as_an_argument_error() {
    let err = Scene::load(&examples_dir().join("no-such-scene.toml")).unwrap_err();
    assert!(matches!(err, Error::InvalidArgument { ref name, .. } if name == "path"), "{err:?}");
}

/// The same scene written by hand as a JSON object.
const BASE_JSON: &str = r#"{
  "name": "block-low-friction",
  "object": {
    "outline": [[-0.025, -0.04], [0.025, -0.04], [0.025, 0.04], [-0.025, 0.04]],
    "mass": 0.130,
    "material": "aluminium 6061"
  },
  "grasp": { "force": 20.0, "friction": 0.6, "pad_radius": 0.007 },
  "gravity": { "direction": [0.0, -1.0], "g": 9.81 },
  "pushers": [
    { "name": "bottom", "friction": 0.25, "points": [[-0.02, -0.04], [0.02, -0.04]], "normal": [0.0, 1.0] },
    { "name": "left", "friction": 0.25, "points": [[-0.025, -0.03], [-0.025, 0.03]], "normal": [1.0, 0.0] },
    { "name": "right", "friction": 0.25, "points": [[0.025, -0.03], [0.025, 0.03]], "normal": [-1.0, 0.0] },
    { "name": "top", "friction": 0.25, "points": [[-0.02, 0.04], [0.02, 0.04]], "normal": [0.0, -1.0] }
  ],
  "task": { "start": [0.0, 0.0, 0.0], "goal": [0.012, 0.008, 0.0], "tolerance": [0.001, 0.001, 0.0175] }
}"#;

fn assert_same_scene(a: &Scene, b: &Scene, what: &str) {
    assert_eq!(a.name, b.name, "{what}: name");
    assert_eq!(a.mass, b.mass, "{what}: mass");
    assert_eq!(a.com, b.com, "{what}: com");
    assert_eq!(a.length, b.length, "{what}: length");
    assert_eq!(a.gravity_dir, b.gravity_dir, "{what}: gravity direction");
    assert_eq!(a.g, b.g, "{what}: g");
    assert_eq!(a.outline.vertices(), b.outline.vertices(), "{what}: outline");
    assert_eq!(a.friction_scale(), b.friction_scale(), "{what}: friction scale");
    assert_eq!(a.pushers.len(), b.pushers.len(), "{what}: pushers");
    for (p, q) in a.pushers.iter().zip(&b.pushers) {
        assert_eq!(p.name, q.name, "{what}: pusher name");
        assert_eq!(p.contact.points, q.contact.points, "{what}: pusher {} points", p.name);
        assert_eq!(p.contact.normal, q.contact.normal, "{what}: pusher {} normal", p.name);
        assert_eq!(p.contact.friction, q.contact.friction, "{what}: pusher {} friction", p.name);
    }
    match (a.task, b.task) {
        (None, None) => {}
        (Some(s), Some(t)) => {
            assert_eq!(s.start, t.start, "{what}: task.start");
            assert_eq!(s.goal, t.goal, "{what}: task.goal");
            assert_eq!(s.tolerance, t.tolerance, "{what}: task.tolerance");
        }
        _ => panic!("{what}: one scene has a task and the other not"),
    }
}

#[test]
fn json_scene_loads_like_the_toml_one() {
    let from_toml = Scene::from_toml_str(BASE).unwrap();
    let from_json = Scene::from_json_str(BASE_JSON).expect("the JSON scene loads");
    assert_same_scene(&from_toml, &from_json, "hand-written JSON");
}

#[test]
fn every_bundled_example_loads_from_equivalent_json() {
    for entry in std::fs::read_dir(examples_dir()).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().and_then(|e| e.to_str()) != Some("toml") {
            continue;
        }
        let text = std::fs::read_to_string(&path).unwrap();
        if text.contains("dimension = 3") {
            continue;
        }
        let value: toml::Value = toml::from_str(&text).unwrap();
        let json = serde_json::to_string_pretty(&value).unwrap();
        let a = Scene::from_toml_str(&text).unwrap();
        let b = Scene::from_json_str(&json).unwrap_or_else(|e| panic!("{} as JSON: {e}", path.display()));
        assert_same_scene(&a, &b, &path.display().to_string());
    }
}

#[test]
fn json_errors_are_scene_errors() {
    let err = Scene::from_json_str(&BASE_JSON.replace(r#""mass": 0.130"#, r#""mass": -0.130"#)).unwrap_err();
    assert!(matches!(err, Error::Scene { ref field, .. } if field == "object.mass"), "{err:?}");
    let err = Scene::from_json_str(&BASE_JSON.replace(r#""mass": 0.130"#, r#""mass": 0.130, "colour": "red""#))
        .unwrap_err();
    assert!(matches!(err, Error::Scene { .. }), "{err:?}");
    let err = Scene::from_json_str("{ not json").unwrap_err();
    assert!(matches!(err, Error::Scene { .. }), "{err:?}");
}

// ---------------------------------------------------------------------------------------------
// Positive quantities: negative, zero, missing, non-finite

/// Every bad value of a positive quantity written as `key = good` in the base.
fn check_positive(key_value: &str, field: &str) {
    let key = key_value.split('=').next().unwrap().trim();
    for (what, bad) in [
        ("negative", format!("{key} = -1.5")),
        ("zero", format!("{key} = 0.0")),
        ("integer zero", format!("{key} = 0")),
        ("negative zero", format!("{key} = -0.0")),
        ("NaN", format!("{key} = nan")),
        ("+inf", format!("{key} = inf")),
        ("-inf", format!("{key} = -inf")),
    ] {
        expect_field(&format!("{field} {what}"), &edit(key_value, &bad), field);
    }
    expect_field(&format!("{field} missing"), &edit(&format!("{key_value}\n"), ""), field);
}

#[test]
fn object_mass_must_be_positive() {
    check_positive("mass = 0.130", "object.mass");
}

#[test]
fn toml_nan_mass_is_rejected() {
    expect_field("mass = nan", &edit("mass = 0.130", "mass = nan"), "object.mass");
    expect_field("mass = -nan", &edit("mass = 0.130", "mass = -nan"), "object.mass");
}

#[test]
fn grasp_force_must_be_positive() {
    check_positive("force = 20.0", "grasp.force");
}

#[test]
fn grasp_friction_must_be_positive() {
    check_positive("friction = 0.6", "grasp.friction");
}

#[test]
fn grasp_pad_radius_must_be_positive() {
    check_positive("pad_radius = 0.007", "grasp.pad_radius");
}

#[test]
fn pusher_friction_must_not_be_negative() {
    let old = "name = \"left\"\nfriction = 0.25";
    expect_field("negative", &edit(old, "name = \"left\"\nfriction = -0.25"), "pushers[1].friction");
    expect_field("NaN", &edit(old, "name = \"left\"\nfriction = nan"), "pushers[1].friction");
    expect_field("missing", &edit(old, "name = \"left\""), "pushers[1].friction");
    // zero friction is a valid (frictionless) pusher
    Scene::from_toml_str(&edit(old, "name = \"left\"\nfriction = 0.0")).expect("a frictionless pusher is valid");
}

// ---------------------------------------------------------------------------------------------
// Outline

const OUTLINE: &str = "outline = [[-0.025, -0.04], [0.025, -0.04], [0.025, 0.04], [-0.025, 0.04]]";

#[test]
fn bow_tie_outline_is_rejected() {
    let text = edit(OUTLINE, "outline = [[-0.025, -0.04], [0.025, 0.04], [0.025, -0.04], [-0.025, 0.04]]");
    expect_field("bow-tie", &text, "object.outline");
}

#[test]
fn clockwise_outline_is_rejected() {
    let text = edit(OUTLINE, "outline = [[-0.025, -0.04], [-0.025, 0.04], [0.025, 0.04], [0.025, -0.04]]");
    expect_field("clockwise", &text, "object.outline");
}

#[test]
fn degenerate_outlines_are_rejected() {
    expect_field("two vertices", &edit(OUTLINE, "outline = [[-0.025, -0.04], [0.025, -0.04]]"), "object.outline");
    expect_field(
        "collinear",
        &edit(OUTLINE, "outline = [[-0.025, -0.04], [0.0, -0.04], [0.025, -0.04]]"),
        "object.outline",
    );
    expect_field(
        "repeated vertex",
        &edit(OUTLINE, "outline = [[-0.025, -0.04], [0.025, -0.04], [0.025, -0.04], [0.025, 0.04], [-0.025, 0.04]]"),
        "object.outline",
    );
    expect_field("missing", &edit(&format!("{OUTLINE}\n"), ""), "object.outline");
    expect_field(
        "NaN vertex",
        &edit(OUTLINE, "outline = [[-0.025, -0.04], [0.025, nan], [0.025, 0.04], [-0.025, 0.04]]"),
        "object.outline[1]",
    );
}

// ---------------------------------------------------------------------------------------------
// Pushers

#[test]
fn pusher_point_off_the_outline_is_rejected() {
    let old = "points = [[-0.02, -0.04], [0.02, -0.04]]";
    // inside the block, 10 mm above the bottom face; outside it
    for (what, first) in [("inside", "[-0.02, -0.03]"), ("outside", "[-0.02, -0.05]")] {
        expect_field(what, &edit(old, &format!("points = [{first}, [0.02, -0.04]]")), "pushers[0].points[0]");
    }
}

#[test]
fn bad_pusher_normals_are_rejected() {
    let old = "points = [[-0.02, -0.04], [0.02, -0.04]]\nnormal = [0.0, 1.0]";
    // pointing out; still into the object but tilted by ~6 degrees from the face normal (a line
    // pusher's normal must be perpendicular to its line); zero
    for (what, normal) in [("outward", "[0.0, -1.0]"), ("tilted", "[0.1, 0.995]"), ("zero normal", "[0.0, 0.0]")] {
        let text = edit(old, &format!("points = [[-0.02, -0.04], [0.02, -0.04]]\nnormal = {normal}"));
        expect_field(what, &text, "pushers[0].normal");
    }
}

#[test]
fn duplicate_pusher_names_are_rejected() {
    let text = edit("name = \"left\"", "name = \"bottom\"");
    expect_field("duplicate", &text, "pushers[1].name");
}

#[test]
fn pushers_are_required() {
    let at = BASE.find("[[pushers]]").unwrap();
    let task = BASE.find("[task]").unwrap();
    let text = format!("{}{}", &BASE[..at], &BASE[task..]);
    expect_field("no pushers", &text, "pushers");
}

// ---------------------------------------------------------------------------------------------
// Gravity, support, task

#[test]
fn gravity_direction_must_be_unit() {
    let old = "direction = [0.0, -1.0]";
    for (what, d) in [("norm 2", "[0.0, -2.0]"), ("norm 0.5", "[0.3, -0.4]"), ("zero", "[0.0, 0.0]"), ("NaN", "[nan, -1.0]")] {
        expect_field(what, &edit(old, &format!("direction = {d}")), "gravity.direction");
    }
    // a unit vector other than -Z is fine
    Scene::from_toml_str(&edit(old, "direction = [-0.6, -0.8]")).expect("a tilted unit gravity is valid");
}

#[test]
fn grasp_scene_needs_a_task() {
    expect_field("no task", &without_task(), "task");
}

#[test]
fn goal_with_the_pad_off_the_object_is_rejected() {
    let cases = [
        // pad centre at object point (-0.03, 0): outside the 50 mm wide block
        ("goal off the object", "goal = [0.012, 0.008, 0.0]", "goal = [0.03, 0.0, 0.0]", "task.goal"),
        // pad centre inside but 5 mm from the edge, with a 7 mm pad
        ("goal pad overhangs", "goal = [0.012, 0.008, 0.0]", "goal = [0.02, 0.0, 0.0]", "task.goal"),
        ("start pad overhangs", "start = [0.0, 0.0, 0.0]", "start = [0.0, 0.035, 0.0]", "task.start"),
    ];
    for (what, old, new, field) in cases {
        expect_field(what, &edit(old, new), field);
    }
}

#[test]
fn tolerance_components_must_be_positive() {
    let old = "tolerance = [0.001, 0.001, 0.0175]";
    let cases = [("zero theta tol", "[0.001, 0.001, 0.0]", 2), ("negative x tol", "[-0.001, 0.001, 0.0175]", 0), ("zero z tol", "[0.001, 0.0, 0.0175]", 1)];
    for (what, tol, k) in cases {
        expect_field(what, &edit(old, &format!("tolerance = {tol}")), &format!("task.tolerance[{k}]"));
    }
}

#[test]
fn object_too_heavy_for_the_grasp_is_rejected() {
    // 2 x 20 N x 0.6 = 24 N of pad friction against 981 N of weight
    expect_field("100 kg", &edit("mass = 0.130", "mass = 100.0"), "grasp.force");
    // just above the limit for the translational part alone: m g > 2 μ N
    let m = 2.0 * 20.0 * 0.6 / 9.81 * 1.01;
    expect_field("just too heavy", &edit("mass = 0.130", &format!("mass = {m}")), "grasp.force");
}

#[test]
fn grasp_and_surface_together_are_rejected() {
    let text = edit("[gravity]", "[surface]\nfriction = 0.35\n\n[gravity]");
    let field = expect_scene_error("grasp + surface", &text);
    assert!(field == "surface" || field == "grasp", "grasp + surface: unexpected field `{field}`");
}

#[test]
fn a_scene_needs_a_support() {
    let at = BASE.find("[grasp]").unwrap();
    let gr = BASE.find("[gravity]").unwrap();
    let text = format!("{}{}", &BASE[..at], &BASE[gr..]);
    let field = expect_scene_error("no support", &text);
    assert!(field == "grasp" || field == "surface", "no support: unexpected field `{field}`");
}

#[test]
fn unknown_keys_are_rejected() {
    let material = "material = \"aluminium 6061\"";
    expect_scene_error("unknown object key", &edit(material, &format!("{material}\ncolour = \"red\"")));
    expect_scene_error("unknown grasp key", &edit("pad_radius = 0.007", "pad_radius = 0.007\npad_radus = 0.007"));
    expect_scene_error("unknown pusher key", &edit("name = \"left\"", "name = \"left\"\nstiffness = 1.0"));
    expect_scene_error("unknown top-level key", &format!("version = 2\n{BASE}"));
    expect_scene_error("unknown table", &format!("{BASE}\n[camera]\nfov = 1.0\n"));
}

#[test]
fn malformed_toml_is_a_scene_error() {
    expect_scene_error("syntax", &edit("mass = 0.130", "mass = "));
    expect_scene_error("type", &edit("mass = 0.130", "mass = \"heavy\""));
}

// ---------------------------------------------------------------------------------------------
// Admissibility

#[test]
fn block_admissibility_at_the_edge() {
    // pad radius 7 mm in a 50 mm wide block: the pad centre may come within 18 mm of the centre
    let s = Scene::from_toml_str(BASE).unwrap();
    assert!(s.admissible(&[0.0179, 0.0, 0.0]), "pad centre 7.1 mm from the left face");
    assert!(!s.admissible(&[0.0181, 0.0, 0.0]), "pad centre 6.9 mm from the left face");
    assert!(s.admissible(&[-0.0179, 0.0, 0.0]), "pad centre 7.1 mm from the right face");
    assert!(!s.admissible(&[-0.0181, 0.0, 0.0]), "pad centre 6.9 mm from the right face");
    // 80 mm tall: 33 mm up or down
    assert!(s.admissible(&[0.0, 0.0329, 0.0]) && !s.admissible(&[0.0, 0.0331, 0.0]));
    assert!(s.admissible(&[0.0, -0.0329, 0.0]) && !s.admissible(&[0.0, -0.0331, 0.0]));
    assert!(s.pad_clearance(&[0.0179, 0.0, 0.0]) > 0.0);
    assert!(s.pad_clearance(&[0.0181, 0.0, 0.0]) < 0.0);
    assert!(s.check_pose(&[0.0181, 0.0, 0.0]).is_err());
    assert!(!s.admissible(&[f64::NAN, 0.0, 0.0]));
}

#[test]
fn block_admissibility_with_rotation() {
    // c = −Rᵀ t: the same object point with the object rotated must give the same answer
    let s = Scene::from_toml_str(BASE).unwrap();
    for theta in [-1.0, -0.3, 0.2, 0.7, 2.5] {
        assert!(s.admissible(&pad_at(-0.0179, 0.0, theta)), "theta {theta}: 7.1 mm clearance");
        assert!(!s.admissible(&pad_at(-0.0181, 0.0, theta)), "theta {theta}: 6.9 mm clearance");
        assert!(s.admissible(&pad_at(0.0, 0.0329, theta)), "theta {theta}: 7.1 mm from the top");
        assert!(!s.admissible(&pad_at(0.0, 0.0331, theta)), "theta {theta}: 6.9 mm from the top");
    }
    // with theta = 0, pad_at(-0.0179, 0) is the pose [0.0179, 0, 0]
    assert_eq!(pad_at(-0.0179, 0.0, 0.0), [0.0179, -0.0, 0.0]);
}

#[test]
fn t_shape_notch_is_not_admissible() {
    let s = Scene::load(&examples_dir().join("t-shape.toml")).unwrap();
    // (0.025, 0.0) lies in the notch right of the stem and below the bar: off the object
    for theta in [0.0, 0.4, -0.8] {
        let q = pad_at(0.025, 0.0, theta);
        assert!(!s.admissible(&q), "theta {theta}: pad centre in the notch at {q:?}");
    }
    assert!(!s.admissible(&[-0.025, 0.0, 0.0]));
    // in the bar, right of the notch (10 mm from the bar's long faces, 15 mm from its end)
    assert!(s.admissible(&pad_at(0.025, 0.03, 0.0)));
    // in the stem, well clear of its sides
    assert!(s.admissible(&pad_at(0.0, -0.01, 0.0)));
    // in the bar but overlapping the notch (4 mm above it, pad radius 6 mm)
    assert!(!s.admissible(&pad_at(0.014, 0.024, 0.0)));
    // off the object, 7.07 mm diagonally from the reflex corner (0.01, 0.02)
    assert!(!s.admissible(&pad_at(0.015, 0.015, 0.0)));
    // on the object just above the stem, 8.5 mm from the reflex corner (0.01, 0.02) of the notch
    assert!(s.admissible(&pad_at(0.004, 0.026, 0.0)));
}

// ---------------------------------------------------------------------------------------------
// Regressions

/// A TOML error names the key's dotted path and the line the offending key starts on (the
/// line was one short when the error started a line).
#[test]
fn toml_error_names_the_offending_line() {
    let text = edit("material = \"aluminium 6061\"", "material = \"aluminium 6061\"\ncolour = \"red\"");
    let line = text.lines().position(|l| l.starts_with("colour")).unwrap() + 1;
    let field = expect_scene_error("unknown key", &text);
    assert_eq!(field, "object.colour");
    let msg = Scene::from_toml_str(&text).unwrap_err().to_string();
    assert!(msg.contains(&format!("line {line}")), "{msg}");
    // a value of the wrong type names its field too
    let text = edit("mass = 0.130", "mass = \"heavy\"");
    assert_eq!(expect_scene_error("string mass", &text), "object.mass");
}

/// An object that slides down its incline is reported on a surface field (was `grasp.force`),
/// with or without a task.
#[test]
fn sliding_surface_scene_names_a_surface_field() {
    let text = include_str!("../../../examples/block-on-incline.toml");
    // tan(0.2) = 0.203 > μ = 0.1: the block slides down the incline
    let text = edit_text(text, "friction = 0.35", "friction = 0.1");
    let text = format!("{text}\n[task]\nstart = [0.0, 0.0, 0.0]\ngoal = [0.0, 0.001, 0.0]\ntolerance = [0.001, 0.001, 0.01]\n");
    let field = expect_scene_error("sliding surface", &text);
    assert!(field.starts_with("surface."), "field `{field}` for a scene without a grasp");
    let no_task = edit_text(include_str!("../../../examples/block-on-incline.toml"), "friction = 0.35", "friction = 0.1");
    let field = expect_scene_error("sliding surface without a task", &no_task);
    assert!(field.starts_with("surface."), "field `{field}`");
}

/// Pushers along a whole face, at either corner, and with normals that do not fit the outline.
#[test]
fn pusher_geometry_is_checked_against_the_outline() {
    let base = include_str!("../../../examples/block-low-friction.toml");
    let with_bottom = |points: &str, normal: &str| {
        base.replace("points = [[-0.02, -0.04], [0.02, -0.04]]\nnormal = [0.0, 1.0]", &format!("points = {points}\nnormal = {normal}"))
    };
    // a line pusher covering the whole bottom face, corners included
    assert!(Scene::from_toml_str(&with_bottom("[[-0.025, -0.04], [0.025, -0.04]]", "[0.0, 1.0]")).is_ok());
    // point pushers at either bottom corner, pushing up
    assert!(Scene::from_toml_str(&with_bottom("[[-0.025, -0.04]]", "[0.0, 1.0]")).is_ok());
    assert!(Scene::from_toml_str(&with_bottom("[[0.025, -0.04]]", "[0.0, 1.0]")).is_ok());
    // at a corner, diagonally inwards is fine, outwards is not
    assert!(Scene::from_toml_str(&with_bottom("[[0.025, -0.04]]", "[-0.7071, 0.7071]")).is_ok());
    let e = Scene::from_toml_str(&with_bottom("[[0.025, -0.04]]", "[0.7071, 0.7071]")).unwrap_err();
    assert!(e.to_string().contains("pushers[0].normal"), "{e}");
    // a point pusher in the middle of a face must push along the face's normal
    let e = Scene::from_toml_str(&with_bottom("[[0.0, -0.04]]", "[0.9987, 0.05]")).unwrap_err();
    assert!(e.to_string().contains("pushers[0].normal"), "{e}");
    // a line pusher whose segment leaves the outline (crosses the object) is rejected
    let t = include_str!("../../../examples/t-shape.toml").replace(
        "points = [[-0.03, 0.04], [0.03, 0.04]]\nnormal = [0.0, -1.0]",
        "points = [[-0.035, 0.02], [0.015, 0.02]]\nnormal = [0.0, 1.0]",
    );
    let e = Scene::from_toml_str(&t).unwrap_err();
    assert!(e.to_string().contains("pushers[0]"), "{e}");
}
