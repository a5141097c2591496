//! The step of a point pusher in the planar planner (issue 18, item 1).
//!
//! A plan's step from pose `a` to `b` moves the pusher, relative to the grasp, with the constant
//! body twist `ξ = log(a⁻¹b)` (what the quasi-static replay and the arm execute). A line pusher
//! that sticks carries the object along exactly; a point pusher imposes only its contact point's
//! velocity `u_b = ξ_lin + ξ_ω r⊥` (pusher frame) and the object turns about the contact as its
//! mechanics say ([`SupportFrame::point_twist`]). So the object's motion is the flow
//!
//! `q̇ = [R(θ) v_lin, v_ω]`, `v = point_twist(r, R(θ_ξ(t) − θ) u_b)`, `θ_ξ(t) = θ_a + t ξ_ω`,
//!
//! integrated over unit time (RK4). The contact sticks, so the contact point always lands where
//! the pusher's does; the step is consistent when the object's rotation also lands on `b`'s.
//! [`steer`] finds that rotation (a fixed point on `ξ_ω` for a chosen contact velocity);
//! [`check`] decides a given step: sticking all along, and landing on `b` within
//! [`LANDING_TOL`].

use crate::cones::frame::SupportFrame;
use crate::mechanics::geometry::{perp, rot, Vec2, Vec3};
use std::f64::consts::PI;
use crate::pose::planar::{body_twist, distance, integrate};
use crate::scene::Scene;

/// How far (metric distance over L) the object's flow may end from the step's end pose.
pub const LANDING_TOL: f64 = 1e-6;

/// How closely [`steer`] settles the rotation [rad]: far inside [`LANDING_TOL`], and smooth
/// enough for the finite differences of [`connect`].
const SETTLE_TOL: f64 = 1e-11;

/// The object's motion over a point pusher's step.
#[derive(Clone, Debug)]
pub struct Flow {
    pub pusher: usize,
    /// Poses at the `n + 1` integration nodes (the start first).
    pub poses: Vec<[f64; 3]>,
    /// Smallest margin of the exact test at the integration nodes before the end (the first
    /// node's separately).
    pub first_margin: f64,
    pub margin: f64,
}

impl Flow {
    pub fn end(&self) -> [f64; 3] {
        *self.poses.last().expect("a flow has its start")
    }
}

/// The pusher's contact point of pusher `p` (object frame), if it is a point pusher.
pub fn contact_point(scene: &Scene, p: usize) -> Option<Vec2> {
    let points = &scene.pushers.get(p)?.contact.points;
    (points.len() == 1).then(|| points[0])
}

/// The object's twist at `q` at time `t` of a step from `a` with pusher twist `xi`; the frame
/// when the pad is on the object and the grasp holds.
/// `phi` carries the last root (warm start) from one evaluation to the next.
fn rate(scene: &Scene, r: &Vec2, a: &[f64; 3], xi: &Vec3, t: f64, q: &[f64; 3], phi: &mut Option<f64>) -> Option<(Vec3, SupportFrame)> {
    if !scene.admissible(q) {
        return None;
    }
    let f = scene.frame(q);
    if !(f.hold_ratio < 1.0) {
        return None;
    }
    let ub = Vec2::new(xi.x, xi.y) + perp(r) * xi.z;
    let u = rot(a[2] + t * xi.z - q[2]) * ub;
    let (v, root) = f.point_twist_near(r, &u, scene.length, *phi)?;
    *phi = Some(root);
    Some((v, f))
}

/// `q̇` of body twist `v` at pose `q`.
fn pose_rate(q: &[f64; 3], v: &Vec3) -> [f64; 3] {
    let d = rot(q[2]) * Vec2::new(v.x, v.y);
    [d.x, d.y, v.z]
}

fn axpy(q: &[f64; 3], h: f64, d: &[f64; 3]) -> [f64; 3] {
    [q[0] + h * d[0], q[1] + h * d[1], q[2] + h * d[2]]
}

/// The object's flow over a step from `a` with pusher twist `xi` by pusher `p` (a point
/// pusher), `n` RK4 steps per tenth of L of the pusher's motion (metric length of `xi`). `None` when the pusher is not a point, the pad leaves the object or
/// the grasp cannot hold somewhere, or no rotation rate balances the moment.
pub fn flow(scene: &Scene, p: usize, a: &[f64; 3], xi: &Vec3, n: usize) -> Option<Flow> {
    let r = contact_point(scene, p)?;
    let model = &scene.pushers[p].model;
    // `n` steps per tenth of L of the pusher's motion (a unit step's at the planner's defaults)
    let tenths = (scene.metric().twist_norm(xi) / (0.1 * scene.length)).ceil().clamp(1.0, 1000.0);
    let n = n.max(1) * tenths as usize;
    let h = 1.0 / n as f64;
    let mut poses = Vec::with_capacity(n + 1);
    poses.push(*a);
    let (mut first_margin, mut margin) = (f64::INFINITY, f64::INFINITY);
    let mut q = *a;
    let mut phi = None;
    for k in 0..n {
        let t = k as f64 * h;
        let (v1, f) = rate(scene, &r, a, xi, t, &q, &mut phi)?;
        let m = f.classify(model, &v1).margin;
        if k == 0 { first_margin = m } else { margin = margin.min(m) }
        let k1 = pose_rate(&q, &v1);
        let q2 = axpy(&q, 0.5 * h, &k1);
        let k2 = pose_rate(&q2, &rate(scene, &r, a, xi, t + 0.5 * h, &q2, &mut phi)?.0);
        let q3 = axpy(&q, 0.5 * h, &k2);
        let k3 = pose_rate(&q3, &rate(scene, &r, a, xi, t + 0.5 * h, &q3, &mut phi)?.0);
        let q4 = axpy(&q, h, &k3);
        let k4 = pose_rate(&q4, &rate(scene, &r, a, xi, t + h, &q4, &mut phi)?.0);
        q = [0, 1, 2].map(|i| q[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]));
        poses.push(q);
    }
    (scene.admissible(&q) && scene.frame(&q).hold_ratio < 1.0).then_some(Flow { pusher: p, poses, first_margin, margin })
}

/// The step of point pusher `p` from `a` whose contact point moves with `u_b` (pusher frame,
/// m per unit time): the pusher twist `ξ = (u_b − ξ_ω r⊥, ξ_ω)` whose flow lands on `a·exp(ξ)`,
/// i.e. the root of `g(ξ_ω) = θ_end(ξ_ω) − θ_a − ξ_ω` by secant steps from the start's rotation
/// rate, on a flow of a quarter of the `n` steps first (at most 16 flows), and its flow. `None`
/// when a flow fails, the rotation does not settle within [`SETTLE_TOL`] or the flow does not
/// land within [`LANDING_TOL`].
pub fn steer(scene: &Scene, p: usize, a: &[f64; 3], ub: &Vec2, n: usize) -> Option<(Vec3, Flow)> {
    let r = contact_point(scene, p)?;
    let xi = |w: f64| {
        let lin = ub - perp(&r) * w;
        Vec3::new(lin.x, lin.y, w)
    };
    let mut w = scene.frame(a).point_twist(&r, ub, scene.length)?.z;
    // secant steps on a coarse flow (a quarter of the steps) first, then on the flow itself
    let coarse = (n / 4).max(2);
    let mut prev: Option<(f64, f64)> = None;
    let mut fine = coarse >= n;
    for _ in 0..16 {
        let fl = flow(scene, p, a, &xi(w), if fine { n } else { coarse })?;
        let end = fl.end();
        let g = end[2] - a[2] - w;
        if g.abs() <= if fine { SETTLE_TOL } else { 1e-3 * LANDING_TOL.max(SETTLE_TOL) } {
            if !fine {
                (fine, prev) = (true, None);
                continue;
            }
            // the rotation settled; the contact point lands by construction, to the integration's error
            let lands = distance(scene.length, &end, &integrate(a, &xi(w), 1.0)) <= 0.5 * LANDING_TOL * scene.length;
            return lands.then(|| (xi(w), fl));
        }
        let next = match prev {
            Some((w0, g0)) if (g - g0).abs() > 1e-300 => w - g * (w - w0) / (g - g0),
            _ => w + g, // the fixed-point step first
        };
        prev = Some((w, g));
        w = next;
        if !w.is_finite() {
            return None;
        }
    }
    None
}

/// Decides the step `a → b` of point pusher `p` with `n` integration steps: its flow's margins
/// and how far (metric distance over L) the flow ends from `b`. `None` when the flow fails.
pub fn check(scene: &Scene, p: usize, a: &[f64; 3], b: &[f64; 3], n: usize) -> Option<(Flow, f64)> {
    let xi = body_twist(a, b);
    let fl = flow(scene, p, a, &xi, n)?;
    let miss = distance(scene.length, &fl.end(), b) / scene.length;
    Some((fl, miss))
}

/// Two steps of point pushers from `a`: `p1` with contact velocity `x[0..2]`, then `p2` from
/// where it lands with `x[2..4]` (each in its pusher's frame): the pusher twists, the flows and
/// the poses reached.
fn two_steps(scene: &Scene, ps: [usize; 2], a: &[f64; 3], x: &[f64; 4], n: usize) -> Option<[(Vec3, Flow, [f64; 3]); 2]> {
    let (xi1, f1) = steer(scene, ps[0], a, &Vec2::new(x[0], x[1]), n)?;
    let mid = integrate(a, &xi1, 1.0);
    let (xi2, f2) = steer(scene, ps[1], &mid, &Vec2::new(x[2], x[3]), n)?;
    let end = integrate(&mid, &xi2, 1.0);
    Some([(xi1, f1, mid), (xi2, f2, end)])
}

/// A local planner for point pushers (issue 18, item 2): two steps of point pushers from `a`
/// to within `tol` (per component, m, m, rad) of `goal`. One step of a point pusher reaches
/// only a surface of poses (the rotation follows the contact velocity); two reach a
/// neighbourhood. Guesses from the linearized motion: the start's twists of each point
/// pusher's contact directions (32 around) with margin ≥ [`GUESS_MARGIN`] × `margin`, and the
/// pairs of them with non-negative speeds whose twists sum closest to the straight motion. The
/// best [`GUESSES`] are refined by [`refine`] on flows of a sixteenth of the `n` steps, then the
/// steps taken with `n` must end within `tol`; `accept` decides each flow. Returns the pushers
/// and both steps (pusher twist, flow, pose reached).
pub fn connect(
    scene: &Scene,
    pushers: &[usize],
    a: &[f64; 3],
    goal: &[f64; 3],
    tol: &[f64; 3],
    n: usize,
    margin: f64,
    accept: impl Fn(&Flow) -> bool,
) -> Option<([usize; 2], [(Vec3, Flow, [f64; 3]); 2])> {
    let m = scene.metric();
    let delta = m.twist(&body_twist(a, goal));
    let f = scene.frame(a);
    // (pusher, contact velocity direction, metric twist per unit contact speed)
    let mut dirs: Vec<(usize, Vec2, Vec3)> = Vec::new();
    for &p in pushers {
        let Some(r) = contact_point(scene, p) else { continue };
        for k in 0..32 {
            let d = Vec2::new((k as f64 * PI / 16.0).cos(), (k as f64 * PI / 16.0).sin());
            if let Some(v) = f.point_twist(&r, &d, scene.length) {
                if f.classify(&scene.pushers[p].model, &v).margin >= GUESS_MARGIN * margin {
                    dirs.push((p, d, m.twist(&v)));
                }
            }
        }
    }
    let mut guesses: Vec<(f64, [usize; 2], [f64; 4])> = Vec::new();
    for (p1, d1, v1) in &dirs {
        for (p2, d2, v2) in &dirs {
            // min |s1 v1 + s2 v2 − δ| over s ≥ 0 (both positive, else skipped)
            let g = nalgebra::Matrix2::new(v1.dot(v1), v1.dot(v2), v1.dot(v2), v2.dot(v2));
            let Some(gi) = g.try_inverse() else { continue };
            let sv = gi * nalgebra::Vector2::new(v1.dot(&delta), v2.dot(&delta));
            if !(sv.x > 0.0 && sv.y > 0.0) {
                continue;
            }
            let res = (v1 * sv.x + v2 * sv.y - delta).norm();
            guesses.push((res, [*p1, *p2], [d1.x * sv.x, d1.y * sv.x, d2.x * sv.y, d2.y * sv.y]));
        }
    }
    guesses.sort_by(|x, y| x.0.total_cmp(&y.0));
    guesses.into_iter().take(GUESSES).find_map(|(_, ps, x)| {
        // refined on flows of a sixteenth of the steps (one per tenth of L at the defaults), then
        // the steps themselves taken
        let x = refine(scene, ps, a, goal, tol, (n / 16).max(1), x)?;
        let st = two_steps(scene, ps, a, &x, n)?;
        let inside = (0..3).all(|k| (st[1].2[k] - goal[k]).abs() <= tol[k]);
        (inside && accept(&st[0].1) && accept(&st[1].1)).then_some((ps, st))
    })
}

/// How many linearized guesses [`connect`] refines.
pub const GUESSES: usize = 4;

/// A guess's contact directions lie this many times `margin` inside the pusher's cone at the
/// start: the refinement and the flow erode the margin (chosen on the point-pusher bench scene
/// over 60 seeds, before the refinement ran on coarse flows: 3x, 6x and 10x gave p90s of 110, 78
/// and 105 ms).
pub const GUESS_MARGIN: f64 = 6.0;

/// Gauss–Newton on the four contact-velocity components `x` of two steps (weighted
/// minimum-norm steps that prefer changing speeds to turning; a forward-difference Jacobian,
/// then Broyden's updates, fresh again when a step fails; halved until the miss shrinks; at most
/// 10 rounds) until the end lies within half of `tol` of `goal`; the contact velocities.
fn refine(scene: &Scene, ps: [usize; 2], a: &[f64; 3], goal: &[f64; 3], tol: &[f64; 3], n: usize, mut x: [f64; 4]) -> Option<[f64; 4]> {
    let l = scene.length;
    let miss = |end: &[f64; 3]| Vec3::new(end[0] - goal[0], end[1] - goal[1], l * (end[2] - goal[2]));
    let inside = |end: &[f64; 3]| (0..3).all(|k| (end[k] - goal[k]).abs() <= 0.5 * tol[k]);
    let mut steps = two_steps(scene, ps, a, &x, n)?;
    let mut e = miss(&steps[1].2);
    let mut jac: Option<nalgebra::Matrix3x4<f64>> = None;
    for _ in 0..10 {
        if inside(&steps[1].2) {
            return Some(x);
        }
        let j = match jac {
            Some(j) => j,
            None => {
                let h = 1e-5 * x.iter().fold(0.0f64, |m, v| m.max(v.abs())).max(1e-6);
                let mut j = nalgebra::Matrix3x4::zeros();
                for c in 0..4 {
                    let mut xc = x;
                    xc[c] += h;
                    j.set_column(c, &((miss(&two_steps(scene, ps, a, &xc, n)?[1].2) - e) / h));
                }
                j
            }
        };
        // weighted minimum-norm step: a contact velocity turns (which may lose the margin the
        // guess had) ~30x less readily than it changes speed (weight 1e-3 on the squared turn)
        let mut w = nalgebra::Matrix4::zeros();
        for i in 0..2 {
            let u = Vec2::new(x[2 * i], x[2 * i + 1]);
            let d = if u.norm() > 0.0 { u / u.norm() } else { Vec2::x() };
            let blk = d * d.transpose() + (nalgebra::Matrix2::identity() - d * d.transpose()) * 1e-3;
            w.fixed_view_mut::<2, 2>(2 * i, 2 * i).copy_from(&blk);
        }
        let dx = w * j.transpose() * (j * w * j.transpose()).try_inverse()? * (-e);
        let mut alpha = 1.0;
        let mut improved = false;
        for _ in 0..4 {
            let xt = [0, 1, 2, 3].map(|k| x[k] + alpha * dx[k]);
            if let Some(st) = two_steps(scene, ps, a, &xt, n) {
                let et = miss(&st[1].2);
                if et.norm() < e.norm() {
                    // Broyden's update of the Jacobian along the step taken
                    let s = nalgebra::Vector4::from(xt) - nalgebra::Vector4::from(x);
                    jac = Some(j + (et - e - j * s) * s.transpose() / s.norm_squared());
                    (x, steps, e, improved) = (xt, st, et, true);
                    break;
                }
            }
            alpha *= 0.5;
        }
        if !improved {
            if jac.is_none() {
                return None;
            }
            jac = None; // a fresh finite-difference Jacobian before giving up
        }
    }
    inside(&steps[1].2).then_some(x)
}

