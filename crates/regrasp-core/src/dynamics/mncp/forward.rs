//! The forward problem (thesis §3.2): the pusher's twist given, the object's twist and every
//! contact force. The object moving with the pusher is decided exactly by the inverse problem;
//! otherwise the semismooth Newton solver ([`super::newton`]) is tried from a few starts, exact,
//! smoothed, with other projection steps and by continuation in the pusher's friction and
//! twist, until one attempt meets every constraint.

use super::newton::Newton;
use super::{finish, solve_inverse, FrictionLaw, Problem, Settings, Side, Solution};
use crate::error::{Error, Result};
use nalgebra::DVector;

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
    if let Some(sol) = moves_with_pusher(p, u, settings) {
        return Ok(sol);
    }
    let mut tries = Attempts { p, u, accept: settings.accept, best: None };
    let nw = Newton::new(p, u);
    // 2. Semismooth Newton on the exact equations from the object moving with the pusher: fast
    //    when it converges (slides near the sticking solution mostly do).
    let (x, _, it) = nw.solve(nw.start(u), 0.0, settings.tolerance, 25);
    if let Some(s) = tries.consider(&nw, &x, it) {
        return Ok(s);
    }
    // 3. Smoothing Newton from each start, then plain semismooth Newton from the same start.
    let starts = starts(p, u, &nw, settings);
    for x0 in &starts {
        crate::interrupt::check()?;
        let (x, _, its) = smooth_then_exact(&nw, x0.clone(), 0.1, settings);
        if let Some(s) = tries.consider(&nw, &x, its) {
            return Ok(s);
        }
        let (x, _, it) = nw.solve(x0.clone(), 0.0, settings.tolerance, settings.max_iterations);
        if let Some(s) = tries.consider(&nw, &x, it) {
            return Ok(s);
        }
    }
    // 4. Other projection steps ρ (same solutions, other basins of convergence), continuing
    //    from the best point found so far as well as from the starts.
    for rho_scale in [0.1, 10.0, 0.01, 100.0] {
        let nr = Newton::with_rho(p, u, rho_scale);
        let best = tries.best().map(|b| nr.pack(b));
        for x0 in best.into_iter().chain(starts.iter().cloned()) {
            crate::interrupt::check()?;
            let (x, _, its) = smooth_then_exact(&nr, x0, 0.3, settings);
            if let Some(s) = tries.consider(&nr, &x, its) {
                return Ok(s);
            }
        }
    }
    // 5. Continuation in the pusher's friction: from a frictionless pusher (the easiest
    //    problem) up to its own, each solve starting from the last one's solution.
    if let Some(s) = friction_continuation(p, u, settings, &mut tries)? {
        return Ok(s);
    }
    // 6. Continuation in the pusher's twist: from the push with one component larger.
    if let Some(s) = twist_continuation(p, u, settings, &mut tries)? {
        return Ok(s);
    }
    crate::interrupt::check()?; // an interrupt that cut the last attempt short is not a failure to converge
    Err(tries.failure())
}

/// Step 5: the pusher's friction coefficients scaled by `CONTINUATION` in turn, each problem
/// solved from the previous one's solution; the last is `p`.
fn friction_continuation(p: &Problem, u: &DVector<f64>, settings: &Settings, tries: &mut Attempts<'_>) -> Result<Option<Solution>> {
    let stages = CONTINUATION.iter().map(|&scale| {
        let mut q = p.clone();
        for c in q.contacts.iter_mut().filter(|c| c.side == Side::Pusher) {
            if let FrictionLaw::Coulomb(mu) = &mut c.friction {
                *mu *= scale;
            }
        }
        (scale, q, u.clone())
    });
    let x = follow(stages, settings)?;
    Ok(x.and_then(|(x, its)| tries.consider(&Newton::new(p, u), &x, its)))
}

/// The pusher-friction scales of [`friction_continuation`] (the last is the problem's own).
const CONTINUATION: [f64; 6] = [0.0, 0.2, 0.4, 0.6, 0.8, 1.0];

/// Step 6: continuation in the pusher's twist, along each component in each sign: from `u`
/// plus `δ` times the component's scale, `δ` down `TWIST_DELTAS` to 0. A push whose twist is
/// nearly degenerate (sliding along a face with a rotation of 1e-4 of its speed, no gravity)
/// has a solution linear in that small component that Newton does not reach from any start,
/// but reaches from the same push with the component larger. Scales: the velocity scale for a
/// translation, over the radius of gyration `√(M_kk / max M_ii)` for a rotation.
fn twist_continuation(p: &Problem, u: &DVector<f64>, settings: &Settings, tries: &mut Attempts<'_>) -> Result<Option<Solution>> {
    let top = p.mass.diagonal().iter().fold(0.0f64, |m, x| m.max(*x));
    for k in 0..p.dim {
        let scale = p.velocity_scale * (top / p.mass[(k, k)].max(1e-300)).sqrt().min(1e6);
        // the sign of the component first (the push made more of what it already is)
        let first = if u[k] < 0.0 { -1.0 } else { 1.0 };
        for sign in [first, -first] {
            let stages = TWIST_DELTAS.iter().map(|&d| {
                let mut w = u.clone();
                w[k] += sign * d * scale;
                (d, p.clone(), w)
            });
            if let Some((x, its)) = follow(stages, settings)? {
                if let Some(s) = tries.consider(&Newton::new(p, u), &x, its) {
                    return Ok(Some(s));
                }
            }
        }
    }
    Ok(None)
}

/// The perturbations of [`twist_continuation`], in units of the component's scale.
const TWIST_DELTAS: [f64; 10] = [0.3, 0.1, 0.03, 0.01, 3e-3, 1e-3, 3e-4, 1e-4, 3e-5, 0.0];

/// Solves each stage (its parameter `t`, a problem and a pusher twist) from the previous
/// stages' solutions, linearly extrapolated in `t` (a branch of solutions is locally affine in
/// it), exact Newton first, smoothing where that fails; returns the last stage's point and the
/// iterations of all.
fn follow(stages: impl Iterator<Item = (f64, Problem, DVector<f64>)>, settings: &Settings) -> Result<Option<(DVector<f64>, usize)>> {
    let mut done: Vec<(f64, DVector<f64>)> = Vec::new();
    let mut total = 0;
    for (t, q, w) in stages {
        crate::interrupt::check()?;
        let nw = Newton::new(&q, &w);
        let (xs, _, its) = match done.as_slice() {
            [] => smooth_then_exact(&nw, nw.start(&w), 0.1, settings),
            [.., (t0, x0), (t1, x1)] if t1 != t0 => {
                let x = x1 + (x1 - x0) * ((t - t1) / (t1 - t0));
                polish(&nw, x, settings)
            }
            [.., (_, x1)] => polish(&nw, x1.clone(), settings),
        };
        total += its;
        done.push((t, xs));
    }
    Ok(done.pop().map(|(_, x)| (x, total)))
}

/// Exact Newton from `x0`, near a solution; where it does not converge, the better (by the
/// exact equations' residual) of its end and smoothing Newton's from `x0`.
fn polish(nw: &Newton<'_>, x0: DVector<f64>, settings: &Settings) -> (DVector<f64>, f64, usize) {
    let exact = nw.solve(x0.clone(), 0.0, settings.tolerance, settings.max_iterations);
    if exact.1 <= settings.tolerance {
        return exact;
    }
    let smooth = smooth_then_exact(nw, x0, 0.1, settings);
    if smooth.1 <= exact.1 {
        smooth
    } else {
        exact
    }
}

/// Step 1: the solution of the inverse problem at `V = U`, if it exists and is accepted (the
/// object moving rigidly with the pusher).
fn moves_with_pusher(p: &Problem, u: &DVector<f64>, settings: &Settings) -> Option<Solution> {
    let mut sol = solve_inverse(p, u, settings).ok()?;
    if sol.residuals.max() > settings.accept {
        return None;
    }
    sol.iterations = 0;
    Some(sol)
}

/// The attempts of one forward solve: returns the first accepted, keeps the best of the others
/// (the smallest scaled constraint residual).
struct Attempts<'a> {
    p: &'a Problem,
    u: &'a DVector<f64>,
    accept: f64,
    best: Option<(f64, Solution)>,
}

impl Attempts<'_> {
    /// The solution at `nw`'s unknowns `x` after `iterations`: returned when it is accepted,
    /// kept when it is the best so far.
    fn consider(&mut self, nw: &Newton<'_>, x: &DVector<f64>, iterations: usize) -> Option<Solution> {
        let (v, fns, fts) = nw.unpack(x);
        let sol = finish(self.p, v, self.u.clone(), fns, fts, iterations);
        let r = sol.residuals.max();
        if r <= self.accept {
            return Some(sol);
        }
        if self.best.as_ref().is_none_or(|(b, _)| r < *b) {
            self.best = Some((r, sol));
        }
        None
    }

    fn best(&self) -> Option<&Solution> {
        self.best.as_ref().map(|(_, s)| s)
    }

    /// The error when no attempt was accepted, with the best one's residuals.
    fn failure(self) -> Error {
        let (r, sol) = self.best.expect("at least one attempt");
        Error::arg(
            "mncp",
            format!(
                "the forward solve did not converge: largest scaled constraint residual {r:.2e} after {} iterations ({:?})",
                sol.iterations, sol.residuals
            ),
        )
    }
}

/// Smoothing Newton: the equations with max and the projections smoothed by ε, from ε = 1 (in
/// units of the force scale) down to 1e-10 by `factor`, each solve warm-starting the next, then
/// polished with the exact equations. Returns the point, its residual of the exact equations
/// and the iterations of all the solves.
fn smooth_then_exact(nw: &Newton<'_>, x0: DVector<f64>, factor: f64, settings: &Settings) -> (DVector<f64>, f64, usize) {
    let mut x = x0;
    let mut its = 0;
    let mut e = 1.0;
    while e > 1e-10 {
        let (xe, _, it) = nw.solve(x, e, 0.1 * e, 40);
        its += it;
        x = xe;
        e *= factor;
    }
    let (x, r, it) = nw.solve(x, 0.0, settings.tolerance, settings.max_iterations);
    (x, r, its + it)
}

/// The starts of step 3: the object moving with the pusher with the forces of a push by a very
/// rough pusher (when that inverse problem has a solution), then the object moving with the
/// pusher, at rest and falling freely, with zero forces.
fn starts(p: &Problem, u: &DVector<f64>, nw: &Newton<'_>, settings: &Settings) -> Vec<DVector<f64>> {
    let mut starts = Vec::new();
    let mut rough = p.clone();
    for c in rough.contacts.iter_mut().filter(|c| c.side == Side::Pusher) {
        c.friction = FrictionLaw::Coulomb(1e3);
    }
    if let Ok(s0) = solve_inverse(&rough, u, settings) {
        starts.push(nw.pack(&s0));
    }
    let free_fall = p.mass.clone().lu().solve(&p.wrench).unwrap_or_else(|| DVector::zeros(p.dim));
    for v0 in [u.clone(), DVector::zeros(p.dim), free_fall] {
        starts.push(nw.start(&v0));
    }
    starts
}

#[cfg(test)]
mod tests {
    use super::super::fixtures::{block, push};
    use super::super::ContactState;

    #[test]
    fn push_along_the_normal_sticks_and_the_fingers_slide() {
        let s = push(&block(8, 20.0, 0.5), &[0.01, 0.0, 0.0]);
        assert!(s.residuals.max() < 1e-8, "{:?}", s.residuals);
        assert!((&s.twist - &s.pusher_twist).norm() < 1e-9, "moves with the pusher: {}", s.twist);
        let (fingers, pushers) = s.states.split_at(8);
        assert!(fingers.iter().all(|c| *c == ContactState::Slide));
        assert!(pushers.iter().all(|c| *c == ContactState::Stick));
    }

    #[test]
    fn lifting_with_a_side_pusher_slips() {
        let s = push(&block(8, 20.0, 0.2), &[0.002, 0.01, 0.0]);
        assert!(s.residuals.max() < 1e-8, "{:?}", s.residuals);
        assert!(s.states[8..].iter().all(|c| *c == ContactState::Slide), "{:?}", s.states);
    }

    #[test]
    fn zero_grip_drops_the_object() {
        let s = push(&block(8, 0.0, 0.5), &[0.01, 0.0, 0.0]);
        assert!(s.twist[1] < -1.0, "falls: {}", s.twist);
    }
}
