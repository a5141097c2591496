//! regrasp: mechanics, motion cones and planning for in-hand regrasps by prehensile pushing
//! (Chavan-Dafle, *Dexterous Manipulation with Simple Grippers*, MIT 2020).
//!
//! The modules follow the pipeline: [`pose`] → [`mechanics`] → [`cones`] → [`scene`] →
//! [`dynamics`] → [`planning`] → [`control`], planar and spatial side by side in each stage.

pub mod cones;
pub mod control;
pub mod dynamics;
pub mod error;
pub mod interrupt;
pub mod mechanics;
pub mod planning;
pub mod pose;
pub mod scene;

pub use cones::motion_cone::{Classification, GripForceRange, PlanarPush, PushSpec};
pub use error::{Error, Result};
pub use mechanics::metric::Metric;
pub use scene::Scene;
