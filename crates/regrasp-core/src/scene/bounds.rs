//! The physical ranges every scene number must lie in, stated once (`docs/scene-file.md`,
//! "Bounds"). They are wide enough that no gripper, object or fixture a robot handles meets
//! them by accident, and narrow enough to exclude nonsense (1e300, 1e-300) that would overflow
//! the mechanics into inf or NaN.

use crate::error::{Error, Result};

/// A closed interval `[lo, hi]` of admissible values, in `unit`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bound {
    pub lo: f64,
    pub hi: f64,
    pub unit: &'static str,
}

impl Bound {
    const fn new(lo: f64, hi: f64, unit: &'static str) -> Self {
        Bound { lo, hi, unit }
    }

    /// `v` itself when finite and within the bound, else an error naming `field` and the range.
    pub fn check(&self, field: &str, v: f64) -> Result<f64> {
        if v.is_finite() && v >= self.lo && v <= self.hi {
            return Ok(v);
        }
        let unit = if self.unit.is_empty() { String::new() } else { format!(" {}", self.unit) };
        Err(Error::scene(field, format!("must be a number in [{:e}, {:e}]{unit} (got {v})", self.lo, self.hi)))
    }

    /// Like [`Self::check`] for a call argument `name` (an [`Error::InvalidArgument`]).
    pub fn check_arg(&self, name: &str, v: f64) -> Result<f64> {
        self.check(name, v).map_err(|e| match e {
            Error::Scene { message, .. } => Error::arg(name, message),
            other => other,
        })
    }

    /// Every component of `v` checked (fields `field[k]`).
    pub fn check_each<const N: usize>(&self, field: &str, v: [f64; N]) -> Result<[f64; N]> {
        for (k, x) in v.iter().enumerate() {
            self.check(&format!("{field}[{k}]"), *x)?;
        }
        Ok(v)
    }
}

/// Object size [m]: a planar outline's bounding-box diagonal, a box's sides, a sphere's radius,
/// a mesh's largest distance from its origin (0.1 mm to 10 m).
pub const SIZE: Bound = Bound::new(1e-4, 10.0, "m");
/// Finger pad radius and rectangular pad sides [m] (1 µm to 10 m).
pub const PAD: Bound = Bound::new(1e-6, 10.0, "m");
/// Any coordinate of a point or a position [m] (outline vertices, centre of mass, pusher points,
/// task positions): within 100 m of the frame's origin.
pub const COORD: Bound = Bound::new(-100.0, 100.0, "m");
/// Angles of planar poses [rad] (±1000 rad, about 160 turns).
pub const ANGLE: Bound = Bound::new(-1e3, 1e3, "rad");
/// Object mass [kg].
pub const MASS: Bound = Bound::new(1e-9, 1e4, "kg");
/// Grip force of each finger [N]: up to the mechanics' largest normal force.
pub const FORCE: Bound = Bound::new(1e-6, crate::mechanics::limit_surface::MAX_NORMAL_FORCE, "N");
/// Coulomb coefficient of a support (finger pads, a surface).
pub const SUPPORT_FRICTION: Bound = Bound::new(1e-6, 100.0, "");
/// Coulomb coefficient of a pusher (0: frictionless).
pub const PUSHER_FRICTION: Bound = Bound::new(0.0, 100.0, "");
/// Gravitational acceleration [m/s²] (0: gravity-free).
pub const G: Bound = Bound::new(0.0, 1e3, "m/s²");
/// Norm of a direction given as a vector that is normalized (a pusher normal, a quaternion).
pub const DIRECTION_NORM: Bound = Bound::new(1e-6, 1e6, "");
/// Task tolerance on a position component [m].
pub const TOL_POSITION: Bound = Bound::new(1e-9, 10.0, "m");
/// Task tolerance on an angle [rad].
pub const TOL_ANGLE: Bound = Bound::new(1e-9, std::f64::consts::TAU, "rad");

/// Most vertices of a planar outline (its simplicity test is a sweep over them).
pub const MAX_OUTLINE_VERTICES: usize = 10_000;
/// Most vertices and triangles of a 3-D mesh (its convexity test is vertices × triangles).
pub const MAX_MESH_VERTICES: usize = 5_000;
pub const MAX_MESH_TRIANGLES: usize = 10_000;
/// The most convex parts of a non-convex 3-D object.
pub const MAX_MESH_PARTS: usize = 64;
/// Most points of one 3-D pusher.
pub const MAX_PUSHER_POINTS: usize = 1_000;
/// Most pushers in a scene.
pub const MAX_PUSHERS: usize = 1_000;

/// The most bytes one input file may hold (a scene, a mesh, a plan, a workcell, a grasp graph, a
/// trajectory, an object file): a larger one, or an endless stream, is refused after this much.
pub const MAX_FILE_BYTES: u64 = 64 << 20;
/// The deepest nesting of arrays and tables (objects) in a TOML or JSON input.
pub const MAX_NESTING: usize = 32;
/// The most steps (poses after the start) of a plan file or a plan given to execute.
pub const MAX_PLAN_STEPS: usize = 1_000;
/// The most fixed features of a workcell.
pub const MAX_WORKCELL_FEATURES: usize = 256;
/// The most nodes (grasps) and edges (regrasp actions) of a grasp graph file.
pub const MAX_GRAPH_NODES: usize = 10_000;
pub const MAX_GRAPH_EDGES: usize = 100_000;
/// The most samples of a trajectory file.
pub const MAX_TRAJECTORY_SAMPLES: usize = 1_000_000;

/// The input limits by name, for the bindings and the docs (`docs/guarantees.md`, "Limits").
pub const LIMITS: [(&str, f64); 15] = [
    ("file_bytes", MAX_FILE_BYTES as f64),
    ("nesting", MAX_NESTING as f64),
    ("plan_steps", MAX_PLAN_STEPS as f64),
    ("workcell_features", MAX_WORKCELL_FEATURES as f64),
    ("graph_nodes", MAX_GRAPH_NODES as f64),
    ("graph_edges", MAX_GRAPH_EDGES as f64),
    ("trajectory_samples", MAX_TRAJECTORY_SAMPLES as f64),
    ("outline_vertices", MAX_OUTLINE_VERTICES as f64),
    ("mesh_vertices", MAX_MESH_VERTICES as f64),
    ("mesh_triangles", MAX_MESH_TRIANGLES as f64),
    ("mesh_parts", MAX_MESH_PARTS as f64),
    ("pusher_points", MAX_PUSHER_POINTS as f64),
    ("pushers", MAX_PUSHERS as f64),
    ("coordinate", COORD.hi),
    ("angle", ANGLE.hi),
];

/// The UTF-8 text of the file at `path`, read at most [`MAX_FILE_BYTES`]: an error naming
/// `field` (a scene error when `scene`, else an argument error) when it cannot be read, holds
/// more, or is not text.
pub fn read_file(path: &std::path::Path, field: &str, scene: bool) -> Result<String> {
    use std::io::Read;
    let fail = |m: String| if scene { Error::scene(field, m) } else { Error::arg(field, m) };
    let f = std::fs::File::open(path).map_err(|e| fail(format!("cannot read {}: {e}", path.display())))?;
    let mut data = Vec::new();
    f.take(MAX_FILE_BYTES + 1).read_to_end(&mut data).map_err(|e| fail(format!("cannot read {}: {e}", path.display())))?;
    if data.len() as u64 > MAX_FILE_BYTES {
        return Err(fail(format!("{} holds more than {MAX_FILE_BYTES} bytes (the most an input file may hold)", path.display())));
    }
    String::from_utf8(data).map_err(|e| fail(format!("{} is not UTF-8 text (at byte {})", path.display(), e.utf8_error().valid_up_to())))
}

/// How far a pusher point may lie from the object's boundary [m] and still be taken as on it
/// (then moved onto it, with a note): scene files are measured and rounded to 0.1 mm.
pub const SNAP_DISTANCE: f64 = 1e-4;

/// An error when `n` items exceed `max`.
pub fn count(field: &str, n: usize, max: usize, what: &str) -> Result<()> {
    if n > max {
        return Err(Error::scene(field, format!("has {n} {what}; at most {max} are allowed")));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_endless_file_is_refused_after_the_limit() {
        let e = read_file(std::path::Path::new("/dev/zero"), "object.mesh", true).unwrap_err();
        assert!(e.to_string().contains("object.mesh") && e.to_string().contains("more than"), "{e}");
    }

    #[test]
    fn a_file_that_is_not_text_is_refused_naming_the_field() {
        let p = std::env::temp_dir().join(format!("regrasp-bounds-{}.obj", std::process::id()));
        std::fs::write(&p, [0xffu8, 0xfe, 0]).unwrap();
        let e = read_file(&p, "path", false).unwrap_err();
        std::fs::remove_file(&p).ok();
        assert!(e.to_string().contains("path") && e.to_string().contains("UTF-8"), "{e}");
    }

    #[test]
    fn a_deeply_nested_scene_is_a_scene_error() {
        let deep = format!("name = \"x\"\nextra = {}1{}\n", "[".repeat(5000), "]".repeat(5000));
        assert!(crate::scene::planar::Scene::from_toml_str(&deep).is_err());
        assert!(crate::scene::spatial::Scene3::from_toml_str(&format!("dimension = 3\n{deep}"), None).is_err());
    }
}
