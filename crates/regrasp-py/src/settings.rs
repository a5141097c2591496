//! Planner settings across the boundary: the Rust `Default`s as a dict (the only place Python
//! and the CLI read them from) and a dict of overrides applied onto them, each key checked.

use crate::{arg_err, to_py};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use regrasp::planning::planar::{PlanarSettings, Propagation};
use regrasp::planning::spatial::SpatialSettings;
use regrasp::planning::trrt::SearchSettings;

/// Extracts `v` as a `T`, or an `ArgumentError` naming `key`.
fn get<'py, T: FromPyObject<'py>>(key: &str, v: &Bound<'py, PyAny>, what: &str) -> PyResult<T> {
    v.extract().map_err(|_| arg_err(key, format!("must be {what} (got {v})")))
}

/// The search settings as `(name, value)` pairs.
fn search_dict<'py>(py: Python<'py>, s: &SearchSettings, d: &Bound<'py, PyDict>) -> PyResult<()> {
    let _ = py;
    d.set_item("seed", s.seed)?;
    d.set_item("time_limit", s.time_limit)?;
    d.set_item("max_nodes", s.max_nodes)?;
    d.set_item("max_iterations", s.max_iterations)?;
    d.set_item("goal_bias", s.goal_bias)?;
    d.set_item("step", s.step)?;
    d.set_item("checks", s.checks)?;
    d.set_item("k", s.k)?;
    d.set_item("t0", s.t0)?;
    d.set_item("alpha", s.alpha)?;
    d.set_item("n_fail", s.n_fail)?;
    d.set_item("c_max", s.c_max)?;
    d.set_item("neighbour_steps", s.neighbour_steps)?;
    d.set_item("same_pusher_cost", s.same_pusher_cost)?;
    d.set_item("switch_cost", s.switch_cost)?;
    d.set_item("length_weight", s.length_weight)?;
    d.set_item("cost_threshold", s.cost_threshold)?;
    d.set_item("random_tries", s.random_tries)?;
    d.set_item("theta_margin", s.theta_margin)?;
    d.set_item("connect", s.connect)?;
    Ok(())
}

/// Sets search setting `key` from `v`; false when `key` is not a search setting.
fn set_search(s: &mut SearchSettings, key: &str, v: &Bound<'_, PyAny>) -> PyResult<bool> {
    const WHOLE: &str = "a whole number >= 0";
    const NUM: &str = "a number";
    match key {
        "seed" => s.seed = get(key, v, WHOLE)?,
        "time_limit" => s.time_limit = get(key, v, NUM)?,
        "max_nodes" => s.max_nodes = get(key, v, WHOLE)?,
        "max_iterations" => s.max_iterations = get(key, v, WHOLE)?,
        "goal_bias" => s.goal_bias = get(key, v, NUM)?,
        "step" => s.step = get(key, v, "a number or None")?,
        "checks" => s.checks = get(key, v, WHOLE)?,
        "k" => s.k = get(key, v, NUM)?,
        "t0" => s.t0 = get(key, v, NUM)?,
        "alpha" => s.alpha = get(key, v, NUM)?,
        "n_fail" => s.n_fail = get(key, v, WHOLE)?,
        "c_max" => s.c_max = get(key, v, NUM)?,
        "neighbour_steps" => s.neighbour_steps = get(key, v, NUM)?,
        "same_pusher_cost" => s.same_pusher_cost = get(key, v, NUM)?,
        "switch_cost" => s.switch_cost = get(key, v, NUM)?,
        "length_weight" => s.length_weight = get(key, v, NUM)?,
        "cost_threshold" => s.cost_threshold = get(key, v, NUM)?,
        "random_tries" => s.random_tries = get(key, v, WHOLE)?,
        "theta_margin" => s.theta_margin = get(key, v, NUM)?,
        "connect" => s.connect = get(key, v, "True or False")?,
        _ => return Ok(false),
    }
    Ok(true)
}

/// The planar settings as a dict.
pub fn planar_dict<'py>(py: Python<'py>, s: &PlanarSettings) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    search_dict(py, &s.search, &d)?;
    d.set_item("margin", s.margin)?;
    d.set_item("propagation", s.propagation.label())?;
    d.set_item("plain", s.plain)?;
    Ok(d)
}

/// The spatial settings as a dict.
pub fn spatial_dict<'py>(py: Python<'py>, s: &SpatialSettings) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    search_dict(py, &s.search, &d)?;
    Ok(d)
}

/// The keys of `overrides` in order, as strings.
fn items<'py>(overrides: Option<&Bound<'py, PyDict>>) -> PyResult<Vec<(String, Bound<'py, PyAny>)>> {
    let Some(d) = overrides else { return Ok(Vec::new()) };
    d.iter().map(|(k, v)| Ok((k.extract::<String>().map_err(|_| arg_err("settings", "keys must be strings"))?, v))).collect()
}

/// The planar settings: the defaults with `overrides` applied (unknown keys are errors).
pub fn planar(overrides: Option<&Bound<'_, PyDict>>) -> PyResult<PlanarSettings> {
    let mut s = PlanarSettings::default();
    for (k, v) in items(overrides)? {
        if set_search(&mut s.search, &k, &v)? {
            continue;
        }
        match k.as_str() {
            "margin" => s.margin = get(&k, &v, "a number")?,
            "propagation" => s.propagation = Propagation::parse(&get::<String>(&k, &v, "a string")?).map_err(to_py)?,
            "plain" => s.plain = get(&k, &v, "True or False")?,
            _ => return Err(arg_err(&k, "is not a setting of the planar planner")),
        }
    }
    s.check().map_err(to_py)?;
    Ok(s)
}

/// The spatial settings: the defaults with `overrides` applied (unknown keys are errors).
pub fn spatial(overrides: Option<&Bound<'_, PyDict>>) -> PyResult<SpatialSettings> {
    let mut s = SpatialSettings::default();
    for (k, v) in items(overrides)? {
        if !set_search(&mut s.search, &k, &v)? {
            return Err(arg_err(&k, "is not a setting of the 3-D planner"));
        }
    }
    s.search.check().map_err(to_py)?;
    Ok(s)
}

/// The planner's default settings for scenes of `dimension` 2 or 3 (the Rust `Default`s).
#[pyfunction]
pub fn planner_defaults(py: Python<'_>, dimension: u8) -> PyResult<Bound<'_, PyDict>> {
    match dimension {
        2 => planar_dict(py, &PlanarSettings::default()),
        3 => spatial_dict(py, &SpatialSettings::default()),
        _ => Err(arg_err("dimension", "must be 2 or 3")),
    }
}
