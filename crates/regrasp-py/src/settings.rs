//! Settings across the boundary: the Rust `Default`s as dicts (the only place Python and the
//! CLI read them from: `planner_defaults`, `mpc_defaults`, `quasistatic_defaults`) and
//! overrides applied onto them, each key checked (an unknown key is an `ArgumentError`).

use crate::convert::{Arg, arg, dict, positive};
use crate::errors::{arg_err, guard, to_py};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use regrasp::control::mpc::MpcSettings;
use regrasp::dynamics::planar::{Options, SupportModel};
use regrasp::planning::planar::{PlanarSettings, Propagation};
use regrasp::planning::spatial::SpatialSettings;
use regrasp::planning::trrt::SearchSettings;

/// `fields!(to_dict, set, T; a, b)`: `to_dict` writes fields `a`, `b` of a `T` into a dict;
/// `set` sets the field named `key` from a Python value (false when `key` names none).
macro_rules! fields {
    ($to_dict:ident, $set:ident, $t:ty; $($f:ident),* $(,)?) => {
        fn $to_dict(s: &$t, d: &Bound<'_, PyDict>) -> PyResult<()> {
            $(d.set_item(stringify!($f), s.$f)?;)*
            Ok(())
        }

        fn $set(s: &mut $t, key: &str, v: &Arg<'_>) -> PyResult<bool> {
            match key {
                $(stringify!($f) => s.$f = arg(key, v)?,)*
                _ => return Ok(false),
            }
            Ok(true)
        }
    };
}

fields!(search_dict, set_search, SearchSettings;
    seed, time_limit, max_nodes, max_iterations, goal_bias, step, checks, k, t0, alpha, n_fail, c_max,
    neighbour_steps, same_pusher_cost, switch_cost, length_weight, cost_threshold, refine, random_tries,
    theta_margin, connect, goal_share);

fields!(mpc_dict, set_mpc, MpcSettings;
    dt, horizon, speed, stage_weight, terminal_weight, effort_weight, margin, stall_steps, progress,
    replan_error, max_replans, goal_fraction);

/// Argument `settings` (a dict or None) as `(key, value)` pairs.
pub fn items<'py>(settings: Option<&Arg<'py>>) -> PyResult<Vec<(String, Arg<'py>)>> {
    let Some(s) = settings.filter(|s| !s.is_none()) else { return Ok(Vec::new()) };
    let d = s.downcast::<PyDict>().map_err(|_| arg_err("settings", format!("must be a dict (got {s})")))?;
    let key = |k: Bound<'py, PyAny>| match k.extract::<String>() {
        Ok(k) if !k.trim().is_empty() => Ok(k),
        _ => Err(arg_err("settings", format!("keys must be setting names (got {k:?})"))),
    };
    d.iter().map(|(k, v)| Ok((key(k)?, v))).collect()
}

/// The planar planner's settings as a dict.
fn planar_dict<'py>(py: Python<'py>, s: &PlanarSettings) -> PyResult<Bound<'py, PyDict>> {
    let d = dict!(py; "margin" => s.margin, "propagation" => s.propagation.label(), "plain" => s.plain, "guide" => s.guide);
    search_dict(&s.search, &d)?;
    Ok(d)
}

/// The planar planner's settings: the defaults with `overrides` applied.
pub fn planar(overrides: Option<&Arg<'_>>) -> PyResult<PlanarSettings> {
    let mut s = PlanarSettings::default();
    for (k, v) in items(overrides)? {
        if set_search(&mut s.search, &k, &v)? {
            continue;
        }
        match k.as_str() {
            "margin" => s.margin = arg(&k, &v)?,
            "propagation" => s.propagation = Propagation::parse(&arg::<String>(&k, &v)?).map_err(to_py)?,
            "plain" => s.plain = arg(&k, &v)?,
            "guide" => s.guide = arg(&k, &v)?,
            _ => return Err(arg_err(&k, "is not a setting of the planar planner")),
        }
    }
    s.check().map_err(to_py)?;
    Ok(s)
}

/// The 3-D planner's settings: the defaults with `overrides` applied.
pub fn spatial(overrides: Option<&Arg<'_>>) -> PyResult<SpatialSettings> {
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
pub fn planner_defaults<'py>(py: Python<'py>, dimension: &Arg<'py>) -> PyResult<Bound<'py, PyDict>> {
    guard(move || {
        match arg::<usize>("dimension", dimension)? {
            2 => planar_dict(py, &PlanarSettings::default()),
            3 => {
                let d = PyDict::new(py);
                search_dict(&SpatialSettings::default().search, &d)?;
                Ok(d)
            }
            _ => Err(arg_err("dimension", "must be 2 or 3")),
        }
    })
}

/// The MPC's default settings (`regrasp::control::mpc::MpcSettings::default()`): the keywords
/// `_core.Mpc` takes, `replan_time_limit` and `seed` being those of its re-planning.
#[pyfunction]
pub fn mpc_defaults(py: Python<'_>) -> PyResult<Bound<'_, PyDict>> {
    guard(move || {
        let s = MpcSettings::default();
        let d = dict!(py; "replan_time_limit" => s.planner.search.time_limit, "seed" => s.planner.search.seed);
        mpc_dict(&s, &d)?;
        Ok(d)
    })
}

/// The MPC's settings: the defaults with `overrides` applied (None values are skipped); checked
/// by the controller.
pub fn mpc(overrides: &[(String, Arg<'_>)]) -> PyResult<MpcSettings> {
    let mut s = MpcSettings::default();
    for (k, v) in overrides.iter().filter(|(_, v)| !v.is_none()) {
        if set_mpc(&mut s, k, v)? {
            continue;
        }
        match k.as_str() {
            "replan_time_limit" => s.planner.search.time_limit = arg(k, v)?,
            "seed" => s.planner.search.seed = arg(k, v)?,
            _ => return Err(arg_err(k, "is not a setting of the MPC")),
        }
    }
    Ok(s)
}

/// The support model's parts: (label, rings, points, merge_fingers).
fn support_parts(m: SupportModel) -> (&'static str, usize, usize, bool) {
    match m {
        SupportModel::Points { rings, points, merge_fingers } => ("points", rings, points, merge_fingers),
        SupportModel::LimitSurface => ("limit_surface", 0, 0, true),
    }
}

/// The quasi-static model's default options (`regrasp::dynamics::planar::Options::default()`):
/// the keywords of the planar `quasistatic_problem`, `push_outcomes` and `simulate_push`.
#[pyfunction]
pub fn quasistatic_defaults(py: Python<'_>) -> PyResult<Bound<'_, PyDict>> {
    guard(move || {
        let o = Options::default();
        let (support, rings, points, merge_fingers) = support_parts(o.support);
        Ok(dict!(py; "support" => support, "rings" => rings, "points" => points, "merge_fingers" => merge_fingers,
                     "h" => o.h, "speed" => o.speed))
    })
}

/// Rings of the point-set pads that `regrasp validate` simulates unless told
/// (`regrasp::dynamics::planar::VALIDATION_RINGS`).
#[pyfunction]
pub fn validation_rings() -> usize {
    regrasp::dynamics::planar::VALIDATION_RINGS
}

/// The limit surface a scene's motion cones use when its file does not say
/// (`regrasp::mechanics::limit_surface::SurfaceModel::default()`): "true" or "ellipsoid".
#[pyfunction]
pub fn limit_surface_default() -> &'static str {
    regrasp::mechanics::limit_surface::SurfaceModel::default().label()
}

/// Most rings and points a pad's support model may take (each point is a contact of the problem).
const MAX_RINGS: usize = 64;
const MAX_POINTS: usize = 1024;

/// The quasi-static model's options: the defaults with the `given` ones (None: the default).
pub fn quasistatic(given: &[(&str, Option<&Arg<'_>>)]) -> PyResult<Options> {
    let mut o = Options::default();
    let (label, mut rings, mut points, mut merge_fingers) = support_parts(o.support);
    let mut support = label.to_string();
    for (k, v) in given.iter().filter_map(|(k, v)| v.filter(|v| !v.is_none()).map(|v| (*k, v))) {
        match k {
            "support" => support = arg(k, v)?,
            "rings" => rings = arg(k, v)?,
            "points" => points = arg(k, v)?,
            "merge_fingers" => merge_fingers = arg(k, v)?,
            "h" => o.h = positive(k, v)?,
            "speed" => o.speed = positive(k, v)?,
            _ => return Err(arg_err(k, "is not an option of the quasi-static model")),
        }
    }
    for (name, v, hi) in [("rings", rings, MAX_RINGS), ("points", points, MAX_POINTS)] {
        if v > hi {
            return Err(arg_err(name, format!("must be at most {hi} (got {v})")));
        }
    }
    o.support = match support.as_str() {
        "points" if rings == 0 && points == 0 => return Err(arg_err("points", "give rings > 0 or points > 0")),
        "points" => SupportModel::Points { rings, points, merge_fingers },
        "limit_surface" => SupportModel::LimitSurface,
        other => return Err(arg_err("support", format!("must be \"points\" or \"limit_surface\", got {other:?}"))),
    };
    Ok(o)
}
