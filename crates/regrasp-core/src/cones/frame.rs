//! The pose-dependent frame of a planar push and the pusher's pose-independent model (split as in
//! MuJoCo's model/data), the exact membership test (thesis §3.3, RSS 2018) and the cone modes
//! (nominal, robust, fixtureless; §5.1, CASE 2018).
//!
//! Exact test: for a twist `v`, `v_s = J_s v`, `ŵ = A⁻¹v_s/√(v_sᵀA⁻¹v_s)` (eq 3.10); the
//! required pusher wrench is `w_p = J_sᵀŵ − w_g`; `v` is feasible iff `w_p ∈ W_p`. With the exact
//! limit surface ([`ExactSurface`]) `ŵ = μN W(v_s)` and the rays solve `H(λu + u_g) = 1` on it.

use crate::error::{Error, Result};
use crate::mechanics::exact_surface::ExactSurface;
use crate::mechanics::friction_cone::{ContactLimit, EdgeWrench, PolyhedralCone, PusherContact};
use crate::mechanics::geometry::{Mat3, Vec3};
use crate::mechanics::metric::Metric;

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
#[derive(Clone, Debug)]
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
    /// `√(u_gᵀ A u_g)` (exact surface: `H(u_g/μN)`): < 1 when the support holds the object
    /// against gravity.
    pub hold_ratio: f64,
    /// The exact limit surface (μN = 1) and `μN`, when the support uses it instead of `A`.
    pub exact: Option<(ExactSurface, f64)>,
    /// Which cone the exact test answers for (nominal, robust, fixtureless; [`crate::cones::robust`]).
    pub mode: ConeMode,
}

impl SupportFrame {
    pub fn new(a: Mat3, a_inv: Mat3, js: Mat3, js_inv: Mat3, gravity: Vec3) -> Self {
        let ug = js_inv.tr_mul(&gravity);
        let hold_ratio = ug.dot(&(a * ug)).sqrt();
        Self { a, a_inv, js, js_inv, gravity, ug, hold_ratio, mode: ConeMode::Nominal, exact: None }
    }

    /// Share of the support's friction that an object-frame wrench `w` (N, N, N·m about the
    /// object's origin, like [`Self::gravity`]) uses: `√(uᵀAu)` with `u = J_s⁻ᵀ w` (exact surface:
    /// `H(u/μN)`); `hold_ratio` is this of gravity. < 1: the support can supply `−w` without slip.
    pub fn load_ratio(&self, w: &Vec3) -> f64 {
        let u = self.js_inv.tr_mul(w);
        match &self.exact {
            Some((surface, scale)) => surface.gauge(&(u / *scale)),
            None => u.dot(&(self.a * u)).sqrt(),
        }
    }

    /// The same frame on the exact limit surface `surface` (μN = 1) at `μN = scale` [N].
    pub fn with_exact(mut self, surface: &ExactSurface, scale: f64) -> Self {
        self.hold_ratio = surface.gauge(&(self.ug / scale));
        self.exact = Some((surface.clone(), scale));
        self
    }

    /// The motion-cone ray (unit twist in `metric`) of pusher wrench direction `p`;
    /// `None` if the support cannot hold the object (no positive root).
    #[inline]
    pub fn ray(&self, p: &Vec3, metric: &Metric) -> Option<Vec3> {
        self.ray_with::<true>(p, metric)
    }

    /// [`Self::ray`] on the exact surface as a guess, for searches whose result is then found by
    /// [`Self::ray`] ([`ExactSurface::ray_from`] without polishing: on a disc's profile the twist
    /// of a `λ` within 1e-4 of the root on the inverse's starting table alone
    /// ([`crate::mechanics::disc_profile::DiscProfile::gauge_guess`]), on cube maps the inverse table's twist after one
    /// Newton step on the forward table); the ray itself on the ellipsoid.
    #[inline]
    pub fn ray_guess(&self, p: &Vec3, metric: &Metric) -> Option<Vec3> {
        self.ray_with::<false>(p, metric)
    }

    /// [`Self::ray`] starting from `near`, the ray of a nearby pusher wrench (object frame): on
    /// the exact surface Newton's method from there, cheaper than from the tables.
    #[inline]
    pub fn ray_near(&self, p: &Vec3, metric: &Metric, near: &Vec3) -> Option<Vec3> {
        if let Some((surface, s)) = &self.exact {
            let scale = p.amax();
            if scale > 0.0 && scale.is_finite() && near.amax() > 0.0 && self.hold_ratio < 1.0 {
                let u = self.js_inv.tr_mul(&(p / scale));
                if let Some(vs) = surface.ray_near(&u, &(self.ug / *s), &(self.js * near)) {
                    let v = self.js_inv * vs;
                    return Some(v / metric.twist_norm(&v));
                }
            }
        }
        self.ray(p, metric)
    }

    #[inline]
    fn ray_with<const POLISH: bool>(&self, p: &Vec3, metric: &Metric) -> Option<Vec3> {
        let scale = p.amax();
        if !(scale > 0.0) || !scale.is_finite() {
            return None;
        }
        let u = self.js_inv.tr_mul(&(p / scale));
        // λ: (λu + u_g)ᵀ A (λu + u_g) = 1 on the ellipsoid
        let au = self.a * u;
        let qa = u.dot(&au);
        let qb = 2.0 * self.ug.dot(&au);
        let qc = self.ug.dot(&(self.a * self.ug)) - 1.0;
        let lambda = if !(qc < 0.0) || !(qa > 0.0) {
            None
        } else {
            let disc = (qb * qb - 4.0 * qa * qc).sqrt();
            // positive root, in the cancellation-free form
            Some(if qb >= 0.0 { 2.0 * qc / (-qb - disc) } else { (-qb + disc) / (2.0 * qa) })
        };
        if let Some((surface, s)) = &self.exact {
            // the ellipsoid's root is a first guess on the exact surface
            let v = self.js_inv * surface.ray_from::<POLISH>(&u, &(self.ug / *s), self.hold_ratio, lambda.map(|l| l / s))?;
            return Some(v / metric.twist_norm(&v));
        }
        let v = self.js_inv * (au * lambda? + self.a * self.ug);
        Some(v / metric.twist_norm(&v))
    }

    /// Ray of the gravity-free cone for pusher wrench `p`: `J_s⁻¹ A J_s⁻ᵀ p` (exact surface: the
    /// sliding twist whose load is along `J_s⁻ᵀ p`), unit.
    #[inline]
    pub fn gravity_free_ray(&self, p: &Vec3, metric: &Metric) -> Vec3 {
        let u = self.js_inv.tr_mul(&(p / p.amax()));
        let exact = self.exact.as_ref().and_then(|(surface, _)| surface.twist_for(&u));
        let v = self.js_inv * exact.unwrap_or_else(|| self.a * u);
        v / metric.twist_norm(&v)
    }

    /// Load wrench on the support for twist `v`, mapped to the object frame: `J_sᵀ ŵ` (eq 3.10).
    #[inline]
    pub fn support_load(&self, v: &Vec3) -> Vec3 {
        // only the direction matters: normalize first so that huge or tiny twists are safe
        let vs = self.js * (v / v.amax());
        if let Some((surface, s)) = &self.exact {
            return self.js.tr_mul(&(surface.wrench(&vs) * *s));
        }
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

/// Which cone the exact test, the rays and the planner use.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum ConeMode {
    /// The motion cone at the scene's values.
    #[default]
    Nominal,
    /// `V(ρ_min) ∩ V_gf` (the scene is already the worst case, see [`crate::scene::perturb::worst_case`]).
    Robust,
    /// Fixtureless fixturing: `V_gf` of a pusher that carries the weight, else empty.
    Fixtureless,
}

impl ConeMode {
    pub fn parse(s: &str) -> Result<Self> {
        match s {
            "nominal" => Ok(Self::Nominal),
            "robust" => Ok(Self::Robust),
            "fixtureless" => Ok(Self::Fixtureless),
            _ => Err(Error::arg("mode", format!("must be nominal, robust or fixtureless (got {s:?})"))),
        }
    }
    pub fn label(&self) -> &'static str {
        match self {
            Self::Nominal => "nominal",
            Self::Robust => "robust",
            Self::Fixtureless => "fixtureless",
        }
    }
}

/// Whether the pusher alone can carry the object's weight (`−w_g ∈ W_p`): its pushes inside
/// the gravity-free cone are then invariant to mass, grip force and finger friction.
pub fn carries_weight(frame: &SupportFrame, model: &PusherModel) -> bool {
    frame.gravity.amax() == 0.0 || model.membership(&(-frame.gravity)).0 >= -MEMBERSHIP_TOL
}

/// The margin of the exact test in `mode`, from the nominal margin and the support load.
#[inline]
pub fn mode_margin(mode: ConeMode, frame: &SupportFrame, model: &PusherModel, nominal: f64, support: &Vec3) -> f64 {
    match mode {
        ConeMode::Nominal => nominal,
        ConeMode::Robust => nominal.min(model.membership(support).0),
        ConeMode::Fixtureless => {
            if carries_weight(frame, model) {
                model.membership(support).0
            } else {
                -1.0
            }
        }
    }
}
