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

use crate::error::{Error, Result};
use clarabel::algebra::CscMatrix;
use clarabel::solver::{DefaultSettings, DefaultSolver, IPSolver, SolverStatus, SupportedConeT};
use nalgebra::{DMatrix, DVector};

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
        if self.mass.nrows() != d || self.mass.ncols() != d || self.wrench.len() != d {
            return Err(Error::arg("problem", "mass matrix / wrench do not match the twist dimension"));
        }
        for c in &self.contacts {
            if c.jn.len() != d || c.jt.ncols() != d || c.jn_other.len() != d || c.jt_other.ncols() != d {
                return Err(Error::arg("problem", format!("contact {} has rows of the wrong size", c.label)));
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

/// Layout of the unknowns of the forward problem: `[V, per contact (f_n if unilateral, f_t)]`.
struct Layout {
    n: usize,
    normal: Vec<Option<usize>>,
    tangent: Vec<usize>,
}

impl Layout {
    fn new(p: &Problem) -> Self {
        let mut k = p.dim;
        let mut normal = Vec::with_capacity(p.contacts.len());
        let mut tangent = Vec::with_capacity(p.contacts.len());
        for c in &p.contacts {
            if c.normal == NormalLaw::Unilateral {
                normal.push(Some(k));
                k += 1;
            } else {
                normal.push(None);
            }
            tangent.push(k);
            k += c.tangent_dim();
        }
        Self { n: k, normal, tangent }
    }
}

/// `max(a, b)` smoothed by `e` (exact for `e = 0`): `(a + b + √((a − b)² + e²)) / 2`, and its
/// partial derivatives (at a tie with `e = 0`, the derivative of the `b` branch).
fn smax(a: f64, b: f64, e: f64) -> (f64, f64, f64) {
    if e == 0.0 {
        return if a > b { (a, 1.0, 0.0) } else { (b, 0.0, 1.0) };
    }
    let s = ((a - b) * (a - b) + e * e).sqrt();
    (0.5 * (a + b + s), 0.5 * (1.0 + (a - b) / s), 0.5 * (1.0 - (a - b) / s))
}

/// Projection of `y` on the friction set, smoothed by `e`, and its derivatives
/// `(P, dP/dy, dP/dr)`: `P = y r / smax(r, |y|)` for a Coulomb disc of radius `r`,
/// `P = y / smax(1, √(yᵀAy))` for an ellipsoid (its projection in the metric `A`).
fn project(law: &FrictionLaw, y: &DVector<f64>, r: f64, e: f64) -> (DVector<f64>, DMatrix<f64>, DVector<f64>) {
    let k = y.len();
    match law {
        FrictionLaw::Coulomb(_) => {
            let ny = y.norm();
            let (m, dm_dr, dm_dy) = smax(r, ny, e);
            if m <= 0.0 {
                return (DVector::zeros(k), DMatrix::zeros(k, k), DVector::zeros(k));
            }
            let p = y * (r / m);
            let mut dp = DMatrix::identity(k, k) * (r / m);
            if ny > 0.0 {
                dp -= (y * (y / ny).transpose()) * (r * dm_dy / (m * m));
            }
            let dpr = y / m - y * (r * dm_dr / (m * m));
            (p, dp, dpr)
        }
        FrictionLaw::Ellipsoid(a) => {
            let ay = a * y;
            let q = y.dot(&ay).sqrt();
            let (m, _, dm_dq) = smax(1.0, q, e);
            let p = y / m;
            let mut dp = DMatrix::identity(k, k) / m;
            if q > 0.0 {
                dp -= (y * (&ay / q).transpose()) * (dm_dq / (m * m));
            }
            (p, dp, DVector::zeros(k))
        }
    }
}

/// The metric used for the friction projection of a contact: `ρ G⁻¹ u` with `G⁻¹ = I` for
/// Coulomb and `A⁻¹` for an ellipsoid (see the module notes).
fn metric_inv(law: &FrictionLaw) -> Option<DMatrix<f64>> {
    match law {
        FrictionLaw::Coulomb(_) => None,
        FrictionLaw::Ellipsoid(a) => a.clone().try_inverse(),
    }
}

/// Per-contact data fixed during a solve.
struct Pre {
    /// `J_tᵀ` (d × k).
    jt_t: DMatrix<f64>,
    /// `ρ G⁻¹ J_t` and `ρ G⁻¹ b_t` (the friction projection's velocity term).
    gjt: DMatrix<f64>,
    gbt: DVector<f64>,
    /// Constant part of the normal velocity: `−J_n,other U + gap/h`.
    bn: f64,
}

struct Newton<'a> {
    p: &'a Problem,
    lay: Layout,
    rho_n: f64,
    pre: Vec<Pre>,
}

impl<'a> Newton<'a> {
    fn new(p: &'a Problem, u: &DVector<f64>) -> Self {
        Self::with_rho(p, u, 1.0)
    }

    /// `rho_scale` multiplies the projection steps ρ (any ρ > 0 gives the same solutions; it
    /// changes the Newton iterations' basin of convergence).
    fn with_rho(p: &'a Problem, u: &DVector<f64>, rho_scale: f64) -> Self {
        let rho = rho_scale * p.force_scale / p.velocity_scale;
        let pre = p
            .contacts
            .iter()
            .map(|c| {
                let g = metric_inv(&c.friction);
                // the step ρ of the projection, scaled so that ρ G⁻¹ u is of the size of a
                // friction force: |A⁻¹u| ≈ (μN)² |u| for an ellipsoid
                let rho_t = match &g {
                    None => rho,
                    Some(g) => rho / g[(0, 0)].max(g[(1, 1)]).max(1e-300),
                };
                let bt = -(&c.jt_other * u);
                let (gjt, gbt) = match &g {
                    None => (&c.jt * rho_t, bt * rho_t),
                    Some(g) => (g * &c.jt * rho_t, g * bt * rho_t),
                };
                Pre { jt_t: c.jt.transpose(), gjt, gbt, bn: -c.jn_other.dot(u) + c.gap / p.h }
            })
            .collect();
        Self { p, lay: Layout::new(p), rho_n: rho, pre }
    }

    fn unpack(&self, x: &DVector<f64>) -> (DVector<f64>, Vec<f64>, Vec<DVector<f64>>) {
        let d = self.p.dim;
        let v = x.rows(0, d).into_owned();
        let mut fns = Vec::with_capacity(self.p.contacts.len());
        let mut fts = Vec::with_capacity(self.p.contacts.len());
        for (i, c) in self.p.contacts.iter().enumerate() {
            fns.push(match self.lay.normal[i] {
                Some(k) => x[k],
                None => normal_force(c, 0.0),
            });
            fts.push(x.rows(self.lay.tangent[i], c.tangent_dim()).into_owned());
        }
        (v, fns, fts)
    }

    /// Residual F(x) (smoothed by `e`, in units of `force_scale`; exact for `e = 0`) and, when
    /// asked, its (generalized) Jacobian.
    fn eval(&self, x: &DVector<f64>, jac: bool, e: f64) -> (DVector<f64>, Option<DMatrix<f64>>) {
        let p = self.p;
        let d = p.dim;
        let n = self.lay.n;
        let v = x.rows(0, d);
        let mut f = DVector::zeros(n);
        let mut j = if jac { Some(DMatrix::zeros(n, n)) } else { None };
        let sf = 1.0 / p.force_scale;
        // Newton–Euler (scaled by 1/force_scale)
        let mut ne = &p.wrench - &p.mass * v;
        if let Some(j) = j.as_mut() {
            let mut blk = j.view_mut((0, 0), (d, d));
            blk.copy_from(&p.mass);
            blk *= -sf;
        }
        for (i, c) in p.contacts.iter().enumerate() {
            let pre = &self.pre[i];
            let kt = c.tangent_dim();
            let t0 = self.lay.tangent[i];
            let f_n = match self.lay.normal[i] {
                Some(k) => x[k],
                None => normal_force(c, 0.0),
            };
            let ft = x.rows(t0, kt);
            ne.axpy(f_n, &c.jn, 1.0);
            ne.gemv(1.0, &pre.jt_t, &ft, 1.0);
            if let Some(j) = j.as_mut() {
                if let Some(k) = self.lay.normal[i] {
                    let mut col = j.view_mut((0, k), (d, 1));
                    col.copy_from(&c.jn);
                    col *= sf;
                }
                let mut blk = j.view_mut((0, t0), (d, kt));
                blk.copy_from(&pre.jt_t);
                blk *= sf;
            }
            // normal: F = f_n − max(0, f_n − ρ u_n)
            if let Some(k) = self.lay.normal[i] {
                let un = c.jn.dot(&v) + pre.bn;
                let z = f_n - self.rho_n * un;
                let (m, _, dm) = smax(0.0, z, e * p.force_scale);
                f[k] = (f_n - m) * sf;
                if let Some(j) = j.as_mut() {
                    j[(k, k)] = (1.0 - dm) * sf;
                    for col in 0..d {
                        j[(k, col)] = c.jn[col] * dm * self.rho_n * sf;
                    }
                }
            }
            // friction: F = f_t − P(f_t − ρ G⁻¹ u_t)
            let y = ft - (&pre.gjt * v + &pre.gbt);
            let (r, dr_dfn) = match &c.friction {
                FrictionLaw::Coulomb(mu) => {
                    let (m, _, dm) = smax(0.0, f_n, e * p.force_scale);
                    (mu * m, mu * dm)
                }
                FrictionLaw::Ellipsoid(_) => (1.0, 0.0),
            };
            let pe = match &c.friction {
                FrictionLaw::Coulomb(_) => e * p.force_scale,
                FrictionLaw::Ellipsoid(_) => e,
            };
            let (proj, dp, dpr) = project(&c.friction, &y, r, pe);
            let mut fr = f.rows_mut(t0, kt);
            fr.copy_from(&(ft - proj));
            fr *= sf;
            if let Some(j) = j.as_mut() {
                // dF/df_t = I − dP; dF/dV = dP ρ G⁻¹ J_t; dF/df_n = −dP/dr · dr/df_n
                let mut blk = j.view_mut((t0, t0), (kt, kt));
                blk.copy_from(&(DMatrix::identity(kt, kt) - &dp));
                blk *= sf;
                let mut blk = j.view_mut((t0, 0), (kt, d));
                blk.copy_from(&(&dp * &pre.gjt));
                blk *= sf;
                if let Some(k) = self.lay.normal[i] {
                    let mut col = j.view_mut((t0, k), (kt, 1));
                    col.copy_from(&dpr);
                    col *= -dr_dfn * sf;
                }
            }
        }
        f.rows_mut(0, d).copy_from(&(ne * sf));
        (f, j)
    }

    /// Damped Newton on `F_e = 0` until `|F_e|∞ ≤ tol`.
    fn solve(&self, x0: DVector<f64>, e: f64, tol: f64, max_it: usize) -> (DVector<f64>, f64, usize) {
        let mut x = x0;
        let (mut fx, _) = self.eval(&x, false, e);
        let mut phi = 0.5 * fx.norm_squared();
        let mut it = 0;
        while it < max_it && fx.amax() > tol {
            it += 1;
            if std::env::var("MNCP_TRACE").is_ok() {
                eprintln!("it {it}: |F| = {:.3e}  v = {:?}", fx.amax(), x.rows(0, self.p.dim).as_slice());
            }
            let (_, jac) = self.eval(&x, true, e);
            let jac = jac.expect("jacobian requested");
            let step = match jac.clone().lu().solve(&(-&fx)) {
                Some(dx) if dx.iter().all(|z| z.is_finite()) => dx,
                _ => {
                    // singular generalized Jacobian: a regularized (Levenberg–Marquardt) step
                    let jt = jac.transpose();
                    let m = &jt * &jac + DMatrix::identity(self.lay.n, self.lay.n) * 1e-10;
                    match m.lu().solve(&(-(jt * &fx))) {
                        Some(dx) => dx,
                        None => break,
                    }
                }
            };
            // backtracking line search on ½|F|²
            let mut t = 1.0;
            let mut accepted = false;
            for _ in 0..30 {
                let xn = &x + &step * t;
                let (fn_, _) = self.eval(&xn, false, e);
                let phin = 0.5 * fn_.norm_squared();
                if phin <= (1.0 - 1e-4 * t) * phi || phin < 1e-30 {
                    x = xn;
                    fx = fn_;
                    phi = phin;
                    accepted = true;
                    break;
                }
                t *= 0.5;
            }
            if !accepted {
                break;
            }
        }
        (x, fx.amax(), it)
    }
}

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

/// Forward problem: the pusher moves with twist `u`; find the object twist and every contact
/// force. Tries a few starting points (object moving with the pusher, at rest, falling freely)
/// and returns the first solution whose constraint residual is below `settings.accept`.
pub fn solve_forward(p: &Problem, u: &DVector<f64>, settings: &Settings) -> Result<Solution> {
    p.check()?;
    if u.len() != p.dim || !u.iter().all(|x| x.is_finite()) {
        return Err(Error::arg("pusher_twist", "must be finite with the twist's dimension"));
    }
    // 1. The object moves with the pusher if forces inside every cone allow it: the inverse
    //    problem at V = U decides that exactly, and its solution solves this problem.
    if let Ok(mut sol) = solve_inverse(p, u, settings) {
        if sol.residuals.max() <= settings.accept {
            sol.iterations = 0;
            return Ok(sol);
        }
    }
    let d = p.dim;
    let mut best: Option<(f64, Solution)> = None;
    /// Keeps the best attempt; returns the solution when it is accepted.
    fn consider(best: &mut Option<(f64, Solution)>, sol: Solution, accept: f64) -> Option<Solution> {
        let r = sol.residuals.max();
        if r <= accept {
            return Some(sol);
        }
        if best.as_ref().is_none_or(|(b, _)| r < *b) {
            *best = Some((r, sol));
        }
        None
    }
    let nw = Newton::new(p, u);
    // 2. Semismooth Newton on the exact equations from the object moving with the pusher: fast
    //    when it converges (slides near the sticking solution mostly do).
    {
        let mut x0 = DVector::zeros(nw.lay.n);
        x0.rows_mut(0, d).copy_from(u);
        let (x, _, it) = nw.solve(x0, 0.0, settings.tolerance, 25);
        let (v, fns, fts) = nw.unpack(&x);
        if let Some(s) = consider(&mut best, finish(p, v, u.clone(), fns, fts, it), settings.accept) {
            return Ok(s);
        }
    }
    // 3. Smoothing Newton: the equations with max and the projections smoothed by ε, from
    //    ε = 1 (in units of the force scale) down to 1e-10, each solve warm-starting the next,
    //    then polished with the exact equations.
    let smooth_then_exact = |x0: DVector<f64>| -> (DVector<f64>, usize) {
        let mut x = x0;
        let mut its = 0;
        let mut e = 1.0;
        while e > 1e-10 {
            let (xe, _, it) = nw.solve(x.clone(), e, 0.1 * e, 40);
            its += it;
            x = xe;
            e *= 0.1;
        }
        let (xe, _, it) = nw.solve(x, 0.0, settings.tolerance, settings.max_iterations);
        (xe, its + it)
    };
    let mut starts = Vec::new();
    // the object moving with the pusher, forces from the push with a very rough pusher
    let mut rough = p.clone();
    for c in rough.contacts.iter_mut().filter(|c| c.side == Side::Pusher) {
        c.friction = FrictionLaw::Coulomb(1e3);
    }
    if let Ok(s0) = solve_inverse(&rough, u, settings) {
        starts.push(pack(&nw, &s0));
    }
    let free_fall = p.mass.clone().lu().solve(&p.wrench).unwrap_or_else(|| DVector::zeros(d));
    for v0 in [u.clone(), DVector::zeros(d), free_fall] {
        let mut x0 = DVector::zeros(nw.lay.n);
        x0.rows_mut(0, d).copy_from(&v0);
        starts.push(x0);
    }
    for x0 in &starts {
        let (x, its) = smooth_then_exact(x0.clone());
        let (v, fns, fts) = nw.unpack(&x);
        if let Some(s) = consider(&mut best, finish(p, v, u.clone(), fns, fts, its), settings.accept) {
            return Ok(s);
        }
        // plain semismooth Newton from the same start
        let (x, _, it) = nw.solve(x0.clone(), 0.0, settings.tolerance, settings.max_iterations);
        let (v, fns, fts) = nw.unpack(&x);
        if let Some(s) = consider(&mut best, finish(p, v, u.clone(), fns, fts, it), settings.accept) {
            return Ok(s);
        }
    }
    // 4. Other projection steps ρ (same solutions, other basins of convergence), continuing
    //    from the best point found so far as well as from the starts.
    for rho_scale in [0.1, 10.0, 0.01, 100.0] {
        let nr = Newton::with_rho(p, u, rho_scale);
        let mut from = starts.clone();
        if let Some((_, b)) = &best {
            from.insert(0, pack(&nr, b));
        }
        for x0 in from {
            let mut x = x0;
            let mut its = 0;
            let mut e = 1.0;
            while e > 1e-10 {
                let (xe, _, it) = nr.solve(x.clone(), e, 0.1 * e, 40);
                its += it;
                x = xe;
                e *= 0.3;
            }
            let (x, _, it) = nr.solve(x, 0.0, settings.tolerance, settings.max_iterations);
            let (v, fns, fts) = nr.unpack(&x);
            if let Some(s) = consider(&mut best, finish(p, v, u.clone(), fns, fts, its + it), settings.accept) {
                return Ok(s);
            }
        }
    }
    let (r, sol) = best.expect("at least one attempt");
    Err(Error::arg(
        "mncp",
        format!(
            "the forward solve did not converge: largest scaled constraint residual {r:.2e} after {} iterations ({:?})",
            sol.iterations, sol.residuals
        ),
    ))
}

/// The unknowns of the forward problem from a solution.
fn pack(nw: &Newton<'_>, s: &Solution) -> DVector<f64> {
    let d = nw.p.dim;
    let mut x = DVector::zeros(nw.lay.n);
    x.rows_mut(0, d).copy_from(&s.twist);
    for (i, c) in nw.p.contacts.iter().enumerate() {
        if let Some(k) = nw.lay.normal[i] {
            x[k] = s.normal_forces[i];
        }
        x.rows_mut(nw.lay.tangent[i], c.tangent_dim()).copy_from(&s.friction_forces[i]);
    }
    x
}

/// Inverse problem: find a pusher motion and contact forces that produce object twist `v`, or
/// report that no push can. With `v` given, the velocity of every contact is known, so every
/// finger and fixed contact's mode is known; the pusher may as well stick (a sliding pusher's
/// force is on its cone, which sticking allows too), so the pusher twist is `v` and the forces
/// solve a second-order cone program: minimize the pusher forces subject to balance and cones.
pub fn solve_inverse(p: &Problem, v: &DVector<f64>, settings: &Settings) -> Result<Solution> {
    p.check()?;
    if v.len() != p.dim || !v.iter().all(|x| x.is_finite()) {
        return Err(Error::arg("twist", "must be finite with the twist's dimension"));
    }
    let d = p.dim;
    let (fs, vs) = (p.force_scale, p.velocity_scale);
    let vtol = 1e-9 * vs;
    let u = v.clone();
    // variables: per contact, [f_n (unilateral and not separating), f_t (if free)]
    // fixed wrench contributions go to the right-hand side
    let mut rhs = -(&p.wrench - &p.mass * v); // Σ Jᵀ f = −(w − M v)
    enum Var {
        None,
        /// f_n index, f_t index (free disc) or None (sliding: f_t = −μ f_n û).
        Unilateral(usize, Option<usize>, DVector<f64>),
        /// free friction at a fixed-normal contact (disc radius or ellipsoid)
        Friction(usize),
    }
    let mut vars: Vec<Var> = Vec::new();
    let mut cols: Vec<DVector<f64>> = Vec::new(); // columns of the balance matrix
    let mut is_pusher: Vec<bool> = Vec::new();
    let mut fixed_ft: Vec<Option<DVector<f64>>> = Vec::new();
    for c in &p.contacts {
        let (un, ut) = p.velocities(c, v, &u);
        let slip = ut.norm();
        let pusher = c.side == Side::Pusher;
        match c.normal {
            NormalLaw::Unilateral => {
                if un > vtol {
                    vars.push(Var::None);
                    fixed_ft.push(None);
                    continue;
                }
                if un < -vtol {
                    return Err(Error::arg(
                        "twist",
                        format!("the object would move into {} (normal velocity {un:.3e} m/s)", c.label),
                    ));
                }
                let kf = cols.len();
                let mu = match c.friction {
                    FrictionLaw::Coulomb(mu) => mu,
                    FrictionLaw::Ellipsoid(_) => {
                        return Err(Error::arg("problem", "an ellipsoid patch needs a fixed normal force"))
                    }
                };
                if slip > vtol {
                    // f = f_n (n − μ û): one variable
                    let uh = &ut / slip;
                    cols.push(&c.jn - c.jt.transpose() * &uh * mu);
                    is_pusher.push(pusher);
                    vars.push(Var::Unilateral(kf, None, uh));
                } else {
                    cols.push(c.jn.clone());
                    is_pusher.push(pusher);
                    let kt = cols.len();
                    for r in 0..c.tangent_dim() {
                        cols.push(c.jt.row(r).transpose());
                        is_pusher.push(pusher);
                    }
                    vars.push(Var::Unilateral(kf, Some(kt), DVector::zeros(0)));
                }
                fixed_ft.push(None);
            }
            NormalLaw::Fixed(fnv) => {
                rhs -= &c.jn * fnv;
                let fixed = match &c.friction {
                    FrictionLaw::Coulomb(mu) if slip > vtol => Some(-&ut / slip * (mu * fnv)),
                    FrictionLaw::Ellipsoid(a) if slip > vtol => {
                        let ainv = a.clone().try_inverse().ok_or_else(|| Error::arg("problem", "singular ellipsoid"))?;
                        let au = &ainv * &ut;
                        Some(-&au / ut.dot(&au).sqrt())
                    }
                    _ => None,
                };
                match fixed {
                    Some(ft) => {
                        rhs -= c.jt.transpose() * &ft;
                        vars.push(Var::None);
                        fixed_ft.push(Some(ft));
                    }
                    None => {
                        let kt = cols.len();
                        for r in 0..c.tangent_dim() {
                            cols.push(c.jt.row(r).transpose());
                            is_pusher.push(false);
                        }
                        vars.push(Var::Friction(kt));
                        fixed_ft.push(None);
                    }
                }
            }
        }
    }
    let nvar = cols.len();
    // Clarabel: min ½ xᵀPx s.t. A x + s = b, s ∈ K; scale forces by fs
    let mut a_rows: Vec<Vec<f64>> = Vec::new();
    let mut b: Vec<f64> = Vec::new();
    let mut cones: Vec<SupportedConeT<f64>> = Vec::new();
    for r in 0..d {
        a_rows.push((0..nvar).map(|k| cols[k][r] * fs).collect());
        b.push(rhs[r]);
    }
    cones.push(SupportedConeT::ZeroConeT(d));
    // each cone row: s = b − a·x, as (a, b)
    let row = |entries: &[(usize, f64)], b0: f64| -> (Vec<f64>, f64) {
        let mut r = vec![0.0; nvar];
        for &(k, v) in entries {
            r[k] = v;
        }
        (r, b0)
    };
    let mut nonneg: Vec<(Vec<f64>, f64)> = Vec::new();
    let mut socs: Vec<Vec<(Vec<f64>, f64)>> = Vec::new();
    for (i, c) in p.contacts.iter().enumerate() {
        match &vars[i] {
            Var::None => {}
            Var::Unilateral(kf, kt, _) => {
                nonneg.push(row(&[(*kf, -fs)], 0.0));
                if let (Some(kt), FrictionLaw::Coulomb(mu)) = (kt, &c.friction) {
                    // (μ f_n, f_t) ∈ SOC
                    let mut cone = vec![row(&[(*kf, -mu * fs)], 0.0)];
                    for k in 0..c.tangent_dim() {
                        cone.push(row(&[(kt + k, -fs)], 0.0));
                    }
                    socs.push(cone);
                }
            }
            Var::Friction(kt) => {
                let fnv = normal_force(c, 0.0);
                let kd = c.tangent_dim();
                match &c.friction {
                    FrictionLaw::Coulomb(mu) => {
                        // (μ N, f_t) ∈ SOC
                        let mut cone = vec![row(&[], mu * fnv)];
                        for k in 0..kd {
                            cone.push(row(&[(kt + k, -fs)], 0.0));
                        }
                        socs.push(cone);
                    }
                    FrictionLaw::Ellipsoid(a) => {
                        // (1, Lᵀ f) ∈ SOC with L Lᵀ = A
                        let l = a.clone().cholesky().ok_or_else(|| Error::arg("problem", "ellipsoid not SPD"))?.l();
                        let mut cone = vec![row(&[], 1.0)];
                        for r in 0..kd {
                            let e: Vec<(usize, f64)> = (0..kd).map(|k| (kt + k, -l[(k, r)] * fs)).collect();
                            cone.push(row(&e, 0.0));
                        }
                        socs.push(cone);
                    }
                }
            }
        }
    }
    if !nonneg.is_empty() {
        cones.push(SupportedConeT::NonnegativeConeT(nonneg.len()));
        for (r, b0) in nonneg {
            a_rows.push(r);
            b.push(b0);
        }
    }
    for cone in socs {
        cones.push(SupportedConeT::SecondOrderConeT(cone.len()));
        for (r, b0) in cone {
            a_rows.push(r);
            b.push(b0);
        }
    }
    // objective: small pusher forces (and a tiny weight on all forces for uniqueness)
    let mut pdiag = vec![1e-8; nvar];
    for k in 0..nvar {
        if is_pusher[k] {
            pdiag[k] = 1.0;
        }
    }
    let pm = CscMatrix::from(&(0..nvar).map(|i| (0..nvar).map(|j| if i == j { pdiag[i] } else { 0.0 }).collect::<Vec<_>>()).collect::<Vec<_>>());
    let am = CscMatrix::from(&a_rows);
    let q = vec![0.0; nvar];
    let cfg = DefaultSettings { verbose: false, tol_gap_abs: 1e-12, tol_gap_rel: 1e-12, tol_feas: 1e-12, ..DefaultSettings::default() };
    let mut solver = DefaultSolver::new(&pm, &q, &am, &b, &cones, cfg)
        .map_err(|e| Error::arg("mncp", format!("inverse problem setup: {e:?}")))?;
    solver.solve();
    match solver.solution.status {
        SolverStatus::Solved | SolverStatus::AlmostSolved => {}
        SolverStatus::PrimalInfeasible | SolverStatus::AlmostPrimalInfeasible => {
            return Err(Error::arg(
                "twist",
                "no push can produce this object motion: no pusher force inside its friction cone balances the grasp and gravity",
            ))
        }
        s => return Err(Error::arg("mncp", format!("inverse problem: solver stopped with {s:?}"))),
    }
    let x: Vec<f64> = solver.solution.x.iter().map(|z| z * fs).collect();
    let mut fns = Vec::new();
    let mut fts = Vec::new();
    for (i, c) in p.contacts.iter().enumerate() {
        let kt = c.tangent_dim();
        match (&vars[i], &fixed_ft[i]) {
            (Var::Unilateral(kf, Some(t), _), _) => {
                fns.push(x[*kf].max(0.0));
                fts.push(DVector::from_fn(kt, |r, _| x[t + r]));
            }
            (Var::Unilateral(kf, None, uh), _) => {
                let mu = if let FrictionLaw::Coulomb(mu) = c.friction { mu } else { 0.0 };
                fns.push(x[*kf].max(0.0));
                fts.push(-uh * (mu * x[*kf].max(0.0)));
            }
            (Var::Friction(t), _) => {
                fns.push(normal_force(c, 0.0));
                fts.push(DVector::from_fn(kt, |r, _| x[t + r]));
            }
            (Var::None, Some(ft)) => {
                fns.push(normal_force(c, 0.0));
                fts.push(ft.clone());
            }
            (Var::None, None) => {
                fns.push(normal_force(c, 0.0));
                fts.push(DVector::zeros(kt));
            }
        }
    }
    let sol = finish(p, v.clone(), u, fns, fts, solver.info.iterations as usize);
    if sol.residuals.max() > settings.accept {
        return Err(Error::arg(
            "mncp",
            format!("inverse solution residual {:.2e} above tolerance ({:?})", sol.residuals.max(), sol.residuals),
        ));
    }
    Ok(sol)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A planar block held by a circular patch of `k` points at the origin, pushed by a line
    /// pusher along +x at its left face (points at (-0.025, ±0.02)).
    fn block(k: usize, grip: f64, mu_p: f64) -> Problem {
        let d = 3;
        let mut contacts = Vec::new();
        let (rho, mu_s) = (0.006, 0.6);
        for i in 0..k {
            let a = 2.0 * std::f64::consts::PI * i as f64 / k as f64;
            let r = [rho * a.cos(), rho * a.sin()];
            contacts.push(Contact {
                label: format!("finger[{i}]"),
                side: Side::Finger,
                normal: NormalLaw::Fixed(2.0 * grip / k as f64),
                friction: FrictionLaw::Coulomb(mu_s),
                jn: DVector::zeros(d),
                jt: DMatrix::from_row_slice(2, 3, &[1.0, 0.0, -r[1], 0.0, 1.0, r[0]]),
                jn_other: DVector::zeros(d),
                jt_other: DMatrix::zeros(2, 3),
                gap: 0.0,
            });
        }
        for (i, z) in [-0.02, 0.02].iter().enumerate() {
            let r = [-0.025, *z];
            // n = +x, t = +z: jn = [1, 0, r×n] with r×n = r_x n_z − r_z n_x = −r_z
            let jn = DVector::from_row_slice(&[1.0, 0.0, -r[1]]);
            let jt = DMatrix::from_row_slice(1, 3, &[0.0, 1.0, r[0]]);
            contacts.push(Contact {
                label: format!("pusher[{i}]"),
                side: Side::Pusher,
                normal: NormalLaw::Unilateral,
                friction: FrictionLaw::Coulomb(mu_p),
                jn_other: jn.clone(),
                jt_other: jt.clone(),
                jn,
                jt,
                gap: 0.0,
            });
        }
        let m = 0.13;
        Problem {
            dim: d,
            mass: DMatrix::from_diagonal(&DVector::from_row_slice(&[m, m, m * 7e-4])),
            wrench: DVector::from_row_slice(&[0.0, -m * 9.81, 0.0]),
            contacts,
            h: 1.0,
            force_scale: 2.0 * grip * 0.6 + m * 9.81,
            velocity_scale: 0.01,
            length: 0.027,
        }
    }

    fn with_patch(mut p: Problem, k: usize) -> Problem {
        // replace the k finger points by one ellipsoidal patch (μN = 24 N, k = 0.6·7 mm)
        p.contacts.drain(0..k);
        let s = 24.0f64;
        let kk = 0.0042f64;
        let a = DMatrix::from_diagonal(&DVector::from_row_slice(&[1.0 / (s * s), 1.0 / (s * s), 1.0 / (kk * kk * s * s)]));
        p.contacts.insert(
            0,
            Contact {
                label: "patch".into(),
                side: Side::Finger,
                normal: NormalLaw::Fixed(s),
                friction: FrictionLaw::Ellipsoid(a),
                jn: DVector::zeros(3),
                jt: DMatrix::identity(3, 3),
                jn_other: DVector::zeros(3),
                jt_other: DMatrix::zeros(3, 3),
                gap: 0.0,
            },
        );
        p
    }

    #[test]
    fn generalized_jacobian_matches_finite_differences() {
        for (patch, e) in [(false, 0.0), (true, 0.0), (false, 0.3), (true, 0.3)] {
            let p = if patch { with_patch(block(8, 20.0, 0.5), 8) } else { block(8, 20.0, 0.5) };
            let u = DVector::from_row_slice(&[0.01, 0.002, 0.1]);
            let nw = Newton::new(&p, &u);
            let mut x = DVector::from_fn(nw.lay.n, |i, _| ((i as f64) * 1.7).sin());
            x.rows_mut(0, 3).copy_from(&DVector::from_row_slice(&[0.007, -0.003, 0.2]));
            let (f0, j) = nw.eval(&x, true, e);
            let j = j.unwrap();
            for k in 0..nw.lay.n {
                let eps = 1e-7 * (1.0 + x[k].abs());
                let mut xp = x.clone();
                xp[k] += eps;
                let (f1, _) = nw.eval(&xp, false, e);
                let fd = (f1 - &f0) / eps;
                let err = (&fd - j.column(k)).amax();
                assert!(err < 1e-4 * (1.0 + fd.amax()), "patch {patch}, e {e}: column {k}: fd {fd} vs {}", j.column(k));
            }
        }
    }

    #[test]
    fn push_along_the_normal_sticks_and_the_fingers_slide() {
        let p = block(8, 20.0, 0.5);
        let u = DVector::from_row_slice(&[0.01, 0.0, 0.0]);
        let s = solve_forward(&p, &u, &Settings::default()).unwrap();
        assert!(s.residuals.max() < 1e-8, "{:?}", s.residuals);
        assert!((&s.twist - &u).norm() < 1e-9, "moves with the pusher: {}", s.twist);
        let (fingers, pushers) = s.states.split_at(8);
        assert!(fingers.iter().all(|c| *c == ContactState::Slide));
        assert!(pushers.iter().all(|c| *c == ContactState::Stick));
    }

    #[test]
    fn lifting_with_a_side_pusher_slips() {
        let p = block(8, 20.0, 0.2);
        let u = DVector::from_row_slice(&[0.002, 0.01, 0.0]);
        let s = solve_forward(&p, &u, &Settings::default()).unwrap();
        assert!(s.residuals.max() < 1e-8, "{:?}", s.residuals);
        assert!(s.states[8..].iter().all(|c| *c == ContactState::Slide), "{:?}", s.states);
    }

    #[test]
    fn zero_grip_drops_the_object() {
        let p = block(8, 0.0, 0.5);
        let u = DVector::from_row_slice(&[0.01, 0.0, 0.0]);
        let s = solve_forward(&p, &u, &Settings::default()).unwrap();
        assert!(s.twist[1] < -1.0, "falls: {}", s.twist);
    }

    #[test]
    fn inverse_agrees_with_forward_when_sticking() {
        let p = block(8, 20.0, 0.5);
        let v = DVector::from_row_slice(&[0.01, 0.001, 0.05]);
        let inv = solve_inverse(&p, &v, &Settings::default()).unwrap();
        assert!(inv.residuals.max() < 1e-7, "{:?}", inv.residuals);
        let fwd = solve_forward(&p, &inv.pusher_twist, &Settings::default()).unwrap();
        assert!((&fwd.twist - &v).norm() < 1e-7 * v.norm(), "{} vs {}", fwd.twist, v);
        // lifting straight up with the side pusher: impossible
        let up = DVector::from_row_slice(&[0.0, 0.01, 0.0]);
        assert!(solve_inverse(&p, &up, &Settings::default()).is_err());
    }
}
