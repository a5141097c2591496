//! Quasi-static pushing dynamics as a mixed nonlinear complementarity problem (thesis §3.2).
//!
//! One rigid object (twist `V`, dimension 3 in the plane or 6 in space) touches:
//! * **finger** contacts: points of the finger pads, with a fixed share of the grip force as
//!   normal force (eq 3.5: the shares of a pad sum to the grip force) and Coulomb friction;
//! * **unilateral** contacts: points of a pusher (moving with twist `U`) or of a fixed feature,
//!   with `u_n ≥ 0 ⊥ f_n ≥ 0` (eq 3.16) and Coulomb friction;
//! * optionally **limit-surface patches**: a pad as one contact whose friction wrench lies in
//!   an ellipsoid (eq 3.7), for cross-checks against the motion cones.
//!
//! A line or a patch is a rigid set of points (eq 3.4 holds by construction: every point's
//! velocity comes from the same body twists). The quasi-static Newton–Euler equation over one
//! time step `h` (eq 3.13) is `Σ J_nᵀ f_n + J_tᵀ f_t + w_ext = (M/h) V`; relative velocities at
//! the contacts are `u = J V + b` (eqs 3.14–3.15, `b` from the pusher's motion and the gap).
//!
//! Coulomb's law with maximum dissipation (eqs 3.1–3.3) is written in the projection form of
//! Alart & Curnier: `f_t = Proj_{|f_t| ≤ μ f_n}(f_t − ρ u_t)`, `f_n = max(0, f_n − ρ u_n)`;
//! [`solve_forward`] solves the resulting non-smooth equations by a damped semismooth Newton
//! method with exact circular cones. [`solve_inverse`] (desired object twist → pusher motion
//! and forces) is convex: with the object's motion given every contact's mode is known except
//! the pusher's, which may as well stick; it is a second-order cone program (clarabel).
//! [`residuals`] checks any candidate solution against every constraint in its original form.
//!
//! Files: this one holds the problem and its [`residuals`]; `newton` the semismooth Newton
//! solver, `arrow` its linear-time step, `forward` the forward solve's attempts, `inverse` the cone program.

use crate::error::{Error, Result};
use nalgebra::{DMatrix, DVector};

mod arrow;
mod forward;
mod inverse;
mod newton;
#[cfg(test)]
mod fixtures;

pub use forward::solve_forward;
pub use inverse::solve_inverse;

/// How the normal force of a contact is determined.
#[derive(Clone, Debug, PartialEq)]
pub enum NormalLaw {
    /// A given normal force (a finger's share of the grip force).
    Fixed(f64),
    /// `u_n ≥ 0 ⊥ f_n ≥ 0`.
    Unilateral,
}

/// The set the friction force of a contact lies in.
#[derive(Clone, Debug, PartialEq)]
pub enum FrictionLaw {
    /// `|f_t| ≤ μ f_n` (1 or 2 tangent directions).
    Coulomb(f64),
    /// A limit-surface patch: `fᵀ A f ≤ 1` (A given, already scaled by its normal force).
    Ellipsoid(DMatrix<f64>),
}

/// Which body a contact's other side belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Side {
    /// A finger of the gripper (fixed in the planner's view).
    Finger,
    /// The pusher (moving with twist `U`).
    Pusher,
    /// A fixed feature of the environment.
    Fixed,
}

#[derive(Clone, Debug)]
pub struct Contact {
    /// E.g. "finger0[2]", "pusher:bottom[1]".
    pub label: String,
    pub side: Side,
    pub normal: NormalLaw,
    pub friction: FrictionLaw,
    /// Normal row: object twist → normal relative velocity (object minus other side).
    pub jn: DVector<f64>,
    /// Tangent rows (k × d).
    pub jt: DMatrix<f64>,
    /// The same rows for the pusher's twist (zero unless `side == Pusher`).
    pub jn_other: DVector<f64>,
    pub jt_other: DMatrix<f64>,
    /// Gap to the other body [m] (≥ 0 apart); enters as `u_n + gap/h`.
    pub gap: f64,
}

impl Contact {
    /// A point with a given normal force `normal_force` and a Coulomb disc `μ` (a finger pad's
    /// share of the grip force, eq 3.5, or a point of a support): nothing on its other side moves.
    pub fn fixed_normal(label: String, side: Side, normal_force: f64, mu: f64, jn: DVector<f64>, jt: DMatrix<f64>) -> Self {
        let (jn_other, jt_other) = (DVector::zeros(jn.len()), DMatrix::zeros(jt.nrows(), jt.ncols()));
        Self { label, side, normal: NormalLaw::Fixed(normal_force), friction: FrictionLaw::Coulomb(mu), jn, jt, jn_other, jt_other, gap: 0.0 }
    }

    /// A point of the pusher at gap `gap`: unilateral (eq 3.16) with a Coulomb cone `μ`, the
    /// pusher's twist entering through the same rows as the object's (the point is on both).
    pub fn pusher_point(label: String, mu: f64, jn: DVector<f64>, jt: DMatrix<f64>, gap: f64) -> Self {
        let (jn_other, jt_other) = (jn.clone(), jt.clone());
        Self { label, side: Side::Pusher, normal: NormalLaw::Unilateral, friction: FrictionLaw::Coulomb(mu), jn, jt, jn_other, jt_other, gap }
    }

    pub fn tangent_dim(&self) -> usize {
        self.jt.nrows()
    }
}

/// One instantaneous quasi-static problem.
#[derive(Clone, Debug)]
pub struct Problem {
    /// Twist dimension (3 planar, 6 spatial).
    pub dim: usize,
    /// `M / h` (d × d, positive definite).
    pub mass: DMatrix<f64>,
    /// External wrench (gravity), same coordinates as the twist.
    pub wrench: DVector<f64>,
    pub contacts: Vec<Contact>,
    /// Time step h [s] (the gap enters as gap / h).
    pub h: f64,
    /// Typical force [N] and velocity [m/s] for scaling residuals.
    pub force_scale: f64,
    pub velocity_scale: f64,
    /// A length [m] to compare rotations with translations.
    pub length: f64,
}

/// State of a contact in a solution.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ContactState {
    Stick,
    Slide,
    Separate,
}

impl ContactState {
    pub fn label(&self) -> &'static str {
        match self {
            ContactState::Stick => "stick",
            ContactState::Slide => "slide",
            ContactState::Separate => "separate",
        }
    }
}

/// Largest violation of each constraint, scaled (forces by `force_scale`, velocities by
/// `velocity_scale`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Residuals {
    /// Newton–Euler balance (eq 3.13).
    pub newton_euler: f64,
    /// `f_n ≥ 0` and `u_n ≥ 0` (eq 3.16).
    pub normal_feasibility: f64,
    /// `u_n f_n = 0` (eq 3.16).
    pub normal_complementarity: f64,
    /// `|f_t| ≤ μ f_n` (eq 3.1) or `fᵀAf ≤ 1`.
    pub cone: f64,
    /// `((μ f_n)² − |f_t|²)|u_t| = 0` (eq 3.2).
    pub friction_complementarity: f64,
    /// `μ f_n u_t + f_t |u_t| = 0` (eq 3.3, maximum dissipation).
    pub dissipation: f64,
}

impl Residuals {
    pub fn max(&self) -> f64 {
        [
            self.newton_euler,
            self.normal_feasibility,
            self.normal_complementarity,
            self.cone,
            self.friction_complementarity,
            self.dissipation,
        ]
        .into_iter()
        .fold(0.0, f64::max)
    }
}

/// A solution of the forward or inverse problem.
#[derive(Clone, Debug)]
pub struct Solution {
    /// Object twist.
    pub twist: DVector<f64>,
    /// Pusher twist.
    pub pusher_twist: DVector<f64>,
    /// Normal force per contact (fixed ones included).
    pub normal_forces: Vec<f64>,
    /// Friction force per contact.
    pub friction_forces: Vec<DVector<f64>>,
    /// Relative velocities per contact (`u_n` includes gap / h).
    pub normal_velocities: Vec<f64>,
    pub tangent_velocities: Vec<DVector<f64>>,
    pub states: Vec<ContactState>,
    pub residuals: Residuals,
    pub iterations: usize,
}

/// Solver settings.
#[derive(Clone, Copy, Debug)]
pub struct Settings {
    pub max_iterations: usize,
    /// Convergence: scaled residual of the projection equations.
    pub tolerance: f64,
    /// A solve whose scaled constraint residual exceeds this is an error.
    pub accept: f64,
}

impl Default for Settings {
    fn default() -> Self {
        Self { max_iterations: 100, tolerance: 1e-11, accept: 1e-6 }
    }
}

impl Problem {
    fn check(&self) -> Result<()> {
        let d = self.dim;
        if d != 3 && d != 6 {
            return Err(Error::arg("problem", format!("the twist has 3 (planar) or 6 (spatial) components, not {d}")));
        }
        if self.mass.nrows() != d || self.mass.ncols() != d || self.wrench.len() != d {
            return Err(Error::arg("problem", "mass matrix / wrench do not match the twist dimension"));
        }
        for c in &self.contacts {
            if c.jn.len() != d || c.jt.ncols() != d || c.jn_other.len() != d || c.jt_other.ncols() != d {
                return Err(Error::arg("problem", format!("contact {} has rows of the wrong size", c.label)));
            }
            // the forward solve's block step works on contacts of at most 3 unknowns
            if c.tangent_dim() + (c.normal == NormalLaw::Unilateral) as usize > 3 {
                return Err(Error::arg("problem", format!("contact {} has more than 3 force components", c.label)));
            }
            if c.jt_other.nrows() != c.jt.nrows() {
                return Err(Error::arg("problem", format!("contact {} tangent rows differ", c.label)));
            }
            match &c.friction {
                FrictionLaw::Coulomb(mu) if !(*mu >= 0.0) => {
                    return Err(Error::arg("problem", format!("contact {}: negative friction", c.label)))
                }
                FrictionLaw::Ellipsoid(a) if a.nrows() != c.jt.nrows() => {
                    return Err(Error::arg("problem", format!("contact {}: ellipsoid size", c.label)))
                }
                _ => {}
            }
            if let NormalLaw::Fixed(f) = c.normal {
                if !(f >= 0.0) {
                    return Err(Error::arg("problem", format!("contact {}: negative normal force", c.label)));
                }
            }
        }
        if !(self.h > 0.0) || !(self.force_scale > 0.0) || !(self.velocity_scale > 0.0) {
            return Err(Error::arg("problem", "h, force_scale and velocity_scale must be positive"));
        }
        Ok(())
    }

    /// Relative velocities of contact `c` for object twist `v` and pusher twist `u`.
    fn velocities(&self, c: &Contact, v: &DVector<f64>, u: &DVector<f64>) -> (f64, DVector<f64>) {
        let un = c.jn.dot(v) - c.jn_other.dot(u) + c.gap / self.h;
        let ut = &c.jt * v - &c.jt_other * u;
        (un, ut)
    }
}

fn normal_force(c: &Contact, f_n: f64) -> f64 {
    match c.normal {
        NormalLaw::Fixed(f) => f,
        NormalLaw::Unilateral => f_n,
    }
}

/// Evaluates every constraint of the complementarity problem, in its original form, for a
/// candidate solution (used for our solvers and for the reference solver alike).
pub fn residuals(
    p: &Problem,
    v: &DVector<f64>,
    u: &DVector<f64>,
    normal_forces: &[f64],
    friction_forces: &[DVector<f64>],
) -> Residuals {
    let (fs, vs) = (p.force_scale, p.velocity_scale);
    let mut r = Residuals::default();
    let mut ne = &p.wrench - &p.mass * v;
    for (i, c) in p.contacts.iter().enumerate() {
        let f_n = normal_force(c, normal_forces[i]);
        let f_t = &friction_forces[i];
        ne += &c.jn * f_n + c.jt.transpose() * f_t;
        let (un, ut) = p.velocities(c, v, u);
        let slip = ut.norm();
        if c.normal == NormalLaw::Unilateral {
            r.normal_feasibility = r.normal_feasibility.max((-f_n).max(0.0) / fs).max((-un).max(0.0) / vs);
            r.normal_complementarity = r.normal_complementarity.max((f_n * un).abs() / (fs * vs));
        }
        match &c.friction {
            FrictionLaw::Coulomb(mu) => {
                let lim = mu * f_n.max(0.0);
                r.cone = r.cone.max((f_t.norm() - lim).max(0.0) / fs);
                r.friction_complementarity =
                    r.friction_complementarity.max(((lim * lim - f_t.norm_squared()) * slip).abs() / (fs * fs * vs));
                r.dissipation = r.dissipation.max((&ut * lim + f_t * slip).norm() / (fs * vs));
            }
            FrictionLaw::Ellipsoid(a) => {
                // the patch's friction wrench lies in fᵀAf ≤ 1 and opposes the slip with the
                // maximum dissipation: f = −A⁻¹u/√(uᵀA⁻¹u) when u ≠ 0
                let q = f_t.dot(&(a * f_t));
                r.cone = r.cone.max((q.sqrt() - 1.0).max(0.0));
                if let Some(ainv) = a.clone().try_inverse() {
                    let au = &ainv * &ut;
                    let n = ut.dot(&au).sqrt();
                    if n > 1e-300 {
                        let expect = -au / n;
                        let scale = ainv.diagonal().iter().fold(0.0f64, |m, x| m.max(x.sqrt()));
                        let s = slip / vs;
                        r.dissipation = r.dissipation.max((f_t - expect).norm() / scale * s.min(1.0));
                        r.friction_complementarity = r.friction_complementarity.max((1.0 - q).abs() * s);
                    }
                }
            }
        }
    }
    r.newton_euler = ne.amax() / fs;
    r
}

/// The solution at object twist `v`, pusher twist `u` and forces `fns`, `fts` (normal forces of
/// fixed contacts included): relative velocities, contact states and [`residuals`].
fn finish(p: &Problem, v: DVector<f64>, u: DVector<f64>, fns: Vec<f64>, fts: Vec<DVector<f64>>, it: usize) -> Solution {
    let (mut nv, mut tv, mut st) = (Vec::new(), Vec::new(), Vec::new());
    let vtol = 1e-7 * p.velocity_scale;
    for (i, c) in p.contacts.iter().enumerate() {
        let (un, ut) = p.velocities(c, &v, &u);
        let fnorm = normal_force(c, fns[i]);
        let state = if c.normal == NormalLaw::Unilateral && fnorm <= 1e-9 * p.force_scale && un > vtol {
            ContactState::Separate
        } else if ut.norm() > vtol {
            ContactState::Slide
        } else {
            ContactState::Stick
        };
        nv.push(un);
        tv.push(ut);
        st.push(state);
    }
    let residuals = residuals(p, &v, &u, &fns, &fts);
    Solution {
        twist: v,
        pusher_twist: u,
        normal_forces: fns,
        friction_forces: fts,
        normal_velocities: nv,
        tangent_velocities: tv,
        states: st,
        residuals,
        iterations: it,
    }
}
