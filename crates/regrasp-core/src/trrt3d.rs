//! T-RRT* over SE(3) object poses in the grasp, with unit steps propagated by the inverse
//! quasi-static complementarity dynamics (thesis §4.2).
//!
//! * **Metric**: `d(a, b) = √(‖p‖² + (L θ)²)` for the relative pose `a⁻¹b = (R, p)` with `θ` the
//!   angle of `R` and `L` the object's radius of gyration; neighbours are searched in a k-d tree
//!   on `[x, y, z, 2L q]` (`q` the unit quaternion with `q_w ≥ 0`; `2‖Δq‖ ≈ θ` for small angles),
//!   the candidates re-ranked with the exact metric.
//! * **Interpolation**: the constant body twist `ξ = log(a⁻¹b)` (screw motion; [`se3_log`] is
//!   the inverse of [`crate::quasistatic3d::integrate`]).
//! * **Unit step** (§4.2.1): from the nearest node towards the sample, a step of at most one unit
//!   length; for each pusher (evaluated in parallel) the inverse problem finds forces that make
//!   the object move with that twist with the pusher sticking — accepted only when the solve
//!   meets every constraint to 1e-6 — at the step's start and at `checks` poses along it, with
//!   both pads on the object. A point or edge contact does not fix the object's whole twist, and
//!   a line contact's feasible twists are a 5-D subset: then the forward problem (the pusher
//!   moving with the desired twist, 4 time steps) gives the motion the object makes, kept if the
//!   pusher keeps contact and the object heads within 60° of the target (the plan stores the
//!   pusher's twist, so a replay reproduces it). If no pusher can, random directions within 60° of the desired one are tried
//!   (the closest first).
//! * **Tree**: T-RRT transition test on the cost-to-go map ([`crate::trrt::Transition`]), RRT*
//!   choose-parent and rewiring with the switch-over edge cost (0.1 same pusher, 1 switch), a
//!   straight-push goal connection from each new node.

use crate::error::{Error, Result};
use crate::mncp;
use crate::quasistatic3d::{integrate, push_problem, simulate_push};
use crate::scene3d::{Scene3, V3};
use crate::tree::{edge_cost, pusher_order, switch_overs, Tree, TreeNode};
use crate::trrt::{stop_reason, Settings, StopReason, Transition};
use kiddo::{KdTree, SquaredEuclidean};
use nalgebra::{DVector, Isometry3, Matrix3, UnitQuaternion};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use std::time::Instant;

/// A body twist `[v, ω]` (unit time).
pub type Twist6 = [f64; 6];

fn skew(r: &V3) -> Matrix3<f64> {
    Matrix3::new(0.0, -r.z, r.y, r.z, 0.0, -r.x, -r.y, r.x, 0.0)
}

/// The constant body twist taking `a` to `b` in unit time: `log(a⁻¹b)` (inverse of
/// [`integrate`]).
pub fn se3_log(a: &Isometry3<f64>, b: &Isometry3<f64>) -> Twist6 {
    let rel = a.inverse() * b;
    let w = rel.rotation.scaled_axis();
    let th = w.norm();
    let wx = skew(&w);
    let (a_, b_) = if th < 1e-8 { (0.5 - th * th / 24.0, 1.0 / 6.0 - th * th / 120.0) } else {
        ((1.0 - th.cos()) / (th * th), (th - th.sin()) / (th * th * th))
    };
    let vmat = Matrix3::identity() + wx * a_ + wx * wx * b_;
    let v = vmat.try_inverse().unwrap_or_else(Matrix3::identity) * rel.translation.vector;
    [v.x, v.y, v.z, w.x, w.y, w.z]
}

/// The metric distance between two poses: `√(‖p‖² + (L θ)²)` of `a⁻¹b`.
pub fn distance(l: f64, a: &Isometry3<f64>, b: &Isometry3<f64>) -> f64 {
    let rel = a.inverse() * b;
    (rel.translation.vector.norm_squared() + (l * rel.rotation.angle()).powi(2)).sqrt()
}

/// Length of a body twist in the metric: `√(‖v‖² + (L‖ω‖)²)` (for small steps, ≈ the distance
/// it travels).
pub fn twist_length(l: f64, u: &Twist6) -> f64 {
    (u[0] * u[0] + u[1] * u[1] + u[2] * u[2] + l * l * (u[3] * u[3] + u[4] * u[4] + u[5] * u[5])).sqrt()
}

/// A node of the 3-D tree (see [`crate::tree`]); its `edge` is the pusher's body twist over the
/// step from the parent (unit time).
pub type Node3 = TreeNode<Isometry3<f64>, Twist6>;

/// The planner's answer.
#[derive(Clone, Debug)]
pub struct PlanResult3 {
    pub found: bool,
    pub stop_reason: StopReason,
    pub path: Vec<(Isometry3<f64>, Option<usize>)>,
    /// The pusher's body twist of each step (zero for the start).
    pub twists: Vec<Twist6>,
    pub nodes: usize,
    pub iterations: usize,
    pub planning_time_s: f64,
    pub switch_overs: usize,
    pub cost: f64,
    pub goal_distance: f64,
    /// Inverse-dynamics solves made (each a second-order cone program).
    pub solves: usize,
}

crate::trrt::impl_summary!(PlanResult3);

struct Planner3<'a> {
    scene: &'a Scene3,
    s: &'a Settings,
    l: f64,
    step: f64,
    goal: Isometry3<f64>,
    rng: ChaCha8Rng,
    nodes: Tree<Isometry3<f64>, Twist6>,
    tree: KdTree<f64, 7>,
    transition: Transition,
    solves: std::sync::atomic::AtomicUsize,
    /// The object's largest vertex distance from its frame.
    reach: f64,
}

fn key(l: f64, q: &Isometry3<f64>) -> [f64; 7] {
    let r = q.rotation.quaternion();
    let s = if r.w < 0.0 { -2.0 * l } else { 2.0 * l };
    [q.translation.x, q.translation.y, q.translation.z, s * r.w, s * r.i, s * r.j, s * r.k]
}

/// Whether both pads touch the object at `q` (a face: at least 6 of the pad's 8 ring points on
/// it; an edge or a vertex: itself).
pub fn pads_on(scene: &Scene3, q: &Isometry3<f64>) -> bool {
    let pads = scene.pad_contacts(q);
    pads.iter().all(|p| !p.is_empty() && (p.len() >= 6 || p.len() <= 2))
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
pub fn step_feasible(scene: &Scene3, q: &Isometry3<f64>, u: &Twist6, p: usize, checks: usize, solves: Option<&std::sync::atomic::AtomicUsize>) -> bool {
    if scene.pushers[p].plane {
        return false;
    }
    let n = checks.max(1);
    let v = DVector::from_row_slice(u);
    let settings = mncp::Settings::default();
    for k in 0..=n {
        let qk = if k == 0 { *q } else { integrate(q, u, k as f64 / n as f64) };
        if !pads_on(scene, &qk) {
            return false;
        }
        if k == n {
            break;
        }
        let Ok(prob) = push_problem(scene, &qk, p, 1.0) else { return false };
        if let Some(c) = solves {
            c.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
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
        let qk = crate::scene3d::pose_from_array("pose", &tr.pose[k]).ok()?;
        if !pads_on(scene, &qk) {
            return None;
        }
    }
    crate::scene3d::pose_from_array("pose", tr.pose.last()?).ok()
}

impl<'a> Planner3<'a> {
    fn dist(&self, a: &Isometry3<f64>, b: &Isometry3<f64>) -> f64 {
        distance(self.l, a, b)
    }

    fn cost_to_go(&self, q: &Isometry3<f64>) -> f64 {
        self.dist(q, &self.goal) / self.l
    }

    fn at_goal(&self, q: &Isometry3<f64>) -> bool {
        let rel = self.goal.inverse() * q;
        let t = self.scene.tolerance;
        let d = q.translation.vector - self.goal.translation.vector;
        d.x.abs() <= t[0] && d.y.abs() <= t[1] && d.z.abs() <= t[2] && rel.rotation.angle() <= t[3]
    }

    fn edge_cost(&self, parent_pusher: Option<usize>, pusher: usize, length: f64) -> f64 {
        let s = self.s;
        edge_cost(s.same_pusher_cost, s.switch_cost, s.length_weight, self.l, parent_pusher, pusher, length)
    }

    fn order(&self, first: Option<usize>) -> Vec<usize> {
        pusher_order(self.scene.pushers.len(), first)
    }

    /// The first pusher (in `order`) that can take step `u` from `q`, pushers evaluated in
    /// parallel, with the pose it reaches and the pusher's twist: `u` itself when the inverse
    /// problem accepts it along the step; else (a point or edge contact does not fix the
    /// object's whole twist, a twist feasible at the step's start may not stay so, a plane only
    /// rolls) the pose the forward dynamics reach while the pusher moves with
    /// [`pusher_motion`]`(u)` and keeps contact, if the motion still heads towards the target
    /// (within 60°).
    fn feasible_pusher(&self, q: &Isometry3<f64>, u: &Twist6, order: &[usize]) -> Option<(usize, Isometry3<f64>, Twist6)> {
        let l = self.l;
        let len = twist_length(l, u);
        // the first pusher in order that can (the later ones are not evaluated once it is known)
        order.par_iter().find_map_first(|&p| {
                if step_feasible(self.scene, q, u, p, self.s.checks, Some(&self.solves)) {
                    return Some((p, integrate(q, u, 1.0), *u));
                }
                self.solves.fetch_add(FORWARD_STEPS + 1, std::sync::atomic::Ordering::Relaxed);
                let up = pusher_motion(self.scene, q, p, u);
                let end = simulate_step(self.scene, q, &up, p, FORWARD_STEPS)?;
                let v = se3_log(q, &end);
                let vl = twist_length(l, &v);
                if vl < 0.2 * len {
                    return None;
                }
                let m = |x: &Twist6| [x[0], x[1], x[2], l * x[3], l * x[4], l * x[5]];
                let cos = m(&v).iter().zip(m(u).iter()).map(|(a, b)| a * b).sum::<f64>() / (vl * len);
                (cos >= 0.5).then_some((p, end, up))
        })
    }

    fn gauss(&mut self) -> f64 {
        let (u1, u2): (f64, f64) = (self.rng.random::<f64>().max(1e-300), self.rng.random());
        (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
    }

    /// A random pose near the start–goal region: translation within the object's reach, rotation
    /// a random interpolation between start and goal perturbed by up to `theta_margin`.
    fn sample(&mut self) -> Isometry3<f64> {
        if self.rng.random::<f64>() < self.s.goal_bias {
            return self.goal;
        }
        let start = self.nodes[0].q;
        let reach = self.reach;
        let t: f64 = self.rng.random();
        let rot = start.rotation.slerp(&self.goal.rotation, t);
        let ax = V3::new(self.gauss(), self.gauss(), self.gauss());
        let ang = self.s.theta_margin * self.rng.random::<f64>();
        let rot = UnitQuaternion::from_scaled_axis(ax.normalize() * ang) * rot;
        let c = (start.translation.vector + self.goal.translation.vector) * 0.5;
        let span = (start.translation.vector - self.goal.translation.vector).norm() + 0.5 * reach;
        let p = c + V3::new(self.rng.random_range(-1.0..1.0), self.rng.random_range(-1.0..1.0), self.rng.random_range(-1.0..1.0)) * span;
        Isometry3::from_parts(p.into(), rot)
    }

    /// Propagation by the inverse dynamics: the desired unit step, else up to `random_tries`
    /// directions within 60° of it (closest first).
    fn propagate(&mut self, near: usize, target: &Isometry3<f64>) -> Option<(Isometry3<f64>, usize, Twist6)> {
        // returns the new pose, the pusher and the pusher's twist
        let q = self.nodes[near].q;
        let xi = se3_log(&q, target);
        let len = twist_length(self.l, &xi);
        if len < 1e-12 {
            return None;
        }
        let scale = self.step.min(len) / len;
        let want: Twist6 = xi.map(|x| x * scale);
        let order = self.order(self.nodes[near].pusher);
        if let Some((p, end, up)) = self.feasible_pusher(&q, &want, &order) {
            return Some((end, p, up));
        }
        // random directions around the desired one, in the metric's coordinates
        let wl = twist_length(self.l, &want);
        let m = |u: &Twist6| [u[0], u[1], u[2], self.l * u[3], self.l * u[4], self.l * u[5]];
        let d: Vec<f64> = m(&want).iter().map(|x| x / wl).collect();
        let mut cands: Vec<(f64, Twist6)> = Vec::with_capacity(self.s.random_tries);
        for _ in 0..self.s.random_tries {
            let mut r: Vec<f64> = (0..6).map(|_| self.gauss()).collect();
            let dot: f64 = r.iter().zip(&d).map(|(a, b)| a * b).sum();
            for (x, y) in r.iter_mut().zip(&d) {
                *x -= dot * y;
            }
            let nr = r.iter().map(|x| x * x).sum::<f64>().sqrt().max(1e-12);
            let ang = self.rng.random_range(0.0..std::f64::consts::FRAC_PI_3);
            let dir: Vec<f64> = d.iter().zip(&r).map(|(a, b)| ang.cos() * a + ang.sin() * b / nr).collect();
            let u = [dir[0], dir[1], dir[2], dir[3] / self.l, dir[4] / self.l, dir[5] / self.l].map(|x| x * wl);
            cands.push((ang, u));
        }
        cands.sort_by(|a, b| a.0.total_cmp(&b.0));
        for (_, u) in cands {
            if let Some((p, end, up)) = self.feasible_pusher(&q, &u, &order) {
                return Some((end, p, up));
            }
        }
        None
    }

    fn add(&mut self, q: Isometry3<f64>, parent: usize, pusher: usize, cost: f64, twist: Twist6) -> usize {
        let i = self.nodes.add(q, parent, pusher, cost, twist);
        self.tree.add(&key(self.l, &q), i as u64);
        i
    }

    fn near(&self, q: &Isometry3<f64>, r: f64) -> Vec<usize> {
        self.tree
            .within::<SquaredEuclidean>(&key(self.l, q), (1.5 * r) * (1.5 * r))
            .iter()
            .map(|n| n.item as usize)
            .filter(|&k| self.dist(&self.nodes[k].q, q) <= r)
            .collect()
    }

    fn choose_parent(&self, q: &Isometry3<f64>, near: usize, pusher: usize, len: f64, twist: Twist6) -> (usize, usize, f64, Twist6) {
        let mut best = (near, pusher, self.nodes[near].cost + self.edge_cost(self.nodes[near].pusher, pusher, len), twist);
        if self.s.neighbour_steps <= 0.0 {
            return best;
        }
        let r = self.s.neighbour_steps * self.step;
        for k in self.near(q, r) {
            if k == near {
                continue;
            }
            let qk = self.nodes[k].q;
            let u = se3_log(&qk, q);
            let l = twist_length(self.l, &u);
            for p in self.order(self.nodes[k].pusher) {
                let c = self.nodes[k].cost + self.edge_cost(self.nodes[k].pusher, p, l);
                if c < best.2 - 1e-12 && step_feasible(self.scene, &qk, &u, p, self.s.checks, Some(&self.solves)) {
                    best = (k, p, c, u);
                    break;
                }
            }
        }
        best
    }

    fn rewire(&mut self, i: usize) {
        if self.s.neighbour_steps <= 0.0 {
            return;
        }
        let r = self.s.neighbour_steps * self.step;
        let qi = self.nodes[i].q;
        for k in self.near(&qi, r) {
            if k == i || Some(k) == self.nodes[i].parent || self.nodes[k].parent.is_none() {
                continue;
            }
            let Some(pk) = self.nodes[k].pusher else { continue };
            let u = se3_log(&qi, &self.nodes[k].q);
            let c = self.nodes[i].cost + self.edge_cost(self.nodes[i].pusher, pk, twist_length(self.l, &u));
            if c < self.nodes[k].cost - 1e-12
                && !self.nodes.is_ancestor(k, i)
                && step_feasible(self.scene, &qi, &u, pk, self.s.checks, Some(&self.solves))
            {
                self.nodes.reparent(k, i, c, u);
            }
        }
    }

    /// Rolling to the goal from node `i` with a plane pusher (whose pushes are forward-dynamics
    /// steps, never exact): unit steps re-aimed at the goal after each, at most `n + 4`, kept if
    /// the goal is reached (within its tolerance) while each step closes in on it. A position
    /// already within the tolerance is not chased (the aim is then the goal's orientation only:
    /// rolling moves the object's centre as a side effect).
    fn connect_goal_rolling(&mut self, i: usize, n: usize) -> Option<usize> {
        let q0 = self.nodes[i].q;
        let planes: Vec<usize> = self.order(self.nodes[i].pusher).into_iter().filter(|&p| self.scene.pushers[p].plane).collect();
        let found = planes.par_iter().find_map_first(|&p| {
            let (mut q, mut steps) = (q0, Vec::new());
            for _ in 0..n + 4 {
                let d = q.translation.vector - self.goal.translation.vector;
                let t = self.scene.tolerance;
                let aim = if d.x.abs() <= t[0] && d.y.abs() <= t[1] && d.z.abs() <= t[2] {
                    Isometry3::from_parts(q.translation, self.goal.rotation)
                } else {
                    self.goal
                };
                let xi = se3_log(&q, &aim);
                let len = twist_length(self.l, &xi);
                let u: Twist6 = xi.map(|x| x * self.step.min(len) / len.max(1e-300));
                let up = pusher_motion(self.scene, &q, p, &u);
                self.solves.fetch_add(FORWARD_STEPS + 1, std::sync::atomic::Ordering::Relaxed);
                let end = simulate_step(self.scene, &q, &up, p, FORWARD_STEPS)?;
                if self.dist(&end, &self.goal) >= self.dist(&q, &self.goal) {
                    return None;
                }
                steps.push((end, up));
                q = end;
                if self.at_goal(&q) {
                    return Some((p, steps));
                }
            }
            None
        })?;
        let (p, steps) = found;
        let (mut last, mut prev) = (i, q0);
        for (q, up) in steps {
            let c = self.nodes[last].cost + self.edge_cost(self.nodes[last].pusher, p, self.dist(&prev, &q));
            last = self.add(q, last, p, c, up);
            prev = q;
        }
        Some(last)
    }

    /// Straight push to the goal from node `i` (unit steps of one constant twist, one pusher);
    /// when no pusher can take it (and it is at most 20 steps), rolling with a plane
    /// ([`Self::connect_goal_rolling`]).
    fn connect_goal(&mut self, i: usize) -> Option<usize> {
        let q = self.nodes[i].q;
        let xi = se3_log(&q, &self.goal);
        let len = twist_length(self.l, &xi);
        if len < 1e-12 {
            return None;
        }
        let n = (len / self.step).ceil().max(1.0) as usize;
        if n > 100 {
            return None;
        }
        let u: Twist6 = xi.map(|x| x / n as f64);
        let order = self.order(self.nodes[i].pusher);
        let ok: Vec<bool> = order
            .par_iter()
            .map(|&p| {
                let mut qk = q;
                for _ in 0..n {
                    if !step_feasible(self.scene, &qk, &u, p, self.s.checks, Some(&self.solves)) {
                        return false;
                    }
                    qk = integrate(&qk, &u, 1.0);
                }
                true
            })
            .collect();
        let Some(p) = order.iter().zip(ok).find(|(_, o)| *o).map(|(p, _)| *p) else {
            return if n <= 20 { self.connect_goal_rolling(i, n) } else { None };
        };
        let d = len / n as f64;
        let (mut last, mut qk) = (i, q);
        for k in 0..n {
            qk = if k + 1 == n { self.goal } else { integrate(&qk, &u, 1.0) };
            let c = self.nodes[last].cost + self.edge_cost(self.nodes[last].pusher, p, d);
            last = self.add(qk, last, p, c, u);
        }
        Some(last)
    }

}

/// Plans a 3-D regrasp from `start` to `goal` (defaults: the scene's task). Uses the planar
/// planner's settings: `step` (default L/5), `checks` (default 16, here capped at 4 poses per
/// step), `random_tries`, `theta_margin`, T-RRT and RRT* parameters, budgets, `connect`.
pub fn plan3(scene: &Scene3, start: Option<Isometry3<f64>>, goal: Option<Isometry3<f64>>, settings: &Settings) -> Result<PlanResult3> {
    let start = start.unwrap_or(scene.start);
    let goal = goal.unwrap_or(scene.goal);
    for (name, q) in [("start", &start), ("goal", &goal)] {
        if !pads_on(scene, q) {
            return Err(Error::arg(name, "the finger pads do not both touch the object there"));
        }
    }
    settings.check()?;
    let l = scene.length;
    let step = settings.step.unwrap_or(0.2 * l);
    if !(step > 0.0) {
        return Err(Error::arg("step", "must be positive"));
    }
    let s3 = Settings { checks: settings.checks.min(4), ..settings.clone() };
    let mut pl = Planner3 {
        scene,
        s: &s3,
        l,
        step,
        goal,
        rng: ChaCha8Rng::seed_from_u64(settings.seed),
        nodes: Tree::new(start, [0.0; 6]),
        tree: KdTree::new(),
        transition: Transition::new(settings, 0.0),
        solves: std::sync::atomic::AtomicUsize::new(0),
        reach: scene.size(),
    };
    pl.transition.c_max = settings.c_max * pl.cost_to_go(&start).max(1.0);
    pl.tree.add(&key(l, &start), 0);
    let t0 = Instant::now();
    let mut best: Option<usize> = if pl.at_goal(&start) { Some(0) } else { None };
    if best.is_none() && settings.connect {
        best = pl.connect_goal(0);
    }
    let mut closest = best.unwrap_or(0);
    let mut iterations = 0;
    let stop = loop {
        if let Some(r) = stop_reason(settings, best.map(|g| pl.nodes[g].cost), &t0, pl.nodes.len(), iterations) {
            break r;
        }
        iterations += 1;
        let target = pl.sample();
        let near = pl.tree.nearest_n::<SquaredEuclidean>(&key(l, &target), 8)
            .iter()
            .map(|n| n.item as usize)
            .min_by(|&a, &b| pl.dist(&pl.nodes[a].q, &target).total_cmp(&pl.dist(&pl.nodes[b].q, &target)))
            .unwrap_or(0);
        let Some((q_new, pusher, u)) = pl.propagate(near, &target) else { continue };
        // the object's motion (u is the pusher's, which differs for forward-dynamics steps)
        let len = pl.dist(&pl.nodes[near].q, &q_new);
        if pl.tree.nearest_one::<SquaredEuclidean>(&key(l, &q_new)).distance <= (1e-9 * l).powi(2) {
            continue;
        }
        let (c_near, c_new) = (pl.cost_to_go(&pl.nodes[near].q), pl.cost_to_go(&q_new));
        if !pl.transition.test(&mut pl.rng, c_near, c_new, len / l) {
            continue;
        }
        let (parent, p, cost, tw) = pl.choose_parent(&q_new, near, pusher, len, u);
        let i = pl.add(q_new, parent, p, cost, tw);
        pl.rewire(i);
        if pl.cost_to_go(&q_new) < pl.cost_to_go(&pl.nodes[closest].q) {
            closest = i;
        }
        if pl.at_goal(&q_new) {
            pl.nodes.keep_cheaper(&mut best, i);
        } else if let Some(g) = if settings.connect { pl.connect_goal(i) } else { None } {
            pl.nodes.keep_cheaper(&mut best, g);
        }
    };
    // rewiring may have made another goal node the cheapest
    if best.is_some() {
        best = pl.nodes.cheapest(|q| pl.at_goal(q));
    }
    let end = best.unwrap_or(closest);
    let full = pl.nodes.path_to(end);
    let switch_overs = switch_overs(&full);
    let twists: Vec<Twist6> = full.iter().map(|x| x.2).collect();
    let path: Vec<(Isometry3<f64>, Option<usize>)> = full.into_iter().map(|x| (x.0, x.1)).collect();
    Ok(PlanResult3 {
        twists,
        found: best.is_some(),
        stop_reason: if best.is_some() { StopReason::GoalReached } else { stop },
        goal_distance: pl.dist(&path.last().expect("path").0, &goal),
        cost: pl.nodes[end].cost,
        path,
        nodes: pl.nodes.len(),
        iterations,
        planning_time_s: t0.elapsed().as_secs_f64(),
        switch_overs,
        solves: pl.solves.load(std::sync::atomic::Ordering::Relaxed),
    })
}

/// Checks a 3-D path: for each step, whether its pusher can take it — the inverse problem along
/// the constant twist between the poses (8 poses), or, given the pusher's twist of the step, the
/// forward dynamics with the pusher sticking reach the next pose (within 1e-6 m / L). An error
/// names a step without a valid pusher.
pub fn validate_path3(scene: &Scene3, path: &[(Isometry3<f64>, Option<usize>)], twists: Option<&[Twist6]>) -> Result<Vec<bool>> {
    path.windows(2)
        .enumerate()
        .map(|(i, w)| {
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
        let r = plan3(&s, None, None, &Settings { seed: 0, time_limit: 20.0, ..Settings::default() }).unwrap();
        assert!(r.found, "{:?}", r.stop_reason);
        let ok = validate_path3(&s, &r.path, Some(&r.twists)).unwrap();
        assert!(ok.iter().all(|x| *x), "{ok:?}");
        for (k, u) in r.twists.iter().enumerate().skip(1) {
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
