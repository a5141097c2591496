//! Planar scenes (the TOML contract of `docs/scene-file.md`), validated field by field.
//!
//! A scene is immutable once built: object outline, mass and centre of mass; the support
//! (a parallel-jaw grasp, or a surface the object lies on); gravity; named pushers; the task.
//! [`Scene::push`] builds the [`PlanarPush`] of one pusher at one pose.

use crate::error::{Error, Result};
use crate::mechanics::friction_cone::PusherContact;
use crate::mechanics::geometry::{rot, shift_jacobian, Mat3, Polygon, Vec2, Vec3};
use crate::mechanics::gravity::gravity_wrench;
use crate::mechanics::exact_surface::{ExactSurface, Region};
use crate::mechanics::limit_surface::{LimitSurface, Pressure, SurfaceModel};
use crate::mechanics::metric::Metric;
use crate::cones::motion_cone::{PlanarPush, PushSpec, PusherModel, SupportFrame};
use crate::cones::robust::{ConeMode, Uncertainty};


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
    /// Unit ellipsoidal limit surface of one pad, gripper axes (both pads act as one with
    /// normal force 2N).
    pub limit_surface: LimitSurface,
    /// The pad's exact limit surface, when the scene uses it.
    pub exact: Option<ExactSurface>,
}

#[derive(Clone, Debug)]
pub struct Surface {
    pub friction: f64,
    pub incline: f64,
    /// Unit ellipsoidal limit surface of the footprint (uniform pressure), object axes, about `cop`.
    pub limit_surface: LimitSurface,
    /// The footprint's exact limit surface, when the scene uses it.
    pub exact: Option<ExactSurface>,
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

/// The goal tolerance `[x, z, θ]` (m, m, rad) where a scene states none: 1 mm and 1°.
pub const DEFAULT_TOLERANCE: [f64; 3] = [1e-3, 1e-3, 0.0175];

/// The error `pose − goal` `[x, z, θ]` (m, m, rad; θ wrapped into [−π, π)) and whether every
/// component is within `tolerance`: the one test of "is it at the goal?" for planar poses.
pub fn goal_error(pose: &[f64; 3], goal: &[f64; 3], tolerance: &[f64; 3]) -> ([f64; 3], bool) {
    use std::f64::consts::{PI, TAU};
    let mut e = [pose[0] - goal[0], pose[1] - goal[1], pose[2] - goal[2]];
    e[2] = (e[2] + PI).rem_euclid(TAU) - PI;
    let within = e.iter().zip(tolerance).all(|(x, t)| x.abs() <= *t);
    (e, within)
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
    /// What the loader changed, e.g. a measured pusher point moved onto the outline.
    pub notes: Vec<String>,
}
/// Most vertices of a footprint's exact limit surface (its tables cost time in proportion).
pub const MAX_FOOTPRINT_VERTICES: usize = 64;

/// The footprint about `cop` for its exact limit surface: the outline, simplified
/// (Ramer–Douglas–Peucker, the tolerance doubled until at most [`MAX_FOOTPRINT_VERTICES`]
/// remain) when it has more vertices, with a note saying so.
fn footprint(outline: &Polygon, cop: &Vec2) -> (Vec<Vec2>, Option<String>) {
    use geo::Simplify;
    let pts: Vec<Vec2> = outline.vertices().iter().map(|v| v - cop).collect();
    if pts.len() <= MAX_FOOTPRINT_VERTICES {
        return (pts, None);
    }
    let ring: geo::LineString<f64> = pts.iter().chain(std::iter::once(&pts[0])).map(|p| geo::coord! { x: p.x, y: p.y }).collect();
    let mut eps = 1e-4 * outline.bbox_diagonal();
    loop {
        let simple = ring.simplify(eps);
        let n = simple.0.len().saturating_sub(1);
        if n <= MAX_FOOTPRINT_VERTICES && n >= 3 {
            let v = simple.0[..n].iter().map(|c| Vec2::new(c.x, c.y)).collect();
            let note = format!(
                "the footprint's exact limit surface uses the outline simplified to {n} of its {} vertices (within {:.3} mm)",
                pts.len(),
                eps * 1e3
            );
            return (v, Some(note));
        }
        if n < 3 {
            // (a tolerance that removes nearly everything at once) every k-th vertex instead
            let k = pts.len().div_ceil(MAX_FOOTPRINT_VERTICES);
            let v: Vec<Vec2> = pts.iter().step_by(k).copied().collect();
            let note = format!("the footprint's exact limit surface uses every {k}-th of the outline's {} vertices", pts.len());
            return (v, Some(note));
        }
        eps *= 2.0;
    }
}

impl Grasp {
    /// The pad's region and pressure (pad frame, centred).
    pub fn region(&self) -> Region {
        match self.pad {
            PadShape::Circle { radius } => Region::Disc { radius, pressure: self.pressure },
            PadShape::Rectangle { width, height } => {
                let (w, h) = (width / 2.0, height / 2.0);
                Region::Polygon { vertices: vec![Vec2::new(-w, -h), Vec2::new(w, -h), Vec2::new(w, h), Vec2::new(-w, h)] }
            }
        }
    }
}

impl Scene {
    /// The task's goal tolerance, or [`DEFAULT_TOLERANCE`] without a task.
    pub fn tolerance(&self) -> [f64; 3] {
        self.task.map(|t| t.tolerance).unwrap_or(DEFAULT_TOLERANCE)
    }

    /// The limit surface the motion cones use.
    pub fn surface_model(&self) -> SurfaceModel {
        let exact = match &self.support {
            Support::Grasp(g) => g.exact.is_some(),
            Support::Surface(s) => s.exact.is_some(),
        };
        if exact {
            SurfaceModel::True
        } else {
            SurfaceModel::Ellipsoid
        }
    }

    /// A copy whose motion cones use limit surface `model` (the exact one built or shared).
    pub fn with_surface_model(&self, model: SurfaceModel) -> Scene {
        let mut s = self.clone();
        let outline = &self.outline;
        match &mut s.support {
            Support::Grasp(g) => g.exact = (model == SurfaceModel::True).then(|| ExactSurface::new(&g.region())),
            Support::Surface(sf) => {
                sf.exact = None;
                if model == SurfaceModel::True {
                    let (vertices, note) = footprint(outline, &sf.cop);
                    sf.exact = Some(ExactSurface::new(&Region::Polygon { vertices }));
                    s.notes.extend(note);
                }
            }
        }
        s
    }

    fn exact_surface(&self) -> Option<&ExactSurface> {
        match &self.support {
            Support::Grasp(g) => g.exact.as_ref(),
            Support::Surface(s) => s.exact.as_ref(),
        }
    }

    /// What the loader changed in the file's values (pusher points snapped onto the outline).
    pub fn notes(&self) -> &[String] {
        &self.notes
    }

    /// Error naming the field to change when gravity alone would make the support slip at `q`.
    pub(crate) fn check_holds(&self, q: &[f64; 3], at: &str) -> Result<()> {
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

    /// The finger pad's centre in the object frame at pose `q` and the radius [m] of the largest
    /// disc inside the pad (a rectangle's half shorter side); None on a surface.
    pub fn pad_disc(&self, q: &[f64; 3]) -> Option<(Vec2, f64)> {
        let Support::Grasp(g) = &self.support else { return None };
        let c = -(rot(-q[2]) * Vec2::new(q[0], q[1]));
        Some(match g.pad {
            PadShape::Circle { radius } => (c, radius),
            PadShape::Rectangle { width, height } => (c, 0.5 * width.min(height)),
        })
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

    /// Share of the support's friction that the object-frame wrench `w` (N, N, N·m about the
    /// object's origin) uses at pose `q` ([`SupportFrame::load_ratio`]): gravity's is
    /// [`Self::hold_ratio`]; an arm's motion adds its inertial load (`−m a`, `−I α − ω × Iω`).
    pub fn load_ratio(&self, q: &[f64; 3], w: &Vec3) -> f64 {
        self.frame(q).load_ratio(w)
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
        match self.exact_surface() {
            Some(e) => f.with_exact(e, s),
            None => f,
        }
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
            exact: self.exact_surface().cloned(),
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

    /// A copy with another per-finger grip force [N] (grasp scenes), the force checked against
    /// [`crate::scene::bounds::FORCE`] (an error on the argument `force`).
    pub fn try_with_grip_force(&self, force: f64) -> Result<Scene> {
        crate::scene::bounds::FORCE.check_arg("force", force)?;
        Ok(self.with_grip_force(force))
    }

    /// A copy with another per-finger grip force (grasp scenes; unchecked: see
    /// [`Self::try_with_grip_force`]).
    pub fn with_grip_force(&self, force: f64) -> Scene {
        let mut s = self.clone();
        if let Support::Grasp(g) = &mut s.support {
            g.force = force;
        }
        s
    }
}

