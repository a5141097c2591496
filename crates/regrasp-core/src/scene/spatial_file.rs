//! The 3-D scene file (TOML, `dimension = 3`; `docs/scene-file.md`): its raw layout and its
//! validation field by field into a [`Scene3`].

use crate::error::{Error, Result};
use crate::pose::spatial::{from_array as pose_from_array, V3};
use crate::scene::{bounds, exact};
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
    #[allow(dead_code)] // read by the grasp graph (Python), not the core
    taxonomy: Option<RawTaxonomy>,
}

/// `[taxonomy]`: options of the grasp graph's taxonomy (docs/scene-file.md), checked for its keys
/// here and for its values where the grasp graph reads them.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawTaxonomy {
    #[allow(dead_code)]
    lateral: Option<Vec<f64>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawObject {
    shape: Option<String>,
    #[serde(default, deserialize_with = "exact::opt::<3, _>")]
    size: Option<[f64; 3]>,
    mesh: Option<String>,
    radius: Option<f64>,
    mass: Option<f64>,
    #[serde(default, deserialize_with = "exact::opt::<3, _>")]
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
    #[serde(default, deserialize_with = "exact::opt::<3, _>")]
    direction: Option<[f64; 3]>,
    g: Option<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawPusher {
    name: Option<String>,
    friction: Option<f64>,
    #[serde(default, deserialize_with = "exact::opt_list::<3, _>")]
    points: Option<Vec<[f64; 3]>>,
    #[serde(default, deserialize_with = "exact::opt::<3, _>")]
    normal: Option<[f64; 3]>,
    plane: Option<bool>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawTask {
    #[serde(default, deserialize_with = "exact::opt::<7, _>")]
    start: Option<[f64; 7]>,
    #[serde(default, deserialize_with = "exact::opt::<7, _>")]
    goal: Option<[f64; 7]>,
    #[serde(default, deserialize_with = "exact::opt::<4, _>")]
    tolerance: Option<[f64; 4]>,
}

fn req<T>(field: &str, v: Option<T>) -> Result<T> {
    v.ok_or_else(|| Error::scene(field, "is required"))
}

fn vec3(field: &str, v: [f64; 3]) -> Result<V3> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(V3::new(v[0], v[1], v[2]))
    } else {
        Err(Error::scene(field, "has a non-finite component"))
    }
}

/// A point or position: finite, each coordinate within [`bounds::COORD`].
fn point3(field: &str, v: [f64; 3]) -> Result<V3> {
    let p = vec3(field, v)?;
    for x in p.iter() {
        bounds::COORD.check(field, *x)?;
    }
    Ok(p)
}

/// A direction: finite, its norm within [`bounds::DIRECTION_NORM`]; normalized.
fn direction3(field: &str, v: [f64; 3]) -> Result<V3> {
    let d = vec3(field, v)?;
    let (n, b) = (d.norm(), bounds::DIRECTION_NORM);
    if n == 0.0 {
        return Err(Error::scene(field, "must be non-zero"));
    }
    if n < b.lo || n > b.hi {
        return Err(Error::scene(field, format!("its norm must be in [{:e}, {:e}] (got {n:e})", b.lo, b.hi)));
    }
    Ok(d / n)
}

/// A name: present and not blank.
fn name(field: &str, v: Option<String>) -> Result<String> {
    let n = req(field, v)?;
    if n.trim().is_empty() {
        return Err(Error::scene(field, "must not be empty"));
    }
    Ok(n)
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
        let name = name("name", raw.name)?;
        let obj = req("object", raw.object)?;
        let solid = shape(&obj, base)?;
        let (mass, com, inertia) = mass_properties(&obj, &solid)?;
        let gr = req("grasp", raw.grasp)?;
        let (start, goal, tolerance) = task(req("task", raw.task)?)?;
        let mut notes = Vec::new();
        let s = Scene3 {
            name,
            pushers: pushers(req("pushers", raw.pushers)?, &solid, &mut notes)?,
            mesh: solid.mesh,
            parts: solid.parts,
            sphere: solid.sphere,
            mass,
            com,
            inertia,
            grip_force: bounds::FORCE.check("grasp.force", req("grasp.force", gr.force)?)?,
            grip_friction: bounds::SUPPORT_FRICTION.check("grasp.friction", req("grasp.friction", gr.friction)?)?,
            pad_radius: bounds::PAD.check("grasp.pad_radius", req("grasp.pad_radius", gr.pad_radius)?)?,
            gravity: gravity(raw.gravity)?,
            start,
            goal,
            tolerance,
            length: (inertia.trace() / (2.0 * mass)).sqrt(),
            notes,
        };
        for (field, p) in [("task.start", &s.start), ("task.goal", &s.goal)] {
            if s.pad_contacts(p).iter().any(|c| c.is_empty()) {
                return Err(Error::scene(field, "a finger pad does not touch the object at this pose"));
            }
        }
        Ok(s)
    }

    pub fn load(path: &Path) -> Result<Self> {
        let text = bounds::read_file(path, "path", false)?;
        Self::from_toml_str(&text, path.parent())
    }
}

/// The object's solid while the scene is read: its mesh (a non-convex object's convex hull),
/// its convex parts (empty for a convex object) and a sphere's radius.
struct Solid {
    mesh: ConvexMesh,
    parts: Vec<ConvexMesh>,
    sphere: Option<f64>,
}

impl Solid {
    fn distance(&self, p: &V3) -> f64 {
        surface_distance(&self.mesh, &self.parts, self.sphere, p)
    }
}

/// The object's surface: a box, an OBJ mesh (relative to `base`: one convex mesh, or the convex
/// parts of a non-convex object, [`parts`]) or a sphere (with its radius; its mesh an
/// icosphere for drawing and contacts); its size within [`bounds::SIZE`].
fn shape(obj: &RawObject, base: Option<&Path>) -> Result<Solid> {
    let kind = match obj.shape.as_deref() {
        Some(k @ ("box" | "mesh" | "sphere")) => k,
        Some(other) => return Err(Error::scene("object.shape", format!("must be \"box\", \"mesh\" or \"sphere\" (got \"{other}\")"))),
        None => return Err(Error::scene("object.shape", "is required (\"box\", \"mesh\" or \"sphere\")")),
    };
    for (key, given, owner) in [
        ("object.size", obj.size.is_some(), "box"),
        ("object.mesh", obj.mesh.is_some(), "mesh"),
        ("object.radius", obj.radius.is_some(), "sphere"),
    ] {
        if given && kind != owner {
            return Err(Error::scene(key, format!("is for shape = \"{owner}\", not \"{kind}\"")));
        }
    }
    match kind {
        "box" => {
            let s = vec3("object.size", req("object.size", obj.size)?)?;
            bounds::SIZE.check_each("object.size", [s.x, s.y, s.z])?;
            let m = ConvexMesh::try_cuboid(&s).map_err(|e| Error::scene("object.size", e))?;
            Ok(Solid { mesh: m, parts: vec![], sphere: None })
        }
        "mesh" => {
            let file = req("object.mesh", obj.mesh.clone())?;
            let path = base.map(|b| b.join(&file)).unwrap_or_else(|| file.clone().into());
            let text = bounds::read_file(&path, "object.mesh", true)?;
            let (m, parts) = parts(&text)?;
            let size = m.vertices.iter().map(|v| v.norm()).fold(0.0, f64::max);
            if bounds::SIZE.check("object.mesh", size).is_err() {
                let b = bounds::SIZE;
                return Err(Error::scene(
                    "object.mesh",
                    format!("its size (largest distance of a vertex from the origin) must be in [{:e}, {:e}] m (got {size:e})", b.lo, b.hi),
                ));
            }
            Ok(Solid { mesh: m, parts, sphere: None })
        }
        _ => {
            let r = bounds::SIZE.check("object.radius", req("object.radius", obj.radius)?)?;
            let m = ConvexMesh::try_icosphere(r, 2).map_err(|e| Error::scene("object.radius", e))?;
            Ok(Solid { mesh: m, parts: vec![], sphere: Some(r) })
        }
    }
}

/// An OBJ file's object: one convex mesh (no parts), or a non-convex object given as convex
/// parts (`o`/`g` groups, at most [`bounds::MAX_MESH_PARTS`]) whose interiors do not overlap,
/// with their convex hull.
fn parts(text: &str) -> Result<(ConvexMesh, Vec<ConvexMesh>)> {
    let mut parts = ConvexMesh::parts_from_obj(text).map_err(|e| {
        let hint = if e.contains("not convex") {
            "; a non-convex object is given as convex parts, one `o` group each (e.g. from a convex decomposition)"
        } else {
            ""
        };
        Error::scene("object.mesh", format!("{e}{hint}"))
    })?;
    bounds::count("object.mesh", parts.len(), bounds::MAX_MESH_PARTS, "convex parts (`o` groups)")?;
    if parts.len() == 1 {
        return Ok((parts.remove(0), vec![]));
    }
    let all: Vec<V3> = parts.iter().flat_map(|m| m.vertices.iter().copied()).collect();
    let triangles: usize = parts.iter().map(|m| m.triangles.len()).sum();
    // the parts together within one mesh's bounds (this also bounds the overlap test's work)
    bounds::count("object.mesh", all.len(), bounds::MAX_MESH_VERTICES, "vertices in all its parts")?;
    bounds::count("object.mesh", triangles, bounds::MAX_MESH_TRIANGLES, "triangles in all its parts")?;
    let size = all.iter().map(|v| v.norm()).fold(0.0, f64::max);
    let boxes: Vec<(V3, V3)> = parts.iter().map(|m| m.vertices.iter().fold((m.vertices[0], m.vertices[0]), |(l, h), v| (l.inf(v), h.sup(v)))).collect();
    // overlapping interiors would count their volume twice: no part's vertex, face centre or
    // centroid lies inside another part (only parts whose bounding boxes meet are compared)
    for (i, a) in parts.iter().enumerate() {
        let probes = a.vertices.iter().copied().chain(a.triangles.iter().map(|t| (a.vertices[t[0]] + a.vertices[t[1]] + a.vertices[t[2]]) / 3.0));
        let probes: Vec<V3> = probes.chain(std::iter::once(a.mass_properties().1)).collect();
        let meet = |j: usize| (0..3).all(|k| boxes[i].0[k] < boxes[j].1[k] && boxes[j].0[k] < boxes[i].1[k]);
        for (j, b) in parts.iter().enumerate().filter(|(j, _)| *j != i && meet(*j)) {
            if probes.iter().any(|p| b.signed_distance(p) < -1e-6 * size) {
                return Err(Error::scene("object.mesh", format!("convex parts {i} and {j} overlap: the parts of a non-convex object may touch, not overlap")));
            }
        }
    }
    let hull = ConvexMesh::hull(&all).map_err(|e| Error::scene("object.mesh", format!("the parts' convex hull: {e}")))?;
    Ok((hull, parts))
}

/// Mass [kg], centre of mass (default: the volume centroid; inside the object) and inertia about
/// it [kg m²] of a uniform-density object (a moved centre of mass shifts the inertia by the
/// parallel-axis rule).
fn mass_properties(obj: &RawObject, solid: &Solid) -> Result<(f64, V3, Matrix3<f64>)> {
    let mass = bounds::MASS.check("object.mass", req("object.mass", obj.mass)?)?;
    let (centroid, inertia_unit) = match solid.sphere {
        // a solid sphere: I = (2/5) r² per unit mass
        Some(r) => (V3::zeros(), Matrix3::identity() * 0.4 * r * r),
        None if !solid.parts.is_empty() => compound_mass_properties(&solid.parts),
        None => {
            let (_, c, i) = solid.mesh.mass_properties();
            (c, i)
        }
    };
    let com = match obj.com {
        Some(c) => point3("object.com", c)?,
        None => centroid,
    };
    if solid.distance(&com) > 0.0 {
        return Err(Error::scene("object.com", "must lie inside the object"));
    }
    let d = com - centroid;
    let inertia = inertia_unit * mass - (Matrix3::identity() * d.norm_squared() - d * d.transpose()) * mass;
    Ok((mass, com, inertia))
}

/// Centroid and inertia about it per unit mass of the union of `parts` (uniform density): the
/// volumes add, each part's inertia moved to the common centroid (parallel axes).
fn compound_mass_properties(parts: &[ConvexMesh]) -> (V3, Matrix3<f64>) {
    let props: Vec<(f64, V3, Matrix3<f64>)> = parts.iter().map(|m| m.mass_properties()).collect();
    let vol: f64 = props.iter().map(|p| p.0).sum();
    let c = props.iter().fold(V3::zeros(), |a, p| a + p.1 * p.0) / vol;
    let i = props.iter().fold(Matrix3::zeros(), |a, (v, ci, ii)| {
        let d = ci - c;
        a + (ii + Matrix3::identity() * d.norm_squared() - d * d.transpose()) * *v
    });
    (c, i / vol)
}

/// The gravity vector [m/s²] in the gripper frame (default `[0, 0, −9.81]`).
fn gravity(gv: Option<RawGravity>) -> Result<V3> {
    let Some(gv) = gv else { return Ok(V3::new(0.0, 0.0, -9.81)) };
    let d = vec3("gravity.direction", gv.direction.unwrap_or([0.0, 0.0, -1.0]))?;
    if (d.norm() - 1.0).abs() > 1e-3 {
        return Err(Error::scene("gravity.direction", "must be a unit vector"));
    }
    let g = bounds::G.check("gravity.g", gv.g.unwrap_or(9.81))?;
    Ok(d.normalize() * g)
}

/// The pushers (at least one, unique names): planes, or point sets on the object's surface
/// with an inward normal.
fn pushers(raw: Vec<RawPusher>, solid: &Solid, notes: &mut Vec<String>) -> Result<Vec<Pusher3>> {
    bounds::count("pushers", raw.len(), bounds::MAX_PUSHERS, "entries")?;
    let size = solid.mesh.vertices.iter().map(|v| v.norm()).fold(0.0, f64::max);
    let mut out: Vec<Pusher3> = Vec::new();
    for (i, p) in raw.into_iter().enumerate() {
        let f = format!("pushers[{i}]");
        let pusher = self::pusher(&f, p, solid, size, notes)?;
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
fn pusher(f: &str, p: RawPusher, solid: &Solid, size: f64, notes: &mut Vec<String>) -> Result<Pusher3> {
    let name = self::name(&format!("{f}.name"), p.name)?;
    let friction = bounds::PUSHER_FRICTION.check(&format!("{f}.friction"), req(&format!("{f}.friction"), p.friction)?)?;
    let normal = direction3(&format!("{f}.normal"), req(&format!("{f}.normal"), p.normal)?)?;
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
    bounds::count(&format!("{f}.points"), pts.len(), bounds::MAX_PUSHER_POINTS, "points")?;
    let mut points: Vec<V3> = Vec::new();
    for (k, q) in pts.iter().enumerate() {
        let fk = format!("{f}.points[{k}]");
        let q = on_surface(&fk, point3(&fk, *q)?, solid, notes)?;
        if let Some(j) = points.iter().position(|p| (p - q).norm() <= 1e-6 * size) {
            return Err(Error::scene(fk, format!("coincides with {f}.points[{j}]: a pusher's points must be distinct")));
        }
        if solid.distance(&(q + normal * 1e-3 * size)) > 0.0 {
            return Err(Error::scene(format!("{f}.normal"), "must point into the object"));
        }
        points.push(q);
    }
    Ok(Pusher3 { name, friction, points, normal, plane: false })
}

/// A measured pusher point taken onto the object's surface: within [`bounds::SNAP_DISTANCE`] it
/// is moved onto it (a note says so when it moves more than 1 nm); farther is an error.
fn on_surface(field: &str, q: V3, solid: &Solid, notes: &mut Vec<String>) -> Result<V3> {
    let dist = solid.distance(&q);
    if dist.abs() > bounds::SNAP_DISTANCE {
        return Err(Error::scene(
            field,
            format!(
                "is not on the object's surface: it is {:.1} µm {}, more than the {:.1} µm a measured point may be off",
                dist.abs() * 1e6,
                if dist > 0.0 { "outside" } else { "inside" },
                bounds::SNAP_DISTANCE * 1e6
            ),
        ));
    }
    if dist.abs() <= 1e-9 {
        return Ok(q);
    }
    let snapped = match solid.sphere {
        Some(r) if q.norm() > 0.0 => q * (r / q.norm()),
        // onto the part whose surface is nearest
        _ if !solid.parts.is_empty() => {
            let near = solid.parts.iter().min_by(|a, b| a.signed_distance(&q).abs().total_cmp(&b.signed_distance(&q).abs()));
            snap_to_mesh(near.expect("parts"), q)
        }
        _ => snap_to_mesh(&solid.mesh, q),
    };
    let moved = (snapped - q).norm();
    notes.push(format!("{field} moved {:.1} µm onto the object's surface", moved * 1e6));
    Ok(snapped)
}

/// `q` (near the surface) moved onto a convex mesh: along the normal of the face plane it is
/// farthest outside of (or, inside, nearest to), repeated for points near an edge or a corner.
fn snap_to_mesh(mesh: &ConvexMesh, mut q: V3) -> V3 {
    for _ in 0..8 {
        let Some((n, d)) = mesh.planes.iter().map(|(n, d)| (n, n.dot(&q) - d)).max_by(|a, b| a.1.total_cmp(&b.1)) else { break };
        if d.abs() <= 1e-12 {
            break;
        }
        q -= n * d;
    }
    q
}

/// Start and goal poses and the tolerance (position components [m], then the angle [rad]).
fn task(task: RawTask) -> Result<(Isometry3<f64>, Isometry3<f64>, [f64; 4])> {
    let start = pose("task.start", req("task.start", task.start)?)?;
    let goal = pose("task.goal", req("task.goal", task.goal)?)?;
    let tolerance = req("task.tolerance", task.tolerance)?;
    for (k, t) in tolerance.iter().enumerate() {
        let b = if k < 3 { bounds::TOL_POSITION } else { bounds::TOL_ANGLE };
        b.check(&format!("task.tolerance[{k}]"), *t)?;
    }
    Ok((start, goal, tolerance))
}

/// A pose `[x, y, z, qw, qx, qy, qz]`: the position within [`bounds::COORD`], the quaternion's
/// norm within [`bounds::DIRECTION_NORM`].
fn pose(field: &str, a: [f64; 7]) -> Result<Isometry3<f64>> {
    if !a.iter().all(|x| x.is_finite()) {
        return Err(Error::scene(field, "has a non-finite component"));
    }
    point3(field, [a[0], a[1], a[2]])?;
    let n = (a[3] * a[3] + a[4] * a[4] + a[5] * a[5] + a[6] * a[6]).sqrt();
    let b = bounds::DIRECTION_NORM;
    if n != 0.0 && !(n >= b.lo && n <= b.hi) {
        return Err(Error::scene(field, format!("the quaternion's norm must be in [{:e}, {:e}] (got {n:e})", b.lo, b.hi)));
    }
    pose_from_array(field, &a)
}
