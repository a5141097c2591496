//! Test problems: a planar block held by finger points or one limit-surface patch, pushed by a
//! line pusher.

use super::{solve_forward, Contact, FrictionLaw, NormalLaw, Problem, Settings, Side, Solution};
use nalgebra::{DMatrix, DVector};

/// A planar block held by a circular patch of `k` points at the origin, pushed by a line
/// pusher along +x at its left face (points at (-0.025, ±0.02)).
pub(super) fn block(k: usize, grip: f64, mu_p: f64) -> Problem {
    let d = 3;
    let mut contacts = Vec::new();
    let (rho, mu_s) = (0.006, 0.6);
    for i in 0..k {
        let a = 2.0 * std::f64::consts::PI * i as f64 / k as f64;
        let r = [rho * a.cos(), rho * a.sin()];
        let jt = DMatrix::from_row_slice(2, 3, &[1.0, 0.0, -r[1], 0.0, 1.0, r[0]]);
        contacts.push(Contact::fixed_normal(format!("finger[{i}]"), Side::Finger, 2.0 * grip / k as f64, mu_s, DVector::zeros(d), jt));
    }
    for (i, z) in [-0.02, 0.02].iter().enumerate() {
        let r = [-0.025, *z];
        // n = +x, t = +z: jn = [1, 0, r×n] with r×n = r_x n_z − r_z n_x = −r_z
        let jn = DVector::from_row_slice(&[1.0, 0.0, -r[1]]);
        let jt = DMatrix::from_row_slice(1, 3, &[0.0, 1.0, r[0]]);
        contacts.push(Contact::pusher_point(format!("pusher[{i}]"), mu_p, jn, jt, 0.0));
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

/// `p` with its first `k` contacts (the finger points) replaced by one ellipsoidal patch
/// (μN = 24 N, k = 0.6·7 mm).
pub(super) fn with_patch(mut p: Problem, k: usize) -> Problem {
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

/// The forward solution of `p` for pusher twist `u` (default settings).
pub(super) fn push(p: &Problem, u: &[f64]) -> Solution {
    solve_forward(p, &DVector::from_row_slice(u), &Settings::default()).unwrap()
}
