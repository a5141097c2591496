//! Planning (`regrasp::planning`): T-RRT* plans of planar and 3-D scenes as dicts, and the
//! checks of a given path.

use crate::convert::{Arg, arg, dict, optional, path, pose3, pose7, twist6};
use crate::errors::{interruptible, to_py};
use crate::settings;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use regrasp::planning::planar::{self as trrt, PlanarSettings};
use regrasp::planning::spatial::{plan3, validate_path3};
use regrasp::planning::trrt::{Plan, SearchSettings};
use regrasp::pose::spatial::to_array;
use regrasp::scene::spatial::Scene3;
use regrasp::Scene;

/// The arguments of `plan`: optional start and goal poses, optional settings overrides.
pub struct Request<'a, 'py> {
    pub start: Option<&'a Arg<'py>>,
    pub goal: Option<&'a Arg<'py>>,
    pub settings: Option<&'a Arg<'py>>,
}

impl Request<'_, '_> {
    /// The start and goal poses, each converted by `pose` when given.
    fn ends<Q>(&self, pose: impl Fn(&str, &Arg<'_>) -> PyResult<Q>) -> PyResult<(Option<Q>, Option<Q>)> {
        Ok((optional(self.start, |v| pose("start", v))?, optional(self.goal, |v| pose("goal", v))?))
    }
}

/// What a plan dict says beyond the plan: the scene's name and pushers, the propagation, the seed.
struct About<'a> {
    scene: &'a str,
    pushers: Vec<String>,
    propagation: &'a str,
    seed: u64,
}

/// A plan as a dict; `step` adds a path step's pose (and more) to the step's dict.
fn plan_dict<'py, Q, E>(
    py: Python<'py>,
    about: About<'_>,
    r: &Plan<Q, E>,
    step: impl Fn(&Bound<'py, PyDict>, &Q, Option<usize>, &E) -> PyResult<()>,
) -> PyResult<Bound<'py, PyDict>> {
    let path = r
        .path
        .iter()
        .map(|(q, p, e)| {
            let k = dict!(py; "pusher" => p.and_then(|i| about.pushers.get(i)));
            step(&k, q, *p, e)?;
            Ok(k)
        })
        .collect::<PyResult<Vec<_>>>()?;
    Ok(dict!(py;
        "scene" => about.scene, "found" => r.found, "stop_reason" => r.stop_reason.label(),
        "planning_time_s" => r.planning_time_s, "nodes" => r.nodes, "iterations" => r.iterations,
        "switch_overs" => r.switch_overs, "cost" => r.cost, "goal_distance" => r.goal_distance,
        "propagation" => about.propagation, "seed" => about.seed, "path" => path, "reason" => r.reason.as_deref(),
        "first_time_s" => r.first.map(|f| f.planning_time_s), "first_switch_overs" => r.first.map(|f| f.switch_overs),
    ))
}

/// `Scene.plan`: a planar plan from `start` to `goal` (default: the task's) with `settings`
/// overriding `planner_defaults(2)`.
pub fn plan_planar<'py>(py: Python<'py>, scene: &Scene, r: Request<'_, 'py>) -> PyResult<Bound<'py, PyDict>> {
    let ((start, goal), s) = (r.ends(pose3)?, settings::planar(r.settings)?);
    let plan = interruptible(py, || trrt::plan(scene, start, goal, &s))?;
    let pushers = scene.pushers.iter().map(|p| p.name.clone()).collect();
    let about = About { scene: &scene.name, pushers, propagation: s.propagation.label(), seed: s.search.seed };
    plan_dict(py, about, &plan, |k, q, _, _| k.set_item("pose", q.to_vec()))
}

/// `Scene3D.plan`: a 3-D plan (poses `[x, y, z, qw, qx, qy, qz]`, each step's pusher twist),
/// `settings` overriding `planner_defaults(3)`; the dict also gives the number of solves.
pub fn plan_spatial<'py>(py: Python<'py>, scene: &Scene3, r: Request<'_, 'py>) -> PyResult<Bound<'py, PyDict>> {
    let ((start, goal), s) = (r.ends(pose7)?, settings::spatial(r.settings)?);
    let r = interruptible(py, || plan3(scene, start, goal, &s))?;
    let about = About {
        scene: &scene.name,
        pushers: scene.pushers.iter().map(|p| p.name.clone()).collect(),
        propagation: "mncp_inverse",
        seed: s.search.seed,
    };
    let d = plan_dict(py, about, &r.plan, |k, q, p, u| {
        k.set_item("pose", to_array(q).to_vec())?;
        if p.is_some() {
            k.set_item("pusher_twist", u.to_vec())?;
        }
        Ok(())
    })?;
    d.set_item("solves", r.solves)?;
    Ok(d)
}

/// `Scene.validate_path`: the smallest exact-test margin along each step of a path, checked
/// at `checks` poses a step (default: the planner's).
pub fn validate_planar(py: Python<'_>, scene: &Scene, poses: &Arg<'_>, pushers: &Arg<'_>, checks: Option<&Arg<'_>>) -> PyResult<Vec<f64>> {
    let path = path("path", poses, pushers, pose3, |n| scene.pusher_index(n))?;
    let checks = optional(checks, |v| arg("checks", v))?.unwrap_or(PlanarSettings::default().search.checks);
    SearchSettings { checks, ..SearchSettings::default() }.check().map_err(to_py)?;
    interruptible(py, || trrt::validate_path(scene, &path, checks))
}

/// `Scene3D.validate_path`: whether each step of a path can be taken by its pusher (with
/// the steps' pusher twists `twists`, when given).
pub fn validate_spatial(py: Python<'_>, scene: &Scene3, poses: &Arg<'_>, pushers: &Arg<'_>, twists: Option<&Arg<'_>>) -> PyResult<Vec<bool>> {
    let twists = optional(twists, |t| {
        let t: Vec<Arg<'_>> = arg("twists", t)?;
        t.iter().enumerate().map(|(i, v)| twist6(&format!("path[{i}].pusher_twist"), v)).collect::<PyResult<Vec<_>>>()
    })?;
    let path = path("path", poses, pushers, pose7, |n| scene.pusher_index(n))?;
    interruptible(py, || validate_path3(scene, &path, twists.as_deref()))
}
