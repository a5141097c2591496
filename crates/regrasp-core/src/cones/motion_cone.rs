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
use crate::mechanics::friction_cone::{ConeShape, ContactLimit, EdgeWrench, PolyhedralCone, PusherContact};
use crate::mechanics::geometry::{cross2, perp, Mat3, Vec2, Vec3};
use crate::mechanics::limit_surface::LimitSurface;
use crate::mechanics::metric::Metric;
use crate::cones::robust::{mode_margin, ConeMode};

/// Tolerance of the exact membership test on the (dimensionless) margin.
pub const MEMBERSHIP_TOL: f64 = 1e-9;

/// A pusher's generalized friction cone in the object frame (pose-independent).
#[derive(Clone, Debug)]
pub struct PusherModel {
    pub contact: PusherContact,
    /// Edge wrenches, physical units, unit normal force (eq 3.6).
    pub edges: Vec<EdgeWrench>,
    /// `W_p` in the scaled wrench space of `metric`.
    pub cone: PolyhedralCone,
    pub metric: Metric,
}

impl PusherModel {
    pub fn new(contact: PusherContact, metric: Metric) -> Result<Self> {
        if !(metric.length > 0.0) {
            return Err(Error::arg("length", "must be positive"));
        }
        let edges = contact.edge_wrenches();
        let scaled: Vec<Vec3> = edges.iter().map(|e| metric.wrench(&e.wrench)).collect();
        let cone = PolyhedralCone::from_edges(&scaled)
            .map_err(|e| Error::arg("pusher", format!("its friction cone is degenerate ({e:?})")))?;
        Ok(Self { contact, edges, cone, metric })
    }

    /// Signed margin of pusher wrench `w` and the contact limit nearest to it.
    pub fn membership(&self, w: &Vec3) -> (f64, ContactLimit) {
        let m = self.cone.membership(&self.metric.wrench(w));
        (m.margin, self.contact.limit_of(&self.edges, m.active, w))
    }
}

/// Pose-dependent quantities of a push: limit surface, support Jacobian, gravity.
#[derive(Clone, Copy, Debug)]
pub struct SupportFrame {
    /// `A` (eq 3.7), support frame.
    pub a: Mat3,
    pub a_inv: Mat3,
    /// `J_s`: object twist → support twist.
    pub js: Mat3,
    pub js_inv: Mat3,
    /// Gravity wrench, object frame.
    pub gravity: Vec3,
    /// `J_s⁻ᵀ w_g`.
    pub ug: Vec3,
    /// `√(u_gᵀ A u_g)`: < 1 when the support holds the object against gravity.
    pub hold_ratio: f64,
    /// Which cone the exact test answers for (nominal, robust, fixtureless; [`crate::cones::robust`]).
    pub mode: ConeMode,
}

impl SupportFrame {
    pub fn new(a: Mat3, a_inv: Mat3, js: Mat3, js_inv: Mat3, gravity: Vec3) -> Self {
        let ug = js_inv.tr_mul(&gravity);
        let hold_ratio = ug.dot(&(a * ug)).sqrt();
        Self { a, a_inv, js, js_inv, gravity, ug, hold_ratio, mode: ConeMode::Nominal }
    }

    /// The motion-cone ray (unit twist in `metric`) of pusher wrench direction `p`;
    /// `None` if the support cannot hold the object (no positive root).
    #[inline]
    pub fn ray(&self, p: &Vec3, metric: &Metric) -> Option<Vec3> {
        let scale = p.amax();
        if !(scale > 0.0) || !scale.is_finite() {
            return None;
        }
        let u = self.js_inv.tr_mul(&(p / scale));
        let au = self.a * u;
        let qa = u.dot(&au);
        let qb = 2.0 * self.ug.dot(&au);
        let qc = self.hold_ratio * self.hold_ratio - 1.0;
        if !(qc < 0.0) || !(qa > 0.0) {
            return None;
        }
        let disc = (qb * qb - 4.0 * qa * qc).sqrt();
        // positive root, in the cancellation-free form
        let lambda = if qb >= 0.0 { 2.0 * qc / (-qb - disc) } else { (-qb + disc) / (2.0 * qa) };
        let v = self.js_inv * (au * lambda + self.a * self.ug);
        Some(v / metric.twist_norm(&v))
    }

    /// Ray of the gravity-free cone for pusher wrench `p`: `J_s⁻¹ A J_s⁻ᵀ p`, unit.
    #[inline]
    pub fn gravity_free_ray(&self, p: &Vec3, metric: &Metric) -> Vec3 {
        let v = self.js_inv * (self.a * self.js_inv.tr_mul(&(p / p.amax())));
        v / metric.twist_norm(&v)
    }

    /// Load wrench on the support for twist `v`, mapped to the object frame: `J_sᵀ ŵ` (eq 3.10).
    #[inline]
    pub fn support_load(&self, v: &Vec3) -> Vec3 {
        // only the direction matters: normalize first so that huge or tiny twists are safe
        let vs = self.js * (v / v.amax());
        let w = self.a_inv * vs;
        self.js.tr_mul(&(w / vs.dot(&w).sqrt()))
    }

    /// The exact test (twist assumed finite and non-zero, support assumed to hold).
    #[inline]
    pub fn classify(&self, model: &PusherModel, v: &Vec3) -> Classification {
        let support = self.support_load(v);
        let wp = support - self.gravity;
        let (margin, limit) = model.membership(&wp);
        let margin = mode_margin(self.mode, self, model, margin, &support);
        Classification { feasible: margin >= -MEMBERSHIP_TOL, margin, limit, pusher_wrench: wp, support_wrench: support }
    }
}

/// Everything that defines one push at one pose.
#[derive(Clone, Debug)]
pub struct PushSpec {
    /// Unit limit surface of the support, in the support frame.
    pub limit_surface: LimitSurface,
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

/// Result of the exact membership test.
#[derive(Clone, Copy, Debug)]
pub struct Classification {
    pub feasible: bool,
    /// Signed margin (≥ 0 inside): the sine of the angle from the required pusher wrench to the
    /// nearest boundary of `W_p`, in the scaled wrench metric.
    pub margin: f64,
    /// The contact limit nearest to being violated (active when `margin ≈ 0`).
    pub limit: ContactLimit,
    /// Wrench the pusher must apply [N, N, N·m], object frame.
    pub pusher_wrench: Vec3,
    /// Load wrench of the object on the support, mapped to the object frame (`J_sᵀŵ`).
    pub support_wrench: Vec3,
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
        let l = self.spec.metric.length;
        let un = u.norm();
        let uhat = if un > 0.0 { u / un } else { Vec2::zeros() };
        let pr = perp(&r);
        let twist = |phi: f64| -> Vec3 {
            let (sp, cp) = phi.sin_cos();
            let w = sp / l;
            let lin = uhat * cp - pr * w;
            Vec3::new(lin.x, lin.y, w)
        };
        let binv = self.spec.limit_surface.b_inv;
        let js = self.spec.support_jacobian;
        // moment about r of the required pusher wrench; non-decreasing in phi because the
        // load wrench is the gradient of a convex dissipation function (a monotone map)
        let h = |phi: f64| -> f64 {
            let v = twist(phi);
            let w = js.tr_mul(&LimitSurface::wrench_for_twist(&binv, &(js * v))) * s - self.spec.gravity;
            w.z - cross2(&r, &Vec2::new(w.x, w.y))
        };
        let half = std::f64::consts::FRAC_PI_2;
        if un == 0.0 {
            // the contact point does not move: a pure rotation about it, either way
            return [half, -half].into_iter().find(|&phi| h(phi).abs() < 1e-12 * (1.0 + s)).map(twist);
        }
        let (mut lo, mut hi) = (-half, half);
        if h(lo) > 0.0 || h(hi) < 0.0 {
            return None;
        }
        for _ in 0..100 {
            let mid = 0.5 * (lo + hi);
            if h(mid) < 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
            if hi - lo < 1e-15 {
                break;
            }
        }
        let phi = 0.5 * (lo + hi);
        (phi.abs() < half - 1e-12).then(|| twist(phi))
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
        // u_gᵀ A u_g = u_gᵀ B u_g / s² < 1  ⇔  s > √(u_gᵀ B u_g)
        let s_hold = self.frame.ug.dot(&(self.spec.limit_surface.b * self.frame.ug)).sqrt();
        let v = v / v.amax();
        let range = if self.spec.pusher.is_line() { self.line_scale_range(&v, s_hold) } else { self.point_scale_range(&v, s_hold) };
        Ok(range.map(|(lo, hi)| GripForceRange { min: lo * per, max: hi * per }))
    }

    fn unit_load(&self, v: &Vec3) -> Vec3 {
        let js = self.spec.support_jacobian;
        js.tr_mul(&LimitSurface::wrench_for_twist(&self.spec.limit_surface.b_inv, &(js * v)))
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

/// Closest feasible twist (see [`PlanarPush::project`]); the support must hold.
pub fn project_exact(frame: &SupportFrame, model: &PusherModel, d: &Vec3) -> Vec3 {
    let scale = d.amax();
    if scale == 0.0 {
        return Vec3::zeros();
    }
    let dd = d / scale;
    if frame.classify(model, &dd).feasible {
        return *d;
    }
    let dn = model.metric.twist_norm(&dd);
    let (cos, u) = nearest_boundary_ray(frame, model, &dd);
    if cos > 0.0 {
        u * (cos * dn * scale)
    } else {
        Vec3::zeros()
    }
}

/// Closest twist to `want` in the cone (of the frame's mode) with at least margin `margin`: the
/// projection on the polyhedral cone of its generators when the exact test accepts it, else the
/// exact projection, then moved towards the mean of the generators until the margin holds.
/// `None` when the cone is empty or the support cannot hold the object.
pub fn project_with_margin(frame: &SupportFrame, model: &PusherModel, want: &Vec3, margin_min: f64) -> Option<Vec3> {
    project_with_margin_on(frame, model, &crate::cones::robust::generators(frame, model), want, margin_min)
}

/// [`project_with_margin`] with the cone's generators already computed (`gens`, unit twists).
pub fn project_with_margin_on(frame: &SupportFrame, model: &PusherModel, gens: &[Vec3], want: &Vec3, margin_min: f64) -> Option<Vec3> {
    let m = &model.metric;
    // (a nominal cone with fewer rays than W_p has edges: the support cannot hold the object)
    if gens.is_empty() || (frame.mode == ConeMode::Nominal && gens.len() < model.edges.len()) {
        return None;
    }
    let gs: Vec<Vec3> = gens.iter().map(|g| m.twist(g)).collect();
    let (pp, _) = project_onto_generators(&gs, &m.twist(want));
    let mut v = m.twist_inv(&pp);
    if v.amax() == 0.0 || frame.classify(model, &v).margin < 0.0 {
        v = project_exact(frame, model, want);
        if v.amax() == 0.0 {
            return None;
        }
    }
    let margin = |x: &Vec3| frame.classify(model, x).margin;
    if margin(&v) >= margin_min {
        return Some(v);
    }
    // towards the mean of the cone's rays
    let centre = gens.iter().fold(Vec3::zeros(), |a, g| a + g);
    if centre.amax() == 0.0 || margin(&centre) < margin_min {
        return (margin(&v) >= 0.0).then_some(v);
    }
    let (vn, cn) = (m.twist_norm(&v), m.twist_norm(&centre));
    let (mut lo, mut hi) = (0.0, 1.0);
    for _ in 0..30 {
        let mid = 0.5 * (lo + hi);
        let x = v / vn * (1.0 - mid) + centre / cn * mid;
        if margin(&x) >= margin_min {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    // the blend of two unit directions is shorter than either: back to the projection's speed
    let x = v / vn * (1.0 - hi) + centre / cn * hi;
    Some(x * (vn / m.twist_norm(&x)))
}

/// Maximizes the cosine between `d` and the rays on the boundary of the exact cone (images of
/// the boundary fans of `W_p`). Each fan is sampled until consecutive rays are less than 4°
/// apart (the boundary can turn quickly where gravity matters most), then the best two local
/// maxima are refined by golden-section search. Returns the cosine and the unit ray.
fn nearest_boundary_ray(frame: &SupportFrame, model: &PusherModel, d: &Vec3) -> (f64, Vec3) {
    const MAX_STEP: f64 = 0.07; // rad between consecutive samples
    const MAX_SAMPLES: usize = 4096;
    let m = &model.metric;
    let ds = m.twist(d).normalize();
    // (t, cosine, unit ray in the metric, ray)
    type Sample = (f64, f64, Vec3, Vec3);
    let sample = |p: &Vec3, t: f64| -> Sample {
        match frame.ray(&m.wrench_inv(p), m) {
            Some(v) => {
                let s = m.twist(&v);
                (t, s.dot(&ds), s, v)
            }
            None => (t, f64::NEG_INFINITY, Vec3::zeros(), Vec3::zeros()),
        }
    };
    let mut best = (f64::NEG_INFINITY, Vec3::zeros());
    // sample every boundary fan finely enough, keeping (segment, samples)
    let segments = model.cone.boundary_segments();
    let mut sampled: Vec<Vec<Sample>> = Vec::with_capacity(segments.len());
    for &(i, j) in &segments {
        let (ea, eb) = (model.cone.edges[i], model.cone.edges[j]);
        let at = |t: f64| ea * (1.0 - t) + eb * t;
        if i == j {
            sampled.push(vec![sample(&ea, 0.0)]);
            continue;
        }
        // depth-first subdivision of each interval until its end rays are close
        let cos_step = MAX_STEP.cos();
        let mut pts: Vec<Sample> = Vec::with_capacity(64);
        let mut stack: Vec<Sample> = Vec::with_capacity(32);
        let first = sample(&at(0.0), 0.0);
        pts.push(first);
        for k in (1..=8).rev() {
            stack.push(sample(&at(k as f64 / 8.0), k as f64 / 8.0));
        }
        while let Some(right) = stack.pop() {
            let left = *pts.last().expect("samples");
            if left.2.dot(&right.2) < cos_step && right.0 - left.0 > 1e-9 && pts.len() + stack.len() < MAX_SAMPLES {
                let t = 0.5 * (left.0 + right.0);
                stack.push(right);
                stack.push(sample(&at(t), t));
            } else {
                pts.push(right);
            }
        }
        sampled.push(pts);
    }
    let top = sampled.iter().flatten().map(|s| s.1).fold(f64::NEG_INFINITY, f64::max);
    // between samples at most MAX_STEP apart the cosine can rise by about MAX_STEP²/2 above
    // the better sample: refine every local maximum within that of the best one
    let slack = MAX_STEP * MAX_STEP;
    for (seg, pts) in sampled.iter().enumerate() {
        let (i, j) = segments[seg];
        let (ea, eb) = (model.cone.edges[i], model.cone.edges[j]);
        let at = |t: f64| ea * (1.0 - t) + eb * t;
        for k in 0..pts.len() {
            let is_peak = (k == 0 || pts[k].1 >= pts[k - 1].1) && (k + 1 == pts.len() || pts[k].1 >= pts[k + 1].1);
            if !is_peak || pts[k].1 < top - slack {
                continue;
            }
            if pts[k].1 > best.0 {
                best = (pts[k].1, pts[k].3);
            }
            if pts.len() < 2 {
                continue;
            }
            let (mut lo, mut hi) = (pts[k.saturating_sub(1)].0, pts[(k + 1).min(pts.len() - 1)].0);
            let g = 0.5 * (5f64.sqrt() - 1.0);
            let (mut x1, mut x2) = (hi - g * (hi - lo), lo + g * (hi - lo));
            let (mut f1, mut f2) = (sample(&at(x1), x1), sample(&at(x2), x2));
            let stop = 1e-7 * (hi - lo);
            while hi - lo > stop {
                if f1.1 >= f2.1 {
                    hi = x2;
                    x2 = x1;
                    f2 = f1;
                    x1 = hi - g * (hi - lo);
                    f1 = sample(&at(x1), x1);
                } else {
                    lo = x1;
                    x1 = x2;
                    f1 = f2;
                    x2 = lo + g * (hi - lo);
                    f2 = sample(&at(x2), x2);
                }
            }
            for f in [f1, f2] {
                if f.1 > best.0 {
                    best = (f.1, f.3);
                }
            }
        }
    }
    best
}

/// Euclidean projection of `d` onto the cone generated by `gens` (non-negative least squares,
/// exact by enumerating the faces: a projection lies in the relative interior of a face spanned
/// by at most 3 independent generators). Returns the projection and the weights.
pub fn project_onto_generators(gens: &[Vec3], d: &Vec3) -> (Vec3, Vec<f64>) {
    let k = gens.len();
    let mut best = (d.norm_squared(), Vec3::zeros(), vec![0.0; k]);
    // every face spanned by 1, 2 or 3 generators: O(k³) small fixed-size solves
    let mut consider = |idx: &[usize]| {
        let n = idx.len();
        let mut g = nalgebra::Matrix3::<f64>::zeros();
        for (j, &i) in idx.iter().enumerate() {
            g.set_column(j, &gens[i]);
        }
        let g = g.columns(0, n);
        let gtg = g.transpose() * g;
        if gtg.determinant().abs() < 1e-14 * gtg.norm().powi(n as i32) {
            return;
        }
        let Some(inv) = gtg.try_inverse() else { return };
        let alpha = inv * (g.transpose() * d);
        if alpha.iter().any(|&a| a < 0.0) {
            return;
        }
        let p: Vec3 = g * &alpha;
        let res = (d - p).norm_squared();
        if res < best.0 {
            let mut w = vec![0.0; k];
            for (j, &i) in idx.iter().enumerate() {
                w[i] = alpha[j];
            }
            best = (res, p, w);
        }
    };
    for a in 0..k {
        consider(&[a]);
        for b in a + 1..k {
            consider(&[a, b]);
            for c in b + 1..k {
                consider(&[a, b, c]);
            }
        }
    }
    (best.1, best.2)
}
