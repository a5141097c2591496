//! The planar scene file (the TOML contract of `docs/scene-file.md`): its raw layout, every
//! value optional so that a missing one is reported by its dotted name, and its validation field
//! by field into a [`Scene`].

use crate::cones::motion_cone::PusherModel;
use crate::cones::robust::{ConeMode, Uncertainty};
use crate::error::{Error, Result};
use crate::mechanics::friction_cone::PusherContact;
use crate::mechanics::geometry::{cross2, perp, point_segment_distance, Polygon, Vec2};
use crate::mechanics::limit_surface::{LimitSurface, Pressure, PressureDistribution, SurfaceModel};
use crate::mechanics::metric::Metric;
use crate::scene::{bounds, exact};
use crate::scene::planar::{Grasp, PadShape, Pusher, Scene, Support, Surface, Task};
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
    #[serde(default, deserialize_with = "exact::opt_list::<2, _>")]
    pub outline: Option<Vec<[f64; 2]>>,
    pub mass: Option<f64>,
    #[serde(default, deserialize_with = "exact::opt::<2, _>")]
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
    #[serde(default, deserialize_with = "exact::opt::<2, _>")]
    pub pad_size: Option<[f64; 2]>,
    /// `"uniform"` (default) or `"hertzian"` (circular pads only).
    pub pressure: Option<String>,
    /// `"true"` or `"ellipsoid"`: the limit surface the motion cones use (default
    /// [`SurfaceModel::default`]).
    pub limit_surface: Option<String>,
}

#[derive(Deserialize, Serialize, Default, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct RawSurface {
    pub friction: Option<f64>,
    /// Inclination of the surface [rad], 0 = horizontal.
    pub incline: Option<f64>,
    /// `"true"` or `"ellipsoid"`, as for the grasp.
    pub limit_surface: Option<String>,
}

#[derive(Deserialize, Serialize, Default, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct RawGravity {
    #[serde(default, deserialize_with = "exact::opt::<2, _>")]
    pub direction: Option<[f64; 2]>,
    pub g: Option<f64>,
}

#[derive(Deserialize, Serialize, Default, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct RawPusher {
    pub name: Option<String>,
    pub friction: Option<f64>,
    #[serde(default, deserialize_with = "exact::opt_list::<2, _>")]
    pub points: Option<Vec<[f64; 2]>>,
    #[serde(default, deserialize_with = "exact::opt::<2, _>")]
    pub normal: Option<[f64; 2]>,
}

#[derive(Deserialize, Serialize, Default, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct RawTask {
    #[serde(default, deserialize_with = "exact::opt::<3, _>")]
    pub start: Option<[f64; 3]>,
    #[serde(default, deserialize_with = "exact::opt::<3, _>")]
    pub goal: Option<[f64; 3]>,
    #[serde(default, deserialize_with = "exact::opt::<3, _>")]
    pub tolerance: Option<[f64; 3]>,
}

// ---------------------------------------------------------------------------------------------
// Validated scene

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

fn req<T>(field: &str, v: Option<T>) -> Result<T> {
    v.ok_or_else(|| Error::scene(field, "is required"))
}

fn finite2(field: &str, v: [f64; 2]) -> Result<Vec2> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(Vec2::new(v[0], v[1]))
    } else {
        Err(Error::scene(field, "has a non-finite component"))
    }
}

/// A point or position: finite, each coordinate within [`bounds::COORD`].
fn point2(field: &str, v: [f64; 2]) -> Result<Vec2> {
    let p = finite2(field, v)?;
    for x in p.iter() {
        bounds::COORD.check(field, *x)?;
    }
    Ok(p)
}

/// A planar pose `[x, z, theta]`: positions within [`bounds::COORD`], the angle within
/// [`bounds::ANGLE`] (errors on `field`).
fn pose3(field: &str, v: Option<[f64; 3]>) -> Result<[f64; 3]> {
    let v = req(field, v)?;
    if !v.iter().all(|x| x.is_finite()) {
        return Err(Error::scene(field, "has a non-finite component"));
    }
    point2(field, [v[0], v[1]])?;
    bounds::ANGLE.check(field, v[2])?;
    Ok(v)
}

fn unit2(field: &str, v: [f64; 2]) -> Result<Vec2> {
    let v = finite2(field, v)?;
    let n = v.norm();
    if n == 0.0 {
        return Err(Error::scene(field, "must be a non-zero vector"));
    }
    let b = bounds::DIRECTION_NORM;
    if n < b.lo || n > b.hi {
        return Err(Error::scene(field, format!("its norm must be in [{:e}, {:e}] (got {n:e})", b.lo, b.hi)));
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
            let field = if path.is_empty() || path == "." { "(toml)".to_string() } else { path };
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
        let text = bounds::read_file(path, "path", false)?;
        Self::from_toml_str(&text)
    }

    /// Validates a raw scene: every value checked, errors naming the field.
    pub fn from_raw(raw: RawScene) -> Result<Scene> {
        let name = raw.name.clone().ok_or_else(|| Error::scene("name", "is required"))?;
        if name.trim().is_empty() {
            return Err(Error::scene("name", "must not be empty"));
        }
        let obj = raw.object.clone().ok_or_else(|| Error::scene("object", "table is required"))?;
        let (outline, mass, com) = Self::object(&obj)?;
        let (gravity_dir, g) = Self::gravity(raw.gravity.as_ref())?;
        let support = match (&raw.grasp, &raw.surface) {
            (Some(_), Some(_)) => {
                return Err(Error::scene("surface", "a scene has either a [grasp] or a [surface] table, not both"))
            }
            (None, None) => return Err(Error::scene("grasp", "table is required")),
            (Some(gr), None) => Support::Grasp(Self::grasp(gr)?),
            (None, Some(sf)) => Support::Surface(Self::surface(sf, &outline, &com)?),
        };
        let length = outline.gyration_radius_sq(&com).sqrt();
        let mut notes = Vec::new();
        let pushers = Self::pushers(raw.pushers.as_deref(), &outline, Metric::new(com, length), &mut notes)?;
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
            uncertainty: raw.uncertainty.as_ref().map(Self::uncertainty).transpose()?,
            mode: ConeMode::Nominal,
            notes,
        };
        let model = match (&raw.grasp, &raw.surface) {
            (Some(gr), _) => Self::read_surface_model("grasp.limit_surface", gr.limit_surface.as_deref())?,
            (_, Some(sf)) => Self::read_surface_model("surface.limit_surface", sf.limit_surface.as_deref())?,
            _ => SurfaceModel::default(),
        };
        if model != SurfaceModel::Ellipsoid {
            scene = scene.with_surface_model(model);
        }
        scene.task = Self::task(raw.task.as_ref(), &scene)?;
        if let Support::Surface(_) = scene.support {
            // the support frame sits under the centre of mass: holding depends on the heading only
            for k in 0..16 {
                let th = k as f64 * std::f64::consts::PI / 8.0;
                scene.check_holds(&[0.0, 0.0, th], "surface")?;
            }
        }
        Ok(scene)
    }

    /// The object's outline, mass [kg] and centre of mass (default: the area centroid).
    fn object(obj: &RawObject) -> Result<(Polygon, f64, Vec2)> {
        let outline_raw = req("object.outline", obj.outline.as_ref())?;
        bounds::count("object.outline", outline_raw.len(), bounds::MAX_OUTLINE_VERTICES, "vertices")?;
        let pts = outline_raw
            .iter()
            .enumerate()
            .map(|(i, p)| point2(&format!("object.outline[{i}]"), *p))
            .collect::<Result<Vec<_>>>()?;
        let outline = Polygon::new(pts).map_err(|d| Error::scene("object.outline", d.to_string()))?;
        let size = outline.bbox_diagonal();
        if bounds::SIZE.check("object.outline", size).is_err() {
            let b = bounds::SIZE;
            return Err(Error::scene(
                "object.outline",
                format!("its size (bounding-box diagonal) must be in [{:e}, {:e}] m (got {size:e})", b.lo, b.hi),
            ));
        }
        let mass = bounds::MASS.check("object.mass", req("object.mass", obj.mass)?)?;
        let com = match obj.com {
            Some(c) => point2("object.com", c)?,
            None => outline.centroid(),
        };
        Ok((outline, mass, com))
    }

    /// Gravity's unit direction in the plane and `g` [m/s²] (defaults: `[0, −1]`, 9.81).
    fn gravity(gr: Option<&RawGravity>) -> Result<(Vec2, f64)> {
        let Some(gr) = gr else { return Ok((Vec2::new(0.0, -1.0), 9.81)) };
        let d = match gr.direction {
            None => Vec2::new(0.0, -1.0),
            Some(d) => {
                let v = finite2("gravity.direction", d)?;
                if (v.norm() - 1.0).abs() > 1e-3 {
                    return Err(Error::scene("gravity.direction", format!("must be a unit vector (its norm is {:.6})", v.norm())));
                }
                v.normalize()
            }
        };
        let g = match gr.g {
            None => 9.81,
            Some(g) => bounds::G.check("gravity.g", g)?,
        };
        Ok((d, g))
    }

    /// The `limit_surface` key of the support's table (default [`SurfaceModel::default`]).
    fn read_surface_model(field: &str, raw: Option<&str>) -> Result<SurfaceModel> {
        match raw {
            None => Ok(SurfaceModel::default()),
            Some(s) => SurfaceModel::parse(s)
                .ok_or_else(|| Error::scene(field, format!("must be \"true\" or \"ellipsoid\" (got {s:?})"))),
        }
    }

    /// A surface the object lies on (incline below π/2; uniform pressure over the outline, so
    /// the centre of mass must be the centroid); its limit surface fitted to the footprint.
    fn surface(sf: &RawSurface, outline: &Polygon, com: &Vec2) -> Result<Surface> {
        let friction = bounds::SUPPORT_FRICTION.check("surface.friction", req("surface.friction", sf.friction)?)?;
        let incline = sf.incline.unwrap_or(0.0);
        if !(incline.is_finite() && incline >= 0.0) {
            return Err(Error::scene("surface.incline", format!("must be a non-negative number (got {incline})")));
        }
        if incline >= std::f64::consts::FRAC_PI_2 {
            return Err(Error::scene("surface.incline", "must be below π/2 rad"));
        }
        let centroid = outline.centroid();
        if (com - centroid).norm() > 1e-9 * outline.bbox_diagonal().max(1e-300) + 1e-12 {
            return Err(Error::scene(
                "object.com",
                "on a surface the pressure is taken uniform over the outline, so the centre of mass must be the area centroid (omit object.com)",
            ));
        }
        let (ls, _) = LimitSurface::fit(&PressureDistribution::polygon(outline, &centroid, 80));
        Ok(Surface { friction, incline, limit_surface: ls, cop: centroid, exact: None })
    }

    /// The pushers (at least one, unique names), their cones in the scene's metric.
    fn pushers(raw: Option<&[RawPusher]>, outline: &Polygon, metric: Metric, notes: &mut Vec<String>) -> Result<Vec<Pusher>> {
        let raw = raw.filter(|r| !r.is_empty()).ok_or_else(|| Error::scene("pushers", "at least one [[pushers]] is required"))?;
        bounds::count("pushers", raw.len(), bounds::MAX_PUSHERS, "entries")?;
        let size = outline.bbox_diagonal();
        let mut pushers: Vec<Pusher> = Vec::new();
        for (i, p) in raw.iter().enumerate() {
            let mut pusher = Self::pusher(&format!("pushers[{i}]"), p, outline, size, notes)?;
            if pushers.iter().any(|q| q.name == pusher.name) {
                return Err(Error::scene(format!("pushers[{i}].name"), format!("`{}` is used twice", pusher.name)));
            }
            pusher.model = PusherModel::new(pusher.contact.clone(), metric).map_err(|e| Error::scene(format!("pushers[{i}]"), e.to_string()))?;
            pushers.push(pusher);
        }
        Ok(pushers)
    }

    /// The `[uncertainty]` spreads (missing ones 0), each in [0, 1).
    fn uncertainty(u: &RawUncertainty) -> Result<Uncertainty> {
        Uncertainty {
            pusher_friction: u.pusher_friction.unwrap_or(0.0),
            finger_friction: u.finger_friction.unwrap_or(0.0),
            grip_force: u.grip_force.unwrap_or(0.0),
            mass: u.mass.unwrap_or(0.0),
        }
        .checked()
    }

    /// The task (required with a grasp): start and goal admissible and held, tolerances positive.
    fn task(t: Option<&RawTask>, scene: &Scene) -> Result<Option<Task>> {
        let t = match (t, &scene.support) {
            (None, Support::Grasp(_)) => return Err(Error::scene("task", "table is required")),
            (None, Support::Surface(_)) => return Ok(None),
            (Some(t), _) => t,
        };
        let start = pose3("task.start", t.start)?;
        let goal = pose3("task.goal", t.goal)?;
        let tol = req("task.tolerance", t.tolerance)?;
        for (k, v) in tol.iter().enumerate() {
            let b = if k < 2 { bounds::TOL_POSITION } else { bounds::TOL_ANGLE };
            b.check(&format!("task.tolerance[{k}]"), *v)?;
        }
        for (field, q) in [("task.start", start), ("task.goal", goal)] {
            if !scene.admissible(&q) {
                return Err(Error::scene(field, format!("pose {q:?} is not admissible: the finger pad is not entirely on the object")));
            }
            scene.check_holds(&q, field)?;
        }
        Ok(Some(Task { start, goal, tolerance: tol }))
    }

    fn grasp(gr: &RawGrasp) -> Result<Grasp> {
        let force = bounds::FORCE.check("grasp.force", req("grasp.force", gr.force)?)?;
        let friction = bounds::SUPPORT_FRICTION.check("grasp.friction", req("grasp.friction", gr.friction)?)?;
        let pressure = match gr.pressure.as_deref() {
            None | Some("uniform") => Pressure::Uniform,
            Some("hertzian") => Pressure::Hertzian,
            Some(other) => {
                return Err(Error::scene("grasp.pressure", format!("must be \"uniform\" or \"hertzian\" (got \"{other}\")")))
            }
        };
        let pad = match gr.pad_shape.as_deref() {
            None | Some("circle") => {
                if gr.pad_size.is_some() {
                    return Err(Error::scene("grasp.pad_size", "is for pad_shape = \"rectangle\"; a circular pad is sized by grasp.pad_radius"));
                }
                PadShape::Circle { radius: bounds::PAD.check("grasp.pad_radius", req("grasp.pad_radius", gr.pad_radius)?)? }
            }
            Some("rectangle") => {
                if gr.pad_radius.is_some() {
                    return Err(Error::scene(
                        "grasp.pad_radius",
                        "a rectangular pad is sized by grasp.pad_size; remove pad_radius",
                    ));
                }
                let s = gr.pad_size.ok_or_else(|| Error::scene("grasp.pad_size", "is required for a rectangular pad"))?;
                PadShape::Rectangle {
                    width: bounds::PAD.check("grasp.pad_size[0]", s[0])?,
                    height: bounds::PAD.check("grasp.pad_size[1]", s[1])?,
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
        Ok(Grasp { force, friction, pad, pressure, limit_surface, exact: None })
    }

    fn pusher(field: &str, p: &RawPusher, outline: &Polygon, size: f64, notes: &mut Vec<String>) -> Result<Pusher> {
        let name = p.name.clone().ok_or_else(|| Error::scene(format!("{field}.name"), "is required"))?;
        if name.trim().is_empty() {
            return Err(Error::scene(format!("{field}.name"), "must not be empty"));
        }
        let friction = bounds::PUSHER_FRICTION.check(&format!("{field}.friction"), req(&format!("{field}.friction"), p.friction)?)?;
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
            let q = on_outline(&f, point2(&f, *q)?, outline, notes)?;
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
}

/// A measured pusher point taken onto the outline: within [`bounds::SNAP_DISTANCE`] it is moved
/// to the nearest outline point (a note says so when it moves more than 1 nm); farther, an
/// error names the nearest outline point.
fn on_outline(field: &str, q: Vec2, outline: &Polygon, notes: &mut Vec<String>) -> Result<Vec2> {
    let (near, edge, d) = outline.closest_point(&q);
    if d > bounds::SNAP_DISTANCE {
        return Err(Error::scene(
            field,
            format!(
                "[{}, {}] is not on the object outline: it is {:.1} µm away, more than the {:.1} µm a measured point may be off; the nearest outline point is [{:.6}, {:.6}] (edge {edge})",
                q.x, q.y, d * 1e6, bounds::SNAP_DISTANCE * 1e6, near.x, near.y
            ),
        ));
    }
    if d <= 1e-9 {
        return Ok(q);
    }
    notes.push(format!("{field} moved {:.1} µm onto the outline (edge {edge})", d * 1e6));
    Ok(near)
}
