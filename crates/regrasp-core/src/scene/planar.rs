//! Planar scenes (the TOML contract of `interface.md`), validated field by field.
//!
//! A scene is immutable once built: object outline, mass and centre of mass; the support
//! (a parallel-jaw grasp, or a surface the object lies on); gravity; named pushers; the task.
//! [`Scene::push`] builds the [`PlanarPush`] of one pusher at one pose.

use crate::error::{Error, Result};
use crate::mechanics::friction_cone::PusherContact;
use crate::mechanics::geometry::{cross2, perp, point_segment_distance, rot, shift_jacobian, Mat3, Polygon, Vec2, Vec3};
use crate::mechanics::gravity::gravity_wrench;
use crate::mechanics::limit_surface::{LimitSurface, Pressure, PressureDistribution};
use crate::mechanics::metric::Metric;
use crate::cones::motion_cone::{PlanarPush, PushSpec, PusherModel, SupportFrame};
use crate::cones::robust::{ConeMode, Uncertainty};
use serde::{Deserialize, Serialize};

// ---------------------------------------------------------------------------------------------
// Raw file layout (every value optional so that a missing one is reported by its dotted name)

#[derive(Deserialize, Serialize, Default, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct RawScene {
    pub name: Option<String>,
    pub description: Option<String>,
    pub object: Option<RawObject>,
    pub grasp: Option<RawGrasp>,
    pub surface: Option<RawSurface>,
    pub gravity: Option<RawGravity>,
    pub pushers: Option<Vec<RawPusher>>,
    pub task: Option<RawTask>,
    pub uncertainty: Option<RawUncertainty>,
}

/// `[uncertainty]`: relative spreads (0.2 = ±20%) of the parameters the plan must survive.
#[derive(Deserialize, Serialize, Default, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct RawUncertainty {
    pub pusher_friction: Option<f64>,
    pub finger_friction: Option<f64>,
    pub grip_force: Option<f64>,
    pub mass: Option<f64>,
}

#[derive(Deserialize, Serialize, Default, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct RawObject {
    pub outline: Option<Vec<[f64; 2]>>,
    pub mass: Option<f64>,
    pub com: Option<[f64; 2]>,
    /// Documentation only: what the object is made of.
    pub material: Option<String>,
}

#[derive(Deserialize, Serialize, Default, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct RawGrasp {
    pub force: Option<f64>,
    pub friction: Option<f64>,
    pub pad_radius: Option<f64>,
    /// `"circle"` (default) or `"rectangle"`.
    pub pad_shape: Option<String>,
    /// `[width, height]` of a rectangular pad (gripper X × Z) [m].
    pub pad_size: Option<[f64; 2]>,
    /// `"uniform"` (default) or `"hertzian"` (circular pads only).
    pub pressure: Option<String>,
}

#[derive(Deserialize, Serialize, Default, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct RawSurface {
    pub friction: Option<f64>,
    /// Inclination of the surface [rad], 0 = horizontal.
    pub incline: Option<f64>,
}

#[derive(Deserialize, Serialize, Default, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct RawGravity {
    pub direction: Option<[f64; 2]>,
    pub g: Option<f64>,
}

#[derive(Deserialize, Serialize, Default, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct RawPusher {
    pub name: Option<String>,
    pub friction: Option<f64>,
    pub points: Option<Vec<[f64; 2]>>,
    pub normal: Option<[f64; 2]>,
}

#[derive(Deserialize, Serialize, Default, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct RawTask {
    pub start: Option<[f64; 3]>,
    pub goal: Option<[f64; 3]>,
    pub tolerance: Option<[f64; 3]>,
}

// ---------------------------------------------------------------------------------------------
// Validated scene

#[derive(Clone, Debug, PartialEq)]
pub enum PadShape {
    Circle { radius: f64 },
    Rectangle { width: f64, height: f64 },
}

#[derive(Clone, Debug)]
pub struct Grasp {
    /// Grip force of each finger [N].
    pub force: f64,
    /// Pad-object Coulomb coefficient.
    pub friction: f64,
    pub pad: PadShape,
    pub pressure: Pressure,
    /// Unit limit surface of one pad, gripper axes (both pads act as one with normal force 2N).
    pub limit_surface: LimitSurface,
}

#[derive(Clone, Debug)]
pub struct Surface {
    pub friction: f64,
    pub incline: f64,
    /// Unit limit surface of the footprint (uniform pressure), object axes, about `cop`.
    pub limit_surface: LimitSurface,
    /// Centre of pressure, object frame (the area centroid).
    pub cop: Vec2,
}

#[derive(Clone, Debug)]
pub enum Support {
    Grasp(Grasp),
    Surface(Surface),
}

#[derive(Clone, Debug)]
pub struct Pusher {
    pub name: String,
    pub contact: PusherContact,
    /// Its generalized friction cone in the object frame (pose-independent).
    pub model: PusherModel,
}

#[derive(Clone, Copy, Debug)]
pub struct Task {
    pub start: [f64; 3],
    pub goal: [f64; 3],
    pub tolerance: [f64; 3],
}

#[derive(Clone, Debug)]
pub struct Scene {
    pub name: String,
    pub description: Option<String>,
    pub outline: Polygon,
    pub mass: f64,
    pub com: Vec2,
    pub support: Support,
    /// Unit direction of gravity in the gripper (or surface) frame.
    pub gravity_dir: Vec2,
    pub g: f64,
    pub pushers: Vec<Pusher>,
    pub task: Option<Task>,
    /// Characteristic length L [m]: the radius of gyration of the outline about the COM.
    pub length: f64,
    /// The optional `[uncertainty]` table (relative spreads, [`crate::cones::robust`]).
    pub uncertainty: Option<Uncertainty>,
    /// Which motion cones the scene answers with (nominal unless made robust or fixtureless).
    pub mode: ConeMode,
}

/// Whether `n` is an admissible pushing direction at boundary point `q`: the inward normal of
/// the edge `q` lies on, or at a corner any direction between its two edges' inward normals.
fn normal_fits(outline: &Polygon, q: &Vec2, n: &Vec2, tol: f64) -> bool {
    let pts = outline.vertices();
    let m = pts.len();
    let inward = |i: usize| perp(&(pts[(i + 1) % m] - pts[i])).normalize();
    for i in 0..m {
        if (pts[i] - q).norm() <= tol {
            // corner between edge i-1 and edge i
            let (a, b) = (inward((i + m - 1) % m), inward(i));
            let (ca, cb) = (cross2(&a, n), cross2(n, &b));
            let turn = cross2(&a, &b);
            return if turn >= 0.0 {
                ca >= -1e-9 && cb >= -1e-9
            } else {
                // reflex corner: the shorter arc between the normals
                ca <= 1e-9 && cb <= 1e-9
            } && n.dot(&(a + b)) > 0.0;
        }
    }
    outline
        .edges()
        .enumerate()
        .filter(|(_, (a, b))| point_segment_distance(q, a, b) <= tol)
        .any(|(i, _)| inward(i).dot(n) > 1.0 - 1e-6)
}

/// Largest values accepted for forces [N], masses [kg], friction coefficients and lengths [m]
/// (beyond them the numbers stop meaning a gripper and a hand-held object).
const MAX_FORCE: f64 = 1e6;
const MAX_MASS: f64 = 1e4;
const MAX_FRICTION: f64 = 100.0;

fn bounded(field: &str, v: f64, lo: f64, hi: f64) -> Result<f64> {
    if v < lo || v > hi {
        return Err(Error::scene(field, format!("must be between {lo:e} and {hi:e} (got {v})")));
    }
    Ok(v)
}

fn positive(field: &str, v: Option<f64>) -> Result<f64> {
    let v = v.ok_or_else(|| Error::scene(field, "is required"))?;
    if !v.is_finite() || v <= 0.0 {
        return Err(Error::scene(field, format!("must be a positive number (got {v})")));
    }
    Ok(v)
}

fn non_negative(field: &str, v: Option<f64>) -> Result<f64> {
    let v = v.ok_or_else(|| Error::scene(field, "is required"))?;
    if !v.is_finite() || v < 0.0 {
        return Err(Error::scene(field, format!("must be a non-negative number (got {v})")));
    }
    Ok(v)
}

fn finite2(field: &str, v: [f64; 2]) -> Result<Vec2> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(Vec2::new(v[0], v[1]))
    } else {
        Err(Error::scene(field, "has a non-finite component"))
    }
}

fn finite3(field: &str, v: Option<[f64; 3]>) -> Result<[f64; 3]> {
    let v = v.ok_or_else(|| Error::scene(field, "is required"))?;
    if v.iter().all(|x| x.is_finite()) {
        Ok(v)
    } else {
        Err(Error::scene(field, "has a non-finite component"))
    }
}

fn unit2(field: &str, v: [f64; 2]) -> Result<Vec2> {
    let v = finite2(field, v)?;
    let n = v.norm();
    if n == 0.0 {
        return Err(Error::scene(field, "must be a non-zero vector"));
    }
    Ok(v / n)
}

impl Scene {
    /// Parses and validates a scene from TOML text.
    pub fn from_toml_str(text: &str) -> Result<Scene> {
        let de = toml::Deserializer::new(text);
        let raw: RawScene = serde_path_to_error::deserialize(de).map_err(|e| {
            let path = e.path().to_string();
            let inner = e.into_inner();
            let line = inner
                .span()
                .map(|s| format!(" (line {})", text[..s.start.min(text.len())].matches('\n').count() + 1))
                .unwrap_or_default();
            let field = if path.is_empty() || path == "." { format!("(line{line})").replace("( ", "(") } else { path };
            Error::scene(field, format!("{}{line}", inner.message()))
        })?;
        Self::from_raw(raw)
    }

    /// Parses and validates a scene from JSON text with the same layout as the TOML file.
    pub fn from_json_str(text: &str) -> Result<Scene> {
        let mut de = serde_json::Deserializer::from_str(text);
        let raw: RawScene = serde_path_to_error::deserialize(&mut de).map_err(|e| {
            let path = e.path().to_string();
            Error::scene(if path.is_empty() || path == "." { "(json)".to_string() } else { path }, e.into_inner().to_string())
        })?;
        Self::from_raw(raw)
    }

    pub fn load(path: &std::path::Path) -> Result<Scene> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| Error::arg("path", format!("cannot read {}: {e}", path.display())))?;
        Self::from_toml_str(&text)
    }

    pub fn from_raw(raw: RawScene) -> Result<Scene> {
        let name = raw.name.clone().ok_or_else(|| Error::scene("name", "is required"))?;
        if name.trim().is_empty() {
            return Err(Error::scene("name", "must not be empty"));
        }
        let obj = raw.object.clone().ok_or_else(|| Error::scene("object", "table is required"))?;
        let outline_raw = obj.outline.clone().ok_or_else(|| Error::scene("object.outline", "is required"))?;
        let pts = outline_raw
            .iter()
            .enumerate()
            .map(|(i, p)| finite2(&format!("object.outline[{i}]"), *p))
            .collect::<Result<Vec<_>>>()?;
        let outline = Polygon::new(pts).map_err(|d| Error::scene("object.outline", d.to_string()))?;
        let mass = bounded("object.mass", positive("object.mass", obj.mass)?, 1e-9, MAX_MASS)?;
        let centroid = outline.centroid();
        let com = match obj.com {
            Some(c) => finite2("object.com", c)?,
            None => centroid,
        };
        let size = outline.bbox_diagonal();

        let (gravity_dir, g) = match &raw.gravity {
            None => (Vec2::new(0.0, -1.0), 9.81),
            Some(gr) => {
                let d = match gr.direction {
                    None => Vec2::new(0.0, -1.0),
                    Some(d) => {
                        let v = finite2("gravity.direction", d)?;
                        if (v.norm() - 1.0).abs() > 1e-3 {
                            return Err(Error::scene(
                                "gravity.direction",
                                format!("must be a unit vector (its norm is {:.6})", v.norm()),
                            ));
                        }
                        v.normalize()
                    }
                };
                let g = match gr.g {
                    None => 9.81,
                    Some(g) => bounded("gravity.g", non_negative("gravity.g", Some(g))?, 0.0, 1e3)?,
                };
                (d, g)
            }
        };

        let support = match (&raw.grasp, &raw.surface) {
            (Some(_), Some(_)) => {
                return Err(Error::scene("surface", "a scene has either a [grasp] or a [surface] table, not both"))
            }
            (None, None) => return Err(Error::scene("grasp", "table is required")),
            (Some(gr), None) => Support::Grasp(Self::grasp(gr)?),
            (None, Some(sf)) => {
                let friction = bounded("surface.friction", positive("surface.friction", sf.friction)?, 1e-6, MAX_FRICTION)?;
                let incline = match sf.incline {
                    None => 0.0,
                    Some(a) => non_negative("surface.incline", Some(a))?,
                };
                if incline >= std::f64::consts::FRAC_PI_2 {
                    return Err(Error::scene("surface.incline", "must be below π/2 rad"));
                }
                if (com - centroid).norm() > 1e-9 * size.max(1e-300) + 1e-12 {
                    return Err(Error::scene(
                        "object.com",
                        "on a surface the pressure is taken uniform over the outline, so the centre of mass must be the area centroid (omit object.com)",
                    ));
                }
                let (ls, _) = LimitSurface::fit(&PressureDistribution::polygon(&outline, &centroid, 80));
                Support::Surface(Surface { friction, incline, limit_surface: ls, cop: centroid })
            }
        };

        let raw_pushers = raw.pushers.clone().ok_or_else(|| Error::scene("pushers", "at least one [[pushers]] is required"))?;
        if raw_pushers.is_empty() {
            return Err(Error::scene("pushers", "at least one [[pushers]] is required"));
        }
        let mut pushers: Vec<Pusher> = Vec::new();
        for (i, p) in raw_pushers.iter().enumerate() {
            let pusher = Self::pusher(&format!("pushers[{i}]"), p, &outline, size)?;
            if pushers.iter().any(|q| q.name == pusher.name) {
                return Err(Error::scene(format!("pushers[{i}].name"), format!("`{}` is used twice", pusher.name)));
            }
            pushers.push(pusher);
        }

        let length = outline.gyration_radius_sq(&com).sqrt();
        for (i, p) in pushers.iter_mut().enumerate() {
            p.model = PusherModel::new(p.contact.clone(), Metric::new(com, length))
                .map_err(|e| Error::scene(format!("pushers[{i}]"), e.to_string()))?;
        }
        let mut scene = Scene {
            name,
            description: raw.description.clone(),
            outline,
            mass,
            com,
            support,
            gravity_dir,
            g,
            pushers,
            task: None,
            length,
            uncertainty: None,
            mode: ConeMode::Nominal,
        };
        if let Some(u) = &raw.uncertainty {
            scene.uncertainty = Some(
                Uncertainty {
                    pusher_friction: u.pusher_friction.unwrap_or(0.0),
                    finger_friction: u.finger_friction.unwrap_or(0.0),
                    grip_force: u.grip_force.unwrap_or(0.0),
                    mass: u.mass.unwrap_or(0.0),
                }
                .checked()?,
            );
        }

        match (&raw.task, &scene.support) {
            (None, Support::Grasp(_)) => return Err(Error::scene("task", "table is required")),
            (None, Support::Surface(_)) => {}
            (Some(t), _) => {
                let start = finite3("task.start", t.start)?;
                let goal = finite3("task.goal", t.goal)?;
                let tol = finite3("task.tolerance", t.tolerance)?;
                for (k, v) in tol.iter().enumerate() {
                    if *v <= 0.0 {
                        return Err(Error::scene(format!("task.tolerance[{k}]"), format!("must be positive (got {v})")));
                    }
                }
                for (field, q) in [("task.start", start), ("task.goal", goal)] {
                    if !scene.admissible(&q) {
                        return Err(Error::scene(
                            field,
                            format!("pose {q:?} is not admissible: the finger pad is not entirely on the object"),
                        ));
                    }
                    scene.check_holds(&q, field)?;
                }
                scene.task = Some(Task { start, goal, tolerance: tol });
            }
        }
        if let Support::Surface(_) = scene.support {
            // the support frame sits under the centre of mass: holding depends on the heading only
            for k in 0..16 {
                let th = k as f64 * std::f64::consts::PI / 8.0;
                scene.check_holds(&[0.0, 0.0, th], "surface")?;
            }
        }
        Ok(scene)
    }

    /// Error naming the field to change when gravity alone would make the support slip at `q`.
    fn check_holds(&self, q: &[f64; 3], at: &str) -> Result<()> {
        let ratio = self.hold_ratio(q);
        if ratio < 1.0 {
            return Ok(());
        }
        Err(match &self.support {
            Support::Grasp(_) => Error::scene(
                "grasp.force",
                format!(
                    "the grasp cannot hold the object against gravity at {at} = {q:?}: gravity needs {ratio:.3}x the friction the pads can give"
                ),
            ),
            Support::Surface(s) => Error::scene(
                "surface.friction",
                format!(
                    "the object slides down the incline by itself (heading {:.3} rad): gravity needs {ratio:.3}x the friction the surface can give (tan(incline) = {:.3})",
                    q[2],
                    s.incline.tan()
                ),
            ),
        })
    }

    fn grasp(gr: &RawGrasp) -> Result<Grasp> {
        let force = bounded("grasp.force", positive("grasp.force", gr.force)?, 1e-6, MAX_FORCE)?;
        let friction = bounded("grasp.friction", positive("grasp.friction", gr.friction)?, 1e-6, MAX_FRICTION)?;
        let pressure = match gr.pressure.as_deref() {
            None | Some("uniform") => Pressure::Uniform,
            Some("hertzian") => Pressure::Hertzian,
            Some(other) => {
                return Err(Error::scene("grasp.pressure", format!("must be \"uniform\" or \"hertzian\" (got \"{other}\")")))
            }
        };
        let pad = match gr.pad_shape.as_deref() {
            None | Some("circle") => PadShape::Circle {
                radius: bounded("grasp.pad_radius", positive("grasp.pad_radius", gr.pad_radius)?, 1e-6, 10.0)?,
            },
            Some("rectangle") => {
                if gr.pad_radius.is_some() {
                    return Err(Error::scene(
                        "grasp.pad_radius",
                        "a rectangular pad is sized by grasp.pad_size; remove pad_radius",
                    ));
                }
                let s = gr.pad_size.ok_or_else(|| Error::scene("grasp.pad_size", "is required for a rectangular pad"))?;
                PadShape::Rectangle {
                    width: positive("grasp.pad_size[0]", Some(s[0]))?,
                    height: positive("grasp.pad_size[1]", Some(s[1]))?,
                }
            }
            Some(other) => {
                return Err(Error::scene("grasp.pad_shape", format!("must be \"circle\" or \"rectangle\" (got \"{other}\")")))
            }
        };
        let limit_surface = match (&pad, pressure) {
            (PadShape::Circle { radius }, Pressure::Uniform) => LimitSurface::circular(*radius),
            (PadShape::Circle { radius }, Pressure::Hertzian) => {
                LimitSurface::fit(&PressureDistribution::circle(*radius, Pressure::Hertzian, 60)).0
            }
            (PadShape::Rectangle { width, height }, Pressure::Uniform) => {
                LimitSurface::fit(&PressureDistribution::rectangle(*width, *height, 60)).0
            }
            (PadShape::Rectangle { .. }, Pressure::Hertzian) => {
                return Err(Error::scene("grasp.pressure", "\"hertzian\" is defined for circular pads only"))
            }
        };
        Ok(Grasp { force, friction, pad, pressure, limit_surface })
    }

    fn pusher(field: &str, p: &RawPusher, outline: &Polygon, size: f64) -> Result<Pusher> {
        let name = p.name.clone().ok_or_else(|| Error::scene(format!("{field}.name"), "is required"))?;
        if name.trim().is_empty() {
            return Err(Error::scene(format!("{field}.name"), "must not be empty"));
        }
        let friction = bounded(&format!("{field}.friction"), non_negative(&format!("{field}.friction"), p.friction)?, 0.0, MAX_FRICTION)?;
        let raw_pts = p.points.clone().ok_or_else(|| Error::scene(format!("{field}.points"), "is required"))?;
        if raw_pts.is_empty() || raw_pts.len() > 2 {
            return Err(Error::scene(
                format!("{field}.points"),
                format!("must hold 1 point (point pusher) or 2 (line pusher), got {}", raw_pts.len()),
            ));
        }
        let normal = unit2(
            &format!("{field}.normal"),
            p.normal.ok_or_else(|| Error::scene(format!("{field}.normal"), "is required"))?,
        )?;
        let tol = 1e-4 * size;
        let mut points = Vec::new();
        for (k, q) in raw_pts.iter().enumerate() {
            let f = format!("{field}.points[{k}]");
            let q = finite2(&f, *q)?;
            let d = outline.boundary_distance(&q);
            if d > tol {
                return Err(Error::scene(f, format!("{q:?} is not on the object outline (it is {d:.3e} m away)")));
            }
            if !normal_fits(outline, &q, &normal, tol) {
                return Err(Error::scene(
                    format!("{field}.normal"),
                    format!(
                        "must be the inward normal of the outline at {f} (or, at a corner, between the inward normals of its two edges): the pusher pushes the object along it"
                    ),
                ));
            }
            points.push(q);
        }
        if points.len() == 2 {
            let seg = points[1] - points[0];
            if seg.norm() <= tol {
                return Err(Error::scene(format!("{field}.points"), "the two points of a line pusher coincide"));
            }
            // both points on one straight edge of the outline, the normal being its inward normal
            let on_one_edge = outline.edges().any(|(a, b)| {
                point_segment_distance(&points[0], &a, &b) <= tol
                    && point_segment_distance(&points[1], &a, &b) <= tol
                    && perp(&(b - a)).normalize().dot(&normal) > 1.0 - 1e-6
            });
            if !on_one_edge {
                return Err(Error::scene(
                    format!("{field}.points"),
                    "a line pusher must lie along one straight edge of the outline, with the edge's inward normal as `normal`",
                ));
            }
        }
        let contact = PusherContact { points, normal, friction };
        let model = PusherModel::new(contact.clone(), Metric::new(Vec2::zeros(), size))
            .map_err(|e| Error::scene(field.to_string(), e.to_string()))?;
        Ok(Pusher { name, contact, model })
    }

    pub fn pusher_index(&self, name: &str) -> Result<usize> {
        self.pushers.iter().position(|p| p.name == name).ok_or_else(|| {
            let names: Vec<&str> = self.pushers.iter().map(|p| p.name.as_str()).collect();
            Error::arg("pusher", format!("no pusher named `{name}` (the scene has {names:?})"))
        })
    }

    /// Finger pad outline in the object frame at pose `q` (circle: centre and radius).
    fn pad_in_object(&self, q: &[f64; 3]) -> Option<(Vec2, Vec<Vec2>, f64)> {
        let Support::Grasp(g) = &self.support else { return None };
        let r = rot(-q[2]);
        let c = -(r * Vec2::new(q[0], q[1]));
        match g.pad {
            PadShape::Circle { radius } => Some((c, vec![], radius)),
            PadShape::Rectangle { width, height } => {
                let (w, h) = (width / 2.0, height / 2.0);
                let corners = [Vec2::new(-w, -h), Vec2::new(w, -h), Vec2::new(w, h), Vec2::new(-w, h)]
                    .iter()
                    .map(|p| r * p + c)
                    .collect();
                Some((c, corners, 0.0))
            }
        }
    }

    /// A pose is admissible when the whole finger pad lies on the object (always, on a surface).
    pub fn admissible(&self, q: &[f64; 3]) -> bool {
        if !q.iter().all(|x| x.is_finite()) {
            return false;
        }
        match self.pad_in_object(q) {
            None => true,
            Some((c, corners, radius)) => {
                if corners.is_empty() {
                    self.outline.signed_distance(&c) >= radius
                } else {
                    self.outline.contains_convex(&corners)
                }
            }
        }
    }

    /// Signed clearance of the pad inside the outline [m] (circular pads; ≥ 0 admissible).
    pub fn pad_clearance(&self, q: &[f64; 3]) -> f64 {
        match self.pad_in_object(q) {
            None => f64::INFINITY,
            Some((c, _, radius)) => self.outline.signed_distance(&c) - radius,
        }
    }

    /// `μ_s N` of the support.
    pub fn friction_scale(&self) -> f64 {
        match &self.support {
            Support::Grasp(g) => 2.0 * g.force * g.friction,
            Support::Surface(s) => s.friction * self.mass * self.g * s.incline.cos(),
        }
    }

    /// In-plane gravity acceleration [m/s²]: g, or g sin(incline) on a surface.
    pub fn g_plane(&self) -> f64 {
        match &self.support {
            Support::Grasp(_) => self.g,
            Support::Surface(s) => self.g * s.incline.sin(),
        }
    }

    /// In-plane gravity wrench in the object frame at pose `q`.
    pub fn gravity_wrench(&self, q: &[f64; 3]) -> Vec3 {
        gravity_wrench(self.mass, self.g_plane(), &self.gravity_dir, q[2], &self.com)
    }

    /// `J_s` at pose `q`: object twist → support twist (support frame).
    pub fn support_jacobian(&self, q: &[f64; 3]) -> Mat3 {
        self.frame(q).js
    }

    fn limit_surface(&self) -> LimitSurface {
        match &self.support {
            Support::Grasp(g) => g.limit_surface,
            Support::Surface(s) => s.limit_surface,
        }
    }

    /// How much of the support's friction gravity alone uses at `q` (< 1 to hold).
    pub fn hold_ratio(&self, q: &[f64; 3]) -> f64 {
        self.frame(q).hold_ratio
    }

    pub fn check_pose(&self, q: &[f64; 3]) -> Result<()> {
        if !q.iter().all(|x| x.is_finite()) {
            return Err(Error::arg("pose", "has a non-finite component"));
        }
        if !self.admissible(q) {
            return Err(Error::arg("pose", format!("{q:?} is not admissible: the finger pad is not entirely on the object")));
        }
        Ok(())
    }

    /// The frame-invariant metrics on twists and wrenches of this object.
    pub fn metric(&self) -> Metric {
        Metric::new(self.com, self.length)
    }

    /// Pose-dependent quantities of every push at `q` (no admissibility check).
    pub fn frame(&self, q: &[f64; 3]) -> SupportFrame {
        let s = self.friction_scale();
        let ls = self.limit_surface();
        let (sn, cs) = q[2].sin_cos();
        let (js, js_inv) = match &self.support {
            Support::Grasp(_) => {
                // J_s = diag(R, 1) · shift(c) with c = −Rᵀ t the pad centre in the object frame;
                // J_s⁻¹ = shift(−c) · diag(Rᵀ, 1)
                let cx = -(cs * q[0] + sn * q[1]);
                let cz = -(-sn * q[0] + cs * q[1]);
                let js = Mat3::new(cs, -sn, -cs * cz - sn * cx, sn, cs, -sn * cz + cs * cx, 0.0, 0.0, 1.0);
                let js_inv = Mat3::new(cs, sn, cz, -sn, cs, -cx, 0.0, 0.0, 1.0);
                (js, js_inv)
            }
            Support::Surface(sf) => (shift_jacobian(&sf.cop), shift_jacobian(&-sf.cop)),
        };
        // gravity: Rᵀ d m g at the centre of mass
        let d = self.gravity_dir * (self.mass * self.g_plane());
        let f = Vec2::new(cs * d.x + sn * d.y, -sn * d.x + cs * d.y);
        let wg = Vec3::new(f.x, f.y, self.com.x * f.y - self.com.y * f.x);
        let k = 1.0 / (s * s);
        let mut f = SupportFrame::new(ls.b * k, ls.b_inv * (s * s), js, js_inv, wg);
        f.mode = self.mode;
        f
    }

    /// Checks a pose and returns its frame; the error says what is wrong.
    pub fn checked_frame(&self, q: &[f64; 3]) -> Result<SupportFrame> {
        self.check_pose(q)?;
        let f = self.frame(q);
        if !(f.hold_ratio < 1.0) {
            return Err(Error::GraspCannotHold { pose: *q, ratio: f.hold_ratio });
        }
        Ok(f)
    }

    /// The definition of pusher `pusher` acting at pose `q`.
    pub fn push_spec(&self, q: &[f64; 3], pusher: usize) -> Result<PushSpec> {
        self.check_pose(q)?;
        let p = self.pushers.get(pusher).ok_or_else(|| Error::arg("pusher", format!("index {pusher} out of range")))?;
        Ok(PushSpec {
            limit_surface: self.limit_surface(),
            friction_scale: self.friction_scale(),
            support_jacobian: self.support_jacobian(q),
            pusher: p.contact.clone(),
            gravity: self.gravity_wrench(q),
            metric: self.metric(),
            pose: *q,
            mode: self.mode,
            grip_per_scale: match &self.support {
                Support::Grasp(g) => Some(1.0 / (2.0 * g.friction)),
                Support::Surface(_) => None,
            },
        })
    }

    /// The push of `pusher` at pose `q`; fails if the support cannot hold the object there.
    pub fn push(&self, q: &[f64; 3], pusher: usize) -> Result<PlanarPush> {
        let p = self.push_unchecked(q, pusher)?;
        if !(p.hold_ratio() < 1.0) {
            return Err(Error::GraspCannotHold { pose: *q, ratio: p.hold_ratio() });
        }
        Ok(p)
    }

    /// Like [`Self::push`] but also when gravity alone would make the support slip (for the
    /// gravity-free cone and grip-force queries).
    pub fn push_unchecked(&self, q: &[f64; 3], pusher: usize) -> Result<PlanarPush> {
        let spec = self.push_spec(q, pusher)?;
        PlanarPush::with_model(spec, self.pushers[pusher].model.clone())
    }

    /// Grip force of each finger (grasp scenes).
    pub fn grip_force(&self) -> Option<f64> {
        match &self.support {
            Support::Grasp(g) => Some(g.force),
            Support::Surface(_) => None,
        }
    }

    /// A copy with another per-finger grip force (grasp scenes).
    pub fn with_grip_force(&self, force: f64) -> Scene {
        let mut s = self.clone();
        if let Support::Grasp(g) = &mut s.support {
            g.force = force;
        }
        s
    }
}
