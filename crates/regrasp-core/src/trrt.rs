//! T-RRT* regrasp planner over object poses in the grasp (thesis §4.1, §4.3; RSS 2018).
//!
//! * **Configuration space**: poses `q = [x, z, θ]` where the finger pad lies on the object and
//!   the grasp holds it. **Metric**: `d(q, q')² = Δx² + Δz² + (L Δθ)²` (L: the object's radius
//!   of gyration), the same weighting of rotation against translation as the motion cones.
//! * **Configuration cost**: distance to the goal (`d(q, goal)/L`, dimensionless).
//! * **Transition test** (T-RRT, Jaillet et al. 2010): a new node more costly than its parent is
//!   kept with probability `exp(−(Δc/δ)/(K T))` (δ: the step's length over L); the temperature
//!   `T` falls after an uphill acceptance and rises by `α` after `n_fail` rejections in a row.
//! * **RRT*** choose-parent and rewire with the edge cost of RSS 2018 (0.1 when the pusher stays,
//!   1 on a switch-over) plus the step's length over L; rewiring keeps the rewired node's pusher,
//!   so the costs of its subtree shift by the same amount and stay consistent.
//! * **Unit-step propagation** (Fig 4-9), by [`Propagation`]: the motion cones (the desired step
//!   is taken when some pusher's exact cone contains it, else projected on each cone and the
//!   closest kept, preferring the parent's pusher); or the baselines — random steps kept when a
//!   force-balance feasibility LP passes (ICRA 2018 "stable check"), or the inverse quasi-static
//!   complementarity dynamics (thesis §4.2.1).
//! * Every accepted step is checked along its length by the exact motion-cone test (`checks`
//!   poses), so that a plan's steps are feasible, not only at their start.

use crate::error::{Error, Result};
use crate::geometry::{rot, Vec2, Vec3};
use crate::mncp;
use crate::motion_cone::{project_with_margin, SupportFrame};
use crate::quasistatic::{self, integrate, Options as QsOptions, SupportModel};
use crate::scene::Scene;
use crate::tree::{edge_cost, pusher_order, switch_overs, Tree, TreeNode};
use kiddo::{KdTree, SquaredEuclidean};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::time::Instant;

/// How a unit step is propagated.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Propagation {
    /// Projection on the exact motion cones (this library).
    MotionCone,
    /// Random steps kept when a force-balance LP with a sticking pusher is feasible.
    StableCheck,
    /// The inverse quasi-static complementarity dynamics (point-set pads).
    Mncp,
}

impl Propagation {
    pub fn parse(s: &str) -> Result<Self> {
        match s {
            "motion_cone" | "motion-cone" => Ok(Self::MotionCone),
            "stable_check" | "stable-check" => Ok(Self::StableCheck),
            "mncp" => Ok(Self::Mncp),
            _ => Err(Error::arg("propagation", format!("must be motion_cone, stable_check or mncp (got {s:?})"))),
        }
    }
    pub fn label(&self) -> &'static str {
        match self {
            Self::MotionCone => "motion_cone",
            Self::StableCheck => "stable_check",
            Self::Mncp => "mncp",
        }
    }
}

/// Planner settings (defaults in [`Settings::default`]).
#[derive(Clone, Debug)]
pub struct Settings {
    pub seed: u64,
    /// Wall-clock budget [s].
    pub time_limit: f64,
    pub max_nodes: usize,
    pub max_iterations: usize,
    pub goal_bias: f64,
    /// Length of a unit step in the metric [m]; `None`: a tenth of L.
    pub step: Option<f64>,
    /// Smallest margin of the exact test at the start of an accepted step.
    pub margin: f64,
    /// Poses checked along each step.
    pub checks: usize,
    /// T-RRT: cost scale K, initial temperature, factor α, failures before heating.
    pub k: f64,
    pub t0: f64,
    pub alpha: f64,
    pub n_fail: usize,
    /// Nodes costlier than this (in units of the start's cost) are rejected.
    pub c_max: f64,
    /// RRT*: neighbour radius in steps; 0 disables choose-parent and rewiring.
    pub neighbour_steps: f64,
    pub same_pusher_cost: f64,
    pub switch_cost: f64,
    /// Weight of the path length (per L of length) in the edge cost.
    pub length_weight: f64,
    /// Stop at the first path to the goal whose cost is at most this (∞: the first).
    pub cost_threshold: f64,
    pub propagation: Propagation,
    /// Random directions tried per step by the stable-check propagation.
    pub random_tries: usize,
    /// Bounds of θ explored: the start and goal angles widened by this [rad].
    pub theta_margin: f64,
    /// Try to reach the goal from each new node by a straight push (constant body twist, unit
    /// steps), with the node's pusher first.
    pub connect: bool,
    /// A plain goal-biased RRT (no transition test, no RRT*, no preference for the parent's
    /// pusher, no straight-push connection): the reference for the switch-over count.
    pub plain: bool,
}

impl Settings {
    /// Checks every setting (NaN, negative or absurd values are errors naming the setting).
    pub fn check(&self) -> Result<()> {
        let finite_nonneg = |name: &str, v: f64| {
            if v.is_finite() && v >= 0.0 { Ok(()) } else { Err(Error::arg(name, format!("must be a finite, non-negative number (got {v})"))) }
        };
        let positive = |name: &str, v: f64| {
            if v.is_finite() && v > 0.0 { Ok(()) } else { Err(Error::arg(name, format!("must be a finite, positive number (got {v})"))) }
        };
        finite_nonneg("time_limit", self.time_limit)?;
        if !(0.0..=1.0).contains(&self.goal_bias) {
            return Err(Error::arg("goal_bias", format!("must be in [0, 1] (got {})", self.goal_bias)));
        }
        if let Some(step) = self.step {
            positive("step", step)?;
        }
        finite_nonneg("margin", self.margin)?;
        for (name, v) in [("k", self.k), ("t0", self.t0), ("c_max", self.c_max)] {
            positive(name, v)?;
        }
        if !(self.alpha.is_finite() && self.alpha >= 1.0) {
            return Err(Error::arg("alpha", format!("must be a finite factor >= 1 (got {})", self.alpha)));
        }
        for (name, v) in [("neighbour_steps", self.neighbour_steps), ("same_pusher_cost", self.same_pusher_cost),
                          ("switch_cost", self.switch_cost), ("length_weight", self.length_weight), ("theta_margin", self.theta_margin)] {
            finite_nonneg(name, v)?;
        }
        if self.cost_threshold.is_nan() {
            return Err(Error::arg("cost_threshold", "is NaN"));
        }
        for (name, v, hi) in [("checks", self.checks, 10_000), ("random_tries", self.random_tries, 10_000),
                              ("max_nodes", self.max_nodes, 100_000_000)] {
            if v == 0 && name != "random_tries" || v > hi {
                return Err(Error::arg(name, format!("must be between 1 and {hi} (got {v})")));
            }
        }
        Ok(())
    }
}

impl Default for Settings {
    fn default() -> Self {
        Self {
            seed: 0,
            time_limit: 10.0,
            max_nodes: 20_000,
            max_iterations: 200_000,
            goal_bias: 0.2,
            step: None,
            margin: 0.01,
            checks: 16,
            k: 1.0,
            t0: 0.1,
            alpha: 2.0,
            n_fail: 10,
            c_max: 3.0,
            neighbour_steps: 2.0,
            same_pusher_cost: 0.1,
            switch_cost: 1.0,
            length_weight: 1.0,
            cost_threshold: f64::INFINITY,
            propagation: Propagation::MotionCone,
            random_tries: 8,
            theta_margin: 0.5,
            connect: true,
            plain: false,
        }
    }
}

/// A node of the planar tree (see [`crate::tree`]).
pub type Node = TreeNode<[f64; 3], ()>;

/// What every planner's answer reports besides its path (planar and 3-D).
#[derive(Clone, Copy, Debug)]
pub struct Summary {
    pub found: bool,
    pub stop_reason: StopReason,
    pub planning_time_s: f64,
    pub nodes: usize,
    pub iterations: usize,
    pub switch_overs: usize,
    pub cost: f64,
    pub goal_distance: f64,
}

/// Why the planner stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StopReason {
    GoalReached,
    TimeLimit,
    NodeLimit,
    IterationLimit,
}

impl StopReason {
    pub fn label(&self) -> &'static str {
        match self {
            StopReason::GoalReached => "goal_reached",
            StopReason::TimeLimit => "time_limit",
            StopReason::NodeLimit => "node_limit",
            StopReason::IterationLimit => "iteration_limit",
        }
    }
}

/// The planner's answer: the path (or the best partial path) and statistics.
#[derive(Clone, Debug)]
pub struct PlanResult {
    pub found: bool,
    pub stop_reason: StopReason,
    /// Poses and the pusher reaching each (None for the start).
    pub path: Vec<([f64; 3], Option<usize>)>,
    pub nodes: usize,
    pub iterations: usize,
    pub planning_time_s: f64,
    pub switch_overs: usize,
    pub cost: f64,
    /// Distance (metric, m) from the path's end to the goal.
    pub goal_distance: f64,
}

/// `summary()` for a planner's result type (its fields named as in [`Summary`]).
macro_rules! impl_summary {
    ($t:ty) => {
        impl $t {
            /// What the result reports besides its path.
            pub fn summary(&self) -> $crate::trrt::Summary {
                $crate::trrt::Summary {
                    found: self.found,
                    stop_reason: self.stop_reason,
                    planning_time_s: self.planning_time_s,
                    nodes: self.nodes,
                    iterations: self.iterations,
                    switch_overs: self.switch_overs,
                    cost: self.cost,
                    goal_distance: self.goal_distance,
                }
            }
        }
    };
}
pub(crate) use impl_summary;
impl_summary!(PlanResult);

/// Planar log map: the constant body twist taking `a` to `b` in unit time.
pub fn body_twist(a: &[f64; 3], b: &[f64; 3]) -> Vec3 {
    let d = rot(-a[2]) * Vec2::new(b[0] - a[0], b[1] - a[1]);
    let w = b[2] - a[2];
    if w.abs() < 1e-9 {
        return Vec3::new(d.x, d.y, w);
    }
    let (s, c) = (w.sin() / w, (1.0 - w.cos()) / w);
    let det = s * s + c * c;
    Vec3::new((s * d.x + c * d.y) / det, (-c * d.x + s * d.y) / det, w)
}

/// The T-RRT transition test (Jaillet, Cortés & Siméon 2010) with its temperature adaptation:
/// reject above `c_max`; accept downhill; uphill with probability `exp(−slope / (K T))`,
/// cooling by `α` after an uphill success and heating by `α` after `n_fail` failures.
#[derive(Clone, Debug)]
pub struct Transition {
    pub temperature: f64,
    pub fails: usize,
    pub c_max: f64,
    pub k: f64,
    pub alpha: f64,
    pub n_fail: usize,
}

impl Transition {
    pub fn new(s: &Settings, c_max: f64) -> Self {
        Self { temperature: s.t0, fails: 0, c_max, k: s.k, alpha: s.alpha, n_fail: s.n_fail }
    }

    /// From cost `c_near` to `c_new` over a step of `steps` (length / L).
    pub fn test<R: Rng>(&mut self, rng: &mut R, c_near: f64, c_new: f64, steps: f64) -> bool {
        if c_new > self.c_max {
            return false;
        }
        if c_new <= c_near {
            return true;
        }
        let slope = (c_new - c_near) / steps.max(1e-12);
        if rng.random::<f64>() < (-slope / (self.k * self.temperature)).exp() {
            self.temperature /= self.alpha;
            self.fails = 0;
            true
        } else {
            self.fails += 1;
            if self.fails > self.n_fail {
                self.temperature *= self.alpha;
                self.fails = 0;
            }
            false
        }
    }
}

struct Planner<'a> {
    scene: &'a Scene,
    s: &'a Settings,
    l: f64,
    step: f64,
    goal: [f64; 3],
    tol: [f64; 3],
    rng: ChaCha8Rng,
    nodes: Tree<[f64; 3], ()>,
    tree: KdTree<f64, 3>,
    transition: Transition,
    bounds: ([f64; 2], [f64; 2], [f64; 2]),
    qs_opts: QsOptions,
}

impl<'a> Planner<'a> {
    fn key(&self, q: &[f64; 3]) -> [f64; 3] {
        [q[0], q[1], self.l * q[2]]
    }

    fn dist(&self, a: &[f64; 3], b: &[f64; 3]) -> f64 {
        ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (self.l * (a[2] - b[2])).powi(2)).sqrt()
    }

    fn cost_to_go(&self, q: &[f64; 3]) -> f64 {
        self.dist(q, &self.goal) / self.l
    }

    fn at_goal(&self, q: &[f64; 3]) -> bool {
        (0..3).all(|k| (q[k] - self.goal[k]).abs() <= self.tol[k])
    }

    fn edge_cost(&self, parent_pusher: Option<usize>, pusher: usize, length: f64) -> f64 {
        let s = self.s;
        edge_cost(s.same_pusher_cost, s.switch_cost, s.length_weight, self.l, parent_pusher, pusher, length)
    }

    /// The frame at `q` when the pad is on the object and the grasp holds.
    fn frame(&self, q: &[f64; 3]) -> Option<SupportFrame> {
        if !self.scene.admissible(q) {
            return None;
        }
        let f = self.scene.frame(q);
        (f.hold_ratio < 1.0).then_some(f)
    }

    /// Whether pusher `p` can move the object with body twist `tw` (unit time) from `q`: the
    /// exact test at `checks` poses along the step (margin ≥ `margin` at the start, ≥ half
    /// of it further on), and the pad on the object all along: at each interior pose its
    /// clearance exceeds how far it moves to the neighbouring poses, so it cannot leave the
    /// object between them.
    fn step_feasible(&self, q: &[f64; 3], tw: &Vec3, p: usize, margin: f64) -> bool {
        let model = &self.scene.pushers[p].model;
        let n = self.s.checks.max(1);
        let poses: Vec<[f64; 3]> = (0..=n).map(|k| if k == 0 { *q } else { integrate(q, tw, k as f64 / n as f64) }).collect();
        let pad = |x: &[f64; 3]| rot(-x[2]) * Vec2::new(-x[0], -x[1]);
        let pads: Vec<Vec2> = poses.iter().map(pad).collect();
        for k in 0..=n {
            let Some(f) = self.frame(&poses[k]) else { return false };
            if k > 0 && k < n {
                let reach = (pads[k] - pads[k - 1]).norm().max((pads[k + 1] - pads[k]).norm());
                if self.scene.pad_clearance(&poses[k]) < 1.1 * reach {
                    return false;
                }
            }
            if k == n {
                break; // the end pose: on the object and held; its twist is the next step's
            }
            let m = f.classify(model, tw).margin;
            if m < if k == 0 { margin } else { 0.5 * margin } {
                return false;
            }
        }
        true
    }

    /// The propagation's own feasibility test of a step (exact cone along the step, the
    /// stable-check LP, or the inverse complementarity dynamics).
    fn feasible(&self, q: &[f64; 3], tw: &Vec3, p: usize) -> bool {
        match self.s.propagation {
            Propagation::MotionCone => self.step_feasible(q, tw, p, self.s.margin),
            Propagation::StableCheck => {
                stable_push_lp(self.scene, q, p, tw) && self.frame(&integrate(q, tw, 1.0)).is_some()
            }
            Propagation::Mncp => {
                let Ok(prob) = quasistatic::push_problem(self.scene, q, p, &self.qs_opts) else { return false };
                let v = nalgebra::DVector::from_row_slice(tw.as_slice());
                mncp::solve_inverse(&prob, &v, &mncp::Settings::default()).is_ok()
                    && self.frame(&integrate(q, tw, 1.0)).is_some()
            }
        }
    }

    /// Straight push from node `i` to the goal: unit steps of one constant body twist, all
    /// feasible for one pusher (the node's first). Adds the chain; returns its last node.
    fn connect_goal(&mut self, i: usize) -> Option<usize> {
        let q = self.nodes[i].q;
        let xi = body_twist(&q, &self.goal);
        let len = self.scene.metric().twist_norm(&xi);
        if len < 1e-12 {
            return None;
        }
        let n = (len / self.step).ceil().max(1.0) as usize;
        if n > 200 {
            return None;
        }
        let tw = xi / n as f64;
        for p in self.pusher_order(self.nodes[i].pusher) {
            let mut qk = q;
            let mut ok = true;
            for _ in 0..n {
                if !self.feasible(&qk, &tw, p) {
                    ok = false;
                    break;
                }
                qk = integrate(&qk, &tw, 1.0);
            }
            if ok {
                let d = len / n as f64;
                let mut last = i;
                let mut qk = q;
                for _ in 0..n {
                    qk = integrate(&qk, &tw, 1.0);
                    let c = self.nodes[last].cost + self.edge_cost(self.nodes[last].pusher, p, d);
                    last = self.add(qk, last, p, c);
                }
                return Some(last);
            }
        }
        None
    }

    fn sample(&mut self) -> [f64; 3] {
        if self.rng.random::<f64>() < self.s.goal_bias {
            return self.goal;
        }
        let (bx, bz, bt) = self.bounds;
        for _ in 0..100 {
            let q = [
                self.rng.random_range(bx[0]..=bx[1]),
                self.rng.random_range(bz[0]..=bz[1]),
                self.rng.random_range(bt[0]..=bt[1]),
            ];
            if self.scene.admissible(&q) {
                return q;
            }
        }
        self.goal
    }

    /// Propagation by motion cones: the desired step if some cone contains it (parent's pusher
    /// first), else its projections, the closest in angle kept (parent's pusher preferred).
    fn propagate_cones(&mut self, near: usize, target: &[f64; 3]) -> Option<([f64; 3], usize, Vec3)> {
        let q = self.nodes[near].q;
        let parent_pusher = self.nodes[near].pusher;
        let xi = body_twist(&q, target);
        let m = self.scene.metric();
        let len = m.twist_norm(&xi);
        if len < 1e-12 {
            return None;
        }
        let want = xi * (self.step.min(len) / len);
        let frame = self.frame(&q)?;
        let order = self.pusher_order(if self.s.plain { None } else { parent_pusher });
        // 1. the desired step itself
        for &p in &order {
            if frame.classify(&self.scene.pushers[p].model, &want).margin >= self.s.margin
                && self.step_feasible(&q, &want, p, self.s.margin)
            {
                return Some((integrate(&q, &want, 1.0), p, want));
            }
        }
        // 2. projections on each cone
        let wn = m.twist_norm(&want);
        let mut best: Option<(f64, usize, Vec3)> = None;
        for &p in &order {
            let model = &self.scene.pushers[p].model;
            let Some(v) = self.project_with_margin(&frame, p, &want) else { continue };
            let vn = m.twist_norm(&v);
            if vn < 1e-12 {
                continue;
            }
            let cos = m.twist(&v).dot(&m.twist(&want)) / (vn * wn);
            let bonus = if Some(p) == parent_pusher && !self.s.plain { 0.05 } else { 0.0 };
            if cos > 0.2 && best.as_ref().is_none_or(|b| cos + bonus > b.0) {
                best = Some((cos + bonus, p, v));
            }
            let _ = model;
        }
        let (_, p, v) = best?;
        // a step of the unit length along the projection, halved until feasible along it
        let mut tw = v * (self.step.min(len) / m.twist_norm(&v));
        for _ in 0..4 {
            if self.step_feasible(&q, &tw, p, self.s.margin) {
                return Some((integrate(&q, &tw, 1.0), p, tw));
            }
            tw *= 0.5;
        }
        None
    }

    /// Closest twist to `want` in pusher `p`'s cone with at least the settings' margin.
    fn project_with_margin(&self, frame: &SupportFrame, p: usize, want: &Vec3) -> Option<Vec3> {
        project_with_margin(frame, &self.scene.pushers[p].model, want, self.s.margin)
    }

    fn pusher_order(&self, first: Option<usize>) -> Vec<usize> {
        pusher_order(self.scene.pushers.len(), first)
    }

    /// Stable-check propagation (ICRA 2018): random step directions towards the target's
    /// half-space, kept when a force-balance LP with a sticking pusher is feasible.
    fn propagate_stable(&mut self, near: usize, target: &[f64; 3]) -> Option<([f64; 3], usize, Vec3)> {
        let q = self.nodes[near].q;
        let order = self.pusher_order(self.nodes[near].pusher);
        let m = self.scene.metric();
        let xi = body_twist(&q, target);
        let len = m.twist_norm(&xi);
        if len < 1e-12 {
            return None;
        }
        let dir = m.twist(&xi) / len;
        self.frame(&q)?;
        for _ in 0..self.s.random_tries {
            let mut r = Vec3::new(self.gauss(), self.gauss(), self.gauss()).normalize();
            if r.dot(&dir) < 0.0 {
                r = -r;
            }
            let tw = m.twist_inv(&(r * self.step.min(len)));
            for &p in &order {
                if stable_push_lp(self.scene, &q, p, &tw) {
                    let qn = integrate(&q, &tw, 1.0);
                    if self.frame(&qn).is_some() {
                        return Some((qn, p, tw));
                    }
                }
            }
        }
        None
    }

    fn gauss(&mut self) -> f64 {
        // Box–Muller
        let (u1, u2): (f64, f64) = (self.rng.random::<f64>().max(1e-300), self.rng.random());
        (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
    }

    /// MNCP propagation (thesis §4.2.1): the desired step, or a few perturbations of it, kept
    /// when the inverse quasi-static dynamics finds pusher forces for some pusher.
    fn propagate_mncp(&mut self, near: usize, target: &[f64; 3]) -> Option<([f64; 3], usize, Vec3)> {
        let q = self.nodes[near].q;
        let order = self.pusher_order(self.nodes[near].pusher);
        let m = self.scene.metric();
        let xi = body_twist(&q, target);
        let len = m.twist_norm(&xi);
        if len < 1e-12 {
            return None;
        }
        self.frame(&q)?;
        let dir = m.twist(&xi) / len;
        for k in 0..self.s.random_tries {
            let d = if k == 0 {
                dir
            } else {
                // within about 30° of the desired direction
                let r = Vec3::new(self.gauss(), self.gauss(), self.gauss());
                (dir + (r - dir * r.dot(&dir)) * 0.3).normalize()
            };
            let tw = m.twist_inv(&(d * self.step.min(len)));
            for &p in &order {
                let Ok(prob) = quasistatic::push_problem(self.scene, &q, p, &self.qs_opts) else { continue };
                let v = nalgebra::DVector::from_row_slice(tw.as_slice());
                if mncp::solve_inverse(&prob, &v, &mncp::Settings::default()).is_ok() {
                    let qn = integrate(&q, &tw, 1.0);
                    if self.frame(&qn).is_some() {
                        return Some((qn, p, tw));
                    }
                }
            }
        }
        None
    }

    /// T-RRT transition test from cost `c_near` to `c_new` over a step of length `d`.
    fn transition(&mut self, c_near: f64, c_new: f64, d: f64) -> bool {
        if self.s.plain {
            return true;
        }
        self.transition.test(&mut self.rng, c_near, c_new, d / self.l)
    }

    fn add(&mut self, q: [f64; 3], parent: usize, pusher: usize, cost: f64) -> usize {
        let i = self.nodes.add(q, parent, pusher, cost, ());
        let k = self.key(&q);
        self.tree.add(&k, i as u64);
        i
    }

    /// RRT* choose-parent: the neighbour from which a feasible step reaches `q` cheapest.
    fn choose_parent(&self, q: &[f64; 3], near: usize, pusher: usize, tw_len: f64) -> (usize, usize, f64) {
        let mut best = (near, pusher, self.nodes[near].cost + self.edge_cost(self.nodes[near].pusher, pusher, tw_len));
        if self.s.neighbour_steps <= 0.0 || self.s.propagation != Propagation::MotionCone || self.s.plain {
            return best;
        }
        let r = self.s.neighbour_steps * self.step;
        let m = self.scene.metric();
        for nb in self.tree.within::<SquaredEuclidean>(&self.key(q), r * r) {
            let k = nb.item as usize;
            if k == near {
                continue;
            }
            let qk = self.nodes[k].q;
            let tw = body_twist(&qk, q);
            let len = m.twist_norm(&tw);
            if len > r {
                continue;
            }
            for p in self.pusher_order(self.nodes[k].pusher) {
                let c = self.nodes[k].cost + self.edge_cost(self.nodes[k].pusher, p, len);
                if c < best.2 - 1e-12 && self.step_feasible(&qk, &tw, p, self.s.margin) {
                    best = (k, p, c);
                    break;
                }
            }
        }
        best
    }

    /// RRT* rewire through `i`, keeping each rewired node's pusher (see the module notes).
    fn rewire(&mut self, i: usize) {
        if self.s.neighbour_steps <= 0.0 || self.s.propagation != Propagation::MotionCone || self.s.plain {
            return;
        }
        let r = self.s.neighbour_steps * self.step;
        let m = self.scene.metric();
        let qi = self.nodes[i].q;
        let nbs: Vec<usize> = self.tree.within::<SquaredEuclidean>(&self.key(&qi), r * r).iter().map(|n| n.item as usize).collect();
        for k in nbs {
            if k == i || Some(k) == self.nodes[i].parent || self.nodes[k].parent.is_none() {
                continue;
            }
            let Some(pk) = self.nodes[k].pusher else { continue };
            let tw = body_twist(&qi, &self.nodes[k].q);
            let len = m.twist_norm(&tw);
            let c = self.nodes[i].cost + self.edge_cost(self.nodes[i].pusher, pk, len);
            if c < self.nodes[k].cost - 1e-12 && !self.nodes.is_ancestor(k, i) && self.step_feasible(&qi, &tw, pk, self.s.margin) {
                self.nodes.reparent(k, i, c, ());
            }
        }
    }

    fn path_to(&self, i: usize) -> Vec<([f64; 3], Option<usize>)> {
        self.nodes.path_to(i).into_iter().map(|(q, p, _)| (q, p)).collect()
    }
}

/// The planners' stopping rule: a goal node whose cost is at most the threshold, or a budget
/// (time, nodes, iterations) spent.
pub fn stop_reason(s: &Settings, best_cost: Option<f64>, t0: &Instant, nodes: usize, iterations: usize) -> Option<StopReason> {
    if best_cost.is_some_and(|c| c <= s.cost_threshold) {
        Some(StopReason::GoalReached)
    } else if t0.elapsed().as_secs_f64() >= s.time_limit {
        Some(StopReason::TimeLimit)
    } else if nodes >= s.max_nodes {
        Some(StopReason::NodeLimit)
    } else if iterations >= s.max_iterations {
        Some(StopReason::IterationLimit)
    } else {
        None
    }
}

/// Plans a regrasp from `start` to `goal` (defaults: the scene's task).
pub fn plan(scene: &Scene, start: Option<[f64; 3]>, goal: Option<[f64; 3]>, settings: &Settings) -> Result<PlanResult> {
    plan_tree(scene, start, goal, settings).map(|(r, _)| r)
}

/// [`plan`], also returning the tree.
pub fn plan_tree(
    scene: &Scene,
    start: Option<[f64; 3]>,
    goal: Option<[f64; 3]>,
    settings: &Settings,
) -> Result<(PlanResult, Vec<Node>)> {
    let task = scene.task;
    let start = start.or(task.map(|t| t.start)).ok_or_else(|| Error::arg("start", "the scene has no task: give a start"))?;
    let goal = goal.or(task.map(|t| t.goal)).ok_or_else(|| Error::arg("goal", "the scene has no task: give a goal"))?;
    let tol = task.map(|t| t.tolerance).unwrap_or([1e-3, 1e-3, 0.0175]);
    for (name, q) in [("start", &start), ("goal", &goal)] {
        if !q.iter().all(|x| x.is_finite()) {
            return Err(Error::arg(name, "has a non-finite component"));
        }
        if !scene.admissible(q) {
            return Err(Error::arg(name, format!("{q:?} is not admissible: the finger pad is not entirely on the object")));
        }
        if !(scene.hold_ratio(q) < 1.0) {
            return Err(Error::arg(name, format!("{q:?}: the grasp cannot hold the object against gravity there")));
        }
    }
    settings.check()?;
    let l = scene.length;
    let step = settings.step.unwrap_or(0.1 * l);
    if !(step > 0.0) {
        return Err(Error::arg("step", "must be positive"));
    }
    // the region of poses where the pad can be on the object: t = −R c for c on the object
    let reach = scene.outline.vertices().iter().map(|v| v.norm()).fold(0.0, f64::max);
    let (tlo, thi) = (start[2].min(goal[2]) - settings.theta_margin, start[2].max(goal[2]) + settings.theta_margin);
    let mut pl = Planner {
        scene,
        s: settings,
        l,
        step,
        goal,
        tol,
        rng: ChaCha8Rng::seed_from_u64(settings.seed),
        nodes: Tree::new(start, ()),
        tree: KdTree::new(),
        transition: Transition::new(settings, 0.0),
        bounds: ([-reach, reach], [-reach, reach], [tlo, thi]),
        qs_opts: QsOptions { support: SupportModel::Points { rings: 2, points: 0, merge_fingers: true }, ..QsOptions::default() },
    };
    pl.transition.c_max = settings.c_max * pl.cost_to_go(&start).max(1.0);
    let k0 = pl.key(&start);
    pl.tree.add(&k0, 0);
    let t0 = Instant::now();
    let mut best_goal: Option<usize> = if pl.at_goal(&start) { Some(0) } else { None };
    if best_goal.is_none() && settings.connect && !settings.plain {
        best_goal = pl.connect_goal(0);
    }
    let mut closest = best_goal.unwrap_or(0);
    let mut iterations = 0;
    let stop = loop {
        if let Some(r) = stop_reason(settings, best_goal.map(|g| pl.nodes[g].cost), &t0, pl.nodes.len(), iterations) {
            break r;
        }
        iterations += 1;
        let target = pl.sample();
        let near = pl.tree.nearest_one::<SquaredEuclidean>(&pl.key(&target)).item as usize;
        let prop = match settings.propagation {
            Propagation::MotionCone => pl.propagate_cones(near, &target),
            Propagation::StableCheck => pl.propagate_stable(near, &target),
            Propagation::Mncp => pl.propagate_mncp(near, &target),
        };
        let Some((q_new, pusher, tw)) = prop else { continue };
        // a pose already in the tree (the same step taken again) adds nothing
        let dup = pl.tree.nearest_one::<SquaredEuclidean>(&pl.key(&q_new));
        if dup.distance <= (1e-9 * pl.l).powi(2) {
            continue;
        }
        let (c_near, c_new) = (pl.cost_to_go(&pl.nodes[near].q), pl.cost_to_go(&q_new));
        let d = pl.scene.metric().twist_norm(&tw);
        if !pl.transition(c_near, c_new, d) {
            continue;
        }
        let (parent, p, cost) = pl.choose_parent(&q_new, near, pusher, d);
        let i = pl.add(q_new, parent, p, cost);
        pl.rewire(i);
        if pl.cost_to_go(&q_new) < pl.cost_to_go(&pl.nodes[closest].q) {
            closest = i;
        }
        if pl.at_goal(&q_new) {
            pl.nodes.keep_cheaper(&mut best_goal, i);
        } else if let Some(g) = if settings.connect && !settings.plain { pl.connect_goal(i) } else { None } {
            pl.nodes.keep_cheaper(&mut best_goal, g);
        }
    };
    // rewiring may have made another goal node the cheapest
    if best_goal.is_some() {
        best_goal = pl.nodes.cheapest(|q| pl.at_goal(q));
    }
    let end = best_goal.unwrap_or(closest);
    let path = pl.path_to(end);
    let switch_overs = switch_overs(&pl.nodes.path_to(end));
    let result = PlanResult {
        found: best_goal.is_some(),
        stop_reason: if best_goal.is_some() { StopReason::GoalReached } else { stop },
        goal_distance: pl.dist(&path.last().expect("path").0, &goal),
        cost: pl.nodes[end].cost,
        path,
        nodes: pl.nodes.len(),
        iterations,
        planning_time_s: t0.elapsed().as_secs_f64(),
        switch_overs,
    };
    Ok((result, pl.nodes.into_nodes()))
}

/// ICRA 2018 "stable check": is there a pusher force in its friction cone that, with the
/// fingers sliding as the ellipsoidal limit surface says and gravity, balances the object for
/// twist `tw`? Solved as a small LP (clarabel) over the pusher's edge-force weights.
pub fn stable_push_lp(scene: &Scene, q: &[f64; 3], pusher: usize, tw: &Vec3) -> bool {
    use clarabel::algebra::CscMatrix;
    use clarabel::solver::{DefaultSettings, DefaultSolver, IPSolver, SolverStatus, SupportedConeT};
    let f = scene.frame(q);
    if !(f.hold_ratio < 1.0) || tw.amax() == 0.0 {
        return false;
    }
    let required = f.support_load(tw) - f.gravity;
    let edges = &scene.pushers[pusher].model.edges;
    let k = edges.len();
    let scale = required.amax().max(1e-12);
    // Σ α_i e_i = required, α ≥ 0
    let mut rows = vec![vec![0.0; k]; 3 + k];
    for (j, e) in edges.iter().enumerate() {
        for r in 0..3 {
            rows[r][j] = e.wrench[r];
        }
        rows[3 + j][j] = -1.0;
    }
    // scale the moment row by the length to balance the units
    let l = scene.length;
    for v in rows[2].iter_mut() {
        *v /= l;
    }
    let mut b = vec![required.x / scale, required.y / scale, required.z / l / scale];
    b.extend(std::iter::repeat_n(0.0, k));
    let a = CscMatrix::from(&rows);
    let p = CscMatrix::zeros((k, k));
    let c = vec![0.0; k];
    let cones = [SupportedConeT::ZeroConeT(3), SupportedConeT::NonnegativeConeT(k)];
    let settings = DefaultSettings { verbose: false, ..DefaultSettings::default() };
    let Ok(mut solver) = DefaultSolver::new(&p, &c, &a, &b, &cones, settings) else { return false };
    solver.solve();
    matches!(solver.solution.status, SolverStatus::Solved | SolverStatus::AlmostSolved)
}

/// Checks a path with the exact motion-cone test at `checks` poses along each step; returns
/// the smallest margin of each step (negative: the pusher would slip somewhere along it; −1:
/// the finger pad leaves the object or the grasp cannot hold it somewhere along the step). An
/// error names a step whose pusher is missing or unknown.
pub fn validate_path(scene: &Scene, path: &[([f64; 3], Option<usize>)], checks: usize) -> Result<Vec<f64>> {
    let mut out = Vec::new();
    for (i, w) in path.windows(2).enumerate() {
        let (a, b) = (w[0].0, w[1].0);
        let p = w[1].1.ok_or_else(|| Error::arg(format!("path[{}].pusher", i + 1), "is missing"))?;
        if p >= scene.pushers.len() {
            return Err(Error::arg(format!("path[{}].pusher", i + 1), "is not a pusher of the scene"));
        }
        let tw = body_twist(&a, &b);
        let mut worst = f64::INFINITY;
        let n = checks.max(1);
        for k in 0..=n {
            let qk = integrate(&a, &tw, k as f64 / n as f64);
            if !scene.admissible(&qk) || !(scene.frame(&qk).hold_ratio < 1.0) {
                worst = -1.0;
                break;
            }
            if k < n && tw.amax() > 0.0 {
                worst = worst.min(scene.frame(&qk).classify(&scene.pushers[p].model, &tw).margin);
            }
        }
        out.push(if worst.is_finite() { worst } else { 0.0 });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene(name: &str) -> Scene {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples").join(name);
        Scene::load(&path).unwrap()
    }

    #[test]
    fn log_and_exp_are_inverse() {
        for (a, b) in [([0.0, 0.0, 0.0], [0.01, -0.02, 0.3]), ([0.005, 0.002, -0.4], [-0.003, 0.01, 0.2])] {
            let tw = body_twist(&a, &b);
            let c = integrate(&a, &tw, 1.0);
            for k in 0..3 {
                assert!((c[k] - b[k]).abs() < 1e-12, "{c:?} vs {b:?}");
            }
        }
    }

    #[test]
    fn transition_test_adapts_the_temperature() {
        let s = scene("block-low-friction.toml");
        let settings = Settings::default();
        let mut pl = Planner {
            scene: &s,
            s: &settings,
            l: s.length,
            step: 0.003,
            goal: [0.0; 3],
            tol: [1e-3; 3],
            rng: ChaCha8Rng::seed_from_u64(1),
            nodes: Tree::new([0.0; 3], ()),
            tree: KdTree::new(),
            transition: Transition { temperature: 0.1, ..Transition::new(&settings, 10.0) },
            bounds: ([0.0; 2], [0.0; 2], [0.0; 2]),
            qs_opts: QsOptions::default(),
        };
        assert!(pl.transition(1.0, 0.9, 0.003), "downhill is always accepted");
        assert!(!pl.transition(1.0, 11.0, 0.003), "above c_max is rejected");
        // steep uphill is rejected and, after n_fail rejections, the temperature rises
        let t = pl.transition.temperature;
        for _ in 0..=settings.n_fail {
            assert!(!pl.transition(1.0, 2.0, 0.003 * s.length / s.length));
        }
        assert!(pl.transition.temperature > t);
    }

    /// After choose-parent and rewiring, every node's cost is its parent's plus the edge cost.
    #[test]
    fn rewiring_keeps_costs_consistent() {
        let s = scene("t-shape.toml");
        let settings = Settings { seed: 5, cost_threshold: 0.0, max_iterations: 3000, connect: false, ..Settings::default() };
        let (_, nodes) = plan_tree(&s, None, None, &settings).unwrap();
        assert!(nodes.len() > 100);
        let m = s.metric();
        let sd = &settings;
        let mut rewired = 0;
        for (i, n) in nodes.iter().enumerate().skip(1) {
            let p = n.parent.unwrap();
            let len = m.twist_norm(&body_twist(&nodes[p].q, &n.q));
            let switch = if nodes[p].pusher == n.pusher { sd.same_pusher_cost } else { sd.switch_cost };
            let expect = nodes[p].cost + switch + sd.length_weight * len / s.length;
            assert!((n.cost - expect).abs() < 1e-9, "node {i}: {} vs {expect}", n.cost);
            assert!(nodes[p].children.contains(&i));
            rewired += (p != i - 1) as usize;
        }
        assert!(rewired > 0, "no node was rewired or re-parented");
    }

    #[test]
    fn bad_requests_are_errors_or_reported_failures() {
        let s = scene("block-low-friction.toml");
        // inadmissible start: the pad is off the object
        assert!(plan(&s, Some([0.03, 0.0, 0.0]), None, &Settings::default()).is_err());
        // NaN goal
        assert!(plan(&s, None, Some([f64::NAN, 0.0, 0.0]), &Settings::default()).is_err());
        // zero budget: not found, says why, returns the start as the partial path
        let r = plan(&s, None, None, &Settings { time_limit: 0.0, connect: false, ..Settings::default() }).unwrap();
        assert!(!r.found && r.stop_reason == StopReason::TimeLimit && r.path.len() == 1);
        // unreachable: only the top pusher (pushes down) for a goal above the start
        let text = include_str!("../../../examples/block-low-friction.toml");
        let top_only = text.split("[[pushers]]").enumerate().filter(|(i, p)| *i == 0 || p.contains("name = \"top\"")).map(|(i, p)| if i == 0 { p.to_string() } else { format!("[[pushers]]{p}") }).collect::<String>();
        let s2 = Scene::from_toml_str(&top_only).unwrap();
        assert_eq!(s2.pushers.len(), 1);
        let r = plan(&s2, None, Some([0.0, 0.01, 0.0]), &Settings { time_limit: 0.3, ..Settings::default() }).unwrap();
        assert!(!r.found && r.stop_reason == StopReason::TimeLimit);
        assert!(r.goal_distance > 0.0);
    }

    #[test]
    fn plans_are_deterministic_and_feasible_along_every_step() {
        let s = scene("block-low-friction.toml");
        let settings = Settings { seed: 3, ..Settings::default() };
        let a = plan(&s, None, None, &settings).unwrap();
        let b = plan(&s, None, None, &settings).unwrap();
        assert!(a.found, "{a:?}");
        assert_eq!(a.path, b.path);
        let margins = validate_path(&s, &a.path, 16).unwrap();
        assert!(margins.iter().all(|m| *m >= -1e-9), "{margins:?}");
        let end = a.path.last().unwrap().0;
        let goal = s.task.unwrap().goal;
        assert!((0..3).all(|k| (end[k] - goal[k]).abs() <= s.task.unwrap().tolerance[k]));
    }
}
