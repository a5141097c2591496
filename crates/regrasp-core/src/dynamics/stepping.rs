//! Explicit time stepping of a push (thesis §3.2.3), shared by the planar ([`super::planar`]) and
//! spatial ([`super::spatial`]) models: the checks of the step, the loop that moves the object
//! with its twist and the pusher with its own, the pusher's contacts of a step, and what each step
//! records about them.

use crate::dynamics::mncp::{self, ContactState, Problem, Settings, Side, Solution};
use crate::error::{Error, Result};
use nalgebra::DVector;

/// Most time steps one simulated push may take (a typo in `dt` must not run for hours).
pub const MAX_STEPS: f64 = 1e6;

/// The number of steps of `dt` in `duration`, both checked: `duration` positive and finite,
/// `dt` in (0, duration], at most [`MAX_STEPS`] steps.
pub(super) fn step_count(duration: f64, dt: f64) -> Result<usize> {
    if !(duration > 0.0 && duration.is_finite()) {
        return Err(Error::arg("duration", format!("must be a positive, finite number of seconds (got {duration})")));
    }
    if !(dt > 0.0 && dt <= duration) {
        return Err(Error::arg("dt", format!("must be a time step in (0, duration = {duration}] s (got {dt})")));
    }
    if duration / dt > MAX_STEPS {
        return Err(Error::arg("dt", format!("{:.0} time steps asked for (duration / dt); at most {MAX_STEPS:.0}", duration / dt)));
    }
    Ok((duration / dt).round() as usize)
}

/// Fastest pusher motion the quasi-static model takes [m/s] (metric: |v| + L |ω|): far beyond
/// any gripper's, and where the solver's work stays bounded.
pub const MAX_SPEED: f64 = 100.0;

/// Checks a pusher speed `speed` [m/s] (metric: |v| + L |ω|): finite and at most
/// [`MAX_SPEED`]. Errors name `name`.
pub fn check_speed(name: &str, speed: f64) -> Result<()> {
    if !(speed.is_finite() && speed <= MAX_SPEED) {
        return Err(Error::arg(name, format!("moves the pusher at {speed:.3e} m/s (|v| + L |ω|); at most {MAX_SPEED} m/s")));
    }
    Ok(())
}

/// Checks that a pusher moving at `speed` [m/s] (metric: |v| + L |ω|; see [`check_speed`])
/// moves at most the object's characteristic length `length` [m] in one time step `dt` [s]:
/// a quasi-static step cannot resolve more. Errors name `twist`.
pub fn check_step_motion(speed: f64, dt: f64, length: f64) -> Result<()> {
    check_speed("twist", speed)?;
    if speed * dt > length {
        return Err(Error::arg(
            "twist",
            format!("moves the pusher {:.3e} m in one time step of {dt} s, more than the object's size ({length:.3e} m): slow it down or shorten the step", speed * dt),
        ));
    }
    Ok(())
}

/// Pusher `i` of a scene's pushers.
pub(super) fn pusher_at<T>(pushers: &[T], i: usize) -> Result<&T> {
    pushers.get(i).ok_or_else(|| Error::arg("pusher", format!("index {i} out of range")))
}

/// The points of `candidates` (each with its gap) whose gap is below `reach`: a step's pusher
/// contacts, with their gaps.
pub(super) fn within_reach<P>(candidates: impl IntoIterator<Item = (P, f64)>, reach: f64) -> (Vec<P>, Vec<f64>) {
    candidates.into_iter().filter(|(_, gap)| *gap < reach).unzip()
}

/// Steps `k = 0..=steps` of a push at times `k dt`: `step(t, q, qp)` solves the step with the
/// object at pose `q` and the pusher at `qp` and returns the object's twist; then, but for the
/// last step, the object moves with that twist and the pusher with `u`, both over `dt`
/// (`integrate`: the exponential map of the pose space). Checks for an interrupt every step.
pub(super) fn march<Q: Copy, V>(
    steps: usize,
    dt: f64,
    q0: Q,
    u: &V,
    integrate: fn(&Q, &V, f64) -> Q,
    mut step: impl FnMut(f64, &Q, &Q) -> Result<V>,
) -> Result<()> {
    let (mut q, mut qp) = (q0, q0);
    for k in 0..=steps {
        crate::interrupt::check()?;
        let v = step(k as f64 * dt, &q, &qp)?;
        if k < steps {
            q = integrate(&q, &v, dt);
            qp = integrate(&qp, u, dt);
        }
    }
    Ok(())
}

/// The forward problem of the step at time `t` with pusher twist `u` (object frame).
/// A solution whose velocities or forces are not all finite is an error naming `twist`.
pub(super) fn solve_step(p: &Problem, u: &[f64], settings: &Settings, t: f64) -> Result<Solution> {
    let s = mncp::solve_forward(p, &DVector::from_row_slice(u), settings).map_err(|e| Error::arg("push", format!("at t = {t:.3} s: {e}")))?;
    finite_solution(&s).map_err(|e| Error::arg("twist", format!("at t = {t:.3} s: {e}")))?;
    Ok(s)
}

/// `Ok` when every velocity and force of `s` is finite.
pub fn finite_solution(s: &Solution) -> Result<()> {
    let vectors = s.tangent_velocities.iter().chain(&s.friction_forces).chain([&s.twist, &s.pusher_twist]);
    let finite = vectors.flat_map(|v| v.iter()).chain(&s.normal_forces).chain(&s.normal_velocities).all(|x| x.is_finite());
    if finite && s.residuals.max().is_finite() { Ok(()) } else { Err(Error::arg("twist", "the solution has non-finite velocities or forces")) }
}

/// What a step records about the pusher's contacts.
pub(super) struct PusherContacts {
    /// Largest slip speed at a pusher point in contact.
    pub(super) slip: f64,
    /// Points in contact (not separating), and how many of them stick.
    pub(super) touching: usize,
    pub(super) sticking: usize,
}

impl PusherContacts {
    pub(super) fn of(p: &Problem, s: &Solution) -> Self {
        let mut out = Self { slip: 0.0, touching: 0, sticking: 0 };
        for (i, c) in p.contacts.iter().enumerate() {
            if c.side == Side::Pusher && s.states[i] != ContactState::Separate {
                out.touching += 1;
                out.slip = out.slip.max(s.tangent_velocities[i].norm());
                out.sticking += (s.states[i] == ContactState::Stick) as usize;
            }
        }
        out
    }
}
