//! The inverse problem (thesis §3.2): the object's twist given, a pusher motion and contact
//! forces that produce it. With `V` given every contact's velocity is known, so every finger and
//! fixed contact's mode is known; the pusher may as well stick (a sliding pusher's force is on
//! its cone, which sticking allows too). What is left is convex: a second-order cone program
//! (clarabel) over the unknown forces, with the Newton–Euler balance (eq 3.13) as equalities and
//! the normal (eq 3.16) and friction cones (eqs 3.1, 3.7) as cones.

use super::{finish, normal_force, Contact, FrictionLaw, NormalLaw, Problem, Settings, Side, Solution};
use crate::error::{Error, Result};
use clarabel::algebra::CscMatrix;
use clarabel::solver::{DefaultSettings, DefaultSolver, IPSolver, SolverStatus, SupportedConeT};
use nalgebra::{DMatrix, DVector};

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
    let unknowns = Unknowns::new(p, v)?;
    let mut program = Program::balance(p, &unknowns);
    program.add_cones(p, &unknowns)?;
    let (x, iterations) = program.solve(&unknowns.weights(), p.force_scale)?;
    let (fns, fts) = unknowns.forces(p, &x);
    let sol = finish(p, v.clone(), v.clone(), fns, fts, iterations);
    if sol.residuals.max() > settings.accept {
        return Err(Error::arg(
            "mncp",
            format!("inverse solution residual {:.2e} above tolerance ({:?})", sol.residuals.max(), sol.residuals),
        ));
    }
    Ok(sol)
}

/// The unknown forces of one contact (indices into the unknowns).
enum Var {
    /// A separating unilateral contact: no force.
    Separate,
    /// A fixed-normal contact sliding: its friction force is known (maximum dissipation, eq 3.3).
    Given(DVector<f64>),
    /// A unilateral contact sliding along `û`: `f_n` unknown, `f_t = −μ f_n û`.
    Sliding(usize, DVector<f64>),
    /// A unilateral contact sticking: `f_n` and `f_t` unknown.
    Sticking(usize, usize),
    /// A fixed-normal contact sticking: `f_t` unknown (in a disc or an ellipsoid).
    Friction(usize),
}

/// The unknowns of the cone program: what each contact contributes, the balance matrix's columns
/// (one per unknown) and the wrench they must balance, `−(w_ext − M V)` less the known forces'.
struct Unknowns {
    vars: Vec<Var>,
    cols: Vec<DVector<f64>>,
    is_pusher: Vec<bool>,
    rhs: DVector<f64>,
}

impl Unknowns {
    fn new(p: &Problem, v: &DVector<f64>) -> Result<Self> {
        let vtol = 1e-9 * p.velocity_scale;
        let rhs = -(&p.wrench - &p.mass * v); // Σ Jᵀ f = −(w − M v)
        let mut x = Self { vars: Vec::new(), cols: Vec::new(), is_pusher: Vec::new(), rhs };
        for c in &p.contacts {
            let (un, ut) = p.velocities(c, v, v);
            let var = match c.normal {
                NormalLaw::Unilateral => x.unilateral(c, un, &ut, vtol)?,
                NormalLaw::Fixed(fnv) => x.fixed_normal(c, fnv, &ut, vtol)?,
            };
            x.vars.push(var);
        }
        Ok(x)
    }

    /// Adds an unknown with balance column `col`; returns its index.
    fn add(&mut self, col: DVector<f64>, pusher: bool) -> usize {
        self.cols.push(col);
        self.is_pusher.push(pusher);
        self.cols.len() - 1
    }

    /// Adds the `f_t` unknowns of contact `c` (its tangent rows); returns the first index.
    fn add_tangent(&mut self, c: &Contact, pusher: bool) -> usize {
        let kt = self.cols.len();
        for r in 0..c.tangent_dim() {
            self.add(c.jt.row(r).transpose(), pusher);
        }
        kt
    }

    /// A unilateral contact (eq 3.16) with normal velocity `un` and slip `ut`: separating (no
    /// force), moving into the object (an error), sliding (`f = f_n (n − μ û)`, one unknown) or
    /// sticking (`f_n` and `f_t`).
    fn unilateral(&mut self, c: &Contact, un: f64, ut: &DVector<f64>, vtol: f64) -> Result<Var> {
        if un > vtol {
            return Ok(Var::Separate);
        }
        if un < -vtol {
            return Err(Error::arg("twist", format!("the object would move into {} (normal velocity {un:.3e} m/s)", c.label)));
        }
        let mu = match c.friction {
            FrictionLaw::Coulomb(mu) => mu,
            FrictionLaw::Ellipsoid(_) => return Err(Error::arg("problem", "an ellipsoid patch needs a fixed normal force")),
        };
        let pusher = c.side == Side::Pusher;
        let slip = ut.norm();
        if slip > vtol {
            let uh = ut / slip;
            let kf = self.add(&c.jn - c.jt.transpose() * &uh * mu, pusher);
            return Ok(Var::Sliding(kf, uh));
        }
        let kf = self.add(c.jn.clone(), pusher);
        Ok(Var::Sticking(kf, self.add_tangent(c, pusher)))
    }

    /// A contact with normal force `fnv` (eq 3.5) and slip `ut`: sliding, its friction is known
    /// (maximum dissipation, eq 3.3: `−μN û`, or `−A⁻¹u/√(uᵀA⁻¹u)` for an ellipsoid); else the
    /// friction is unknown. Known forces go to the right-hand side.
    fn fixed_normal(&mut self, c: &Contact, fnv: f64, ut: &DVector<f64>, vtol: f64) -> Result<Var> {
        self.rhs -= &c.jn * fnv;
        let slip = ut.norm();
        let given = match &c.friction {
            FrictionLaw::Coulomb(mu) if slip > vtol => Some(-ut / slip * (mu * fnv)),
            FrictionLaw::Ellipsoid(a) if slip > vtol => {
                let ainv = a.clone().try_inverse().ok_or_else(|| Error::arg("problem", "singular ellipsoid"))?;
                let au = &ainv * ut;
                Some(-&au / ut.dot(&au).sqrt())
            }
            _ => None,
        };
        Ok(match given {
            Some(ft) => {
                self.rhs -= c.jt.transpose() * &ft;
                Var::Given(ft)
            }
            None => Var::Friction(self.add_tangent(c, false)),
        })
    }

    /// The objective's diagonal: small pusher forces (and a tiny weight on all forces for
    /// uniqueness).
    fn weights(&self) -> Vec<f64> {
        self.is_pusher.iter().map(|&pusher| if pusher { 1.0 } else { 1e-8 }).collect()
    }

    /// Every contact's normal and friction force from the unknowns' values `x`.
    fn forces(&self, p: &Problem, x: &[f64]) -> (Vec<f64>, Vec<DVector<f64>>) {
        let mut fns = Vec::new();
        let mut fts = Vec::new();
        for (c, var) in p.contacts.iter().zip(&self.vars) {
            let kt = c.tangent_dim();
            let tangent = |t: usize| DVector::from_fn(kt, |r, _| x[t + r]);
            let (f_n, f_t) = match var {
                Var::Sticking(kf, t) => (x[*kf].max(0.0), tangent(*t)),
                Var::Sliding(kf, uh) => {
                    let mu = if let FrictionLaw::Coulomb(mu) = c.friction { mu } else { 0.0 };
                    (x[*kf].max(0.0), -uh * (mu * x[*kf].max(0.0)))
                }
                Var::Friction(t) => (normal_force(c, 0.0), tangent(*t)),
                Var::Given(ft) => (normal_force(c, 0.0), ft.clone()),
                Var::Separate => (normal_force(c, 0.0), DVector::zeros(kt)),
            };
            fns.push(f_n);
            fts.push(f_t);
        }
        (fns, fts)
    }
}

/// One row `s = b − a·x` of a cone, as `(a, b)`.
type Row = (Vec<f64>, f64);

/// The cone program in clarabel's form, `min ½ xᵀPx s.t. A x + s = b, s ∈ K`, with the forces
/// scaled by `force_scale`.
struct Program {
    nvar: usize,
    a: Vec<Vec<f64>>,
    b: Vec<f64>,
    cones: Vec<SupportedConeT<f64>>,
}

impl Program {
    /// The Newton–Euler balance (eq 3.13) as a zero cone.
    fn balance(p: &Problem, x: &Unknowns) -> Self {
        let nvar = x.cols.len();
        let a = (0..p.dim).map(|r| (0..nvar).map(|k| x.cols[k][r] * p.force_scale).collect()).collect();
        let b = (0..p.dim).map(|r| x.rhs[r]).collect();
        Self { nvar, a, b, cones: vec![SupportedConeT::ZeroConeT(p.dim)] }
    }

    /// A row with entries `(unknown, coefficient)` and `b0`.
    fn row(&self, entries: &[(usize, f64)], b0: f64) -> Row {
        let mut r = vec![0.0; self.nvar];
        for &(k, v) in entries {
            r[k] = v;
        }
        (r, b0)
    }

    /// The rows of the disc `(head, f_t) ∈ SOC` over the `kd` unknowns of `f_t` from `kt`.
    fn disc(&self, head: Row, kt: usize, kd: usize, fs: f64) -> Vec<Row> {
        std::iter::once(head).chain((0..kd).map(|k| self.row(&[(kt + k, -fs)], 0.0))).collect()
    }

    fn push(&mut self, cone: SupportedConeT<f64>, rows: Vec<Row>) {
        self.cones.push(cone);
        for (r, b0) in rows {
            self.a.push(r);
            self.b.push(b0);
        }
    }

    /// The contacts' cones: `f_n ≥ 0` at the unilateral contacts (eq 3.16), then one second-order
    /// cone per friction unknown: `(μ f_n, f_t)` (eq 3.1), `(μ N, f_t)` at a given normal force,
    /// or `(1, Lᵀ f)` with `L Lᵀ = A` for an ellipsoid (eq 3.7).
    fn add_cones(&mut self, p: &Problem, x: &Unknowns) -> Result<()> {
        let fs = p.force_scale;
        let mut nonneg: Vec<Row> = Vec::new();
        let mut socs: Vec<Vec<Row>> = Vec::new();
        for (c, var) in p.contacts.iter().zip(&x.vars) {
            let kd = c.tangent_dim();
            if let Var::Sliding(kf, _) | Var::Sticking(kf, _) = var {
                nonneg.push(self.row(&[(*kf, -fs)], 0.0));
            }
            match (var, &c.friction) {
                (Var::Sticking(kf, kt), FrictionLaw::Coulomb(mu)) => {
                    socs.push(self.disc(self.row(&[(*kf, -mu * fs)], 0.0), *kt, kd, fs));
                }
                (Var::Friction(kt), FrictionLaw::Coulomb(mu)) => {
                    socs.push(self.disc(self.row(&[], mu * normal_force(c, 0.0)), *kt, kd, fs));
                }
                (Var::Friction(kt), FrictionLaw::Ellipsoid(a)) => socs.push(self.ellipsoid(a, *kt, kd, fs)?),
                _ => {}
            }
        }
        if !nonneg.is_empty() {
            self.push(SupportedConeT::NonnegativeConeT(nonneg.len()), nonneg);
        }
        for cone in socs {
            self.push(SupportedConeT::SecondOrderConeT(cone.len()), cone);
        }
        Ok(())
    }

    /// The rows of `(1, Lᵀ f) ∈ SOC` with `L Lᵀ = A`: `fᵀ A f ≤ 1` (eq 3.7).
    fn ellipsoid(&self, a: &DMatrix<f64>, kt: usize, kd: usize, fs: f64) -> Result<Vec<Row>> {
        let l = a.clone().cholesky().ok_or_else(|| Error::arg("problem", "ellipsoid not SPD"))?.l();
        let mut cone = vec![self.row(&[], 1.0)];
        for r in 0..kd {
            let e: Vec<(usize, f64)> = (0..kd).map(|k| (kt + k, -l[(k, r)] * fs)).collect();
            cone.push(self.row(&e, 0.0));
        }
        Ok(cone)
    }

    /// Solves the program with objective diagonal `pdiag` (clarabel); returns the unknowns in
    /// newtons (unscaled by `fs`) and the iterations.
    fn solve(&self, pdiag: &[f64], fs: f64) -> Result<(Vec<f64>, usize)> {
        let n = self.nvar;
        let pm = CscMatrix::from(&(0..n).map(|i| (0..n).map(|j| if i == j { pdiag[i] } else { 0.0 }).collect::<Vec<_>>()).collect::<Vec<_>>());
        let am = CscMatrix::from(&self.a);
        let q = vec![0.0; n];
        let cfg = DefaultSettings { verbose: false, tol_gap_abs: 1e-12, tol_gap_rel: 1e-12, tol_feas: 1e-12, ..DefaultSettings::default() };
        let mut solver = DefaultSolver::new(&pm, &q, &am, &self.b, &self.cones, cfg)
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
        Ok((solver.solution.x.iter().map(|z| z * fs).collect(), solver.info.iterations as usize))
    }
}

#[cfg(test)]
mod tests {
    use super::super::fixtures::{block, push};
    use super::*;

    #[test]
    fn inverse_agrees_with_forward_when_sticking() {
        let p = block(8, 20.0, 0.5);
        let v = DVector::from_row_slice(&[0.01, 0.001, 0.05]);
        let inv = solve_inverse(&p, &v, &Settings::default()).unwrap();
        assert!(inv.residuals.max() < 1e-7, "{:?}", inv.residuals);
        let fwd = push(&p, inv.pusher_twist.as_slice());
        assert!((&fwd.twist - &v).norm() < 1e-7 * v.norm(), "{} vs {}", fwd.twist, v);
        // lifting straight up with the side pusher: impossible
        let up = DVector::from_row_slice(&[0.0, 0.01, 0.0]);
        assert!(solve_inverse(&p, &up, &Settings::default()).is_err());
    }
}
