//! The Newton step of the forward problem in linear time in the contacts.
//!
//! The generalized Jacobian of [`super::newton`]'s equations has a block-arrow form: the
//! Newton–Euler rows `[A | B_1 … B_n]` (the object's `d` unknowns, then each contact's forces)
//! and, per contact, rows `[C_i | D_i]` that touch only the object's twist and that contact's own
//! `k_i ≤ 3` forces. A contact that slides or separates has `D_i` invertible and is eliminated
//! (a Schur complement on the twist); one that sticks, or a unilateral one in contact, has `D_i`
//! singular (exactly 0 in the exact equations): its rows constrain the twist alone, `C_i dV = r_i`,
//! and its forces are multipliers seen only through the wrench `B_i dz_i`. Per contact, the SVD
//! of `D_i` splits its directions into eliminated and constraint ones. What remains is at most
//! `2d` unknowns — the twist and the multipliers' wrench, in the range of their columns — in `d`
//! balance rows and one row per constraint direction, solved in least squares (its normal
//! equations, pseudo-inverted by an SVD of at most 2d × 2d, with two steps of refinement): the
//! exact Newton step when the Jacobian is invertible, a least-squares step with the multipliers of
//! least norm (forces statically indeterminate, constraints inconsistent) otherwise. Cost O(n d²), where the dense
//! LU it replaces took O((d + Σ k_i)³).

use nalgebra::{DMatrix, DVector};

/// One contact's blocks: its unknowns and rows start at `start` (`k` of each).
#[derive(Clone, Debug)]
pub(super) struct Block {
    pub start: usize,
    /// `∂(Newton–Euler)/∂z_i` (d × k).
    pub b: DMatrix<f64>,
    /// `∂F_i/∂V` (k × d).
    pub c: DMatrix<f64>,
    /// `∂F_i/∂z_i` (k × k).
    pub d: DMatrix<f64>,
}

/// The generalized Jacobian in block-arrow form.
#[derive(Clone, Debug)]
pub(super) struct Arrow {
    /// `∂(Newton–Euler)/∂V` (d × d).
    pub a: DMatrix<f64>,
    pub blocks: Vec<Block>,
    /// Number of unknowns (d + Σ k_i).
    pub n: usize,
}

/// Singular values of `D_i` below this share of its scale `s` (the rows' scaling) make constraint
/// directions.
const SINGULAR: f64 = 1e-9;

impl Arrow {
    /// An arrow of `n` unknowns, twist dimension `d`, contacts of `sizes` unknowns each (blocks zero).
    pub fn zeros(d: usize, sizes: &[(usize, usize)]) -> Self {
        let blocks = sizes
            .iter()
            .map(|&(start, k)| Block { start, b: DMatrix::zeros(d, k), c: DMatrix::zeros(k, d), d: DMatrix::zeros(k, k) })
            .collect();
        let n = d + sizes.iter().map(|s| s.1).sum::<usize>();
        Self { a: DMatrix::zeros(d, d), blocks, n }
    }

    /// The dense matrix (tests, and the finite-difference check of the Jacobian).
    #[cfg(test)]
    pub fn dense(&self) -> DMatrix<f64> {
        let d = self.a.nrows();
        let mut j = DMatrix::zeros(self.n, self.n);
        j.view_mut((0, 0), (d, d)).copy_from(&self.a);
        for b in &self.blocks {
            let k = b.d.nrows();
            j.view_mut((0, b.start), (d, k)).copy_from(&b.b);
            j.view_mut((b.start, 0), (k, d)).copy_from(&b.c);
            j.view_mut((b.start, b.start), (k, k)).copy_from(&b.d);
        }
        j
    }

    /// The step `x` with `J x = r` (see the module's notes); `scale` is the size of `D_i`'s
    /// regular singular values (the rows' scaling). None when a number is not finite.
    pub fn solve(&self, r: &DVector<f64>, scale: f64) -> Option<DVector<f64>> {
        let d = self.a.nrows();
        let tau = SINGULAR * scale;
        let mut a = self.a.clone();
        let mut r0 = r.rows(0, d).into_owned();
        // per contact: its SVD (on the stack: k ≤ 3, d ≤ 6), and which directions are constraints
        if d > 6 || self.blocks.iter().any(|b| b.d.nrows() > 3) {
            return None; // twists of 3 or 6, contacts of at most 3 unknowns
        }
        let mut locals: Vec<Local> = Vec::with_capacity(self.blocks.len());
        let (mut crow, mut cval, mut bcol): (Vec<f64>, Vec<f64>, Vec<f64>) = (Vec::new(), Vec::new(), Vec::new());
        for blk in &self.blocks {
            let k = blk.d.nrows();
            let (u, sv, w) = split_small(&blk.d, tau)?;
            let mut l = Local { k, w, sv, ri: [0.0; 3], ci: [[0.0; 6]; 3] };
            for j in 0..k {
                l.ri[j] = (0..k).map(|q| u[q][j] * r[blk.start + q]).sum();
                for col in 0..d {
                    l.ci[j][col] = (0..k).map(|q| u[q][j] * blk.c[(q, col)]).sum();
                }
                // B_i w_j
                let mut bw = [0.0; 6];
                for (row, x) in bw.iter_mut().enumerate().take(d) {
                    *x = (0..k).map(|q| blk.b[(row, q)] * w[q][j]).sum();
                }
                if sv[j] > tau {
                    // dẑ_j = (r̂_j − ĉ_j dV) / σ_j, eliminated from the balance rows
                    for row in 0..d {
                        let bs = bw[row] / sv[j];
                        for col in 0..d {
                            a[(row, col)] -= bs * l.ci[j][col];
                        }
                        r0[row] -= bs * l.ri[j];
                    }
                } else {
                    crow.extend(&l.ci[j][..d]);
                    cval.push(l.ri[j]);
                    bcol.extend(&bw[..d]);
                }
            }
            locals.push(l);
        }
        // the multipliers' wrench w = B_c λ lies in the range of B_c: an orthonormal basis Q
        let m = cval.len();
        let bc = DMatrix::from_column_slice(d, m, &bcol);
        let g = (&bc * bc.transpose()).symmetric_eigen();
        let gmax = g.eigenvalues.iter().fold(0.0, |x: f64, y| x.max(y.abs()));
        let keep: Vec<usize> = (0..d).filter(|&i| g.eigenvalues[i] > 1e-12 * gmax && gmax > 0.0).collect();
        let q = DMatrix::from_fn(d, keep.len(), |i, j| g.eigenvectors[(i, keep[j])]);
        // least squares in (dV, ω): [A Q; C_c 0] [dV; ω] = [r0; r_c]
        let p = keep.len();
        let mut mat = DMatrix::zeros(d + m, d + p);
        mat.view_mut((0, 0), (d, d)).copy_from(&a);
        mat.view_mut((0, d), (d, p)).copy_from(&q);
        for i in 0..m {
            for col in 0..d {
                mat[(d + i, col)] = crow[i * d + col];
            }
        }
        let mut rhs = DVector::zeros(d + m);
        rhs.rows_mut(0, d).copy_from(&r0);
        for (i, v) in cval.iter().enumerate() {
            rhs[d + i] = *v;
        }
        // by its normal equations (d + p ≤ 2d unknowns: O(m d²)), pseudo-inverted, with two steps
        // of iterative refinement (the normal equations square the condition number)
        let normal = mat.tr_mul(&mat);
        let top = normal.amax().max(f64::MIN_POSITIVE);
        let inv = normal.svd(true, true);
        let mut y = inv.solve(&mat.tr_mul(&rhs), 1e-14 * top).ok()?;
        for _ in 0..2 {
            y += inv.solve(&mat.tr_mul(&(&rhs - &mat * &y)), 1e-14 * top).ok()?;
        }
        let dv = y.rows(0, d).into_owned();
        let omega = y.rows(d, p).into_owned();
        // the least-norm multipliers with B_c λ = Q ω: λ = B_cᵀ Q Λ⁻¹ ω
        let lam_w = DVector::from_fn(p, |j, _| omega[j] / g.eigenvalues[keep[j]]);
        let lambda = bc.transpose() * (&q * lam_w);
        // back-substitution
        let mut x = DVector::zeros(self.n);
        x.rows_mut(0, d).copy_from(&dv);
        let mut next = 0;
        for (blk, l) in self.blocks.iter().zip(&locals) {
            let mut zhat = [0.0; 3];
            for j in 0..l.k {
                zhat[j] = if l.sv[j] > tau {
                    (l.ri[j] - (0..d).map(|col| l.ci[j][col] * dv[col]).sum::<f64>()) / l.sv[j]
                } else {
                    next += 1;
                    lambda[next - 1]
                };
            }
            for q in 0..l.k {
                x[blk.start + q] = (0..l.k).map(|j| l.w[q][j] * zhat[j]).sum();
            }
        }
        x.iter().all(|v| v.is_finite()).then_some(x)
    }
}

/// One contact's split for the back-substitution: `W`, `Σ`, `Uᵀ r_i` and `Uᵀ C_i` (k ≤ 3 rows,
/// d ≤ 6 columns used).
struct Local {
    k: usize,
    w: [[f64; 3]; 3],
    sv: [f64; 3],
    ri: [f64; 3],
    ci: [[f64; 6]; 3],
}

/// [`split`] on the stack: a scalar, a 2 × 2 in closed form ([`svd2`]), a 3 × 3 by [`split`]
/// ([`super::Problem`]'s check keeps contacts to at most 3 unknowns).
#[allow(clippy::type_complexity)]
fn split_small(d: &DMatrix<f64>, tau: f64) -> Option<([[f64; 3]; 3], [f64; 3], [[f64; 3]; 3])> {
    let (mut u, mut sv, mut w) = ([[0.0; 3]; 3], [0.0; 3], [[0.0; 3]; 3]);
    match d.nrows() {
        1 => {
            let x = d[(0, 0)];
            u[0][0] = 1.0;
            sv[0] = if x.abs() > tau { x.abs() } else { 0.0 };
            w[0][0] = if x < 0.0 { -1.0 } else { 1.0 };
        }
        2 => {
            let (u2, s2, w2) = svd2(d[(0, 0)], d[(0, 1)], d[(1, 0)], d[(1, 1)]);
            for i in 0..2 {
                sv[i] = if s2[i] > tau { s2[i] } else { 0.0 };
                for j in 0..2 {
                    u[i][j] = u2[i][j];
                    w[i][j] = w2[i][j];
                }
            }
        }
        _ => {
            let (um, s, wm) = split(d, tau)?;
            for i in 0..d.nrows() {
                sv[i] = s[i];
                for j in 0..d.nrows() {
                    u[i][j] = um[(i, j)];
                    w[i][j] = wm[(i, j)];
                }
            }
        }
    }
    (u.iter().chain(w.iter()).flatten().all(|x| x.is_finite()) && sv.iter().all(|x| x.is_finite())).then_some((u, sv, w))
}

/// The SVD of `[[a, b], [c, d]] = U diag(σ₁, σ₂) Wᵀ` in closed form, `σ₁ ≥ σ₂ ≥ 0`: the matrix is
/// a rotation by φ, a scaling and a rotation by θ, with `(a+d)/2 ± …` as in Blinn's 2 × 2 SVD.
#[allow(clippy::type_complexity)]
fn svd2(a: f64, b: f64, c: f64, d: f64) -> ([[f64; 2]; 2], [f64; 2], [[f64; 2]; 2]) {
    let (e, f, g, h) = (0.5 * (a + d), 0.5 * (a - d), 0.5 * (c + b), 0.5 * (c - b));
    let (q, r) = (e.hypot(h), f.hypot(g));
    let (sx, sy) = (q + r, q - r);
    let (a1, a2) = (g.atan2(f), h.atan2(e));
    let (theta, phi) = (0.5 * (a2 - a1), 0.5 * (a2 + a1));
    let (sp, cp) = phi.sin_cos();
    let (st, ct) = theta.sin_cos();
    // U = R(φ) (its second column negated when σ₂ < 0), Wᵀ = R(θ)
    let flip = if sy < 0.0 { -1.0 } else { 1.0 };
    let u = [[cp, sp * -flip], [sp, cp * flip]];
    let w = [[ct, st], [-st, ct]];
    (u, [sx, sy.abs()], w)
}

/// `D = U Σ Wᵀ` for a small square `D` (k ≤ 3), singular values in decreasing order, those at
/// most `tau` set to 0. nalgebra's SVD, checked; where it misses (some rank-one 2 × 2 matrices),
/// `W` and `Σ` from the symmetric eigenproblem of `DᵀD` (its singular values below 1e-7 of the
/// largest are 0 there: squaring loses half the digits), `U`'s columns `D w_j / σ_j` completed by
/// Gram–Schmidt.
fn split(d: &DMatrix<f64>, tau: f64) -> Option<(DMatrix<f64>, DVector<f64>, DMatrix<f64>)> {
    let k = d.nrows();
    let scale = d.amax().max(tau);
    let check = |u: &DMatrix<f64>, sv: &DVector<f64>, w: &DMatrix<f64>| {
        let id = DMatrix::<f64>::identity(k, k);
        (u * DMatrix::from_diagonal(sv) * w.transpose() - d).amax() <= 1e-12 * scale
            && (u.transpose() * u - &id).amax() <= 1e-12
            && (w.transpose() * w - &id).amax() <= 1e-12
    };
    let svd = d.clone().svd(true, true);
    if let (Some(u), Some(vt)) = (svd.u.as_ref(), svd.v_t.as_ref()) {
        let w = vt.transpose();
        if check(u, &svd.singular_values, &w) {
            let mut order: Vec<usize> = (0..k).collect();
            order.sort_by(|&a, &b| svd.singular_values[b].total_cmp(&svd.singular_values[a]));
            let u = DMatrix::from_fn(k, k, |i, j| u[(i, order[j])]);
            let w = DMatrix::from_fn(k, k, |i, j| w[(i, order[j])]);
            let sv = DVector::from_fn(k, |j, _| if svd.singular_values[order[j]] > tau { svd.singular_values[order[j]] } else { 0.0 });
            return Some((u, sv, w));
        }
    }
    let e = (d.transpose() * d).symmetric_eigen();
    let mut order: Vec<usize> = (0..k).collect();
    order.sort_by(|&a, &b| e.eigenvalues[b].total_cmp(&e.eigenvalues[a]));
    let w = DMatrix::from_fn(k, k, |i, j| e.eigenvectors[(i, order[j])]);
    let mut sv = DVector::from_fn(k, |j, _| e.eigenvalues[order[j]].max(0.0).sqrt());
    let floor = tau.max(1e-7 * sv[0]);
    let rank = sv.iter().take_while(|&&x| x > floor).count();
    sv.rows_mut(rank, k - rank).fill(0.0);
    // U: D w_j / σ_j, then the unit vectors, orthogonalized
    let cands = (0..rank).map(|j| d * w.column(j) / sv[j]).chain((0..k).map(|i| DVector::from_fn(k, |r, _| (r == i) as u8 as f64)));
    let mut u = DMatrix::zeros(k, k);
    let mut j = 0;
    for mut v in cands {
        if j == k {
            break;
        }
        for i in 0..j {
            let ui = u.column(i).into_owned();
            v -= &ui * ui.dot(&v);
        }
        if v.norm() > 1e-6 {
            u.set_column(j, &v.normalize());
            j += 1;
        }
    }
    (j == k && u.iter().chain(w.iter()).all(|x| x.is_finite())).then_some((u, sv, w))
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    /// A random arrow: `d`, contacts of 1–3 unknowns; `singular`: the share of contacts whose
    /// `D_i` is zero (sticking) or rank-deficient.
    fn random(d: usize, n: usize, singular: f64, seed: u64) -> Arrow {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let mut sizes = Vec::new();
        let mut at = d;
        for _ in 0..n {
            let k = rng.random_range(1..=3);
            sizes.push((at, k));
            at += k;
        }
        let mut arr = Arrow::zeros(d, &sizes);
        arr.a = DMatrix::from_fn(d, d, |_, _| rng.random::<f64>() - 0.5);
        for blk in arr.blocks.iter_mut() {
            let k = blk.d.nrows();
            blk.b = DMatrix::from_fn(d, k, |_, _| rng.random::<f64>() - 0.5);
            blk.c = DMatrix::from_fn(k, d, |_, _| rng.random::<f64>() - 0.5);
            blk.d = if rng.random::<f64>() < singular {
                if rng.random::<bool>() { DMatrix::zeros(k, k) } else {
                    // rank k − 1
                    let u = DVector::from_fn(k, |_, _| rng.random::<f64>() - 0.5);
                    let mut m = DMatrix::identity(k, k) - &u * u.transpose() / u.norm_squared();
                    m *= 0.7;
                    m
                }
            } else {
                DMatrix::identity(k, k) + DMatrix::from_fn(k, k, |_, _| 0.3 * (rng.random::<f64>() - 0.5))
            };
        }
        arr
    }

    #[test]
    fn the_step_is_the_dense_solution_when_the_jacobian_is_invertible() {
        for seed in 0..200 {
            let (d, n) = if seed % 2 == 0 { (3, 1 + seed as usize % 5) } else { (6, 1 + seed as usize % 4) };
            // few singular blocks: the whole matrix stays square and (generically) invertible
            let arr = random(d, n, if seed % 3 == 0 { 0.3 } else { 0.0 }, seed);
            let j = arr.dense();
            let Some(want) = j.clone().lu().solve(&DVector::from_fn(arr.n, |i, _| (i as f64 * 0.7).sin())) else { continue };
            if j.clone().svd(false, false).singular_values.min() < 1e-6 {
                continue; // near-singular draws: the dense solution is meaningless
            }
            let r = DVector::from_fn(arr.n, |i, _| (i as f64 * 0.7).sin());
            let got = arr.solve(&r, 1.0).unwrap();
            assert!((&got - &want).amax() <= 1e-8 * (1.0 + want.amax()), "seed {seed}: {got} vs {want}");
        }
    }

    #[test]
    fn a_singular_jacobian_gets_an_exact_step_when_one_exists() {
        // many sticking contacts: forces statically indeterminate, the twist overdetermined
        for seed in 0..50 {
            let arr = random(3, 40, 0.8, 1000 + seed);
            let j = arr.dense();
            assert!(j.clone().svd(false, false).singular_values.min() < 1e-9, "seed {seed}: singular by construction");
            // a consistent right-hand side is solved exactly
            let x0 = DVector::from_fn(arr.n, |i, _| (i as f64 * 1.3).sin());
            let r = &j * &x0;
            let got = arr.solve(&r, 1.0).unwrap();
            assert!((&j * &got - &r).amax() < 1e-8 * (1.0 + r.amax()), "seed {seed}: {}", (&j * &got - &r).amax());
            // an inconsistent one gets a finite step that satisfies the eliminated rows
            let r = DVector::from_fn(arr.n, |i, _| (i as f64 * 0.3).cos());
            let got = arr.solve(&r, 1.0).unwrap();
            let res = &j * &got - &r;
            for blk in arr.blocks.iter().filter(|b| b.d.clone().svd(false, false).singular_values.min() > 1e-3) {
                let k = blk.d.nrows();
                assert!(res.rows(blk.start, k).amax() < 1e-8, "seed {seed}: an invertible block's rows");
            }
        }
    }

    #[test]
    fn the_split_reconstructs_small_blocks() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(9);
        let bad = DMatrix::from_row_slice(2, 2, &[0.0007253383286216608, 0.022521339088612206, 0.022521339088612206, 0.6992746616713782]);
        let mut cases = vec![bad, DMatrix::zeros(3, 3), DMatrix::identity(2, 2)];
        for _ in 0..300 {
            let k = rng.random_range(1..=3);
            let u = DVector::from_fn(k, |_, _| rng.random::<f64>() - 0.5);
            let m = DMatrix::from_fn(k, k, |_, _| rng.random::<f64>() - 0.5);
            cases.push(if rng.random::<bool>() { &m - &m * &u * u.transpose() / u.norm_squared() } else { m });
        }
        for d in cases.iter().cloned().chain(cases.iter().map(|d| -d)) {
            let (u3, sv3, w3) = split_small(&d, 1e-9).unwrap();
            let k = d.nrows();
            let (us, ws) = (DMatrix::from_fn(k, k, |i, j| u3[i][j]), DMatrix::from_fn(k, k, |i, j| w3[i][j]));
            let ss = DVector::from_fn(k, |i, _| sv3[i]);
            assert!((&us * DMatrix::from_diagonal(&ss) * ws.transpose() - &d).amax() < 1e-7, "small: {d}");
            assert!((us.transpose() * &us - DMatrix::identity(k, k)).amax() < 1e-9 && (ws.transpose() * &ws - DMatrix::identity(k, k)).amax() < 1e-9);
            assert!((0..k.saturating_sub(1)).all(|i| ss[i] >= ss[i + 1]) && ss.iter().all(|x| *x >= 0.0), "{ss}");
            let (u, sv, w) = split(&d, 1e-9).unwrap();
            let k = d.nrows();
            assert!((&u * DMatrix::from_diagonal(&sv) * w.transpose() - &d).amax() < 1e-7, "{d}");
            assert!((u.transpose() * &u - DMatrix::identity(k, k)).amax() < 1e-9 && (w.transpose() * &w - DMatrix::identity(k, k)).amax() < 1e-9);
        }
    }
}
