//! The semismooth Newton solver of the forward problem (thesis §3.2): the unknowns `[V, f_n, f_t]`,
//! the Alart–Curnier projection equations of eqs 3.1–3.3 and 3.16 (exact, or smoothed by `ε`),
//! their generalized Jacobian, and a damped Newton method with a backtracking line search.

use super::arrow::Arrow;
use super::{normal_force, FrictionLaw, NormalLaw, Problem, Solution};
use nalgebra::{DMatrix, DVector, DVectorView};

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

    /// Each contact's first unknown and its number of unknowns (normal force, then friction).
    fn blocks(&self, p: &Problem) -> Vec<(usize, usize)> {
        p.contacts
            .iter()
            .enumerate()
            .map(|(i, c)| (self.normal[i].unwrap_or(self.tangent[i]), self.normal[i].is_some() as usize + c.tangent_dim()))
            .collect()
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

/// Projection of `y` on an ellipsoid `yᵀAy ≤ 1` in the metric `A`, smoothed by `e`, and its
/// derivative: `P = y / smax(1, √(yᵀAy))` (a Coulomb disc's is [`Newton::coulomb_rows`]').
fn project_ellipsoid(a: &DMatrix<f64>, y: &DVector<f64>, e: f64) -> (DVector<f64>, DMatrix<f64>) {
    let k = y.len();
    let ay = a * y;
    let q = y.dot(&ay).sqrt();
    let (m, _, dm_dq) = smax(1.0, q, e);
    let p = y / m;
    let mut dp = DMatrix::identity(k, k) / m;
    if q > 0.0 {
        dp -= (y * (&ay / q).transpose()) * (dm_dq / (m * m));
    }
    (p, dp)
}

/// The metric used for the friction projection of a contact: `ρ G⁻¹ u` with `G⁻¹ = I` for
/// Coulomb and `A⁻¹` for an ellipsoid (see the module notes).
fn metric_inv(law: &FrictionLaw) -> Option<DMatrix<f64>> {
    match law {
        FrictionLaw::Coulomb(_) => None,
        FrictionLaw::Ellipsoid(a) => a.clone().try_inverse(),
    }
}

/// Iterations over which a Newton solve must shrink |F| to [`STALL_SHRINK`] of it or give up
/// (stalled: the forward solve's next attempt starts elsewhere).
const STALL: usize = 4;
/// The share of |F| left after [`STALL`] iterations above which a solve has stalled.
const STALL_SHRINK: f64 = 0.5;
/// Step halvings of the line search before a Newton step is given up (the attempt then ends).
const HALVINGS: usize = 30;

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

/// What one evaluation of the equations writes: the residual and, when asked, its Jacobian in
/// block-arrow form (rows scaled by `sf = 1/force_scale`), at smoothing `e`.
struct Eval {
    f: DVector<f64>,
    j: Option<Arrow>,
    sf: f64,
    e: f64,
}

/// The forward problem's equations for a pusher twist and a projection step ρ.
pub(super) struct Newton<'a> {
    p: &'a Problem,
    lay: Layout,
    rho_n: f64,
    pre: Vec<Pre>,
}

impl<'a> Newton<'a> {
    pub(super) fn new(p: &'a Problem, u: &DVector<f64>) -> Self {
        Self::with_rho(p, u, 1.0)
    }

    /// `rho_scale` multiplies the projection steps ρ (any ρ > 0 gives the same solutions; it
    /// changes the Newton iterations' basin of convergence).
    pub(super) fn with_rho(p: &'a Problem, u: &DVector<f64>, rho_scale: f64) -> Self {
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

    /// Object twist, normal forces (fixed ones included) and friction forces at unknowns `x`.
    pub(super) fn unpack(&self, x: &DVector<f64>) -> (DVector<f64>, Vec<f64>, Vec<DVector<f64>>) {
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

    /// The unknowns for object twist `v0` and zero forces.
    pub(super) fn start(&self, v0: &DVector<f64>) -> DVector<f64> {
        let mut x = DVector::zeros(self.lay.n);
        x.rows_mut(0, self.p.dim).copy_from(v0);
        x
    }

    /// The unknowns of a solution (to start from it).
    pub(super) fn pack(&self, s: &Solution) -> DVector<f64> {
        let mut x = self.start(&s.twist);
        for (i, c) in self.p.contacts.iter().enumerate() {
            if let Some(k) = self.lay.normal[i] {
                x[k] = s.normal_forces[i];
            }
            x.rows_mut(self.lay.tangent[i], c.tangent_dim()).copy_from(&s.friction_forces[i]);
        }
        x
    }

    /// Residual F(x) (smoothed by `e`, in units of `force_scale`; exact for `e = 0`) and, when
    /// asked, its (generalized) Jacobian: the Newton–Euler rows (eq 3.13), then per contact its
    /// normal row (eq 3.16) and friction rows (eqs 3.1–3.3).
    fn eval(&self, x: &DVector<f64>, jac: bool, e: f64) -> (DVector<f64>, Option<Arrow>) {
        let p = self.p;
        let d = p.dim;
        let n = self.lay.n;
        let v = x.rows(0, d);
        let j = if jac { Some(Arrow::zeros(d, &self.lay.blocks(p))) } else { None };
        let mut out = Eval { f: DVector::zeros(n), j, sf: 1.0 / p.force_scale, e };
        // Newton–Euler (scaled by 1/force_scale)
        let mut ne = &p.wrench - &p.mass * v;
        if let Some(j) = out.j.as_mut() {
            j.a.copy_from(&p.mass);
            j.a *= -out.sf;
        }
        for (i, c) in p.contacts.iter().enumerate() {
            let f_n = match self.lay.normal[i] {
                Some(k) => x[k],
                None => normal_force(c, 0.0),
            };
            let ft = x.rows(self.lay.tangent[i], c.tangent_dim());
            self.balance(i, f_n, ft, &mut ne, &mut out);
            if let Some(k) = self.lay.normal[i] {
                self.normal_row(i, k, f_n, v, &mut out);
            }
            self.friction_rows(i, f_n, ft, v, &mut out);
        }
        out.f.rows_mut(0, d).copy_from(&(ne * out.sf));
        (out.f, out.j)
    }

    /// Contact `i`'s forces in the Newton–Euler equation (eq 3.13): `J_nᵀ f_n + J_tᵀ f_t` added
    /// to `ne`, and their columns of the Jacobian.
    fn balance(&self, i: usize, f_n: f64, ft: DVectorView<'_, f64>, ne: &mut DVector<f64>, out: &mut Eval) {
        let (c, pre) = (&self.p.contacts[i], &self.pre[i]);
        let d = self.p.dim;
        ne.axpy(f_n, &c.jn, 1.0);
        ne.gemv(1.0, &pre.jt_t, &ft, 1.0);
        if let Some(j) = out.j.as_mut() {
            let b = &mut j.blocks[i].b;
            let off = self.lay.normal[i].is_some() as usize;
            for row in 0..d {
                if off == 1 {
                    b[(row, 0)] = c.jn[row] * out.sf;
                }
                for a in 0..c.tangent_dim() {
                    b[(row, off + a)] = pre.jt_t[(row, a)] * out.sf;
                }
            }
        }
    }

    /// Row `k` of unilateral contact `i` (eq 3.16 in projection form): `F = f_n − max(0, f_n − ρ u_n)`.
    fn normal_row(&self, i: usize, k: usize, f_n: f64, v: DVectorView<'_, f64>, out: &mut Eval) {
        let (c, pre) = (&self.p.contacts[i], &self.pre[i]);
        let un = c.jn.dot(&v) + pre.bn;
        let z = f_n - self.rho_n * un;
        let (m, _, dm) = smax(0.0, z, out.e * self.p.force_scale);
        out.f[k] = (f_n - m) * out.sf;
        if let Some(j) = out.j.as_mut() {
            let blk = &mut j.blocks[i];
            blk.d[(0, 0)] = (1.0 - dm) * out.sf;
            for col in 0..self.p.dim {
                blk.c[(0, col)] = c.jn[col] * dm * self.rho_n * out.sf;
            }
        }
    }

    /// Friction rows of contact `i` (eqs 3.1–3.3 in projection form): `F = f_t − P(f_t − ρ G⁻¹ u_t)`;
    /// a Coulomb disc's in [`Self::coulomb_rows`], an ellipsoid's (a fixed normal force: no
    /// `dF/df_n`) here.
    fn friction_rows(&self, i: usize, f_n: f64, ft: DVectorView<'_, f64>, v: DVectorView<'_, f64>, out: &mut Eval) {
        let (c, pre) = (&self.p.contacts[i], &self.pre[i]);
        let (d, kt, t0) = (self.p.dim, c.tangent_dim(), self.lay.tangent[i]);
        let a = match &c.friction {
            FrictionLaw::Coulomb(mu) => return self.coulomb_rows(i, *mu, f_n, ft, v, out),
            FrictionLaw::Ellipsoid(a) => a,
        };
        let sf = out.sf;
        let y = ft - (&pre.gjt * v + &pre.gbt);
        let (proj, dp) = project_ellipsoid(a, &y, out.e);
        let mut fr = out.f.rows_mut(t0, kt);
        fr.copy_from(&(ft - proj));
        fr *= sf;
        if let Some(j) = out.j.as_mut() {
            // dF/df_t = I − dP; dF/dV = dP ρ G⁻¹ J_t
            let blk = &mut j.blocks[i];
            let off = self.lay.normal[i].is_some() as usize;
            blk.d.view_mut((off, off), (kt, kt)).copy_from(&((DMatrix::identity(kt, kt) - &dp) * sf));
            blk.c.view_mut((off, 0), (kt, d)).copy_from(&(&dp * &pre.gjt * sf));
        }
    }

    /// [`Self::friction_rows`] of a Coulomb contact (at most 3 tangent directions, [`Problem`]'s
    /// check) on the stack: `P = y r / smax(r, |y|)` with `r = μ f_n`, and its derivatives
    /// `dP/dy`, `dP/dr` (the solve's inner loop, without temporaries).
    fn coulomb_rows(&self, i: usize, mu: f64, f_n: f64, ft: DVectorView<'_, f64>, v: DVectorView<'_, f64>, out: &mut Eval) {
        let (c, pre) = (&self.p.contacts[i], &self.pre[i]);
        let (d, kt, t0) = (self.p.dim, c.tangent_dim(), self.lay.tangent[i]);
        let (pe, sf) = (out.e * self.p.force_scale, out.sf);
        let mut y = [0.0; 3];
        for a in 0..kt {
            let g = pre.gbt[a] + (0..d).map(|b| pre.gjt[(a, b)] * v[b]).sum::<f64>();
            y[a] = ft[a] - g;
        }
        let (m0, _, dm0) = smax(0.0, f_n, pe);
        let (r, dr_dfn) = (mu * m0, mu * dm0);
        let ny = y[..kt].iter().map(|x| x * x).sum::<f64>().sqrt();
        let (m, dm_dr, dm_dy) = smax(r, ny, pe);
        let (mut p, mut dp, mut dpr) = ([0.0; 3], [[0.0; 3]; 3], [0.0; 3]);
        if m > 0.0 {
            for a in 0..kt {
                p[a] = y[a] * r / m;
                dpr[a] = y[a] / m - y[a] * r * dm_dr / (m * m);
                for b in 0..kt {
                    dp[a][b] = if a == b { r / m } else { 0.0 };
                    if ny > 0.0 {
                        dp[a][b] -= y[a] * y[b] / ny * r * dm_dy / (m * m);
                    }
                }
            }
        }
        for a in 0..kt {
            out.f[t0 + a] = (ft[a] - p[a]) * sf;
        }
        if let Some(j) = out.j.as_mut() {
            let blk = &mut j.blocks[i];
            let off = self.lay.normal[i].is_some() as usize;
            for a in 0..kt {
                for b in 0..kt {
                    blk.d[(off + a, off + b)] = (if a == b { 1.0 } else { 0.0 } - dp[a][b]) * sf;
                }
                for col in 0..d {
                    blk.c[(off + a, col)] = (0..kt).map(|b| dp[a][b] * pre.gjt[(b, col)]).sum::<f64>() * sf;
                }
                if off == 1 {
                    blk.d[(off + a, 0)] = dpr[a] * (-dr_dfn * sf);
                }
            }
        }
    }

    /// Damped Newton on `F_e = 0` until `|F_e|∞ ≤ tol` (or an interrupt, see [`crate::interrupt`]).
    pub(super) fn solve(&self, x0: DVector<f64>, e: f64, tol: f64, max_it: usize) -> (DVector<f64>, f64, usize) {
        let mut x = x0;
        let (mut fx, _) = self.eval(&x, false, e);
        let mut phi = 0.5 * fx.norm_squared();
        let mut it = 0;
        let mut recent = std::collections::VecDeque::from([fx.amax()]);
        // an interrupt ends the iterations; it stays raised for the caller's next check
        while it < max_it && fx.amax() > tol && crate::interrupt::check().is_ok() {
            // stalled: |F| not halved over the last STALL iterations (the caller's next
            // attempt starts elsewhere)
            if recent.len() > STALL && fx.amax() > STALL_SHRINK * recent[0] {
                break;
            }
            it += 1;
            if std::env::var("MNCP_TRACE").is_ok() {
                eprintln!("it {it}: |F| = {:.3e}  v = {:?}", fx.amax(), x.rows(0, self.p.dim).as_slice());
            }
            let (_, jac) = self.eval(&x, true, e);
            let jac = jac.expect("jacobian requested");
            // the block-arrow step: exact where the Jacobian is invertible, least squares where a
            // sticking contact makes it singular ([`super::arrow`])
            let Some(step) = jac.solve(&(-&fx), 1.0 / self.p.force_scale) else { break };
            // backtracking line search on ½|F|²
            let mut t = 1.0;
            let mut accepted = false;
            for _ in 0..HALVINGS {
                if crate::interrupt::check().is_err() {
                    break;
                }
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
            recent.push_back(fx.amax());
            if recent.len() > STALL + 1 {
                recent.pop_front();
            }
        }
        (x, fx.amax(), it)
    }
}

#[cfg(test)]
mod tests {
    use super::super::fixtures::{block, with_patch};
    use super::*;

    #[test]
    fn generalized_jacobian_matches_finite_differences() {
        for (patch, e) in [(false, 0.0), (true, 0.0), (false, 0.3), (true, 0.3)] {
            let p = if patch { with_patch(block(8, 20.0, 0.5), 8) } else { block(8, 20.0, 0.5) };
            let u = DVector::from_row_slice(&[0.01, 0.002, 0.1]);
            let nw = Newton::new(&p, &u);
            let mut x = DVector::from_fn(nw.lay.n, |i, _| ((i as f64) * 1.7).sin());
            x.rows_mut(0, 3).copy_from(&DVector::from_row_slice(&[0.007, -0.003, 0.2]));
            let (f0, j) = nw.eval(&x, true, e);
            let j = j.unwrap().dense();
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
}
