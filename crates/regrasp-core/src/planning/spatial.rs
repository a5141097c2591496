//! The spatial space of the T-RRT* ([`crate::planning::trrt`]): SE(3) object poses in the grasp,
//! with unit steps propagated by the inverse quasi-static complementarity dynamics (thesis §4.2).
//!
//! * **Metric**: `d(a, b) = √(‖p‖² + (L θ)²)` for the relative pose `a⁻¹b = (R, p)` with `θ` the
//!   angle of `R` and `L` the object's radius of gyration; neighbours are searched in a k-d tree
//!   on `[x, y, z, 2L q]` (`q` the unit quaternion with `q_w ≥ 0`; `2‖Δq‖ ≈ θ` for small angles),
//!   the candidates re-ranked with the exact metric.
//! * **Interpolation**: the constant body twist `ξ = log(a⁻¹b)` (screw motion, [`crate::pose::spatial`]).
//! * **Unit step** (§4.2.1): from the nearest node towards the sample, a step of at most one unit
//!   length; for each pusher (evaluated in parallel) the inverse problem finds forces that make
//!   the object move with that twist with the pusher sticking — accepted only when the solve
//!   meets every constraint to 1e-6 — at the step's start and at `checks` poses along it, with
//!   both pads on the object. A point or edge contact does not fix the object's whole twist, and
//!   a line contact's feasible twists are a 5-D subset: then the forward problem (the pusher
//!   moving with the desired twist, 4 time steps) gives the motion the object makes, kept if the
//!   pusher keeps contact and the object heads within 60° of the target (the plan stores the
//!   pusher's twist, so a replay reproduces it). If no pusher can, random directions within 60°
//!   of the desired one are tried (the closest first).
//! * **Goal connection**: a straight push, or rolling with a plane pusher.

use crate::dynamics::mncp;
use crate::dynamics::spatial::{push_problem, simulate_push};
use crate::error::{Error, Result};
use crate::planning::tree::pusher_order;
use crate::planning::trrt::{self, gauss, one_pusher, Chain, SearchSettings, Space, SpaceCore, Step};
use crate::pose::spatial::{distance, integrate, log as se3_log, twist_length, Twist6, V3};
use crate::scene::spatial::Scene3;
use nalgebra::{DVector, Isometry3, UnitQuaternion};
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Settings of the spatial planner (defaults in [`SpatialSettings::default`]; the unit step
/// defaults to a fifth of L).
#[derive(Clone, Debug)]
pub struct SpatialSettings {
    pub search: SearchSettings,
}

impl Default for SpatialSettings {
    fn default() -> Self {
        Self {
            search: SearchSettings {
                max_nodes: 5000,
                goal_bias: 0.3,
                checks: 4,
                neighbour_steps: 1.5,
                random_tries: 6,
                ..SearchSettings::default()
            },
        }
    }
}

/// A spatial plan: poses, the pusher reaching each and the pusher's body twist of the step
/// (zero for the start), with the number of inverse-dynamics solves made.
#[derive(Clone, Debug)]
pub struct SpatialPlan {
    pub plan: trrt::Plan<Isometry3<f64>, Twist6>,
    /// Inverse-dynamics solves made (each a second-order cone program).
    pub solves: usize,
}

fn key(l: f64, q: &Isometry3<f64>) -> [f64; 7] {
    let r = q.rotation.quaternion();
    let s = if r.w < 0.0 { -2.0 * l } else { 2.0 * l };
    [q.translation.x, q.translation.y, q.translation.z, s * r.w, s * r.i, s * r.j, s * r.k]
}

/// The motion (body twist, object frame at `q`) of pusher `p` that makes the object follow `u`
/// where they touch: a rigid pusher moves with `u` (it sticks); a plane rolls the object — it
/// translates with the velocity of the object's contact point and turns only about its own
/// normal, so it stays parallel to itself in the gripper frame (a floor stays level), and it
/// presses into the object at least [`PLANE_PRESS`] of its sliding speed (a plane sliding
/// along a held object leaves the contact force undetermined: the rigid model admits zero).
pub fn pusher_motion(scene: &Scene3, q: &Isometry3<f64>, p: usize, u: &Twist6) -> Twist6 {
    if !scene.pushers[p].plane {
        return *u;
    }
    let (pts, n) = scene.pusher_contacts(p, q);
    let c = pts.iter().sum::<V3>() / pts.len().max(1) as f64;
    let (v, w) = (V3::new(u[0], u[1], u[2]), V3::new(u[3], u[4], u[5]));
    let wn = n * n.dot(&w);
    let vc = v + w.cross(&c);
    let vt = vc - n * n.dot(&vc);
    let vc = vt + n * n.dot(&vc).max(PLANE_PRESS * vt.norm());
    let lin = vc - wn.cross(&c);
    [lin.x, lin.y, lin.z, wn.x, wn.y, wn.z]
}

/// The least speed a plane pusher presses into the object, relative to its sliding speed.
pub const PLANE_PRESS: f64 = 0.05;

/// Time steps of a forward-dynamics step (the planner's and the path check's, so they agree).
pub const FORWARD_STEPS: usize = 4;

/// Whether pusher `p` can move the object with body twist `u` (unit time) from `q`: the inverse
/// problem solves (pusher sticking) at the start and at `checks` poses along the step, both pads
/// on the object all along. Never for a plane: its steps are forward ones
/// ([`pusher_motion`]; a plane sliding with the object leaves its contact force undetermined).
pub fn step_feasible(scene: &Scene3, q: &Isometry3<f64>, u: &Twist6, p: usize, checks: usize, solves: Option<&AtomicUsize>) -> bool {
    if scene.pushers[p].plane {
        return false;
    }
    let n = checks.max(1);
    let v = DVector::from_row_slice(u);
    let settings = mncp::Settings::default();
    for k in 0..=n {
        let qk = if k == 0 { *q } else { integrate(q, u, k as f64 / n as f64) };
        if !scene.pads_on(&qk) {
            return false;
        }
        if k == n {
            break;
        }
        let Ok(prob) = push_problem(scene, &qk, p, 1.0) else { return false };
        if let Some(c) = solves {
            c.fetch_add(1, Ordering::Relaxed);
        }
        if mncp::solve_inverse(&prob, &v, &settings).is_err() {
            return false;
        }
    }
    true
}

/// The pose the object reaches when pusher `p` moves with body twist `u` for unit time from `q`
/// (the forward problem, `n` time steps, every solve meeting its constraints to 1e-6), if the
/// pusher keeps contact all along (it may slide: the plan replays the same pusher motion) and
/// both pads stay on the object.
pub fn simulate_step(scene: &Scene3, q: &Isometry3<f64>, u: &Twist6, p: usize, n: usize) -> Option<Isometry3<f64>> {
    let tr = simulate_push(scene, q, p, u, 1.0, 1.0 / n.max(1) as f64, &mncp::Settings::default()).ok()?;
    for k in 0..tr.t.len() {
        if tr.pusher_contacts[k] == 0 {
            return None;
        }
        let qk = crate::scene::spatial::pose_from_array("pose", &tr.pose[k]).ok()?;
        if !scene.pads_on(&qk) {
            return None;
        }
    }
    crate::scene::spatial::pose_from_array("pose", tr.pose.last()?).ok()
}


/// The spatial space: a scene, a goal, the settings and a count of the solves made.
pub struct SpatialSpace<'a> {
    core: SpaceCore<Isometry3<f64>>,
    scene: &'a Scene3,
    s: &'a SpatialSettings,
    solves: AtomicUsize,
}

impl<'a> SpatialSpace<'a> {
    fn l(&self) -> f64 {
        self.scene.length
    }

    fn checks(&self) -> usize {
        self.s.search.checks
    }

    /// Whether `u` is an exact step of pusher `p` (inverse problem along it), counting solves
    /// in `solves`.
    fn exact(&self, q: &Isometry3<f64>, u: &Twist6, p: usize, solves: &AtomicUsize) -> bool {
        step_feasible(self.scene, q, u, p, self.checks(), Some(solves))
    }

    /// `f(p, solves)` of the pushers `order`, evaluated in parallel: the first (in `order`) that
    /// gives `Some`. The solves counted are those of the pushers up to that one (all of them
    /// when none does), as a sequential search would make: whatever work the parallel search
    /// did beyond it is not counted, so the count depends on the seed only.
    fn first_pusher<T: Send>(&self, order: &[usize], f: impl Fn(usize, &AtomicUsize) -> Option<T> + Sync) -> Option<T> {
        let counts: Vec<AtomicUsize> = order.iter().map(|_| AtomicUsize::new(0)).collect();
        let found = order.par_iter().enumerate().find_map_first(|(i, &p)| f(p, &counts[i]).map(|t| (i, t)));
        let upto = found.as_ref().map_or(order.len(), |(i, _)| i + 1);
        self.solves.fetch_add(counts[..upto].iter().map(|c| c.load(Ordering::Relaxed)).sum(), Ordering::Relaxed);
        found.map(|(_, t)| t)
    }

    /// The first pusher (in `order`) that can take step `u` from `q`, pushers evaluated in
    /// parallel, with the pose it reaches and the pusher's twist: `u` itself when the inverse
    /// problem accepts it along the step; else (a point or edge contact does not fix the
    /// object's whole twist, a twist feasible at the step's start may not stay so, a plane only
    /// rolls) the pose the forward dynamics reach while the pusher moves with
    /// [`pusher_motion`]`(u)` and keeps contact, if the motion still heads towards the target
    /// (within 60°).
    fn feasible_pusher(&self, q: &Isometry3<f64>, u: &Twist6, order: &[usize]) -> Option<Step<Isometry3<f64>, Twist6>> {
        let l = self.l();
        let len = twist_length(l, u);
        self.first_pusher(order, |p, solves| {
            if self.exact(q, u, p, solves) {
                let end = integrate(q, u, 1.0);
                return Some(Step { length: distance(l, q, &end), q: end, pusher: p, edge: *u });
            }
            solves.fetch_add(FORWARD_STEPS + 1, Ordering::Relaxed);
            let up = pusher_motion(self.scene, q, p, u);
            let end = simulate_step(self.scene, q, &up, p, FORWARD_STEPS)?;
            let v = se3_log(q, &end);
            let vl = twist_length(l, &v);
            if vl < 0.2 * len {
                return None;
            }
            let m = |x: &Twist6| [x[0], x[1], x[2], l * x[3], l * x[4], l * x[5]];
            let cos = m(&v).iter().zip(m(u).iter()).map(|(a, b)| a * b).sum::<f64>() / (vl * len);
            (cos >= 0.5).then(|| Step { length: distance(l, q, &end), q: end, pusher: p, edge: up })
        })
    }

    /// Up to `random_tries` unit twists within 60° of `want` in the metric's coordinates,
    /// the closest first.
    fn random_directions(&self, rng: &mut ChaCha8Rng, want: &Twist6) -> Vec<Twist6> {
        let l = self.l();
        let wl = twist_length(l, want);
        let m = |u: &Twist6| [u[0], u[1], u[2], l * u[3], l * u[4], l * u[5]];
        let d: Vec<f64> = m(want).iter().map(|x| x / wl).collect();
        let mut cands: Vec<(f64, Twist6)> = Vec::with_capacity(self.s.search.random_tries);
        for _ in 0..self.s.search.random_tries {
            let mut r: Vec<f64> = (0..6).map(|_| gauss(rng)).collect();
            let dot: f64 = r.iter().zip(&d).map(|(a, b)| a * b).sum();
            for (x, y) in r.iter_mut().zip(&d) {
                *x -= dot * y;
            }
            let nr = r.iter().map(|x| x * x).sum::<f64>().sqrt().max(1e-12);
            let ang = rng.random_range(0.0..std::f64::consts::FRAC_PI_3);
            let dir: Vec<f64> = d.iter().zip(&r).map(|(a, b)| ang.cos() * a + ang.sin() * b / nr).collect();
            cands.push((ang, [dir[0], dir[1], dir[2], dir[3] / l, dir[4] / l, dir[5] / l].map(|x| x * wl)));
        }
        cands.sort_by(|a, b| a.0.total_cmp(&b.0));
        cands.into_iter().map(|c| c.1).collect()
    }

    /// Rolling to the goal from `q0` with a plane pusher (whose pushes are forward-dynamics
    /// steps, never exact): unit steps re-aimed at the goal after each, at most `n + 4`, kept if
    /// the goal is reached (within its inner tolerance) while each step closes in on it, or, when
    /// they stop short of it, if they end within the task's tolerance (the search then decides,
    /// [`trrt::plan_tree`]). A position already within the task's tolerance is not chased (the aim
    /// is then the goal's orientation only: rolling moves the object's centre as a side effect).
    fn connect_rolling(&self, q0: &Isometry3<f64>, pusher: Option<usize>, n: usize) -> Option<(usize, Vec<(Isometry3<f64>, Twist6, f64)>)> {
        let planes: Vec<usize> = pusher_order(self.scene.pushers.len(), pusher).into_iter().filter(|&p| self.scene.pushers[p].plane).collect();
        self.first_pusher(&planes, |p, solves| {
            let (mut q, mut steps) = (*q0, Vec::new());
            for _ in 0..n + 4 {
                let aim = if self.within_position(&q, 1.0) { Isometry3::from_parts(q.translation, self.core.goal.rotation) } else { self.core.goal };
                let xi = se3_log(&q, &aim);
                let len = twist_length(self.l(), &xi);
                let u: Twist6 = xi.map(|x| x * self.core.step.min(len) / len.max(1e-300));
                let up = pusher_motion(self.scene, &q, p, &u);
                solves.fetch_add(FORWARD_STEPS + 1, Ordering::Relaxed);
                let Some(end) = simulate_step(self.scene, &q, &up, p, FORWARD_STEPS) else { break };
                if self.dist(&end, &self.core.goal) >= self.dist(&q, &self.core.goal) {
                    break;
                }
                steps.push((end, up, self.dist(&q, &end)));
                q = end;
                if self.at_goal(&q) {
                    return Some((p, steps));
                }
            }
            (!steps.is_empty() && self.within_task(&q)).then_some((p, steps))
        })
    }

    /// Whether the position of `q` is within `share` of the goal's tolerance.
    fn within_position(&self, q: &Isometry3<f64>, share: f64) -> bool {
        let d = q.translation.vector - self.core.goal.translation.vector;
        let t = self.scene.tolerance.map(|t| t * share);
        d.x.abs() <= t[0] && d.y.abs() <= t[1] && d.z.abs() <= t[2]
    }

    /// Whether `q` is within `share` of the goal's tolerance (position and angle).
    fn in_goal_region(&self, q: &Isometry3<f64>, share: f64) -> bool {
        self.within_position(q, share) && (self.core.goal.inverse() * q).rotation.angle() <= self.scene.tolerance[3] * share
    }
}

impl Space<7> for SpatialSpace<'_> {
    type Q = Isometry3<f64>;
    type Edge = Twist6;
    type Motion = Twist6;

    fn core(&self) -> &SpaceCore<Isometry3<f64>> {
        &self.core
    }
    fn root_edge(&self) -> Twist6 {
        [0.0; 6]
    }
    fn key(&self, q: &Isometry3<f64>) -> [f64; 7] {
        key(self.l(), q)
    }
    fn dist(&self, a: &Isometry3<f64>, b: &Isometry3<f64>) -> f64 {
        distance(self.l(), a, b)
    }
    fn at_goal(&self, q: &Isometry3<f64>) -> bool {
        self.in_goal_region(q, self.s.search.goal_share)
    }
    fn within_task(&self, q: &Isometry3<f64>) -> bool {
        self.in_goal_region(q, 1.0)
    }
    /// A random pose near the start–goal region: translation within the object's reach, rotation
    /// a random interpolation between start and goal perturbed by up to `theta_margin`.
    fn sample(&self, rng: &mut ChaCha8Rng, start: &Isometry3<f64>, _closest: &Isometry3<f64>) -> Isometry3<f64> {
        let t: f64 = rng.random();
        let rot = start.rotation.slerp(&self.core.goal.rotation, t);
        let ax = V3::new(gauss(rng), gauss(rng), gauss(rng));
        let ang = self.s.search.theta_margin * rng.random::<f64>();
        let rot = UnitQuaternion::from_scaled_axis(ax.normalize() * ang) * rot;
        let c = (start.translation.vector + self.core.goal.translation.vector) * 0.5;
        let span = (start.translation.vector - self.core.goal.translation.vector).norm() + 0.5 * self.scene.size();
        let p = c + V3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0)) * span;
        Isometry3::from_parts(p.into(), rot)
    }
    /// The desired unit step, else up to `random_tries` directions within 60° of it.
    fn propagate(&self, rng: &mut ChaCha8Rng, q: &Isometry3<f64>, pusher: Option<usize>, target: &Isometry3<f64>) -> Option<Step<Isometry3<f64>, Twist6>> {
        let xi = se3_log(q, target);
        let len = twist_length(self.l(), &xi);
        if len < 1e-12 {
            return None;
        }
        let want: Twist6 = xi.map(|x| x * self.core.step.min(len) / len);
        let order = pusher_order(self.scene.pushers.len(), pusher);
        if let Some(s) = self.feasible_pusher(q, &want, &order) {
            return Some(s);
        }
        self.random_directions(rng, &want).iter().find_map(|u| self.feasible_pusher(q, u, &order))
    }
    fn interpolate(&self, a: &Isometry3<f64>, b: &Isometry3<f64>) -> (Twist6, f64) {
        let u = se3_log(a, b);
        (u, twist_length(self.l(), &u))
    }
    fn take(&self, a: &Isometry3<f64>, u: &Twist6, p: usize) -> Option<Twist6> {
        self.exact(a, u, p, &self.solves).then_some(*u)
    }
    /// Straight push to the goal (unit steps of one constant twist, one pusher, at most 100);
    /// when no pusher can take it (and it is at most 20 steps), rolling with a plane.
    fn connect_goal(&self, q: &Isometry3<f64>, pusher: Option<usize>) -> Option<Chain<Isometry3<f64>, Twist6>> {
        let xi = se3_log(q, &self.core.goal);
        let len = twist_length(self.l(), &xi);
        if len < 1e-12 {
            return None;
        }
        let n = (len / self.core.step).ceil().max(1.0) as usize;
        if n > 100 {
            return None;
        }
        let u: Twist6 = xi.map(|x| x / n as f64);
        let poses: Vec<Isometry3<f64>> = (1..=n).map(|k| if k == n { self.core.goal } else { integrate(q, &u, k as f64) }).collect();
        let order = pusher_order(self.scene.pushers.len(), pusher);
        let ok: Vec<bool> = order
            .par_iter()
            .map(|&p| std::iter::once(q).chain(poses.iter().take(n - 1)).all(|qk| self.exact(qk, &u, p, &self.solves)))
            .collect();
        let Some(p) = order.iter().zip(ok).find(|(_, o)| *o).map(|(p, _)| *p) else {
            return if n <= 20 { self.connect_rolling(q, pusher, n).map(|(p, c)| one_pusher(p, c)) } else { None };
        };
        Some(one_pusher(p, poses.into_iter().map(|qk| (qk, u, len / n as f64)).collect()))
    }
    fn nearest_candidates(&self) -> usize {
        8
    }
    fn key_slack(&self) -> f64 {
        1.5
    }
    /// Neighbours by the metric distance of the poses (the key's search radius is 1.5 r).
    fn within(&self, a: &Isometry3<f64>, b: &Isometry3<f64>, _len: f64, r: f64) -> bool {
        self.dist(a, b) <= r
    }
}

/// Plans a 3-D regrasp from `start` to `goal` (defaults: the scene's task).
pub fn plan3(scene: &Scene3, start: Option<Isometry3<f64>>, goal: Option<Isometry3<f64>>, settings: &SpatialSettings) -> Result<SpatialPlan> {
    let start = start.unwrap_or(scene.start);
    let goal = goal.unwrap_or(scene.goal);
    for (name, q) in [("start", &start), ("goal", &goal)] {
        if !scene.pads_on(q) {
            return Err(Error::arg(name, "the finger pads do not both touch the object there"));
        }
    }
    settings.search.check()?;
    let t0 = std::time::Instant::now();
    if let Some(reason) = crate::planning::reachability::cannot_hold3(scene, &start, &goal, &scene.tolerance) {
        let plan = trrt::Plan {
            found: false,
            stop_reason: trrt::StopReason::Unreachable,
            path: vec![(start, None, [0.0; 6])],
            nodes: 1,
            iterations: 0,
            planning_time_s: t0.elapsed().as_secs_f64(),
            switch_overs: 0,
            cost: 0.0,
            goal_distance: distance(scene.length, &start, &goal),
            reason: Some(reason),
            first: None,
        };
        return Ok(SpatialPlan { plan, solves: 0 });
    }
    let step = settings.search.step.unwrap_or(0.2 * scene.length);
    let core = SpaceCore { search: settings.search.clone(), length: scene.length, step, pushers: scene.pushers.len(), goal };
    let space = SpatialSpace { core, scene, s: settings, solves: AtomicUsize::new(0) };
    let before = t0.elapsed().as_secs_f64(); // the certificate counts as planning time
    let mut plan = trrt::plan(&space, start)?;
    plan.planning_time_s += before;
    if let Some(f) = plan.first.as_mut() {
        f.planning_time_s += before;
    }
    Ok(SpatialPlan { plan, solves: space.solves.load(Ordering::Relaxed) })
}

/// Checks a 3-D path: for each step, whether its pusher can take it — the inverse problem along
/// the constant twist between the poses (8 poses), or, given the pusher's twist of the step, the
/// forward dynamics with the pusher sticking reach the next pose (within 1e-6 m / L). An error
/// names a step without a valid pusher.
pub fn validate_path3(scene: &Scene3, path: &[(Isometry3<f64>, Option<usize>)], twists: Option<&[Twist6]>) -> Result<Vec<bool>> {
    path.windows(2)
        .enumerate()
        .map(|(i, w)| {
            crate::interrupt::check()?;
            let p = w[1].1.ok_or_else(|| Error::arg(format!("path[{}].pusher", i + 1), "is missing"))?;
            if p >= scene.pushers.len() {
                return Err(Error::arg(format!("path[{}].pusher", i + 1), "is not a pusher of the scene"));
            }
            if step_feasible(scene, &w[0].0, &se3_log(&w[0].0, &w[1].0), p, 8, None) {
                return Ok(true);
            }
            let Some(u) = twists.and_then(|t| t.get(i + 1)) else { return Ok(false) };
            Ok(simulate_step(scene, &w[0].0, u, p, FORWARD_STEPS).is_some_and(|end| distance(scene.length, &end, &w[1].0) < 1e-6))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use nalgebra::Translation3;

    #[test]
    fn log_inverts_integrate_and_the_metric_is_invariant() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        for _ in 0..200 {
            let a = Isometry3::from_parts(
                Translation3::new(rng.random_range(-0.1..0.1), rng.random_range(-0.1..0.1), rng.random_range(-0.1..0.1)),
                UnitQuaternion::from_scaled_axis(V3::new(rng.random_range(-2.0..2.0), rng.random_range(-2.0..2.0), rng.random_range(-2.0..2.0))),
            );
            let u: Twist6 = std::array::from_fn(|_| rng.random_range(-1.0..1.0));
            let b = integrate(&a, &u, 1.0);
            let back = se3_log(&a, &b);
            if V3::new(u[3], u[4], u[5]).norm() < 3.0 {
                for k in 0..6 {
                    assert!((back[k] - u[k]).abs() < 1e-9, "{back:?} vs {u:?}");
                }
            }
            // interpolation reaches b; the metric is left-invariant and symmetric
            let c = integrate(&a, &back, 1.0);
            assert!(distance(0.05, &b, &c) < 1e-9);
            let g = Isometry3::from_parts(Translation3::new(0.3, -0.2, 0.1), UnitQuaternion::from_scaled_axis(V3::new(0.4, 1.0, -0.3)));
            let (d1, d2) = (distance(0.05, &a, &b), distance(0.05, &(g * a), &(g * b)));
            assert!((d1 - d2).abs() < 1e-9 && (d1 - distance(0.05, &b, &a)).abs() < 1e-9);
            // and it is sqrt(|p|^2 + (L theta)^2) of the relative pose, theta from the rotation
            // matrix's trace (an independent formula: cos theta = (tr R - 1) / 2)
            let rel = a.inverse() * b;
            let r = rel.rotation.to_rotation_matrix();
            let th = ((r.matrix().trace() - 1.0) / 2.0).clamp(-1.0, 1.0).acos();
            let want = (rel.translation.vector.norm_squared() + (0.05 * th).powi(2)).sqrt();
            assert!((d1 - want).abs() < 1e-7, "{d1} vs {want}");
        }
    }

    /// The rolling ball example: a plan of floor pushes (forward-dynamics steps with the floor
    /// level), every step valid.
    #[test]
    fn the_ball_is_rolled_to_the_goal() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/ball-roll-3d.toml");
        let s = Scene3::load(&path).unwrap();
        let mut settings = SpatialSettings::default();
        settings.search.time_limit = 20.0;
        let r = plan3(&s, None, None, &settings).unwrap().plan;
        assert!(r.found, "{:?}", r.stop_reason);
        let path = r.poses();
        let twists: Vec<Twist6> = r.path.iter().map(|x| x.2).collect();
        let ok = validate_path3(&s, &path, Some(&twists)).unwrap();
        assert!(ok.iter().all(|x| *x), "{ok:?}");
        for (k, u) in twists.iter().enumerate().skip(1) {
            // the floor never tilts: it turns about its normal (the gripper's Z) at most
            let n = r.path[k - 1].0.rotation.inverse() * V3::z();
            let w = V3::new(u[3], u[4], u[5]);
            assert!((w - n * n.dot(&w)).norm() < 1e-12, "step {k}: {u:?}");
        }
    }

    #[test]
    fn key_distance_approximates_the_metric() {
        let l = 0.05;
        let a = Isometry3::identity();
        for ang in [0.01, 0.05, 0.1] {
            let b = Isometry3::from_parts(Translation3::new(0.001, 0.0, 0.0), UnitQuaternion::from_scaled_axis(V3::new(0.0, ang, 0.0)));
            let (ka, kb) = (key(l, &a), key(l, &b));
            let dk = ka.iter().zip(&kb).map(|(x, y)| (x - y).powi(2)).sum::<f64>().sqrt();
            let d = distance(l, &a, &b);
            assert!((dk - d).abs() < 0.01 * d, "{dk} vs {d}");
        }
        // q and −q are the same rotation
        let r = UnitQuaternion::from_scaled_axis(V3::new(0.0, 3.1, 0.0));
        let b = Isometry3::from_parts(Translation3::identity(), r);
        let c = Isometry3::from_parts(Translation3::identity(), UnitQuaternion::new_unchecked(-r.into_inner()));
        assert_eq!(key(l, &b), key(l, &c));
    }
}
