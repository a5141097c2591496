//! Perturbed copies of a planar scene: scaled parameters, the worst case of an uncertainty
//! range (robust cones, thesis §5.1) and fixtureless fixturing (CASE 2018).

use crate::cones::frame::{ConeMode, PusherModel};
use crate::cones::robust::Uncertainty;
use crate::error::{Error, Result};
use crate::mechanics::friction_cone::PusherContact;
use crate::scene::bounds;
use crate::scene::planar::{Scene, Support};

/// `ρ = μ_s N / (m g)` of a grasp scene (`N` per finger); `None` for an object on a surface or
/// where no weight is to be held (no gravity, or so little that ρ is not a finite number).
pub fn rho(scene: &Scene) -> Option<f64> {
    match &scene.support {
        Support::Grasp(g) => Some(g.friction * g.force / (scene.mass * scene.g)).filter(|r| r.is_finite()),
        _ => None,
    }
}

/// A copy of `scene` with parameters scaled (finger friction, grip force, mass, every pusher's
/// friction) and the given cone mode.
pub fn scaled(scene: &Scene, finger_friction: f64, grip: f64, mass: f64, pusher_friction: f64, mode: ConeMode) -> Result<Scene> {
    for (name, v) in [("finger_friction", finger_friction), ("grip", grip), ("mass", mass), ("pusher_friction", pusher_friction)] {
        if !(v > 0.0) || !v.is_finite() {
            return Err(Error::arg(name, format!("scale must be positive and finite (got {v})")));
        }
    }
    let mut s = scene.clone();
    match &mut s.support {
        Support::Grasp(g) => {
            g.friction *= finger_friction;
            g.force *= grip;
        }
        Support::Surface(sf) => sf.friction *= finger_friction,
    }
    s.mass *= mass;
    within("mass", s.mass, bounds::MASS)?;
    match &s.support {
        Support::Grasp(g) => {
            within("grip", g.force, bounds::FORCE)?;
            within("finger_friction", g.friction, bounds::SUPPORT_FRICTION)?;
        }
        Support::Surface(sf) => {
            within("finger_friction", sf.friction, bounds::SUPPORT_FRICTION)?;
        }
    }
    let metric = s.metric();
    for p in s.pushers.iter_mut() {
        p.contact = PusherContact { friction: within("pusher_friction", p.contact.friction * pusher_friction, bounds::PUSHER_FRICTION)?, ..p.contact.clone() };
        p.model = PusherModel::new(p.contact.clone(), metric)?;
    }
    s.mode = mode;
    Ok(s)
}

/// A scaled value: an error on argument `name` when it leaves the top of its bound (scaling
/// down never leaves a positive value's range in a way that overflows).
fn within(name: &str, v: f64, b: bounds::Bound) -> Result<f64> {
    if v.is_finite() && v <= b.hi {
        return Ok(v);
    }
    Err(Error::arg(name, format!("the scaled value {v:e} exceeds {:e}", b.hi)))
}

/// The worst case of a range (`ρ_min`, lowest pusher friction) with the robust cone mode.
pub fn worst_case(scene: &Scene, u: &Uncertainty) -> Result<Scene> {
    let u = u.checked()?;
    scaled(scene, 1.0 - u.finger_friction, 1.0 - u.grip_force, 1.0 + u.mass, 1.0 - u.pusher_friction, ConeMode::Robust)
}

/// The same scene planning only with fixtureless-fixturing pushes.
pub fn fixtureless(scene: &Scene) -> Scene {
    let mut s = scene.clone();
    s.mode = ConeMode::Fixtureless;
    s
}
