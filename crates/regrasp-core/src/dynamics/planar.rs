//! Planar scenes as complementarity problems ([`crate::dynamics::mncp`]), one push at a time, and the
//! explicit time stepping of long pushes (thesis §3.2.3).
//!
//! The finger pads become rigid sets of points carrying fixed shares of the grip force
//! (uniform or Hertzian pressure over the pad, eq 3.5); a pusher is its one or two points with
//! unilateral contact and Coulomb friction; the object's mass matrix over the step enters the
//! Newton–Euler equation (eq 3.13). Twists are in the object frame, as for the motion cones, so
//! a pusher moving with twist `U` sticks exactly when the object moves with `V = U`.

use crate::error::{Error, Result};
pub use crate::pose::planar::{integrate, relative};
use crate::pose::planar::twist_in;
use crate::mechanics::geometry::{cross2, perp, rot, Vec2, Vec3};
use crate::mechanics::limit_surface::{Pressure, PressureDistribution};
use crate::dynamics::mncp::{self, Contact, ContactState, FrictionLaw, NormalLaw, Problem, Settings, Side, Solution};
use crate::scene::planar::{PadShape, Scene, Support};
use nalgebra::{DMatrix, DVector};

/// Most time steps one simulated push may take (a typo in `dt` must not run for hours).
pub const MAX_STEPS: f64 = 1e6;

/// How the support (finger pads, or the surface under the object) enters the problem.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SupportModel {
    /// Rigid sets of points with fixed shares of the normal force: `rings` rings of 6, 12, 18…
    /// points (or `points` on one ring when `rings == 0`). `merge_fingers` puts both pads'
    /// points together (they coincide in the plane) instead of listing each finger.
    Points { rings: usize, points: usize, merge_fingers: bool },
    /// One contact whose friction wrench lies in the scene's ellipsoidal limit surface (the
    /// model the motion cones use; for cross-checks).
    LimitSurface,
}

impl Default for SupportModel {
    fn default() -> Self {
        SupportModel::Points { rings: 3, points: 0, merge_fingers: true }
    }
}

/// Options of the quasi-static model.
#[derive(Clone, Copy, Debug)]
pub struct Options {
    pub support: SupportModel,
    /// Time step [s] of the quasi-dynamic term `M/h` (a unit step for instantaneous solves).
    pub h: f64,
    /// Typical speed [m/s] for scaling residuals.
    pub speed: f64,
    pub settings: Settings,
}

impl Default for Options {
    fn default() -> Self {
        Self { support: SupportModel::default(), h: 1.0, speed: 0.01, settings: Settings::default() }
    }
}

/// Points of a pad (pad frame, centred) and their shares of the normal force (sum 1).
pub fn pad_points(pad: &PadShape, pressure: Pressure, rings: usize, points: usize) -> Vec<(Vec2, f64)> {
    match pad {
        PadShape::Circle { radius } => {
            let r = *radius;
            let weight = |rho: f64| match pressure {
                Pressure::Uniform => 1.0,
                Pressure::Hertzian => (1.0 - (rho / r).powi(2)).max(0.0).sqrt(),
            };
            let mut out = Vec::new();
            if rings == 0 {
                // one ring of `points` at the pressure-weighted mean radius (matching the pad's
                // largest friction moment)
                let dist = PressureDistribution::circle(r, pressure, 80);
                let mean: f64 = dist.cells.iter().map(|(p, w)| p.norm() * w).sum();
                let k = points.max(1);
                for i in 0..k {
                    let a = 2.0 * std::f64::consts::PI * (i as f64 + 0.5) / k as f64;
                    out.push((Vec2::new(a.cos(), a.sin()) * mean, 1.0 / k as f64));
                }
                return out;
            }
            // annuli of equal width, 6j points on ring j at the annulus' weighted mean radius
            let n = rings;
            let sub = 200;
            let mut total = 0.0;
            for j in 1..=n {
                let (b0, b1) = (r * (j - 1) as f64 / n as f64, r * j as f64 / n as f64);
                let (mut mass, mut moment) = (0.0, 0.0);
                for s in 0..sub {
                    let rho = b0 + (b1 - b0) * (s as f64 + 0.5) / sub as f64;
                    let dm = weight(rho) * rho;
                    mass += dm;
                    moment += dm * rho;
                }
                let rho = moment / mass;
                let m = 6 * j;
                for i in 0..m {
                    let a = 2.0 * std::f64::consts::PI * (i as f64 + 0.5 * (j % 2) as f64) / m as f64;
                    out.push((Vec2::new(a.cos(), a.sin()) * rho, mass / m as f64));
                }
                total += mass;
            }
            for p in &mut out {
                p.1 /= total;
            }
            out
        }
        PadShape::Rectangle { width, height } => {
            let n = (rings.max(1) * 2 + 1).max(3);
            PressureDistribution::rectangle(*width, *height, n).cells
        }
    }
}

/// The planar scene at pose `q` with pusher `pusher` (its points at `points` with gaps
/// `gaps`, object frame; `normal` the direction it pushes, object frame) as a problem.
pub fn planar_problem(
    scene: &Scene,
    q: &[f64; 3],
    pusher: Option<(f64, &[Vec2], &[f64], Vec2)>,
    opts: &Options,
) -> Result<Problem> {
    let d = 3;
    let h = opts.h;
    let mut contacts = Vec::new();
    let r_t = rot(-q[2]);
    let c_pad = -(r_t * Vec2::new(q[0], q[1]));
    let tangent_rows = |r: &Vec2| DMatrix::from_row_slice(2, 3, &[1.0, 0.0, -r.y, 0.0, 1.0, r.x]);
    let frame = scene.frame(q);
    match (&scene.support, opts.support) {
        (_, SupportModel::LimitSurface) => {
            let a = frame.a;
            contacts.push(Contact {
                label: "support".into(),
                side: Side::Finger,
                normal: NormalLaw::Fixed(scene.friction_scale()),
                friction: FrictionLaw::Ellipsoid(DMatrix::from_fn(3, 3, |i, j| a[(i, j)])),
                jn: DVector::zeros(d),
                jt: DMatrix::from_fn(3, 3, |i, j| frame.js[(i, j)]),
                jn_other: DVector::zeros(d),
                jt_other: DMatrix::zeros(3, 3),
                gap: 0.0,
            });
        }
        (Support::Grasp(g), SupportModel::Points { rings, points, merge_fingers }) => {
            let pts = pad_points(&g.pad, g.pressure, rings, points);
            let fingers = if merge_fingers { 1 } else { 2 };
            let share = 2.0 * g.force / fingers as f64;
            for f in 0..fingers {
                for (k, (p, w)) in pts.iter().enumerate() {
                    // pad point in the gripper frame → object frame
                    let r = c_pad + r_t * p;
                    contacts.push(Contact {
                        label: format!("finger{f}[{k}]"),
                        side: Side::Finger,
                        normal: NormalLaw::Fixed(share * w),
                        friction: FrictionLaw::Coulomb(g.friction),
                        jn: DVector::zeros(d),
                        jt: tangent_rows(&r),
                        jn_other: DVector::zeros(d),
                        jt_other: DMatrix::zeros(2, d),
                        gap: 0.0,
                    });
                }
            }
        }
        (Support::Surface(s), SupportModel::Points { rings, .. }) => {
            let n = (rings.max(1) * 6).max(6);
            let dist = PressureDistribution::polygon(&scene.outline, &s.cop, n);
            let total = scene.mass * scene.g * s.incline.cos();
            for (k, (p, w)) in dist.cells.iter().enumerate() {
                let r = s.cop + p;
                contacts.push(Contact {
                    label: format!("surface[{k}]"),
                    side: Side::Fixed,
                    normal: NormalLaw::Fixed(total * w),
                    friction: FrictionLaw::Coulomb(s.friction),
                    jn: DVector::zeros(d),
                    jt: tangent_rows(&r),
                    jn_other: DVector::zeros(d),
                    jt_other: DMatrix::zeros(2, d),
                    gap: 0.0,
                });
            }
        }
    }
    if let Some((mu, points, gaps, normal)) = pusher {
        let n = normal.normalize();
        let t = perp(&n);
        for (k, (r, gap)) in points.iter().zip(gaps).enumerate() {
            let jn = DVector::from_row_slice(&[n.x, n.y, cross2(r, &n)]);
            let jt = DMatrix::from_row_slice(1, 3, &[t.x, t.y, cross2(r, &t)]);
            contacts.push(Contact {
                label: format!("pusher[{k}]"),
                side: Side::Pusher,
                normal: NormalLaw::Unilateral,
                friction: FrictionLaw::Coulomb(mu),
                jn_other: jn.clone(),
                jt_other: jt.clone(),
                jn,
                jt,
                gap: *gap,
            });
        }
    }
    // mass matrix about the object-frame origin, over the step
    let m = scene.mass;
    let c = scene.com;
    let i_c = m * scene.length * scene.length;
    let mass = DMatrix::from_row_slice(
        3,
        3,
        &[m, 0.0, -m * c.y, 0.0, m, m * c.x, -m * c.y, m * c.x, i_c + m * c.norm_squared()],
    ) / h;
    let wg = frame.gravity;
    let force_scale = scene.friction_scale() + scene.mass * scene.g;
    Ok(Problem {
        dim: d,
        mass,
        wrench: DVector::from_row_slice(wg.as_slice()),
        contacts,
        h,
        force_scale,
        velocity_scale: opts.speed,
        length: scene.length,
    })
}

/// The problem of pusher `pusher` of the scene at pose `q`, in contact at its scene points.
pub fn push_problem(scene: &Scene, q: &[f64; 3], pusher: usize, opts: &Options) -> Result<Problem> {
    scene.check_pose(q)?;
    let p = scene.pushers.get(pusher).ok_or_else(|| Error::arg("pusher", format!("index {pusher} out of range")))?;
    let gaps = vec![0.0; p.contact.points.len()];
    planar_problem(scene, q, Some((p.contact.friction, &p.contact.points, &gaps, p.contact.normal)), opts)
}

/// Outcome of one instantaneous push.
#[derive(Clone, Debug)]
pub struct PushOutcome {
    /// Every pusher point sticks (the object moves rigidly with the pusher).
    pub sticks: bool,
    pub solution: Solution,
}

/// Pusher contacts of a solution.
fn pusher_states(p: &Problem, s: &Solution) -> Vec<ContactState> {
    p.contacts.iter().zip(&s.states).filter(|(c, _)| c.side == Side::Pusher).map(|(_, st)| *st).collect()
}

/// One instantaneous push: pusher `pusher` at pose `q` moving with twist `u` (object frame).
pub fn push_outcome(scene: &Scene, q: &[f64; 3], pusher: usize, u: &Vec3, opts: &Options) -> Result<PushOutcome> {
    let p = push_problem(scene, q, pusher, opts)?;
    let sol = mncp::solve_forward(&p, &DVector::from_row_slice(u.as_slice()), &opts.settings)?;
    let sticks = pusher_states(&p, &sol).iter().all(|s| *s == ContactState::Stick);
    Ok(PushOutcome { sticks, solution: sol })
}

/// A recorded push, one row per step.
#[derive(Clone, Debug, Default)]
pub struct Trajectory {
    pub t: Vec<f64>,
    /// Object pose in the gripper frame.
    pub pose: Vec<[f64; 3]>,
    /// Pusher pose in the gripper frame (its frame coincides with the object's at the start).
    pub pusher_pose: Vec<[f64; 3]>,
    /// Object twist (object frame) over the step.
    pub twist: Vec<[f64; 3]>,
    /// Pusher forces on the object (sum, object frame) and largest slip speed at a pusher point.
    pub pusher_wrench: Vec<[f64; 3]>,
    pub pusher_slip: Vec<f64>,
    /// Contact points in contact with the pusher, and how many of them stick.
    pub pusher_contacts: Vec<usize>,
    pub pusher_sticking: Vec<usize>,
    /// Total friction wrench of the support on the object (object frame).
    pub support_wrench: Vec<[f64; 3]>,
    /// Largest scaled constraint residual of the step.
    pub residual: Vec<f64>,
}

/// Simulates a push: the pusher starts in contact at its scene points with the object at `q0`
/// and moves with constant body twist `u` (its frame coincides with the object frame at the
/// start) for `duration` seconds, in steps of `dt` (explicit time stepping). Contact points
/// move with the pusher; a point whose gap exceeds `reach` leaves the problem.
pub fn simulate_push(
    scene: &Scene,
    q0: &[f64; 3],
    pusher: usize,
    u: &Vec3,
    duration: f64,
    dt: f64,
    opts: &Options,
) -> Result<Trajectory> {
    if !(dt > 0.0) || !(duration >= 0.0) || !duration.is_finite() {
        return Err(Error::arg("dt", "time step and duration must be positive and finite"));
    }
    if duration / dt > MAX_STEPS {
        return Err(Error::arg("dt", format!("{:.0} time steps asked for (duration / dt); at most {MAX_STEPS:.0}", duration / dt)));
    }
    scene.check_pose(q0)?;
    let pz = scene.pushers.get(pusher).ok_or_else(|| Error::arg("pusher", format!("index {pusher} out of range")))?;
    let steps = (duration / dt).round() as usize;
    let opts = Options { h: dt, ..*opts };
    let mut traj = Trajectory::default();
    let (mut q, mut qp) = (*q0, *q0);
    let reach = 0.002 + 2.0 * dt * (Vec2::new(u.x, u.y).norm() + u.z.abs() * scene.length);
    for k in 0..=steps {
        let t = k as f64 * dt;
        // pusher points and normal in the object frame
        let rel = relative(&q, &qp);
        let pr = rot(rel[2]);
        let off = Vec2::new(rel[0], rel[1]);
        let normal = pr * pz.contact.normal;
        let mut pts = Vec::new();
        let mut gaps = Vec::new();
        for p in &pz.contact.points {
            let r = pr * p + off;
            let gap = -scene.outline.signed_distance(&r);
            if gap < reach {
                pts.push(r);
                gaps.push(gap);
            }
        }
        if !scene.admissible(&q) {
            return Err(Error::arg(
                "push",
                format!("after {t:.3} s the finger pad leaves the object (pose {q:?}): the push goes too far"),
            ));
        }
        let prob = planar_problem(scene, &q, Some((pz.contact.friction, &pts, &gaps, normal)), &opts)?;
        let uo = twist_in(&rel, u);
        let sol = mncp::solve_forward(&prob, &DVector::from_row_slice(uo.as_slice()), &opts.settings)
            .map_err(|e| Error::arg("push", format!("at t = {t:.3} s: {e}")))?;
        let v = Vec3::new(sol.twist[0], sol.twist[1], sol.twist[2]);
        let (mut wp, mut ws) = (Vec3::zeros(), Vec3::zeros());
        let (mut slip, mut n_contact, mut n_stick) = (0.0f64, 0, 0);
        for (i, c) in prob.contacts.iter().enumerate() {
            let f = &c.jn * sol.normal_forces[i] + c.jt.transpose() * &sol.friction_forces[i];
            let f = Vec3::new(f[0], f[1], f[2]);
            if c.side == Side::Pusher {
                wp += f;
                if sol.states[i] != ContactState::Separate {
                    n_contact += 1;
                    slip = slip.max(sol.tangent_velocities[i].norm());
                    n_stick += (sol.states[i] == ContactState::Stick) as usize;
                }
            } else {
                ws += f;
            }
        }
        traj.t.push(t);
        traj.pose.push(q);
        traj.pusher_pose.push(qp);
        traj.twist.push([v.x, v.y, v.z]);
        traj.pusher_wrench.push([wp.x, wp.y, wp.z]);
        traj.support_wrench.push([ws.x, ws.y, ws.z]);
        traj.pusher_slip.push(slip);
        traj.pusher_contacts.push(n_contact);
        traj.pusher_sticking.push(n_stick);
        traj.residual.push(sol.residuals.max());
        if k < steps {
            q = integrate(&q, &v, dt);
            qp = integrate(&qp, u, dt);
        }
    }
    Ok(traj)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn block() -> Scene {
        Scene::from_toml_str(include_str!("../../../../examples/block-low-friction.toml")).unwrap()
    }

    #[test]
    fn pad_points_sum_to_one_and_match_the_moment_of_the_pad() {
        let pts = pad_points(&PadShape::Circle { radius: 0.01 }, Pressure::Uniform, 3, 0);
        assert_eq!(pts.len(), 6 + 12 + 18);
        assert!((pts.iter().map(|p| p.1).sum::<f64>() - 1.0).abs() < 1e-12);
        // largest friction moment of a uniform disc: 2/3 μ N r
        let m: f64 = pts.iter().map(|(p, w)| p.norm() * w).sum();
        assert!((m - 2.0 / 3.0 * 0.01).abs() < 2e-5, "{m}");
        let ring = pad_points(&PadShape::Circle { radius: 0.01 }, Pressure::Uniform, 0, 4);
        assert_eq!(ring.len(), 4);
        assert!((ring[0].0.norm() - 2.0 / 3.0 * 0.01).abs() < 1e-4);
    }

    #[test]
    fn limit_surface_support_reproduces_the_motion_cone_exactly() {
        let s = block();
        let opts = Options { support: SupportModel::LimitSurface, ..Options::default() };
        let q = [0.004, -0.006, 0.2];
        let i = s.pusher_index("left").unwrap();
        let cone = s.push(&q, i).unwrap();
        let mut checked = 0;
        for k in 0..200 {
            let a = k as f64 * 0.7;
            let v = Vec3::new(a.cos() * 0.01, (a * 1.3).sin() * 0.01, (a * 0.37).sin() / s.length * 0.01);
            let c = cone.classify(&v).unwrap();
            if c.margin.abs() < 1e-6 {
                continue;
            }
            let out = match push_outcome(&s, &q, i, &v, &opts) {
                Ok(o) => o,
                Err(e) => panic!("twist {v:?} margin {} limit {:?}: {e}", c.margin, c.limit),
            };
            assert_eq!(out.sticks, c.feasible, "twist {v:?}, margin {}", c.margin);
            checked += 1;
        }
        assert!(checked > 150);
    }

    #[test]
    fn horizontal_push_drifts_down_under_gravity() {
        let s = block();
        let i = s.pusher_index("left").unwrap();
        let traj = simulate_push(&s, &[0.0, 0.0, 0.0], i, &Vec3::new(0.01, 0.0, 0.0), 1.0, 0.05, &Options::default()).unwrap();
        let last = traj.pose.last().unwrap();
        assert!((last[0] - 0.01).abs() < 1e-3, "moves with the pusher: {last:?}");
        assert!(traj.residual.iter().all(|r| *r < 1e-6));
    }

    #[test]
    fn integrate_is_the_exponential_map() {
        let q = integrate(&[0.0, 0.0, 0.0], &Vec3::new(0.0, 0.0, std::f64::consts::PI), 1.0);
        assert!((q[2] - std::f64::consts::PI).abs() < 1e-12 && q[0].abs() < 1e-12);
        // a circle of radius 1: v = 1, ω = 1 for π/2 → (1, 1)
        let q = integrate(&[0.0, 0.0, 0.0], &Vec3::new(1.0, 0.0, 1.0), std::f64::consts::FRAC_PI_2);
        assert!((q[0] - 1.0).abs() < 1e-12 && (q[1] - 1.0).abs() < 1e-12);
    }
}
