//! The QP of one MPC step ([`crate::control::mpc`]), sparse: the pose errors after each horizon
//! step stay variables beside the generator weights, tied by the dynamics as equalities, so the KKT
//! system is banded and clarabel's sparse factorisation costs O(H) per iteration (the condensed
//! form, positions eliminated, has a dense Hessian: O(H²) to build and more to factor).
//!
//! Variables `x = [α₁ … α_H, e₁ … e_H]`: `αᵢ` the weights of step `i`'s generators (in units of
//! `v_max`), `eᵢ = pᵢ − Tᵢ` the error of the pose after step `i` from its reference knot, in units
//! of one step `ds` with the turn as `L θ` (errors rather than poses: no linear term, an
//! objective of the size of the tracking error, which clarabel's relative tolerances measure).
//!
//! `min Σᵢ wᵢ‖eᵢ‖² + r Σᵢ‖αᵢ‖²  s.t.  eᵢ − eᵢ₋₁ − Bᵢαᵢ = Tᵢ₋₁ − Tᵢ (e₀ = p₀ − T₀, p₀ the
//! measured pose: the first row is e₁ − B₁α₁ = p₀ − T₁),  αᵢ ≥ 0,  Σₖ αᵢₖ ≤ 10,  ‖Σₖ αᵢₖ S gᵢₖ‖ ≤ 1`
//!
//! with `Bᵢ`'s columns the pose rates of the generators (`R(θᵢ) gᵢₖ v_max δt / ds`), `Tᵢ` step
//! `i`'s reference knot, `wᵢ` the stage weight (the terminal weight for the last step): the same
//! optimum as the condensed QP.

use crate::mechanics::geometry::{rot, Vec2, Vec3};
use crate::mechanics::metric::Metric;
use clarabel::algebra::CscMatrix;
use clarabel::solver::SupportedConeT;

/// A horizon step: (pusher, generators, target knot `[x, z, θ]`, heading at the step's start).
pub type Step = (usize, Vec<Vec3>, [f64; 3], f64);

/// The weights of the cost (the MPC's settings).
#[derive(Clone, Copy, Debug)]
pub struct Weights {
    pub stage: f64,
    pub terminal: f64,
    pub effort: f64,
}

/// `½xᵀPx + cᵀx`, `Ax + s = b`, `s ∈ cones`, in clarabel's form (`P` upper triangular).
pub struct StepQp {
    pub p: CscMatrix<f64>,
    pub c: Vec<f64>,
    pub a: CscMatrix<f64>,
    pub b: Vec<f64>,
    pub cones: Vec<SupportedConeT<f64>>,
}

/// The QP from pose `q` over `steps` (`offs[i]`, `sizes[i]`: step `i`'s weights among `α`);
/// `ds` the length of one step [m], `length` the scene's `L` [m], `metric` the twists' metric.
pub fn build(q: &[f64; 3], steps: &[Step], offs: &[usize], sizes: &[usize], w: Weights, ds: f64, length: f64, metric: &Metric) -> StepQp {
    let (n, h) = (sizes.iter().sum::<usize>(), steps.len());
    let dim = n + 3 * h;
    let scaled = |t: &[f64; 3]| Vec3::new(t[0], t[1], length * t[2]) / ds;
    // cost: diagonal, no linear term
    let mut diag = vec![2.0 * w.effort; dim];
    let c = vec![0.0; dim];
    for i in 0..h {
        let wi = if i + 1 == h { w.terminal } else { w.stage };
        diag[n + 3 * i..n + 3 * i + 3].fill(2.0 * wi);
    }
    let p = CscMatrix::new(dim, dim, (0..=dim).collect(), (0..dim).collect(), diag);
    // constraints: the dynamics (zero cone), α ≥ 0 and Σα ≤ 10 (non-negative cone), the speed (second-order cones)
    let (mut ri, mut ci, mut v) = (Vec::new(), Vec::new(), Vec::new());
    let rows = 3 * h + n + h + 4 * h;
    let mut b = vec![0.0; rows];
    let mut before = scaled(q); // p₀, then each step's reference
    for (i, (_, gens, target, th)) in steps.iter().enumerate() {
        let r = rot(*th);
        let t = scaled(target);
        for d in 0..3 {
            let row = 3 * i + d;
            ri.push(row);
            ci.push(n + 3 * i + d);
            v.push(1.0);
            if i > 0 {
                ri.push(row);
                ci.push(n + 3 * (i - 1) + d);
                v.push(-1.0);
            }
            b[row] = before[d] - t[d];
        }
        before = t;
        let sum_row = 3 * h + n + i;
        b[sum_row] = 10.0;
        let soc = 3 * h + n + h + 4 * i;
        b[soc] = 1.0;
        for (k, g) in gens.iter().enumerate() {
            let col = offs[i] + k;
            // the pose rate of the unit twist × v_max × δt, in steps: [dx, dz, L dθ] / ds (δt v_max = ds)
            let dxz = r * Vec2::new(g.x, g.y);
            for (d, x) in [dxz.x, dxz.y, length * g.z].into_iter().enumerate() {
                ri.push(3 * i + d);
                ci.push(col);
                v.push(-x);
            }
            ri.push(3 * h + col);
            ci.push(col);
            v.push(-1.0);
            ri.push(sum_row);
            ci.push(col);
            v.push(1.0);
            let t = metric.twist(g);
            for d in 0..3 {
                ri.push(soc + 1 + d);
                ci.push(col);
                v.push(-t[d]);
            }
        }
    }
    let a = CscMatrix::new_from_triplets(rows, dim, ri, ci, v);
    let mut cones = vec![SupportedConeT::ZeroConeT(3 * h), SupportedConeT::NonnegativeConeT(n + h)];
    cones.extend(std::iter::repeat_n(SupportedConeT::SecondOrderConeT(4), h));
    StepQp { p, c, a, b, cones }
}
