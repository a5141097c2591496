//! regrasp: mechanics, motion cones and planning for in-hand regrasps by prehensile pushing
//! (Chavan-Dafle, *Dexterous Manipulation with Simple Grippers*, MIT 2020).

pub mod batch;
pub mod error;
pub mod friction_cone;
pub mod geometry;
pub mod gravity;
pub mod limit_surface;
pub mod metric;
pub mod mncp;
pub mod motion_cone;
pub mod mpc;
pub mod quasistatic;
pub mod quasistatic3d;
pub mod robust;
pub mod scene;
pub mod scene3d;
pub mod tree;
pub mod trrt;
pub mod trrt3d;

pub use error::{Error, Result};
pub use metric::Metric;
pub use motion_cone::{Classification, GripForceRange, PlanarPush, PushSpec};
pub use scene::Scene;
