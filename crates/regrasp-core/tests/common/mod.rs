//! Random scenes for property tests.
#![allow(dead_code)]

use proptest::prelude::*;
use regrasp::scene::planar_file::{RawGrasp, RawGravity, RawObject, RawPusher, RawScene, RawTask};
use regrasp::Scene;

/// Parameters of a random block scene with one pusher.
#[derive(Clone, Debug)]
pub struct BlockCase {
    pub w: f64,
    pub h: f64,
    pub mass: f64,
    pub force: f64,
    pub mu_s: f64,
    pub pad: f64,
    pub mu_p: f64,
    /// face 0..4 (bottom, right, top, left)
    pub face: usize,
    /// line pusher (true) or point pusher
    pub line: bool,
    /// position of a point pusher along the face, in (-0.45, 0.45) of its length
    pub at: f64,
    /// gravity direction angle from -Z
    pub gdir: f64,
    pub g: f64,
    pub pose: [f64; 3],
    /// offset of the centre of mass from the centroid, as a share of the half sizes
    pub com: [f64; 2],
}

pub fn block_case() -> impl Strategy<Value = BlockCase> {
    (
        (0.03f64..0.1, 0.03f64..0.1, 0.05f64..0.5, 5.0f64..60.0, 0.3f64..1.0, 0.003f64..0.008),
        (0.0f64..1.2, 0usize..4, any::<bool>(), -0.45f64..0.45, -3.14f64..3.14, 0.0f64..12.0),
        (-0.3f64..0.3, -0.3f64..0.3, -3.14f64..3.14, -0.3f64..0.3, -0.3f64..0.3),
    )
        .prop_map(|((w, h, mass, force, mu_s, pad), (mu_p, face, line, at, gdir, g), (px, pz, th, cx, cz))| {
            BlockCase {
                w,
                h,
                mass,
                force,
                mu_s,
                pad,
                mu_p,
                face,
                line,
                at,
                gdir,
                g,
                // pad centre inside the block with clearance
                pose: pad_pose(px * (w / 2.0 - pad), pz * (h / 2.0 - pad), th),
                com: [cx, cz],
            }
        })
}

/// Pose that puts the pad centre (gripper origin) at object point `(cx, cz)`: t = −R c.
pub fn pad_pose(cx: f64, cz: f64, th: f64) -> [f64; 3] {
    let (s, c) = th.sin_cos();
    [-(c * cx - s * cz), -(s * cx + c * cz), th]
}

/// A scene of `outline` (CCW) held by a disc pad of radius `pad` with its centre at `start` and
/// at `goal` (object frame) for the task; one line pusher on the middle of the first edge. None
/// when the loader refuses it (e.g. the pad off the object).
pub fn outline_scene(outline: Vec<[f64; 2]>, pad: f64, start: [f64; 2], goal: [f64; 2]) -> Option<Scene> {
    let (a, b) = (outline[0], outline[1]);
    let (dx, dz) = (b[0] - a[0], b[1] - a[1]);
    Scene::from_raw(RawScene {
        name: Some("outline".into()),
        object: Some(RawObject { outline: Some(outline), mass: Some(0.02), com: None, material: None }),
        grasp: Some(RawGrasp { force: Some(40.0), friction: Some(0.8), pad_radius: Some(pad), ..Default::default() }),
        pushers: Some(vec![RawPusher {
            name: Some("p".into()),
            friction: Some(0.5),
            points: Some(vec![[a[0] + 0.3 * dx, a[1] + 0.3 * dz], [a[0] + 0.7 * dx, a[1] + 0.7 * dz]]),
            normal: Some([-dz, dx]),
        }]),
        task: Some(RawTask {
            start: Some(pad_pose(start[0], start[1], 0.0)),
            goal: Some(pad_pose(goal[0], goal[1], 0.0)),
            tolerance: Some([1e-3, 1e-3, 0.0175]),
        }),
        ..Default::default()
    })
    .ok()
}

/// A star-shaped outline about the origin: `radii` [m] at equal angles, CCW.
pub fn star(radii: &[f64]) -> Vec<[f64; 2]> {
    let n = radii.len() as f64;
    radii.iter().enumerate().map(|(i, r)| {
        let a = 2.0 * std::f64::consts::PI * i as f64 / n;
        [r * a.cos(), r * a.sin()]
    }).collect()
}

/// [`raw_scene`] on the ellipsoidal limit surface (eq 3.7, `k = 0.6 r`).
pub fn raw_scene_ellipsoid(b: &BlockCase) -> RawScene {
    let mut raw = raw_scene(b);
    if let Some(g) = raw.grasp.as_mut() {
        g.limit_surface = Some("ellipsoid".into());
    }
    raw
}

pub fn raw_scene(b: &BlockCase) -> RawScene {
    let (hw, hh) = (b.w / 2.0, b.h / 2.0);
    let outline = vec![[-hw, -hh], [hw, -hh], [hw, hh], [-hw, hh]];
    let (points, normal) = match b.face {
        0 => (vec![[-0.8 * hw, -hh], [0.8 * hw, -hh]], [0.0, 1.0]),
        1 => (vec![[hw, -0.8 * hh], [hw, 0.8 * hh]], [-1.0, 0.0]),
        2 => (vec![[0.8 * hw, hh], [-0.8 * hw, hh]], [0.0, -1.0]),
        _ => (vec![[-hw, 0.8 * hh], [-hw, -0.8 * hh]], [1.0, 0.0]),
    };
    let points = if b.line {
        points
    } else {
        let t = 0.5 + b.at;
        vec![[points[0][0] * (1.0 - t) + points[1][0] * t, points[0][1] * (1.0 - t) + points[1][1] * t]]
    };
    RawScene {
        name: Some("prop".into()),
        object: Some(RawObject {
            outline: Some(outline),
            mass: Some(b.mass),
            com: Some([b.com[0] * hw, b.com[1] * hh]),
            material: None,
        }),
        grasp: Some(RawGrasp {
            force: Some(b.force),
            friction: Some(b.mu_s),
            pad_radius: Some(b.pad),
            ..Default::default()
        }),
        gravity: Some(RawGravity { direction: Some([b.gdir.sin(), -b.gdir.cos()]), g: Some(b.g) }),
        pushers: Some(vec![RawPusher {
            name: Some("p".into()),
            friction: Some(b.mu_p),
            points: Some(points),
            normal: Some(normal),
        }]),
        task: Some(RawTask { start: Some(b.pose), goal: Some(b.pose), tolerance: Some([1e-3, 1e-3, 1e-2]) }),
        ..Default::default()
    }
}

/// The scene, or None when the random grasp cannot hold the object (rejected at load).
/// [`scene`] on the ellipsoidal limit surface.
pub fn scene_ellipsoid(b: &BlockCase) -> Option<Scene> {
    Scene::from_raw(raw_scene_ellipsoid(b)).ok()
}

pub fn scene(b: &BlockCase) -> Option<Scene> {
    Scene::from_raw(raw_scene(b)).ok()
}
