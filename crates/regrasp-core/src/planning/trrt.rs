//! One T-RRT* (thesis §4.1, §4.3; RSS 2018) over any [`Space`] of object poses in the grasp:
//! planar ([`crate::planning::planar`]) and spatial ([`crate::planning::spatial`]).
//!
//! * **Configuration cost**: distance to the goal over L (dimensionless).
//! * **Transition test** (T-RRT, Jaillet, Cortés & Siméon 2010): a new node more costly than its
//!   parent is kept with probability `exp(−(Δc/δ)/(K T))` (δ: the step's length over L); the
//!   temperature `T` falls after an uphill acceptance and rises by `α` after `n_fail` rejections.
//! * **RRT*** choose-parent and rewire with the edge cost of RSS 2018 (0.1 when the pusher stays,
//!   1 on a switch-over) plus the step's length over L; rewiring keeps the rewired node's pusher,
//!   so the costs of its subtree shift by the same amount and stay consistent.
//! * **Goal connection**: from each new node the space may reach the goal directly (a straight
//!   push, or rolling); the cheapest goal node is returned.
//!
//! What differs between dimensions — the metric, sampling, the unit-step propagation and its
//! feasibility test — is the [`Space`]'s; the search itself is written once, here.

use crate::error::Result;
use crate::planning::tree::{edge_cost, pusher_order, switch_overs, Tree, TreeNode};
use kiddo::{KdTree, SquaredEuclidean};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::time::Instant;

/// Settings of the search shared by every space (each space's settings struct embeds one, with
/// its own defaults).
#[derive(Clone, Debug)]
pub struct SearchSettings {
    pub seed: u64,
    /// Wall-clock budget [s].
    pub time_limit: f64,
    pub max_nodes: usize,
    pub max_iterations: usize,
    /// Probability of sampling the goal.
    pub goal_bias: f64,
    /// Length of a unit step in the metric [m]; `None`: the space's default (a fraction of L).
    pub step: Option<f64>,
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
    /// Stop at once at a path to the goal whose cost is at most this (∞: the first path; 0, the
    /// default: none, the refinement below decides).
    pub cost_threshold: f64,
    /// Anytime refinement: after the first path to the goal, RRT* goes on for this fraction of
    /// the iterations the first took (deterministic for a seed), within the other budgets; the
    /// cheapest goal node is returned. 0: stop at the first; ∞: the other budgets decide.
    pub refine: f64,
    /// Random directions tried per step when the desired one is not feasible.
    pub random_tries: usize,
    /// Bounds of the rotations explored: the start and goal widened by this [rad].
    pub theta_margin: f64,
    /// Try to reach the goal from each new node directly (straight push, rolling).
    pub connect: bool,
    /// The share (0, 1] of the task's tolerance within which a plan ends, so that execution has
    /// room ([`Space::at_goal`]); a search that reaches only the whole tolerance returns its
    /// cheapest node there ([`Space::within_task`], [`plan_tree`]).
    pub goal_share: f64,
}

impl Default for SearchSettings {
    fn default() -> Self {
        Self {
            seed: 0,
            time_limit: 10.0,
            max_nodes: 20_000,
            max_iterations: 200_000,
            goal_bias: 0.2,
            step: None,
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
            cost_threshold: 0.0,
            refine: 0.5,
            random_tries: 8,
            theta_margin: 0.5,
            connect: true,
            goal_share: 0.5,
        }
    }
}

impl SearchSettings {
    /// Checks every setting (NaN, negative or absurd values are errors naming the setting).
    pub fn check(&self) -> Result<()> {
        use crate::error::Error;
        let finite_nonneg = |name: &str, v: f64| {
            if v.is_finite() && v >= 0.0 { Ok(()) } else { Err(Error::arg(name, format!("must be a finite, non-negative number (got {v})"))) }
        };
        let positive = |name: &str, v: f64| {
            if v.is_finite() && v > 0.0 { Ok(()) } else { Err(Error::arg(name, format!("must be a finite, positive number (got {v})"))) }
        };
        if self.time_limit.is_nan() || self.time_limit < 0.0 {
            return Err(Error::arg("time_limit", format!("must be a non-negative number of seconds (got {})", self.time_limit)));
        }
        if !(0.0..=1.0).contains(&self.goal_bias) {
            return Err(Error::arg("goal_bias", format!("must be in [0, 1] (got {})", self.goal_bias)));
        }
        if let Some(step) = self.step {
            positive("step", step)?;
        }
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
        if !(self.refine >= 0.0) {
            return Err(Error::arg("refine", format!("must be a non-negative fraction of the iterations, or inf (got {})", self.refine)));
        }
        if !(self.goal_share > 0.0 && self.goal_share <= 1.0) {
            return Err(Error::arg("goal_share", format!("must be a share of the tolerance in (0, 1] (got {})", self.goal_share)));
        }
        if self.cost_threshold.is_nan() {
            return Err(Error::arg("cost_threshold", "is NaN"));
        }
        for (name, v, lo, hi) in [("checks", self.checks, 1, 10_000), ("random_tries", self.random_tries, 0, 10_000),
                                  ("max_nodes", self.max_nodes, 1, 100_000_000), ("max_iterations", self.max_iterations, 1, usize::MAX)] {
            if v < lo || v > hi {
                return Err(Error::arg(name, format!("must be between {lo} and {hi} (got {v})")));
            }
        }
        Ok(())
    }
}

/// Why the planner stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StopReason {
    GoalReached,
    TimeLimit,
    NodeLimit,
    IterationLimit,
    /// Decided before the search: no plan exists ([`crate::planning::reachability`]).
    Unreachable,
}

impl StopReason {
    pub fn label(&self) -> &'static str {
        match self {
            StopReason::GoalReached => "goal_reached",
            StopReason::TimeLimit => "time_limit",
            StopReason::NodeLimit => "node_limit",
            StopReason::IterationLimit => "iteration_limit",
            StopReason::Unreachable => "unreachable",
        }
    }
}

/// A step the space proposes: the pose reached, the pusher, the step's data and its length [m].
#[derive(Clone, Debug)]
pub struct Step<Q, E> {
    pub q: Q,
    pub pusher: usize,
    pub edge: E,
    pub length: f64,
}

/// Steps to the goal: (pose, pusher, step data, length [m]) each.
pub type Chain<Q, E> = Vec<(Q, usize, E, f64)>;

/// A chain of steps all taken by pusher `p`.
pub fn one_pusher<Q, E>(p: usize, steps: Vec<(Q, E, f64)>) -> Chain<Q, E> {
    steps.into_iter().map(|(q, e, len)| (q, p, e, len)).collect()
}

/// What every space holds: the search settings, the object's characteristic length L [m]
/// (radius of gyration), the unit step [m], the number of pushers and the goal.
#[derive(Clone, Debug)]
pub struct SpaceCore<Q> {
    pub search: SearchSettings,
    pub length: f64,
    pub step: f64,
    pub pushers: usize,
    pub goal: Q,
}

/// A space of object poses in the grasp, with its metric, sampling and unit-step propagation.
/// `K` is the dimension of the k-d tree keys ([`Space::key`]).
pub trait Space<const K: usize>: Sync {
    /// A pose of the object in the grasp.
    type Q: Clone + Send + Sync;
    /// What a step needs to be replayed (e.g. the pusher's twist).
    type Edge: Clone + Send + Sync;
    /// The constant motion interpolating two poses (a body twist).
    type Motion;

    fn core(&self) -> &SpaceCore<Self::Q>;
    fn search(&self) -> &SearchSettings {
        &self.core().search
    }
    /// The object's characteristic length L [m] (radius of gyration).
    fn length(&self) -> f64 {
        self.core().length
    }
    /// The unit step [m].
    fn step(&self) -> f64 {
        self.core().step
    }
    fn pushers(&self) -> usize {
        self.core().pushers
    }
    fn goal(&self) -> &Self::Q {
        &self.core().goal
    }
    /// The step data stored with the root.
    fn root_edge(&self) -> Self::Edge;
    /// A k-d tree key whose squared Euclidean distance approximates the squared metric.
    fn key(&self, q: &Self::Q) -> [f64; K];
    /// The metric distance [m].
    fn dist(&self, a: &Self::Q, b: &Self::Q) -> f64;
    /// Whether `q` is within the goal's inner tolerance ([`SearchSettings::goal_share`] of the
    /// task's).
    fn at_goal(&self, q: &Self::Q) -> bool;
    /// Whether `q` is within the task's whole tolerance (default: [`Space::at_goal`]).
    fn within_task(&self, q: &Self::Q) -> bool {
        self.at_goal(q)
    }
    /// T-RRT's cost map: how far `q` is from the goal, in units of L (default: the metric's
    /// distance; a space may know a better one, e.g. around walls).
    fn cost_to_go(&self, q: &Self::Q) -> f64 {
        self.dist(q, self.goal()) / self.length()
    }
    /// A random pose to grow towards (goal bias is the planner's), given the start and the tree's
    /// node closest to the goal by [`Space::cost_to_go`].
    fn sample(&self, rng: &mut ChaCha8Rng, start: &Self::Q, closest: &Self::Q) -> Self::Q;
    /// A unit step from `q` (reached with `pusher`) towards `target`.
    fn propagate(&self, rng: &mut ChaCha8Rng, q: &Self::Q, pusher: Option<usize>, target: &Self::Q) -> Option<Step<Self::Q, Self::Edge>>;
    /// The constant motion from `a` to `b` and its length [m].
    fn interpolate(&self, a: &Self::Q, b: &Self::Q) -> (Self::Motion, f64);
    /// Whether pusher `p` can take `motion` from `a`; the step's data if so.
    fn take(&self, a: &Self::Q, motion: &Self::Motion, p: usize) -> Option<Self::Edge>;
    /// A chain of steps from `q` (reached with `pusher`) to the goal, if the space can reach it
    /// directly.
    fn connect_goal(&self, q: &Self::Q, pusher: Option<usize>) -> Option<Chain<Self::Q, Self::Edge>>;
    /// Whether choose-parent and rewiring apply (the space's propagation may rule them out).
    fn rewires(&self) -> bool {
        true
    }
    /// A plain goal-biased RRT: no transition test, no RRT*, no goal connection.
    fn plain(&self) -> bool {
        false
    }
    /// How many nearest keys are re-ranked by the exact metric (1: the key's distance is exact).
    fn nearest_candidates(&self) -> usize {
        1
    }
    /// Neighbour search radius in the keys' space relative to the metric's (≥ 1).
    fn key_slack(&self) -> f64 {
        1.0
    }
    /// Whether `b` is an RRT* neighbour of `a` within radius `r` [m], given the length `len` of
    /// the motion interpolating them (default: that length).
    fn within(&self, _a: &Self::Q, _b: &Self::Q, len: f64, r: f64) -> bool {
        len <= r
    }
}

/// The planner's answer: the path (or the best partial path) and statistics.
#[derive(Clone, Debug)]
pub struct Plan<Q, E> {
    pub found: bool,
    pub stop_reason: StopReason,
    /// Poses, the pusher reaching each (None for the start) and the step's data.
    pub path: Vec<(Q, Option<usize>, E)>,
    pub nodes: usize,
    pub iterations: usize,
    pub planning_time_s: f64,
    pub switch_overs: usize,
    pub cost: f64,
    /// Distance (metric, m) from the path's end to the goal.
    pub goal_distance: f64,
    /// Why the goal is unreachable (with [`StopReason::Unreachable`]).
    pub reason: Option<String>,
    /// The first path to the goal found, before the refinement: when it was found [s] (from the
    /// search's start) and its switch-overs. `None` when no path was found.
    pub first: Option<FirstPlan>,
}

/// The first path to the goal a search found (the anytime refinement's starting point).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FirstPlan {
    pub planning_time_s: f64,
    pub iterations: usize,
    pub switch_overs: usize,
    pub cost: f64,
}

impl<Q: Clone, E> Plan<Q, E> {
    /// The path's poses and the pusher reaching each, without the steps' data.
    pub fn poses(&self) -> Vec<(Q, Option<usize>)> {
        self.path.iter().map(|(q, p, _)| (q.clone(), *p)).collect()
    }
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
    pub fn new(s: &SearchSettings, c_max: f64) -> Self {
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

/// The planners' stopping rule: a goal node whose cost is at most the threshold, or a budget
/// (time, nodes, iterations) spent.
pub fn stop_reason(s: &SearchSettings, best_cost: Option<f64>, t0: &Instant, nodes: usize, iterations: usize) -> Option<StopReason> {
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

/// The search state: the space, the tree, its k-d index, the node closest to the goal by the
/// cost map, the random source and the transition test's temperature.
struct Search<'a, S: Space<K>, const K: usize> {
    space: &'a S,
    rng: ChaCha8Rng,
    nodes: Tree<S::Q, S::Edge>,
    index: KdTree<f64, K>,
    closest: (usize, f64),
    transition: Transition,
}

impl<'a, S: Space<K>, const K: usize> Search<'a, S, K> {
    fn new(space: &'a S, start: S::Q) -> Self {
        let s = space.search();
        let mut search = Self {
            space,
            rng: ChaCha8Rng::seed_from_u64(s.seed),
            nodes: Tree::new(start.clone(), space.root_edge()),
            index: KdTree::new(),
            closest: (0, space.cost_to_go(&start)),
            transition: Transition::new(s, 0.0),
        };
        search.transition.c_max = s.c_max * search.cost_to_go(&start).max(1.0);
        search.index.add(&space.key(&start), 0);
        search
    }

    fn cost_to_go(&self, q: &S::Q) -> f64 {
        self.space.cost_to_go(q)
    }

    fn edge_cost(&self, parent_pusher: Option<usize>, pusher: usize, length: f64) -> f64 {
        let s = self.space.search();
        edge_cost(s.same_pusher_cost, s.switch_cost, s.length_weight, self.space.length(), parent_pusher, pusher, length)
    }

    /// Adds a node to the tree; to the k-d index only when no indexed node has the same key (a
    /// goal reached again and again by goal connections during the refinement would overflow a
    /// k-d leaf, and a duplicate adds nothing to nearest-neighbour queries).
    fn add(&mut self, q: S::Q, parent: usize, pusher: usize, cost: f64, edge: S::Edge) -> usize {
        let key = self.space.key(&q);
        let to_go = self.cost_to_go(&q);
        let i = self.nodes.add(q, parent, pusher, cost, edge);
        if to_go < self.closest.1 {
            self.closest = (i, to_go);
        }
        if self.index.size() == 0 || self.index.nearest_one::<SquaredEuclidean>(&key).distance > 0.0 {
            self.index.add(&key, i as u64);
        }
        i
    }

    fn sample(&mut self) -> S::Q {
        if self.rng.random::<f64>() < self.space.search().goal_bias {
            return self.space.goal().clone();
        }
        let (start, closest) = (self.nodes[0].q.clone(), self.nodes[self.closest.0].q.clone());
        self.space.sample(&mut self.rng, &start, &closest)
    }

    /// The tree node nearest to `q` in the metric.
    fn nearest(&self, q: &S::Q) -> usize {
        let key = self.space.key(q);
        match self.space.nearest_candidates() {
            0 | 1 => self.index.nearest_one::<SquaredEuclidean>(&key).item as usize,
            n => self
                .index
                .nearest_n::<SquaredEuclidean>(&key, n)
                .iter()
                .map(|nb| nb.item as usize)
                .min_by(|&a, &b| self.space.dist(&self.nodes[a].q, q).total_cmp(&self.space.dist(&self.nodes[b].q, q)))
                .unwrap_or(0),
        }
    }

    /// Tree nodes within the RRT* radius of `q` (candidates of the key index).
    fn neighbours(&self, q: &S::Q) -> Vec<usize> {
        let r = self.space.key_slack() * self.radius();
        self.index.within::<SquaredEuclidean>(&self.space.key(q), r * r).iter().map(|n| n.item as usize).collect()
    }

    fn radius(&self) -> f64 {
        self.space.search().neighbour_steps * self.space.step()
    }

    fn rrt_star(&self) -> bool {
        self.space.search().neighbour_steps > 0.0 && self.space.rewires() && !self.space.plain()
    }

    /// RRT* choose-parent: the neighbour from which a feasible step reaches `step.q` cheapest.
    fn choose_parent(&self, near: usize, step: Step<S::Q, S::Edge>) -> (usize, usize, f64, S::Edge) {
        let mut best = (near, step.pusher, self.nodes[near].cost + self.edge_cost(self.nodes[near].pusher, step.pusher, step.length), step.edge);
        if !self.rrt_star() {
            return best;
        }
        let r = self.radius();
        for k in self.neighbours(&step.q) {
            if k == near {
                continue;
            }
            let (motion, len) = self.space.interpolate(&self.nodes[k].q, &step.q);
            if !self.space.within(&self.nodes[k].q, &step.q, len, r) {
                continue;
            }
            for p in pusher_order(self.space.pushers(), self.nodes[k].pusher) {
                let c = self.nodes[k].cost + self.edge_cost(self.nodes[k].pusher, p, len);
                if c < best.2 - 1e-12 {
                    if let Some(e) = self.space.take(&self.nodes[k].q, &motion, p) {
                        best = (k, p, c, e);
                        break;
                    }
                }
            }
        }
        best
    }

    /// RRT* rewire through node `i`, keeping each rewired node's pusher.
    fn rewire(&mut self, i: usize) {
        if !self.rrt_star() {
            return;
        }
        let r = self.radius();
        let qi = self.nodes[i].q.clone();
        for k in self.neighbours(&qi) {
            if k == i || Some(k) == self.nodes[i].parent || self.nodes[k].parent.is_none() {
                continue;
            }
            let Some(pk) = self.nodes[k].pusher else { continue };
            let (motion, len) = self.space.interpolate(&qi, &self.nodes[k].q);
            if !self.space.within(&qi, &self.nodes[k].q, len, r) {
                continue;
            }
            let c = self.nodes[i].cost + self.edge_cost(self.nodes[i].pusher, pk, len);
            if c < self.nodes[k].cost - 1e-12 && !self.nodes.is_ancestor(k, i) {
                if let Some(e) = self.space.take(&qi, &motion, pk) {
                    self.nodes.reparent(k, i, c, e);
                }
            }
        }
    }

    /// Reaches the goal from node `i` directly if the space can; returns the chain's last node.
    fn connect_goal(&mut self, i: usize) -> Option<usize> {
        if !self.space.search().connect || self.space.plain() {
            return None;
        }
        let chain = self.space.connect_goal(&self.nodes[i].q, self.nodes[i].pusher)?;
        let mut last = i;
        for (q, p, e, len) in chain {
            let c = self.nodes[last].cost + self.edge_cost(self.nodes[last].pusher, p, len);
            last = self.add(q, last, p, c, e);
        }
        Some(last)
    }

    /// One iteration: sample, propagate, transition test, choose parent, rewire; returns the new
    /// node, if any.
    fn grow(&mut self) -> Option<usize> {
        let target = self.sample();
        let near = self.nearest(&target);
        let step = self.space.propagate(&mut self.rng, &self.nodes[near].q, self.nodes[near].pusher, &target)?;
        // a pose already in the tree (the same step taken again) adds nothing
        let dup = self.index.nearest_one::<SquaredEuclidean>(&self.space.key(&step.q));
        if dup.distance <= (1e-9 * self.space.length()).powi(2) {
            return None;
        }
        let (c_near, c_new) = (self.cost_to_go(&self.nodes[near].q), self.cost_to_go(&step.q));
        if !self.space.plain() && !self.transition.test(&mut self.rng, c_near, c_new, step.length / self.space.length()) {
            return None;
        }
        let q = step.q.clone();
        let (parent, p, cost, e) = self.choose_parent(near, step);
        let i = self.add(q, parent, p, cost, e);
        self.rewire(i);
        Some(i)
    }
}

/// A standard normal sample (Box–Muller).
pub fn gauss<R: Rng>(rng: &mut R) -> f64 {
    let (u1, u2): (f64, f64) = (rng.random::<f64>().max(1e-300), rng.random());
    (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
}

/// Plans from `start` to the space's goal.
pub fn plan<S: Space<K>, const K: usize>(space: &S, start: S::Q) -> Result<Plan<S::Q, S::Edge>> {
    plan_tree(space, start).map(|r| r.0)
}

/// The search tree of a plan.
pub type Nodes<S, const K: usize> = Vec<TreeNode<<S as Space<K>>::Q, <S as Space<K>>::Edge>>;

/// How long a search goes on for the inner goal region after its first node within the task's
/// tolerance, at least: iterations and seconds (see [`plan_tree`]).
const MIN_INNER_ITERATIONS: usize = 200;
const MIN_INNER_TIME_S: f64 = 0.1;

/// [`plan`], also returning the search tree; [`crate::interrupt::check`]ed every iteration. The
/// goal is the inner region ([`Space::at_goal`]); once a node lies within the task's whole
/// tolerance ([`Space::within_task`]) at iteration `k`, time `t` [s], the search goes on for the
/// inner region at most `(1 + refine) · max(k, MIN_INNER_ITERATIONS)` more iterations or
/// `(1 + refine) · max(t, MIN_INNER_TIME_S)` more seconds, whichever ends first, then ends at the
/// cheapest node within the task's tolerance (found, the plan ending outside the inner region).
pub fn plan_tree<S: Space<K>, const K: usize>(space: &S, start: S::Q) -> Result<(Plan<S::Q, S::Edge>, Nodes<S, K>)> {
    let s = space.search();
    let mut search = Search::new(space, start);
    let t0 = Instant::now();
    let mut best: Option<usize> = if space.at_goal(&search.nodes[0].q) { Some(0) } else { None };
    if best.is_none() {
        best = search.connect_goal(0).filter(|&g| space.at_goal(&search.nodes[g].q));
    }
    let mut iterations = 0;
    let mut first: Option<FirstPlan> = None;
    // the iteration and time of the first node within the task's tolerance
    let last = search.nodes.len() - 1;
    let mut outer: Option<(usize, f64)> = space.within_task(&search.nodes[last].q).then_some((0, 0.0));
    let stop = loop {
        if let Some(g) = best {
            let f = *first.get_or_insert_with(|| FirstPlan {
                planning_time_s: t0.elapsed().as_secs_f64(),
                iterations,
                switch_overs: switch_overs(&search.nodes.path_to(g)),
                cost: search.nodes[g].cost,
            });
            if s.refine.is_finite() && iterations >= f.iterations + (s.refine * f.iterations as f64).ceil() as usize {
                break StopReason::GoalReached;
            }
        }
        if let Some(r) = stop_reason(s, best.map(|g| search.nodes[g].cost), &t0, search.nodes.len(), iterations) {
            break r;
        }
        if let (None, Some((k, t))) = (best, outer) {
            let more = 1.0 + s.refine;
            if (iterations - k) as f64 >= more * k.max(MIN_INNER_ITERATIONS) as f64
                || t0.elapsed().as_secs_f64() - t >= more * t.max(MIN_INNER_TIME_S)
            {
                break StopReason::GoalReached;
            }
        }
        crate::interrupt::check()?;
        iterations += 1;
        let Some(i) = search.grow() else { continue };
        // the new node, or the end of a chain from it towards the goal (which may stop short)
        let end = if space.at_goal(&search.nodes[i].q) { Some(i) } else { search.connect_goal(i) };
        match end {
            Some(g) if space.at_goal(&search.nodes[g].q) => search.nodes.keep_cheaper(&mut best, g),
            _ if outer.is_none() && space.within_task(&search.nodes[search.nodes.len() - 1].q) => {
                outer = Some((iterations, t0.elapsed().as_secs_f64()));
            }
            _ => {}
        }
    };
    // rewiring may have made another goal node the cheapest
    if best.is_some() {
        best = search.nodes.cheapest(|q| space.at_goal(q));
    } else if outer.is_some() {
        best = search.nodes.cheapest(|q| space.within_task(q));
        if let Some(g) = best {
            first = Some(FirstPlan {
                planning_time_s: t0.elapsed().as_secs_f64(),
                iterations,
                switch_overs: switch_overs(&search.nodes.path_to(g)),
                cost: search.nodes[g].cost,
            });
        }
    }
    let end = best.unwrap_or(search.closest.0);
    let path = search.nodes.path_to(end);
    let plan = Plan {
        found: best.is_some(),
        stop_reason: if best.is_some() { StopReason::GoalReached } else { stop },
        goal_distance: path.last().map_or(f64::INFINITY, |p| space.dist(&p.0, space.goal())),
        cost: search.nodes[end].cost,
        switch_overs: switch_overs(&path),
        path,
        nodes: search.nodes.len(),
        iterations,
        planning_time_s: t0.elapsed().as_secs_f64(),
        reason: None,
        first,
    };
    Ok((plan, search.nodes.into_nodes()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn transition_test_adapts_the_temperature() {
        let settings = SearchSettings::default();
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let mut t = Transition { temperature: 0.1, ..Transition::new(&settings, 10.0) };
        assert!(t.test(&mut rng, 1.0, 0.9, 0.1), "downhill is always accepted");
        assert!(!t.test(&mut rng, 1.0, 11.0, 0.1), "above c_max is rejected");
        // steep uphill is rejected and, after n_fail rejections, the temperature rises
        let t0 = t.temperature;
        for _ in 0..=settings.n_fail {
            assert!(!t.test(&mut rng, 1.0, 2.0, 0.1));
        }
        assert!(t.temperature > t0);
    }
}
