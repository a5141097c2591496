//! Model-predictive control of a regrasp with motion-cone constraints (thesis §5.2,
//! Figs 5-7..5-11).
//!
//! The plan is resampled into reference knots one control period apart (at the commanded
//! speed). At each control step, from the measured pose `q₁`: find the closest knot `j` (a
//! window around the last one); reference `q*ᵢ` = knots `j+1..j+k` with the pushers that reach
//! them; solve the QP
//!
//! `min Σᵢ wᵢ‖S(qᵢ₊₁ − q*ᵢ)‖² + r Σᵢ‖αᵢ‖²  s.t.  qᵢ₊₁ = qᵢ + R(θᵢ) Gᵢ αᵢ δt,  αᵢ ≥ 0,  ‖Gᵢαᵢ‖ ≤ v_max`
//!
//! where `Gᵢ` holds the unit generators of pusher `i`'s motion cone (nominal, robust or
//! fixtureless, as the scene's mode says) at `q₁` for the first step and at the reference poses
//! after it, `R(θ)` turns body twists into pose rates, `S = diag(1, 1, L)` and `‖·‖` the twist
//! metric (the speed bound is a second-order cone: wide cones' opposite generators cannot add
//! up to a fast twist that goes nowhere).
//! The QP keeps the poses after each step as variables (banded: [`crate::control::step_qp`], clarabel).
//! The first step's twist `G₁α₁` is checked with the exact test at `q₁` and projected into the
//! exact cone (with a margin) when the polyhedral approximation overshoots it; and since the
//! polyhedral approximation can also miss directions of the exact cone, each step's generators
//! include the reference's own twist (or its projection on the exact cone).
//!
//! Re-planning (Fig 5-11): when no push of the horizon helps (the command vanishes), or the
//! distance to the goal has not shrunk for `stall_steps` steps, or the object is off the plan by
//! more than `replan_error` steps and not getting closer for `stall_steps` steps, the T-RRT*
//! planner is called from the measured pose.

use crate::error::{Error, Result};
use crate::mechanics::geometry::Vec3;
use crate::cones::motion_cone::{project_exact_with_margin, project_with_margin_on};
use crate::dynamics::planar::integrate;
use crate::cones::robust::generators;
use crate::cones::frame::{ConeMode, PusherModel, SupportFrame};
use crate::scene::planar::Scene;
use crate::planning::planar::{self as trrt, PlanarSettings};
use crate::planning::trrt::SearchSettings;
use crate::pose::planar::body_twist;
use crate::control::step_qp::{self, Weights};
use clarabel::solver::{DefaultSettings, DefaultSolver, IPSolver, SolverStatus};
use std::time::Instant;

/// Controller settings.
#[derive(Clone, Debug)]
pub struct MpcSettings {
    /// Control period δt [s].
    pub dt: f64,
    /// Horizon (steps).
    pub horizon: usize,
    /// Largest speed [m/s, metric] of a commanded twist; also the reference's speed.
    pub speed: f64,
    /// Weight of the tracking error of each step and of the last one.
    pub stage_weight: f64,
    pub terminal_weight: f64,
    /// Weight on the generator weights (effort), in units of (one step)².
    pub effort_weight: f64,
    /// Smallest margin of the exact test for the executed twist.
    pub margin: f64,
    /// Steps without progress towards the goal before re-planning.
    pub stall_steps: usize,
    /// Progress smaller than this fraction of a step does not count.
    pub progress: f64,
    /// Off the plan by more than this many steps without getting closer for `stall_steps`
    /// steps: re-plan (Fig 5-11).
    pub replan_error: f64,
    pub max_replans: usize,
    /// The goal is reached within this fraction of the task's tolerance (or within the
    /// tolerance once progress stops).
    pub goal_fraction: f64,
    /// Planner settings for re-planning.
    pub planner: PlanarSettings,
}

impl MpcSettings {
    /// Checks every setting; the error names it.
    pub fn check(&self) -> Result<()> {
        for (name, v) in [("dt", self.dt), ("speed", self.speed), ("stage_weight", self.stage_weight),
                          ("terminal_weight", self.terminal_weight), ("replan_error", self.replan_error)] {
            if !(v.is_finite() && v > 0.0) {
                return Err(Error::arg(name, format!("must be a finite, positive number (got {v})")));
            }
        }
        for (name, v) in [("effort_weight", self.effort_weight), ("margin", self.margin), ("progress", self.progress)] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(Error::arg(name, format!("must be a finite, non-negative number (got {v})")));
            }
        }
        if !(self.goal_fraction > 0.0 && self.goal_fraction <= 1.0) {
            return Err(Error::arg("goal_fraction", format!("must be in (0, 1] (got {})", self.goal_fraction)));
        }
        if !(1..=MAX_HORIZON).contains(&self.horizon) {
            return Err(Error::arg("horizon", format!("must be between 1 and {MAX_HORIZON} steps (got {})", self.horizon)));
        }
        if self.stall_steps == 0 {
            return Err(Error::arg("stall_steps", "must be at least 1"));
        }
        self.planner.check()
    }
}

/// Cosine to the reference above which its projection on the generators' span is used as it is
/// ([`Mpc::reference_twist`]).
pub const CLOSE_REFERENCE: f64 = 0.9;

/// Longest horizon (steps) of the QP.
pub const MAX_HORIZON: usize = 200;

impl Default for MpcSettings {
    fn default() -> Self {
        Self {
            dt: 0.1,
            horizon: 5,
            speed: 0.01,
            stage_weight: 1.0,
            terminal_weight: 5.0,
            effort_weight: 1e-3,
            margin: 0.01,
            stall_steps: 10,
            progress: 0.05,
            replan_error: 2.0,
            max_replans: 5,
            goal_fraction: 0.5,
            planner: PlanarSettings { search: SearchSettings { time_limit: 2.0, ..SearchSettings::default() }, ..PlanarSettings::default() },
        }
    }
}

/// What the controller does this step.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Status {
    /// A push along the plan.
    Tracking,
    /// The goal is reached (within the task's tolerance): stop.
    AtGoal,
    /// Re-planned from the measured pose this step (the command follows the new plan).
    Replanned,
    /// Nothing helps and re-planning failed or is exhausted: the command is zero.
    Stuck,
}

impl Status {
    pub fn label(&self) -> &'static str {
        match self {
            Status::Tracking => "tracking",
            Status::AtGoal => "at_goal",
            Status::Replanned => "replanned",
            Status::Stuck => "stuck",
        }
    }
}

/// One control step's answer.
#[derive(Clone, Debug)]
pub struct Command {
    pub status: Status,
    /// The pusher to use (None: no push).
    pub pusher: Option<usize>,
    /// Body twist of the object (and of the sticking pusher) [m/s, rad/s].
    pub twist: Vec3,
    /// Index of the closest reference knot.
    pub knot: usize,
    /// Metric distance to that knot [m].
    pub tracking_error: f64,
    /// Whether the QP's first twist had to be projected into the exact cone.
    pub projected: bool,
    /// Time of this step (QP build and solve, exact check) [s].
    pub solve_time_s: f64,
    /// Time spent re-planning this step [s].
    pub replan_time_s: f64,
}

/// The QP of one step: weights of each horizon step's generators.
#[derive(Clone, Debug)]
pub struct QpSolution {
    /// Per horizon step: (pusher, generators, weights).
    pub steps: Vec<(usize, Vec<Vec3>, Vec<f64>)>,
    pub status_ok: bool,
}

/// The controller: a plan's reference, the scene whose cones constrain it, and its state.
pub struct Mpc {
    scene: Scene,
    pub settings: MpcSettings,
    knots: Vec<[f64; 3]>,
    pushers: Vec<Option<usize>>,
    goal: [f64; 3],
    tol: [f64; 3],
    last_knot: usize,
    best_goal_distance: f64,
    since_progress: usize,
    best_tracking: f64,
    since_tracking: usize,
    pub replans: usize,
    /// Why the last re-planning failed (None if it did not).
    pub last_replan_error: Option<String>,
}

/// Most knots a resampled plan may have (a typo in `dt` or `speed` must not exhaust memory).
pub const MAX_KNOTS: usize = 1_000_000;

/// Resamples a path (poses and the pusher reaching each) into knots `ds` apart (metric).
pub fn resample(scene: &Scene, path: &[([f64; 3], Option<usize>)], ds: f64) -> Result<(Vec<[f64; 3]>, Vec<Option<usize>>)> {
    if path.is_empty() {
        return Err(Error::arg("plan", "is empty"));
    }
    if !(ds.is_finite() && ds > 0.0) {
        return Err(Error::arg("settings", format!("the knot spacing speed × dt must be positive (got {ds})")));
    }
    let m = scene.metric();
    let steps: Vec<f64> = path.windows(2).map(|w| m.twist_norm(&body_twist(&w[0].0, &w[1].0)) / ds).collect();
    let total: f64 = steps.iter().map(|n| n.ceil().max(1.0)).sum();
    if !(total <= MAX_KNOTS as f64) {
        return Err(Error::arg("settings", format!("speed × dt = {ds:.3e} m would cut the plan into {total:.3e} knots (at most {MAX_KNOTS})")));
    }
    let mut knots = vec![path[0].0];
    let mut pushers = vec![None];
    for (w, n) in path.windows(2).zip(steps) {
        let (a, b) = (w[0].0, w[1].0);
        let xi = body_twist(&a, &b);
        let n = n.ceil().max(1.0) as usize;
        for k in 1..=n {
            knots.push(integrate(&a, &xi, k as f64 / n as f64));
            pushers.push(w[1].1);
        }
    }
    Ok((knots, pushers))
}

impl Mpc {
    /// A controller tracking `path` (from the planner) to `goal` in `scene` (its cone mode is
    /// the controller's: robust for a robust scene).
    pub fn new(scene: &Scene, path: &[([f64; 3], Option<usize>)], goal: Option<[f64; 3]>, settings: MpcSettings) -> Result<Self> {
        if path.is_empty() {
            return Err(Error::arg("plan", "is empty"));
        }
        for (i, (q, p)) in path.iter().enumerate() {
            if !q.iter().all(|x| x.is_finite()) {
                return Err(Error::arg(format!("plan.path[{i}].pose"), "has a non-finite component"));
            }
            if let Some(p) = p {
                if *p >= scene.pushers.len() {
                    return Err(Error::arg(format!("plan.path[{i}].pusher"), "is not a pusher of the scene"));
                }
            } else if i > 0 {
                return Err(Error::arg(format!("plan.path[{i}].pusher"), "is missing"));
            }
        }
        settings.check()?;
        let goal = goal.or(scene.task.map(|t| t.goal)).unwrap_or(path[path.len() - 1].0);
        if !goal.iter().all(|x| x.is_finite()) {
            return Err(Error::arg("goal", "has a non-finite component"));
        }
        if !scene.admissible(&goal) || !(scene.hold_ratio(&goal) < 1.0) {
            return Err(Error::arg("goal", format!("{goal:?}: the pad is not on the object there or the grasp cannot hold it")));
        }
        let tol = scene.tolerance();
        let (knots, pushers) = resample(scene, path, settings.speed * settings.dt)?;
        Ok(Self {
            scene: scene.clone(),
            settings,
            knots,
            pushers,
            goal,
            tol,
            last_knot: 0,
            best_goal_distance: f64::INFINITY,
            since_progress: 0,
            best_tracking: f64::INFINITY,
            since_tracking: 0,
            replans: 0,
            last_replan_error: None,
        })
    }

    pub fn knots(&self) -> &[[f64; 3]] {
        &self.knots
    }

    pub fn knot_pushers(&self) -> &[Option<usize>] {
        &self.pushers
    }

    fn dist(&self, a: &[f64; 3], b: &[f64; 3]) -> f64 {
        let l = self.scene.length;
        ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (l * (a[2] - b[2])).powi(2)).sqrt()
    }

    /// Within `fraction` of the task's tolerance of the goal.
    fn within(&self, q: &[f64; 3], fraction: f64) -> bool {
        (0..3).all(|k| (q[k] - self.goal[k]).abs() <= fraction * self.tol[k])
    }

    /// Closest knot in a window around the last one.
    fn closest_knot(&self, q: &[f64; 3]) -> usize {
        let lo = self.last_knot.saturating_sub(5);
        let hi = (self.last_knot + 4 * self.settings.horizon + 10).min(self.knots.len() - 1);
        (lo..=hi)
            .min_by(|&a, &b| self.dist(q, &self.knots[a]).total_cmp(&self.dist(q, &self.knots[b])))
            .unwrap_or(0)
    }

    /// The generators of pusher `p`'s cone at pose `at` (none where the pad is off the object or
    /// the grasp cannot hold), plus the reference twist towards `target` or its projection on
    /// the exact cone: the polyhedral approximation may miss the reference's own direction.
    fn step_generators(&self, at: &[f64; 3], p: usize, target: &[f64; 3]) -> Vec<Vec3> {
        if !self.scene.admissible(at) {
            return Vec::new();
        }
        let f = self.scene.frame(at);
        if !(f.hold_ratio < 1.0) {
            return Vec::new();
        }
        let metric = self.scene.metric();
        let model = &self.scene.pushers[p].model;
        let mut g = generators(&f, model);
        let d = body_twist(at, target);
        if metric.twist_norm(&d) > 1e-12 && !g.is_empty() {
            if let Some(u) = self.reference_twist(&f, model, &g, &d) {
                let n = metric.twist_norm(&u);
                if n > 1e-12 {
                    g.push(u / n);
                }
            }
        }
        g
    }

    /// The reference twist `d` in the cone with the margin: its projection on the generators'
    /// span `g`, or, in a nominal cone where that is not close to `d` (cosine below
    /// [`CLOSE_REFERENCE`]), the exact projection when closer: where gravity bends the cone, the
    /// span can miss the reference's direction altogether (a heavy block slid up the pads: the
    /// edges' rays all turn it). (The exact search walks the nominal cone's boundary.)
    fn reference_twist(&self, f: &SupportFrame, model: &PusherModel, g: &[Vec3], d: &Vec3) -> Option<Vec3> {
        let metric = self.scene.metric();
        let margin = self.settings.margin;
        let cos = |u: &Vec3| metric.twist(u).dot(&metric.twist(d)) / (metric.twist_norm(u) * metric.twist_norm(d)).max(1e-300);
        let span = project_with_margin_on(f, model, g, d, margin);
        if f.mode != ConeMode::Nominal || span.as_ref().is_some_and(|u| cos(u) >= CLOSE_REFERENCE) {
            return span;
        }
        let exact = project_exact_with_margin(f, model, g, d, margin);
        match (span, exact) {
            (Some(a), Some(b)) => Some(if cos(&b) > cos(&a) { b } else { a }),
            (a, b) => a.or(b),
        }
    }

    /// The horizon's steps from pose `q` with reference knots after `j`: (pusher, generators,
    /// target knot, heading at the step's start).
    fn horizon(&self, q: &[f64; 3], j: usize) -> Vec<(usize, Vec<Vec3>, [f64; 3], f64)> {
        let n_knots = self.knots.len();
        let last_pusher = self.pushers.iter().rev().find_map(|p| *p);
        let mut steps = Vec::with_capacity(self.settings.horizon);
        for i in 0..self.settings.horizon {
            let r = (j + 1 + i).min(n_knots - 1);
            let Some(p) = self.pushers[r].or(last_pusher) else { break };
            let at = if i == 0 { *q } else { self.knots[(j + i).min(n_knots - 1)] };
            steps.push((p, self.step_generators(&at, p, &self.knots[r]), self.knots[r], at[2]));
        }
        steps
    }

    /// The QP from pose `q` with reference knots after `j`: non-negative weights of each
    /// horizon step's generators minimizing the tracking cost under the speed bound (clarabel).
    pub fn solve_qp(&self, q: &[f64; 3], j: usize) -> Result<QpSolution> {
        if !q.iter().all(|x| x.is_finite()) {
            return Err(Error::arg("pose", "has a non-finite component"));
        }
        let j = j.min(self.knots.len() - 1);
        let steps = self.horizon(q, j);
        let sizes: Vec<usize> = steps.iter().map(|s| s.1.len()).collect();
        let n: usize = sizes.iter().sum();
        if n == 0 {
            return Ok(QpSolution { steps: steps.into_iter().map(|(p, g, _, _)| (p, g, Vec::new())).collect(), status_ok: false });
        }
        let offs: Vec<usize> = sizes.iter().scan(0, |acc, &k| { let o = *acc; *acc += k; Some(o) }).collect();
        let s = &self.settings;
        let weights = Weights { stage: s.stage_weight, terminal: s.terminal_weight, effort: s.effort_weight };
        let qp = step_qp::build(q, &steps, &offs, &sizes, weights, s.speed * s.dt, self.scene.length, &self.scene.metric());
        let settings = DefaultSettings { verbose: false, ..DefaultSettings::default() };
        let mut solver = DefaultSolver::new(&qp.p, &qp.c, &qp.a, &qp.b, &qp.cones, settings)
            .map_err(|e| Error::arg("mpc", format!("QP setup failed: {e:?}")))?;
        solver.solve();
        let ok = matches!(solver.solution.status, SolverStatus::Solved | SolverStatus::AlmostSolved);
        let x = &solver.solution.x;
        let speed = self.settings.speed;
        Ok(QpSolution {
            steps: steps
                .into_iter()
                .enumerate()
                .map(|(i, (p, g, _, _))| (p, g, (0..sizes[i]).map(|k| x[offs[i] + k].max(0.0) * speed).collect()))
                .collect(),
            status_ok: ok,
        })
    }

    /// Re-plans from `q`; true when the planner returned a path (complete or partial).
    fn replan(&mut self, q: &[f64; 3]) -> bool {
        if self.replans >= self.settings.max_replans {
            return false;
        }
        self.replans += 1;
        let mut ps = self.settings.planner.clone();
        ps.search.seed = ps.search.seed.wrapping_add(self.replans as u64);
        let r = match trrt::plan(&self.scene, Some(*q), Some(self.goal), &ps) {
            Ok(r) => r,
            Err(e) => {
                self.last_replan_error = Some(e.to_string());
                return false;
            }
        };
        if r.path.len() < 2 {
            self.last_replan_error = Some(format!("the planner found no step from {q:?} ({})", r.stop_reason.label()));
            return false;
        }
        let Ok((k, p)) = resample(&self.scene, &r.poses(), self.settings.speed * self.settings.dt) else { return false };
        self.knots = k;
        self.pushers = p;
        self.last_knot = 0;
        self.best_goal_distance = f64::INFINITY;
        self.since_progress = 0;
        self.best_tracking = f64::INFINITY;
        self.since_tracking = 0;
        true
    }

    /// The first push of the QP's solution from `q` (knot `j`): (pusher, twist, whether it was
    /// projected to pass the exact test with the margin), if it moves the object at all.
    fn first_push(&self, q: &[f64; 3], j: usize) -> Result<Option<(usize, Vec3, bool)>> {
        let sol = self.solve_qp(q, j)?;
        let Some((p, gens, w)) = sol.steps.first() else { return Ok(None) };
        if !sol.status_ok || w.is_empty() {
            return Ok(None);
        }
        let v = gens.iter().zip(w).fold(Vec3::zeros(), |a, (g, &x)| a + g * x);
        let m = self.scene.metric();
        let slow = 1e-3 * self.settings.speed;
        if m.twist_norm(&v) <= slow {
            return Ok(None);
        }
        let f = self.scene.frame(q);
        let model = &self.scene.pushers[*p].model;
        if f.classify(model, &v).margin >= self.settings.margin {
            return Ok(Some((*p, v, false)));
        }
        let u = project_with_margin_on(&f, model, gens, &v, self.settings.margin).unwrap_or_else(Vec3::zeros);
        Ok((m.twist_norm(&u) > slow).then_some((*p, u, true)))
    }

    /// One control step from the measured pose `q`.
    pub fn step(&mut self, q: &[f64; 3]) -> Result<Command> {
        if !q.iter().all(|x| x.is_finite()) {
            return Err(Error::arg("pose", "has a non-finite component"));
        }
        // the measured angle on the branch of the plan's (a measurement wrapped to (−π, π]
        // must not look 2π away from a plan that crosses ±π)
        let r = self.knots[self.last_knot.min(self.knots.len() - 1)][2];
        let q = &[q[0], q[1], q[2] + std::f64::consts::TAU * ((r - q[2]) / std::f64::consts::TAU).round()];
        let t0 = Instant::now();
        // progress towards the goal
        let dg = self.dist(q, &self.goal);
        let ds = self.settings.speed * self.settings.dt;
        if dg < self.best_goal_distance - self.settings.progress * ds {
            self.best_goal_distance = dg;
            self.since_progress = 0;
        } else {
            self.since_progress += 1;
        }
        // done well inside the tolerance, or inside it once progress stops
        if self.within(q, self.settings.goal_fraction) || (self.within(q, 1.0) && self.since_progress >= 3) {
            return Ok(self.command(q, Status::AtGoal, None, Vec3::zeros(), false, t0, 0.0));
        }
        // the error from the plan: off by more than `replan_error` steps and not shrinking
        let te = self.dist(q, &self.knots[self.closest_knot(q)]);
        if te > self.settings.replan_error * ds && te > self.best_tracking - self.settings.progress * ds {
            self.since_tracking += 1;
        } else {
            self.since_tracking = 0;
        }
        self.best_tracking = self.best_tracking.min(te);
        if te <= self.settings.replan_error * ds {
            self.best_tracking = te;
        }
        let mut status = Status::Tracking;
        let mut replan_time = 0.0;
        if self.since_progress >= self.settings.stall_steps || self.since_tracking >= self.settings.stall_steps {
            let tr = Instant::now();
            if self.replan(q) {
                status = Status::Replanned;
            }
            replan_time += tr.elapsed().as_secs_f64();
            self.since_progress = 0;
            self.since_tracking = 0;
            self.best_goal_distance = dg;
        }
        for attempt in 0..2 {
            let j = self.closest_knot(q);
            self.last_knot = j;
            if let Some((p, v, projected)) = self.first_push(q, j)? {
                let mut c = self.command(q, status, Some(p), v, projected, t0, replan_time);
                c.solve_time_s -= replan_time;
                return Ok(c);
            }
            // no push of the horizon helps: re-plan once, then give up this step
            if attempt == 0 {
                let tr = Instant::now();
                let ok = self.replan(q);
                replan_time += tr.elapsed().as_secs_f64();
                if !ok {
                    break;
                }
                status = Status::Replanned;
            }
        }
        let mut c = self.command(q, Status::Stuck, None, Vec3::zeros(), false, t0, replan_time);
        c.solve_time_s -= replan_time;
        Ok(c)
    }

    fn command(&self, q: &[f64; 3], status: Status, pusher: Option<usize>, twist: Vec3, projected: bool, t0: Instant, replan: f64) -> Command {
        Command {
            status,
            pusher,
            twist,
            knot: self.last_knot,
            tracking_error: self.dist(q, &self.knots[self.last_knot.min(self.knots.len() - 1)]),
            projected,
            solve_time_s: t0.elapsed().as_secs_f64(),
            replan_time_s: replan,
        }
    }
}
