//! The 3-D scene file (TOML, `dimension = 3`; `docs/scene-file.md`): its raw layout and its
//! validation field by field into a [`Scene3`].

use crate::error::{Error, Result};
use crate::pose::spatial::{from_array as pose_from_array, V3};
use crate::scene::spatial::{surface_distance, ConvexMesh, Pusher3, Scene3};
use nalgebra::{Isometry3, Matrix3};
use serde::Deserialize;
use std::path::Path;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Raw {
    dimension: Option<u32>,
    name: Option<String>,
    #[allow(dead_code)] // documentation only
    description: Option<String>,
    object: Option<RawObject>,
    grasp: Option<RawGrasp>,
    gravity: Option<RawGravity>,
    pushers: Option<Vec<RawPusher>>,
    task: Option<RawTask>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawObject {
    shape: Option<String>,
    size: Option<[f64; 3]>,
    mesh: Option<String>,
    radius: Option<f64>,
    mass: Option<f64>,
    com: Option<[f64; 3]>,
    #[allow(dead_code)] // documentation only
    material: Option<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawGrasp {
    force: Option<f64>,
    friction: Option<f64>,
    pad_radius: Option<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawGravity {
    direction: Option<[f64; 3]>,
    g: Option<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawPusher {
    name: Option<String>,
    friction: Option<f64>,
    points: Option<Vec<[f64; 3]>>,
    normal: Option<[f64; 3]>,
    plane: Option<bool>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawTask {
    start: Option<[f64; 7]>,
    goal: Option<[f64; 7]>,
    tolerance: Option<[f64; 4]>,
}

fn req<T>(field: &str, v: Option<T>) -> Result<T> {
    v.ok_or_else(|| Error::scene(field, "is required"))
}

fn pos(field: &str, v: Option<f64>) -> Result<f64> {
    let v = req(field, v)?;
    if !(v.is_finite() && v > 0.0) {
        return Err(Error::scene(field, format!("must be a positive number (got {v})")));
    }
    Ok(v)
}

fn vec3(field: &str, v: [f64; 3]) -> Result<V3> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(V3::new(v[0], v[1], v[2]))
    } else {
        Err(Error::scene(field, "has a non-finite component"))
    }
}

impl Scene3 {
    /// Parses and validates a 3-D scene; `base` resolves a relative mesh path.
    pub fn from_toml_str(text: &str, base: Option<&Path>) -> Result<Self> {
        let de = toml::Deserializer::new(text);
        let raw: Raw = serde_path_to_error::deserialize(de).map_err(|e| {
            let path = e.path().to_string();
            Error::scene(if path.is_empty() || path == "." { "(toml)".to_string() } else { path }, e.into_inner().message().to_string())
        })?;
        if raw.dimension != Some(3) {
            return Err(Error::scene("dimension", "a 3-D scene says `dimension = 3`"));
        }
        let name = req("name", raw.name)?;
        let obj = req("object", raw.object)?;
        let (mesh, sphere) = shape(&obj, base)?;
        let (mass, com, inertia) = mass_properties(&obj, &mesh, sphere)?;
        let gr = req("grasp", raw.grasp)?;
        let (start, goal, tolerance) = task(req("task", raw.task)?)?;
        let s = Scene3 {
            name,
            pushers: pushers(req("pushers", raw.pushers)?, &mesh, sphere)?,
            mesh,
            sphere,
            mass,
            com,
            inertia,
            grip_force: pos("grasp.force", gr.force)?,
            grip_friction: pos("grasp.friction", gr.friction)?,
            pad_radius: pos("grasp.pad_radius", gr.pad_radius)?,
            gravity: gravity(raw.gravity)?,
            start,
            goal,
            tolerance,
            length: (inertia.trace() / (2.0 * mass)).sqrt(),
        };
        for (field, p) in [("task.start", &s.start), ("task.goal", &s.goal)] {
            if s.pad_contacts(p).iter().any(|c| c.is_empty()) {
                return Err(Error::scene(field, "a finger pad does not touch the object at this pose"));
            }
        }
        Ok(s)
    }

    pub fn load(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::arg("path", format!("cannot read {}: {e}", path.display())))?;
        Self::from_toml_str(&text, path.parent())
    }

}

/// The object's surface: a box, a convex OBJ mesh (relative to `base`) or a sphere (with its
/// radius; its mesh an icosphere for drawing and contacts).
fn shape(obj: &RawObject, base: Option<&Path>) -> Result<(ConvexMesh, Option<f64>)> {
    let mesh = match obj.shape.as_deref() {
        Some("box") => {
            let s = vec3("object.size", req("object.size", obj.size)?)?;
            if s.iter().any(|x| !(*x > 0.0)) {
                return Err(Error::scene("object.size", "every size must be positive"));
            }
            ConvexMesh::cuboid(&s)
        }
        Some("mesh") => {
            let file = req("object.mesh", obj.mesh.clone())?;
            let path = base.map(|b| b.join(&file)).unwrap_or_else(|| file.clone().into());
            let text = std::fs::read_to_string(&path)
                .map_err(|e| Error::scene("object.mesh", format!("cannot read {}: {e}", path.display())))?;
            ConvexMesh::from_obj(&text).map_err(|e| Error::scene("object.mesh", e))?
        }
        Some("sphere") => ConvexMesh::icosphere(pos("object.radius", obj.radius)?, 2),
        Some(other) => return Err(Error::scene("object.shape", format!("must be \"box\", \"mesh\" or \"sphere\" (got \"{other}\")"))),
        None => return Err(Error::scene("object.shape", "is required (\"box\", \"mesh\" or \"sphere\")")),
    };
    let sphere = if obj.shape.as_deref() == Some("sphere") { obj.radius } else { None };
    if sphere.is_none() && obj.radius.is_some() {
        return Err(Error::scene("object.radius", "is for shape = \"sphere\""));
    }
    if sphere.is_some() {
        if let Some(f) = [("object.size", obj.size.is_some()), ("object.mesh", obj.mesh.is_some())].iter().find(|f| f.1) {
            return Err(Error::scene(f.0, "is not for shape = \"sphere\" (give `radius`)"));
        }
    }
    Ok((mesh, sphere))
}

/// Mass [kg], centre of mass (default: the volume centroid; inside the object) and inertia about
/// it [kg m²] of a uniform-density object (a moved centre of mass shifts the inertia by the
/// parallel-axis rule).
fn mass_properties(obj: &RawObject, mesh: &ConvexMesh, sphere: Option<f64>) -> Result<(f64, V3, Matrix3<f64>)> {
    let mass = pos("object.mass", obj.mass)?;
    let (centroid, inertia_unit) = match sphere {
        // a solid sphere: I = (2/5) r² per unit mass
        Some(r) => (V3::zeros(), Matrix3::identity() * 0.4 * r * r),
        None => {
            let (_, c, i) = mesh.mass_properties();
            (c, i)
        }
    };
    let com = match obj.com {
        Some(c) => vec3("object.com", c)?,
        None => centroid,
    };
    if surface_distance(mesh, sphere, &com) > 0.0 {
        return Err(Error::scene("object.com", "must lie inside the object"));
    }
    let d = com - centroid;
    let inertia = inertia_unit * mass - (Matrix3::identity() * d.norm_squared() - d * d.transpose()) * mass;
    Ok((mass, com, inertia))
}

/// The gravity vector [m/s²] in the gripper frame (default `[0, 0, −9.81]`).
fn gravity(gv: Option<RawGravity>) -> Result<V3> {
    let Some(gv) = gv else { return Ok(V3::new(0.0, 0.0, -9.81)) };
    let d = vec3("gravity.direction", gv.direction.unwrap_or([0.0, 0.0, -1.0]))?;
    if (d.norm() - 1.0).abs() > 1e-3 {
        return Err(Error::scene("gravity.direction", "must be a unit vector"));
    }
    let g = gv.g.unwrap_or(9.81);
    if !(g >= 0.0 && g.is_finite()) {
        return Err(Error::scene("gravity.g", "must be a non-negative number"));
    }
    Ok(d.normalize() * g)
}

/// The pushers (at least one, unique names): planes, or point sets on the object's surface
/// with an inward normal.
fn pushers(raw: Vec<RawPusher>, mesh: &ConvexMesh, sphere: Option<f64>) -> Result<Vec<Pusher3>> {
    let size = mesh.vertices.iter().map(|v| v.norm()).fold(0.0, f64::max);
    let mut out: Vec<Pusher3> = Vec::new();
    for (i, p) in raw.into_iter().enumerate() {
        let f = format!("pushers[{i}]");
        let pusher = self::pusher(&f, p, mesh, sphere, size)?;
        if out.iter().any(|q| q.name == pusher.name) {
            return Err(Error::scene(format!("{f}.name"), format!("`{}` is used twice", pusher.name)));
        }
        out.push(pusher);
    }
    if out.is_empty() {
        return Err(Error::scene("pushers", "at least one [[pushers]] is required"));
    }
    Ok(out)
}

/// One pusher (`f` its field path).
fn pusher(f: &str, p: RawPusher, mesh: &ConvexMesh, sphere: Option<f64>, size: f64) -> Result<Pusher3> {
    let name = req(&format!("{f}.name"), p.name)?;
    let friction = req(&format!("{f}.friction"), p.friction)?;
    if !(friction >= 0.0 && friction.is_finite()) {
        return Err(Error::scene(format!("{f}.friction"), "must be a non-negative number"));
    }
    let normal = vec3(&format!("{f}.normal"), req(&format!("{f}.normal"), p.normal)?)?;
    if normal.norm() == 0.0 {
        return Err(Error::scene(format!("{f}.normal"), "must be non-zero"));
    }
    let normal = normal.normalize();
    if p.plane == Some(true) {
        if p.points.is_some() {
            return Err(Error::scene(format!("{f}.points"), "a plane has no points (it touches the object where it is lowest)"));
        }
        return Ok(Pusher3 { name, friction, points: Vec::new(), normal, plane: true });
    }
    let pts = req(&format!("{f}.points"), p.points)?;
    if pts.is_empty() {
        return Err(Error::scene(format!("{f}.points"), "needs at least one point"));
    }
    let mut points = Vec::new();
    for (k, q) in pts.iter().enumerate() {
        let q = vec3(&format!("{f}.points[{k}]"), *q)?;
        let dist = surface_distance(mesh, sphere, &q);
        if dist.abs() > 1e-4 * size {
            return Err(Error::scene(format!("{f}.points[{k}]"), format!("is not on the object's surface ({dist:.2e} m off)")));
        }
        if surface_distance(mesh, sphere, &(q + normal * 1e-3 * size)) > 0.0 {
            return Err(Error::scene(format!("{f}.normal"), "must point into the object"));
        }
        points.push(q);
    }
    Ok(Pusher3 { name, friction, points, normal, plane: false })
}

/// Start and goal poses and the tolerance (position components [m], then the angle [rad]).
fn task(task: RawTask) -> Result<(Isometry3<f64>, Isometry3<f64>, [f64; 4])> {
    let start = pose_from_array("task.start", &req("task.start", task.start)?)?;
    let goal = pose_from_array("task.goal", &req("task.goal", task.goal)?)?;
    let tolerance = req("task.tolerance", task.tolerance)?;
    if tolerance.iter().any(|t| !(*t > 0.0)) {
        return Err(Error::scene("task.tolerance", "every component must be positive"));
    }
    Ok((start, goal, tolerance))
}
