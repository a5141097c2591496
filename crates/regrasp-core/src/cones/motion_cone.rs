//! Motion cones of a planar push (Chavan-Dafle, Holladay & Rodriguez, RSS 2018; thesis §3.3).
//!
//! Quasi-static balance in the object frame: `J_sᵀ w_s = w_p + w_g` with `w_s` on the support's
//! limit surface (the support slides), `w_p ∈ W_p` (the pusher sticks) and `w_g` gravity. The
//! motion cone is the set of object twists `v = J_s⁻¹ A w_s` this allows.
//!
//! * **Exact test**: for a twist `v`, `v_s = J_s v`, `ŵ = A⁻¹v_s/√(v_sᵀA⁻¹v_s)` (eq 3.10); the
//!   required pusher wrench is `w_p = J_sᵀŵ − w_g`; `v` is feasible iff `w_p ∈ W_p`.
//! * **Rays**: for a pusher wrench direction `p`, `u = J_s⁻ᵀp`, `u_g = J_s⁻ᵀw_g`; the positive
//!   root `λ` of `(λu + u_g)ᵀA(λu + u_g) = 1` gives the twist `J_s⁻¹A(λu + u_g)`. The
//!   polyhedral approximation takes one ray per edge of `W_p` (its generators).
//! * **Gravity-free cone**: `V_gf = J_s⁻¹ A J_s⁻ᵀ W_p`, exactly polyhedral.
//!
//! The same construction covers a grasp (support = finger pads) and an object on a surface
//! (support = the surface under it, Mason 1986; Lynch & Mason 1996).
//!
//! Twists and wrenches are compared in the frame-invariant, dual metrics of [`Metric`]
//! (centre-of-mass velocity and `Lω`; force and moment about the centre of mass over `L`).
//!
//! Split as in MuJoCo's model/data: a [`PusherModel`] (pose-independent: the pusher's cone in
//! the object frame) and a [`SupportFrame`] (everything that depends on the pose).

use crate::error::{Error, Result};
use crate::mechanics::exact_surface::ExactSurface;
use crate::mechanics::friction_cone::{ConeShape, EdgeWrench, PolyhedralCone, PusherContact};
use crate::mechanics::geometry::{perp, Mat3, Vec2, Vec3};
use crate::mechanics::limit_surface::LimitSurface;
use crate::mechanics::metric::Metric;
pub use crate::cones::frame::{Classification, ConeMode, PusherModel, SupportFrame, MEMBERSHIP_TOL};
pub use crate::cones::projection::{project_exact, project_exact_with_margin, project_onto_generators, project_with_margin, project_with_margin_on};

/// Everything that defines one push at one pose.
#[derive(Clone, Debug)]
pub struct PushSpec {
    /// Unit ellipsoidal limit surface of the support, in the support frame.
    pub limit_surface: LimitSurface,
    /// The exact limit surface (μN = 1) the cones use instead, when the scene selects it.
    pub exact: Option<ExactSurface>,
    /// `μ_s N` of the support [N]: the limit surface is `wᵀ (B / s²) w = 1`.
    pub friction_scale: f64,
    /// `J_s`: object twist (object frame) → support twist (support frame).
    pub support_jacobian: Mat3,
    pub pusher: PusherContact,
    /// Gravity wrench in the object frame.
    pub gravity: Vec3,
    /// Metrics on twists and wrenches.
    pub metric: Metric,
    /// The pose, for error messages.
    pub pose: [f64; 3],
    /// Nominal, robust or fixtureless cone ([`crate::cones::robust`]).
    pub mode: ConeMode,
    /// Grip force of each finger per unit `friction_scale` (`1/(2μ_s)` for a two-pad grasp);
    /// `None` when the normal force is not a free parameter (object on a surface).
    pub grip_per_scale: Option<f64>,
}

/// Range of per-finger grip force for which a given pusher motion sticks.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GripForceRange {
    pub min: f64,
    /// `f64::INFINITY` when unbounded.
    pub max: f64,
}

/// One push at one pose: the motion cone and everything computed from it.
#[derive(Clone, Debug)]
pub struct PlanarPush {
    spec: PushSpec,
    frame: SupportFrame,
    model: PusherModel,
}

impl PlanarPush {
    /// Builds the push; fails when the support cannot hold the object against gravity.
    pub fn new(spec: PushSpec) -> Result<Self> {
        let p = Self::new_unchecked(spec)?;
        p.check_hold()?;
        Ok(p)
    }

    /// Builds the push even when gravity alone would make the support slip: the gravity-free
    /// cone and grip-force queries remain meaningful; rays and the exact test do not.
    pub fn new_unchecked(spec: PushSpec) -> Result<Self> {
        let model = PusherModel::new(spec.pusher.clone(), spec.metric)?;
        Self::with_model(spec, model)
    }

    /// Like [`Self::new_unchecked`] with the pusher's cone already built (`model` must be the
    /// cone of `spec.pusher` in `spec.metric`).
    pub fn with_model(spec: PushSpec, model: PusherModel) -> Result<Self> {
        if !(spec.friction_scale > 0.0) || !spec.friction_scale.is_finite() {
            return Err(Error::arg("friction_scale", "must be positive and finite"));
        }
        let js_inv = spec
            .support_jacobian
            .try_inverse()
            .ok_or_else(|| Error::arg("support_jacobian", "is singular"))?;
        let mut frame = SupportFrame::new(
            spec.limit_surface.matrix(spec.friction_scale),
            spec.limit_surface.matrix_inv(spec.friction_scale),
            spec.support_jacobian,
            js_inv,
            spec.gravity,
        );
        frame.mode = spec.mode;
        if let Some(e) = &spec.exact {
            frame = frame.with_exact(e, spec.friction_scale);
        }
        Ok(Self { spec, frame, model })
    }

    fn check_hold(&self) -> Result<()> {
        if !(self.frame.hold_ratio < 1.0) {
            return Err(Error::GraspCannotHold { pose: self.spec.pose, ratio: self.frame.hold_ratio });
        }
        Ok(())
    }

    pub fn spec(&self) -> &PushSpec {
        &self.spec
    }

    pub fn frame(&self) -> &SupportFrame {
        &self.frame
    }

    /// How much of the support's friction gravity alone uses (< 1 to hold).
    pub fn hold_ratio(&self) -> f64 {
        self.frame.hold_ratio
    }

    /// The pusher's generalized friction cone edges (eq 3.6), physical units.
    pub fn pusher_edges(&self) -> &[EdgeWrench] {
        &self.model.edges
    }

    /// The pusher's generalized friction cone in the scaled wrench space of the metric.
    pub fn pusher_cone(&self) -> &PolyhedralCone {
        &self.model.cone
    }

    pub fn metric(&self) -> &Metric {
        &self.spec.metric
    }

    /// Norm of a twist in the metric.
    pub fn twist_norm(&self, v: &Vec3) -> f64 {
        self.spec.metric.twist_norm(v)
    }

    /// The motion-cone ray produced by pusher wrench direction `p` (physical units), as a unit
    /// twist; `None` if the support cannot hold the object.
    pub fn ray(&self, p: &Vec3) -> Option<Vec3> {
        self.frame.ray(p, &self.spec.metric)
    }

    /// Generators of the polyhedral approximation: one ray per edge of `W_p`, unit twists (in
    /// the robust and fixtureless modes, those of [`crate::cones::robust::generators`]).
    pub fn generators(&self) -> Result<Vec<Vec3>> {
        self.check_hold()?;
        Ok(crate::cones::robust::generators(&self.frame, &self.model))
    }

    /// Whether the pusher alone can carry the object's weight (the invariant case, §5.1).
    pub fn carries_weight(&self) -> bool {
        crate::cones::robust::carries_weight(&self.frame, &self.model)
    }

    /// Generators of the gravity-free cone `J_s⁻¹ A J_s⁻ᵀ e_i`, unit twists.
    pub fn gravity_free_generators(&self) -> Vec<Vec3> {
        self.model.edges.iter().map(|e| self.frame.gravity_free_ray(&e.wrench, &self.spec.metric)).collect()
    }

    fn check_twist(&self, v: &Vec3) -> Result<()> {
        if !v.iter().all(|x| x.is_finite()) {
            return Err(Error::arg("twist", "has a non-finite component"));
        }
        if v.amax() == 0.0 {
            return Err(Error::arg("twist", "is zero: a push must move the object"));
        }
        Ok(())
    }

    /// The exact membership test: can the pusher produce twist `v` while sticking?
    pub fn classify(&self, v: &Vec3) -> Result<Classification> {
        self.check_twist(v)?;
        self.check_hold()?;
        Ok(self.frame.classify(&self.model, v))
    }

    pub fn contains(&self, v: &Vec3) -> Result<bool> {
        Ok(self.classify(v)?.feasible)
    }

    /// The polyhedral approximation as a cone in the scaled twist space of the metric.
    pub fn polyhedral_cone(&self) -> Result<PolyhedralCone> {
        let g: Vec<Vec3> = self.generators()?.iter().map(|v| self.spec.metric.twist(v)).collect();
        PolyhedralCone::from_edges(&g).map_err(|e| Error::arg("pusher", format!("degenerate motion cone ({e:?})")))
    }

    /// Margin of `v` in the gravity-free cone, measured in the wrench space (exact, polyhedral).
    pub fn gravity_free_margin(&self, v: &Vec3) -> Result<f64> {
        self.check_twist(v)?;
        Ok(self.model.membership(&self.frame.support_load(v)).0)
    }

    /// Closest feasible twist to `d` in the twist metric (exact cone): `d` itself
    /// when feasible, else `⟨d, û⟩ û` for the boundary ray `û` nearest in angle (zero when no
    /// ray makes an acute angle with `d`).
    pub fn project(&self, d: &Vec3) -> Result<Vec3> {
        if !d.iter().all(|x| x.is_finite()) {
            return Err(Error::arg("twist", "has a non-finite component"));
        }
        self.check_hold()?;
        Ok(project_exact(&self.frame, &self.model, d))
    }

    /// For a point pusher: the object twist that results when the contact point moves with
    /// velocity `u` (object frame) and the pusher sticks, i.e. the rotation rate that makes
    /// the required pusher wrench pass through the contact point, at friction scale `s`.
    /// `None` when no rotation rate balances the moments.
    pub fn point_pusher_twist(&self, u: &Vec2, s: f64) -> Option<Vec3> {
        let r = *self.spec.pusher.points.first()?;
        crate::cones::point_pusher::contact_twist(&r, u, self.spec.metric.length, |v| self.unit_load(v) * s - self.spec.gravity)
    }

    /// The same push with another friction scale (another grip force).
    pub fn with_friction_scale(&self, s: f64) -> Result<Self> {
        Self::new_unchecked(PushSpec { friction_scale: s, ..self.spec.clone() })
    }

    /// Range of per-finger grip force for which the pusher motion of twist `v` sticks (RSS 2018
    /// Theorem 1: every twist inside the gravity-free cone is stable above some grip force). For
    /// a point pusher the pusher motion is the contact point's velocity; the object's rotation
    /// then depends on the grip force (see [`Self::point_pusher_twist`]).
    ///
    /// A line pusher imposes the whole twist: with `a₀ = J_sᵀŵ₀(v)` (unit surface) and inward
    /// facet normals `nⱼ` of `W_p`, stability is `nⱼ·(s a₀ − w_g) ≥ 0`, linear in `s = μ_s N`
    /// (*derived*), and the support must hold: `s > √(u_gᵀ B u_g)`. A point pusher imposes only
    /// its contact point's velocity; the rotation rate adapts (see
    /// [`Self::point_pusher_twist`]) and the range is found numerically. `None` when no grip
    /// force makes the motion stick.
    pub fn grip_force_range(&self, v: &Vec3) -> Result<Option<GripForceRange>> {
        self.check_twist(v)?;
        let per = self
            .spec
            .grip_per_scale
            .ok_or_else(|| Error::arg("scene", "grip force is defined only for a grasp (not an object on a surface)"))?;
        // the hold ratio is degree −1 in s: it stays below 1 for s > s_hold
        let s_hold = self.frame.hold_ratio * self.spec.friction_scale;
        let v = v / v.amax();
        let range = if self.spec.pusher.is_line() { self.line_scale_range(&v, s_hold) } else { self.point_scale_range(&v, s_hold) };
        Ok(range.map(|(lo, hi)| GripForceRange { min: lo * per, max: hi * per }))
    }

    /// The support's load for twist `v` at unit friction scale (the load is linear in it).
    fn unit_load(&self, v: &Vec3) -> Vec3 {
        self.frame.support_load(v) / self.spec.friction_scale
    }

    /// Line pusher: `w(s) = s a₀ − w_g` must lie in `W_p`, linear in `s` (facet inequalities; for
    /// a frictionless pusher, whose cone is a fan, the fan's plane equation and its edges).
    fn line_scale_range(&self, v: &Vec3, s_hold: f64) -> Option<(f64, f64)> {
        let m = &self.spec.metric;
        let (a0s, wgs) = (m.wrench(&self.unit_load(v)), m.wrench(&self.spec.gravity));
        let (mut lo, mut hi) = (s_hold * (1.0 + 1e-12), f64::INFINITY);
        let tol = 1e-12 * (a0s.norm() + wgs.norm());
        // each constraint n·(s a₀ − w_g) ≥ 0
        let mut inequality = |n: &Vec3| -> bool {
            let (al, be) = (n.dot(&a0s), n.dot(&wgs));
            if al > tol {
                lo = lo.max(be / al);
            } else if al < -tol {
                hi = hi.min(be / al);
            } else if be > tol {
                return false;
            }
            true
        };
        match &self.model.cone.shape {
            ConeShape::Solid { facets } => {
                for f in facets {
                    if !inequality(&f.normal) {
                        return None;
                    }
                }
            }
            ConeShape::Fan { normal, inward, .. } => {
                for n in inward {
                    if !inequality(n) {
                        return None;
                    }
                }
                let (al, be) = (normal.dot(&a0s), normal.dot(&wgs));
                if al.abs() > tol {
                    let s = be / al;
                    if s < lo || s > hi {
                        return None;
                    }
                    return Some((s, s));
                } else if be.abs() > tol {
                    return None;
                }
            }
            ConeShape::Ray | ConeShape::Full => return None,
        }
        (lo <= hi).then_some((lo.max(0.0), hi))
    }

    fn point_scale_range(&self, v: &Vec3, s_hold: f64) -> Option<(f64, f64)> {
        let ConeShape::Fan { inward, .. } = &self.model.cone.shape else { return None };
        let r = self.spec.pusher.points[0];
        let u = Vec2::new(v.x, v.y) + perp(&r) * v.z;
        let m = &self.spec.metric;
        let sticks = |s: f64| -> bool {
            self.point_pusher_twist(&u, s).is_some_and(|t| {
                let ws = m.wrench(&(self.unit_load(&t) * s - self.spec.gravity));
                let n = ws.norm().max(1e-300);
                inward.iter().all(|m| m.dot(&ws) / n >= -MEMBERSHIP_TOL)
            })
        };
        let base = if s_hold > 0.0 { s_hold } else { self.spec.friction_scale * 1e-6 };
        // geometric scan over 8 decades, then bisection at the transitions
        let grid: Vec<f64> = (0..=240).map(|k| base * (1.0 + 1e-9) * 10f64.powf(k as f64 * 8.0 / 240.0)).collect();
        let first = grid.iter().position(|&s| sticks(s))?;
        let refine = |mut a: f64, mut b: f64, want_a: bool| {
            for _ in 0..80 {
                let m = (a * b).sqrt();
                if sticks(m) == want_a {
                    a = m;
                } else {
                    b = m;
                }
            }
            if want_a {
                a
            } else {
                b
            }
        };
        let lo = if first == 0 { grid[0] } else { refine(grid[first - 1], grid[first], false) };
        let hi = match grid[first..].iter().position(|&s| !sticks(s)) {
            None => f64::INFINITY,
            Some(k) => refine(grid[first + k - 1], grid[first + k], true),
        };
        Some((lo, hi))
    }
}
