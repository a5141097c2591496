//! The planar space of the T-RRT* ([`crate::planning::trrt`]): object poses `q = [x, z, θ]` in
//! the grasp where the finger pad lies on the object and the grasp holds it (thesis §4.1, §4.3).
//!
//! * **Metric**: `d(q, q')² = Δx² + Δz² + (L Δθ)²` (L: the object's radius of gyration), the
//!   same weighting of rotation against translation as the motion cones.
//! * **Unit-step propagation** (Fig 4-9), by [`Propagation`]: the motion cones (the desired step
//!   is taken when some pusher's exact cone contains it, else projected on each cone and the
//!   closest kept, preferring the parent's pusher); or the baselines — random steps kept when a
//!   force-balance feasibility LP passes (ICRA 2018 "stable check"), or the inverse quasi-static
//!   complementarity dynamics (thesis §4.2.1).
//! * Every accepted step is checked along its length by the exact motion-cone test (`checks`
//!   poses), so that a plan's steps are feasible, not only at their start.

use crate::cones::motion_cone::{project_with_margin, SupportFrame};
use crate::dynamics::mncp;
use crate::dynamics::planar::{push_problem, Options as QsOptions, SupportModel};
use crate::error::{Error, Result};
use crate::mechanics::geometry::{rot, Vec2, Vec3};
use crate::planning::guide::Guide;
use crate::planning::point_step;
use crate::planning::tree::pusher_order;
use crate::planning::trrt::{self, gauss, Chain, SearchSettings, Space, SpaceCore, Step};
use crate::pose::planar::{body_twist, distance, integrate};
use crate::scene::Scene;
use rand::Rng;
use rand_chacha::ChaCha8Rng;

pub use crate::planning::trrt::StopReason;

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

/// Settings of the planar planner (defaults in [`PlanarSettings::default`]; the unit step
/// defaults to a tenth of L).
#[derive(Clone, Debug)]
pub struct PlanarSettings {
    pub search: SearchSettings,
    /// Smallest margin of the exact test at the start of an accepted step.
    pub margin: f64,
    pub propagation: Propagation,
    /// A plain goal-biased RRT (no transition test, no RRT*, no preference for the parent's
    /// pusher, no straight-push connection): the reference for the switch-over count.
    pub plain: bool,
    /// When the pad's straight path leaves the object, the share of samples drawn along its guide
    /// path just ahead of the tree, whose length left is then T-RRT's cost map ([`Guide`]; 0: no
    /// guide, uniform samples and the metric's distance; none for a `plain` RRT).
    pub guide: f64,
}

impl Default for PlanarSettings {
    fn default() -> Self {
        Self { search: SearchSettings::default(), margin: 0.01, propagation: Propagation::MotionCone, plain: false, guide: 0.7 }
    }
}

impl PlanarSettings {
    /// Checks every setting (errors name the setting).
    pub fn check(&self) -> Result<()> {
        self.search.check()?;
        if !(self.margin.is_finite() && self.margin >= 0.0) {
            return Err(Error::arg("margin", format!("must be a finite, non-negative number (got {})", self.margin)));
        }
        if !(0.0..=1.0).contains(&self.guide) {
            return Err(Error::arg("guide", format!("must be in [0, 1] (got {})", self.guide)));
        }
        Ok(())
    }
}

/// A planar plan: poses and the pusher reaching each (None for the start).
pub type PlanarPlan = trrt::Plan<[f64; 3], ()>;

/// The planar space: a scene, a goal with its tolerance, and the planner's settings.
pub struct PlanarSpace<'a> {
    core: SpaceCore<[f64; 3]>,
    scene: &'a Scene,
    s: &'a PlanarSettings,
    /// The goal's inner tolerance ([`SearchSettings::goal_share`] of `task_tol`) and the task's.
    tol: [f64; 3],
    task_tol: [f64; 3],
    bounds: ([f64; 2], [f64; 2], [f64; 2]),
    qs_opts: QsOptions,
    /// The pad's path around walls, when the straight one leaves the object.
    guide: Option<Guide>,
}

impl<'a> PlanarSpace<'a> {
    /// The space between `start` and `goal` (checked: finite, pad on the object, grasp holding).
    pub fn new(scene: &'a Scene, start: [f64; 3], goal: [f64; 3], tol: [f64; 3], s: &'a PlanarSettings) -> Result<Self> {
        for (name, q) in [("start", &start), ("goal", &goal)] {
            if !q.iter().all(|x| x.is_finite()) {
                return Err(Error::arg(name, "has a non-finite component"));
            }
            if !scene.admissible(q) {
                return Err(Error::arg(name, format!("{q:?} is not admissible: the finger pad is not entirely on the object")));
            }
            // a goal may lie where the grasp cannot hold: the certificate decides
            // ([`crate::planning::reachability::cannot_hold`])
            if name == "start" && !(scene.hold_ratio(q) < 1.0) {
                return Err(Error::arg(name, format!("{q:?}: the grasp cannot hold the object against gravity there")));
            }
        }
        s.check()?;
        // the region of poses where the pad can be on the object: t = −R c for c on the object
        let reach = scene.outline.vertices().iter().map(|v| v.norm()).fold(0.0, f64::max);
        let m = s.search.theta_margin;
        let (tlo, thi) = (start[2].min(goal[2]) - m, start[2].max(goal[2]) + m);
        let step = s.search.step.unwrap_or(0.1 * scene.length);
        Ok(Self {
            core: SpaceCore { search: s.search.clone(), length: scene.length, step, pushers: scene.pushers.len(), goal },
            scene,
            s,
            tol: tol.map(|t| t * s.search.goal_share),
            task_tol: tol,
            bounds: ([-reach, reach], [-reach, reach], [tlo, thi]),
            qs_opts: QsOptions { support: SupportModel::Points { rings: 2, points: 0, merge_fingers: true }, ..QsOptions::default() },
            guide: None, // built once the certificates have let the search go ([`plan_tree`])
        })
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
    /// of it further on), and the pad on the object all along ([`Self::pad_stays_on`]). A point
    /// pusher's step is its flow ([`point_step`]), which must land on `integrate(q, tw, 1)`.
    fn step_feasible(&self, q: &[f64; 3], tw: &Vec3, p: usize) -> bool {
        let n = self.s.search.checks.max(1);
        if point_step::contact_point(self.scene, p).is_some() {
            return point_step::check(self.scene, p, q, &integrate(q, tw, 1.0), n)
                .is_some_and(|(fl, miss)| miss <= point_step::LANDING_TOL && self.flow_feasible(&fl));
        }
        let model = &self.scene.pushers[p].model;
        let poses: Vec<[f64; 3]> = (0..=n).map(|k| if k == 0 { *q } else { integrate(q, tw, k as f64 / n as f64) }).collect();
        for (k, qk) in poses[..n].iter().enumerate() {
            let Some(f) = self.frame(qk) else { return false };
            if f.classify(model, tw).margin < if k == 0 { self.s.margin } else { 0.5 * self.s.margin } {
                return false;
            }
        }
        self.frame(&poses[n]).is_some() && self.pad_stays_on(&poses)
    }

    /// A point pusher's flow ([`point_step`]): margin ≥ `margin` at the start, ≥ half of it
    /// further on, and the pad on the object all along.
    fn flow_feasible(&self, fl: &point_step::Flow) -> bool {
        fl.first_margin >= self.s.margin && fl.margin >= 0.5 * self.s.margin && self.pad_stays_on(&fl.poses)
    }

    /// Whether the pad stays on the object between consecutive `poses`: at each interior pose
    /// its clearance exceeds how far it moves to the neighbouring poses.
    fn pad_stays_on(&self, poses: &[[f64; 3]]) -> bool {
        let pad = |x: &[f64; 3]| rot(-x[2]) * Vec2::new(-x[0], -x[1]);
        let pads: Vec<Vec2> = poses.iter().map(pad).collect();
        (1..poses.len().saturating_sub(1)).all(|k| {
            let reach = (pads[k] - pads[k - 1]).norm().max((pads[k + 1] - pads[k]).norm());
            self.scene.pad_clearance(&poses[k]) >= 1.1 * reach
        })
    }

    /// Whether the inverse quasi-static dynamics find pusher forces for step `tw` with pusher `p`.
    fn mncp_feasible(&self, q: &[f64; 3], tw: &Vec3, p: usize) -> bool {
        let Ok(prob) = push_problem(self.scene, q, p, &self.qs_opts) else { return false };
        let v = nalgebra::DVector::from_row_slice(tw.as_slice());
        mncp::solve_inverse(&prob, &v, &mncp::Settings::default()).is_ok()
    }

    /// The propagation's own feasibility test of a step (exact cone along the step, the
    /// stable-check LP, or the inverse complementarity dynamics).
    fn feasible(&self, q: &[f64; 3], tw: &Vec3, p: usize) -> bool {
        match self.s.propagation {
            Propagation::MotionCone => self.step_feasible(q, tw, p),
            Propagation::StableCheck => stable_push_lp(self.scene, q, p, tw) && self.frame(&integrate(q, tw, 1.0)).is_some(),
            Propagation::Mncp => self.mncp_feasible(q, tw, p) && self.frame(&integrate(q, tw, 1.0)).is_some(),
        }
    }

    fn step_to(&self, q: &[f64; 3], p: usize, tw: Vec3) -> Step<[f64; 3], ()> {
        Step { q: integrate(q, &tw, 1.0), pusher: p, edge: (), length: self.scene.metric().twist_norm(&tw) }
    }

    /// The desired unit step towards `target` (its body twist) and the whole twist's length.
    fn desired(&self, q: &[f64; 3], target: &[f64; 3]) -> Option<(Vec3, f64)> {
        let xi = body_twist(q, target);
        let len = self.scene.metric().twist_norm(&xi);
        (len >= 1e-12).then(|| (xi * (self.core.step.min(len) / len), len))
    }

    /// Propagation by motion cones: the desired step if some cone contains it (parent's pusher
    /// first), else its projections, the closest in angle kept (parent's pusher preferred). A
    /// point pusher's candidate is its steered step along its best contact direction
    /// ([`Self::point_direction`], [`Self::point_step`]).
    fn propagate_cones(&self, q: &[f64; 3], parent_pusher: Option<usize>, target: &[f64; 3]) -> Option<Step<[f64; 3], ()>> {
        let (want, len) = self.desired(q, target)?;
        let m = self.scene.metric();
        let frame = self.frame(q)?;
        let order = pusher_order(self.scene.pushers.len(), if self.s.plain { None } else { parent_pusher });
        let point = |p: usize| point_step::contact_point(self.scene, p);
        // 1. the desired step itself
        for &p in order.iter().filter(|&&p| point(p).is_none()) {
            if frame.classify(&self.scene.pushers[p].model, &want).margin >= self.s.margin && self.step_feasible(q, &want, p) {
                return Some(self.step_to(q, p, want));
            }
        }
        // 2. projections on each cone; a point pusher's step with the desired contact velocity
        let wn = m.twist_norm(&want);
        let mut best: Option<(f64, usize, Vec3, bool)> = None;
        // point pushers: the best contact direction of each; the two best steered, in order
        let mut points: Vec<(f64, usize, Vec2, Vec2)> = order
            .iter()
            .filter_map(|&p| {
                let r = point(p)?;
                let (cos, d) = self.point_direction(&frame, p, &r, &want)?;
                let bonus = if Some(p) == parent_pusher && !self.s.plain { 0.05 } else { 0.0 };
                Some((cos + bonus, p, r, d))
            })
            .collect();
        points.sort_by(|a, b| b.0.total_cmp(&a.0));
        if let Some(step) = points.iter().take(2).find_map(|(_, p, r, d)| self.point_step(q, &frame, *p, parent_pusher, r, d, &want)) {
            best = Some(step);
        }
        for &p in order.iter().filter(|&&p| point(p).is_none()) {
            let (v, done) = match project_with_margin(&frame, &self.scene.pushers[p].model, &want, self.s.margin) {
                Some(v) => (v, false),
                None => continue,
            };
            let vn = m.twist_norm(&v);
            if vn < 1e-12 {
                continue;
            }
            let cos = m.twist(&v).dot(&m.twist(&want)) / (vn * wn);
            let bonus = if Some(p) == parent_pusher && !self.s.plain { 0.05 } else { 0.0 };
            if cos > 0.2 && best.as_ref().is_none_or(|b| cos + bonus > b.0) {
                best = Some((cos + bonus, p, v, done));
            }
        }
        let (_, p, v, done) = best?;
        if done {
            return Some(self.step_to(q, p, v)); // a point pusher's step, feasible along its flow
        }
        // a step of the unit length along the projection, halved until feasible along it
        let mut tw = v * (self.core.step.min(len) / m.twist_norm(&v));
        for _ in 0..4 {
            if self.step_feasible(q, &tw, p) {
                return Some(self.step_to(q, p, tw));
            }
            tw *= 0.5;
        }
        None
    }

    /// Point pusher `p` (contact `r`): of the contact-point velocity directions (16 around, the
    /// one of `want`, and the two halfway beside the best) whose twist at `q` has margin ≥
    /// `margin`, the one whose twist is closest in angle to `want` (cosine > 0.2): (cosine,
    /// direction). Each root search is warm-started at its neighbour's.
    fn point_direction(&self, frame: &SupportFrame, p: usize, r: &Vec2, want: &Vec3) -> Option<(f64, Vec2)> {
        let m = self.scene.metric();
        let (mw, wn) = (m.twist(want), m.twist_norm(want));
        let model = &self.scene.pushers[p].model;
        let mut hint = None;
        let mut score = |d: &Vec2| -> Option<f64> {
            let (v, phi) = frame.point_twist_near(r, d, self.scene.length, hint)?;
            hint = Some(phi);
            let cos = m.twist(&v).dot(&mw) / (m.twist_norm(&v) * wn);
            (cos > 0.2 && frame.classify(model, &v).margin >= self.s.margin).then_some(cos)
        };
        let at = |a: f64| Vec2::new(a.cos(), a.sin());
        let step = std::f64::consts::PI / 8.0;
        let mut best: Option<(f64, f64)> = None; // (cosine, angle)
        for k in 0..16 {
            let a = k as f64 * step;
            if let Some(c) = score(&at(a)) {
                if best.is_none_or(|b| c > b.0) {
                    best = Some((c, a));
                }
            }
        }
        let own = Vec2::new(want.x, want.y) + crate::mechanics::geometry::perp(r) * want.z;
        let mut candidates = vec![own.y.atan2(own.x)];
        if let Some((_, a)) = best {
            candidates.extend([a - 0.5 * step, a + 0.5 * step]);
        }
        for a in candidates {
            if let Some(c) = score(&at(a)) {
                if best.is_none_or(|b| c > b.0) {
                    best = Some((c, a));
                }
            }
        }
        best.map(|(c, a)| (c, at(a)))
    }

    /// The step of point pusher `p` along contact direction `d`: the pusher twist of
    /// [`point_step::steer`] moving the object about as far as `want`, halved until its flow is
    /// feasible; (cosine to `want` with the parent's bonus, pusher, twist, true: a finished step)
    /// for [`Self::propagate_cones`].
    #[allow(clippy::too_many_arguments)]
    fn point_step(&self, q: &[f64; 3], frame: &SupportFrame, p: usize, parent_pusher: Option<usize>, r: &Vec2, d: &Vec2, want: &Vec3) -> Option<(f64, usize, Vec3, bool)> {
        let m = self.scene.metric();
        let v = frame.point_twist(r, d, self.scene.length)?;
        let mut ub = d * (m.twist_norm(want) / m.twist_norm(&v));
        for _ in 0..4 {
            if let Some((xi, fl)) = point_step::steer(self.scene, p, q, &ub, self.s.search.checks) {
                if self.flow_feasible(&fl) {
                    let cos = m.twist(&xi).dot(&m.twist(want)) / (m.twist_norm(&xi) * m.twist_norm(want));
                    let bonus = if Some(p) == parent_pusher && !self.s.plain { 0.05 } else { 0.0 };
                    return (cos > 0.2).then_some((cos + bonus, p, xi, true));
                }
            }
            ub *= 0.5;
        }
        None
    }

    /// Two steps of point pushers from `q` into the goal's tolerance ([`point_step::connect`]),
    /// each feasible and at most 20 unit steps long.
    fn connect_points(&self, q: &[f64; 3], order: &[usize]) -> Option<Chain<[f64; 3], ()>> {
        let m = self.scene.metric();
        let accept = |fl: &point_step::Flow| self.flow_feasible(fl) && self.dist(&fl.poses[0], &fl.end()) <= 20.0 * self.core.step;
        let (ps, st) = point_step::connect(self.scene, order, q, &self.core.goal, &self.tol, self.s.search.checks, self.s.margin, accept)?;
        Some(vec![(st[0].2, ps[0], (), m.twist_norm(&st[0].0)), (st[1].2, ps[1], (), m.twist_norm(&st[1].0))])
    }

    /// Random unit steps for the baselines: the stable check (directions in the target's
    /// half-space, ICRA 2018) or the MNCP (the desired direction first, then within about 30°).
    fn propagate_random(&self, rng: &mut ChaCha8Rng, q: &[f64; 3], pusher: Option<usize>, target: &[f64; 3]) -> Option<Step<[f64; 3], ()>> {
        let (want, _) = self.desired(q, target)?;
        let m = self.scene.metric();
        let wl = m.twist_norm(&want);
        let dir = m.twist(&want) / wl;
        self.frame(q)?;
        let order = pusher_order(self.scene.pushers.len(), pusher);
        for k in 0..self.s.search.random_tries {
            let r = Vec3::new(gauss(rng), gauss(rng), gauss(rng));
            let d = match self.s.propagation {
                Propagation::Mncp if k == 0 => dir,
                Propagation::Mncp => (dir + (r - dir * r.dot(&dir)) * 0.3).normalize(),
                _ => {
                    let r = r.normalize();
                    if r.dot(&dir) < 0.0 { -r } else { r }
                }
            };
            let tw = m.twist_inv(&(d * wl));
            for &p in &order {
                if self.feasible(q, &tw, p) {
                    return Some(self.step_to(q, p, tw));
                }
            }
        }
        None
    }
}

impl Space<3> for PlanarSpace<'_> {
    type Q = [f64; 3];
    type Edge = ();
    type Motion = Vec3;

    fn core(&self) -> &SpaceCore<[f64; 3]> {
        &self.core
    }
    fn root_edge(&self) {}
    fn key(&self, q: &[f64; 3]) -> [f64; 3] {
        [q[0], q[1], self.scene.length * q[2]]
    }
    fn dist(&self, a: &[f64; 3], b: &[f64; 3]) -> f64 {
        distance(self.scene.length, a, b)
    }
    fn at_goal(&self, q: &[f64; 3]) -> bool {
        (0..3).all(|k| (q[k] - self.core.goal[k]).abs() <= self.tol[k])
    }
    fn within_task(&self, q: &[f64; 3]) -> bool {
        (0..3).all(|k| (q[k] - self.core.goal[k]).abs() <= self.task_tol[k])
    }
    /// Around walls, the pad's distance left along its guide path combined with the turn left.
    fn cost_to_go(&self, q: &[f64; 3]) -> f64 {
        let l = self.scene.length;
        match (&self.guide, self.scene.pad_disc(q)) {
            (Some(g), Some((c, _))) => g.to_go(&c).hypot(l * (q[2] - self.core.goal[2])) / l,
            _ => self.dist(q, &self.core.goal) / l,
        }
    }
    /// Uniform in the bounds; around walls, a share `guide` of the samples just ahead of the
    /// closest node along the pad's guide path ([`Guide::sample`]).
    fn sample(&self, rng: &mut ChaCha8Rng, _start: &[f64; 3], closest: &[f64; 3]) -> [f64; 3] {
        let (bx, bz, bt) = self.bounds;
        let guided = self.guide.as_ref().filter(|_| rng.random::<f64>() < self.s.guide);
        let from = guided.zip(self.scene.pad_disc(closest)).map_or(0.0, |(g, (c, _))| g.project(&c).0);
        for _ in 0..100 {
            let q = match guided {
                Some(g) => g.sample(rng, from, self.core.step, self.scene.length, self.core.goal[2]),
                None => [rng.random_range(bx[0]..=bx[1]), rng.random_range(bz[0]..=bz[1]), rng.random_range(bt[0]..=bt[1])],
            };
            if self.scene.admissible(&q) {
                return q;
            }
        }
        self.core.goal
    }
    fn propagate(&self, rng: &mut ChaCha8Rng, q: &[f64; 3], pusher: Option<usize>, target: &[f64; 3]) -> Option<Step<[f64; 3], ()>> {
        match self.s.propagation {
            Propagation::MotionCone => self.propagate_cones(q, pusher, target),
            Propagation::StableCheck | Propagation::Mncp => self.propagate_random(rng, q, pusher, target),
        }
    }
    fn interpolate(&self, a: &[f64; 3], b: &[f64; 3]) -> (Vec3, f64) {
        let tw = body_twist(a, b);
        (tw, self.scene.metric().twist_norm(&tw))
    }
    /// RRT*'s steps between tree nodes. Not for a point pusher: the poses one of its steps
    /// reaches from `a` form a surface (the rotation follows the contact velocity), which
    /// another node lies on with probability zero, so its flow is not tried.
    fn take(&self, a: &[f64; 3], tw: &Vec3, p: usize) -> Option<()> {
        if point_step::contact_point(self.scene, p).is_some() {
            return None;
        }
        self.step_feasible(a, tw, p).then_some(())
    }
    /// Straight push to the goal: unit steps of one constant body twist, all feasible for one
    /// pusher (the node's first), at most 200 of them; else, within three unit steps of the
    /// goal, two steps of point pushers ([`point_step::connect`]).
    fn connect_goal(&self, q: &[f64; 3], pusher: Option<usize>) -> Option<Chain<[f64; 3], ()>> {
        let xi = body_twist(q, &self.core.goal);
        let len = self.scene.metric().twist_norm(&xi);
        if len < 1e-12 {
            return None;
        }
        let n = (len / self.core.step).ceil().max(1.0) as usize;
        if n > 200 {
            return None;
        }
        let tw = xi / n as f64;
        let poses: Vec<[f64; 3]> = (1..=n).scan(*q, |qk, _| {
            *qk = integrate(qk, &tw, 1.0);
            Some(*qk)
        }).collect();
        let starts = std::iter::once(*q).chain(poses.iter().copied().take(n - 1)).collect::<Vec<_>>();
        let order = pusher_order(self.scene.pushers.len(), pusher);
        // a point pusher's step lands on a surface of poses: the straight push is not its
        let line = |p: usize| point_step::contact_point(self.scene, p).is_none();
        if let Some(p) = order.iter().copied().filter(|&p| line(p)).find(|&p| starts.iter().all(|qk| self.feasible(qk, &tw, p))) {
            return Some(trrt::one_pusher(p, poses.into_iter().map(|qk| (qk, (), len / n as f64)).collect()));
        }
        if n > 3 || self.s.propagation != Propagation::MotionCone {
            return None;
        }
        self.connect_points(q, &order)
    }
    fn rewires(&self) -> bool {
        self.s.propagation == Propagation::MotionCone
    }
    fn plain(&self) -> bool {
        self.s.plain
    }
}

/// Plans a regrasp from `start` to `goal` (defaults: the scene's task; tolerance the task's,
/// else 1 mm, 1 mm, 1°).
pub fn plan(scene: &Scene, start: Option<[f64; 3]>, goal: Option<[f64; 3]>, settings: &PlanarSettings) -> Result<PlanarPlan> {
    plan_tree(scene, start, goal, settings).map(|(r, _)| r)
}

/// [`plan`], also returning the search tree.
pub fn plan_tree(
    scene: &Scene,
    start: Option<[f64; 3]>,
    goal: Option<[f64; 3]>,
    settings: &PlanarSettings,
) -> Result<(PlanarPlan, Vec<crate::planning::tree::TreeNode<[f64; 3], ()>>)> {
    let task = scene.task;
    let start = start.or(task.map(|t| t.start)).ok_or_else(|| Error::arg("start", "the scene has no task: give a start"))?;
    let goal = goal.or(task.map(|t| t.goal)).ok_or_else(|| Error::arg("goal", "the scene has no task: give a goal"))?;
    let tol = scene.tolerance();
    let t0 = std::time::Instant::now();
    let mut space = PlanarSpace::new(scene, start, goal, tol, settings)?;
    let reach = crate::planning::reachability::unreachable(scene, &start, &goal, &tol);
    let reach = reach
        .or_else(|| crate::planning::reachability::cannot_hold(scene, &goal, &tol))
        .or_else(|| crate::planning::reachability::one_way(scene, &start, &goal, &tol, space.bounds.2));
    if let Some(reason) = reach {
        let root = crate::planning::tree::TreeNode { q: start, parent: None, pusher: None, edge: (), cost: 0.0, children: vec![] };
        return Ok((unreachable_plan(&space, start, reason, t0), vec![root]));
    }
    // the guide around walls (not for the plain RRT, the switch-overs' reference)
    if settings.guide > 0.0 && !settings.plain {
        space.guide = Guide::new(scene, &start, &goal);
    }
    let before = t0.elapsed().as_secs_f64(); // the checks, the certificates and the guide count as planning time
    trrt::plan_tree(&space, start).map(|(mut r, nodes)| {
        r.planning_time_s += before;
        if let Some(f) = r.first.as_mut() {
            f.planning_time_s += before;
        }
        (r, nodes)
    })
}

/// The answer for a goal decided unreachable: the start alone, its distance to the goal.
fn unreachable_plan(space: &PlanarSpace, start: [f64; 3], reason: String, t0: std::time::Instant) -> PlanarPlan {
    trrt::Plan {
        found: false,
        stop_reason: StopReason::Unreachable,
        goal_distance: space.dist(&start, space.goal()),
        cost: 0.0,
        switch_overs: 0,
        path: vec![(start, None, ())],
        nodes: 1,
        iterations: 0,
        planning_time_s: t0.elapsed().as_secs_f64(),
        reason: Some(reason),
        first: None,
    }
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
/// the finger pad leaves the object or the grasp cannot hold it somewhere along the step). A
/// point pusher's step is its flow ([`point_step`], `checks` RK4 steps per tenth of L of the
/// step's length, as a unit step of the planner has at its defaults): the margins along it,
/// and minus the miss (over L) when it lands farther than [`point_step::LANDING_TOL`] from the
/// step's end. An error names a step whose pusher is missing or unknown.
pub fn validate_path(scene: &Scene, path: &[([f64; 3], Option<usize>)], checks: usize) -> Result<Vec<f64>> {
    let mut out = Vec::new();
    for (i, w) in path.windows(2).enumerate() {
        crate::interrupt::check()?;
        let (a, b) = (w[0].0, w[1].0);
        let p = w[1].1.ok_or_else(|| Error::arg(format!("path[{}].pusher", i + 1), "is missing"))?;
        if p >= scene.pushers.len() {
            return Err(Error::arg(format!("path[{}].pusher", i + 1), "is not a pusher of the scene"));
        }
        let tw = body_twist(&a, &b);
        let mut worst = f64::INFINITY;
        let n = checks.max(1);
        if point_step::contact_point(scene, p).is_some() && tw.amax() > 0.0 {
            out.push(match point_step::check(scene, p, &a, &b, n) {
                None => -1.0,
                Some((fl, miss)) => fl.first_margin.min(fl.margin).min(if miss > point_step::LANDING_TOL { -miss } else { f64::INFINITY }),
            });
            continue;
        }
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

    fn with(search: SearchSettings) -> PlanarSettings {
        PlanarSettings { search, ..PlanarSettings::default() }
    }


    /// After choose-parent and rewiring, every node's cost is its parent's plus the edge cost.
    #[test]
    fn rewiring_keeps_costs_consistent() {
        let s = scene("t-shape.toml");
        let mut settings = PlanarSettings::default();
        settings.search = SearchSettings { seed: 5, refine: f64::INFINITY, max_iterations: 3000, connect: false, ..SearchSettings::default() };
        let (_, nodes) = plan_tree(&s, None, None, &settings).unwrap();
        assert!(nodes.len() > 100);
        let m = s.metric();
        let sd = &settings.search;
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
        assert!(plan(&s, Some([0.03, 0.0, 0.0]), None, &PlanarSettings::default()).is_err());
        // NaN goal
        assert!(plan(&s, None, Some([f64::NAN, 0.0, 0.0]), &PlanarSettings::default()).is_err());
        // zero budget: not found, says why, returns the start as the partial path
        let r = plan(&s, None, None, &with(SearchSettings { time_limit: 0.0, connect: false, ..SearchSettings::default() })).unwrap();
        assert!(!r.found && r.stop_reason == StopReason::TimeLimit && r.path.len() == 1);
        // unreachable: only the top pusher (pushes down) for a goal above the start
        let text = include_str!("../../../../examples/block-low-friction.toml");
        let top_only = text.split("[[pushers]]").enumerate().filter(|(i, p)| *i == 0 || p.contains("name = \"top\"")).map(|(i, p)| if i == 0 { p.to_string() } else { format!("[[pushers]]{p}") }).collect::<String>();
        let s2 = Scene::from_toml_str(&top_only).unwrap();
        assert_eq!(s2.pushers.len(), 1);
        let r = plan(&s2, None, Some([0.0, 0.01, 0.0]), &with(SearchSettings { time_limit: 0.3, ..SearchSettings::default() })).unwrap();
        assert!(!r.found && r.stop_reason == StopReason::Unreachable && r.reason.is_some());
        assert!(r.goal_distance > 0.0);
    }

    #[test]
    fn plans_are_deterministic_and_feasible_along_every_step() {
        let s = scene("block-low-friction.toml");
        let settings = with(SearchSettings { seed: 3, ..SearchSettings::default() });
        let a = plan(&s, None, None, &settings).unwrap();
        let b = plan(&s, None, None, &settings).unwrap();
        assert!(a.found, "{a:?}");
        assert_eq!(a.path, b.path);
        let margins = validate_path(&s, &a.poses(), 16).unwrap();
        assert!(margins.iter().all(|m| *m >= -1e-9), "{margins:?}");
        let end = a.path.last().unwrap().0;
        let goal = s.task.unwrap().goal;
        assert!((0..3).all(|k| (end[k] - goal[k]).abs() <= s.task.unwrap().tolerance[k]));
    }

    /// Anytime refinement (`refine`): the final plan costs no more than the first, which is
    /// recorded; with `refine` 0 the first plan is the answer; the same seed gives the same plan.
    #[test]
    fn refinement_never_costs_more_than_the_first_plan() {
        for name in ["t-shape.toml", "block-xztheta.toml", "block-low-friction.toml"] {
            let s = scene(name);
            for seed in 0..5 {
                let r = plan(&s, None, None, &with(SearchSettings { seed, ..SearchSettings::default() })).unwrap();
                let f = r.first.expect("a first plan");
                assert!(r.found && r.cost <= f.cost + 1e-12, "{name} {seed}: {} > {}", r.cost, f.cost);
                assert!(r.iterations >= f.iterations && f.planning_time_s <= r.planning_time_s);
                let again = plan(&s, None, None, &with(SearchSettings { seed, ..SearchSettings::default() })).unwrap();
                assert_eq!(again.path, r.path);
                let first = plan(&s, None, None, &with(SearchSettings { seed, refine: 0.0, ..SearchSettings::default() })).unwrap();
                assert_eq!(first.switch_overs, f.switch_overs);
                assert!((first.cost - f.cost).abs() < 1e-12 && first.iterations == f.iterations);
            }
        }
    }
}
