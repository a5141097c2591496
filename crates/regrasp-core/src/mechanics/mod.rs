//! Contact mechanics of one object in a grasp: planar geometry and outlines, Coulomb and
//! generalized friction cones (eqs 3.1, 3.6), limit surfaces (eqs 3.7–3.11), the gravity wrench
//! (eq 3.12) and the frame-invariant metrics of twists and wrenches.

pub mod disc_profile;
pub mod exact_surface;
pub mod friction_cone;
pub mod geometry;
pub mod gravity;
pub mod limit_surface;
pub mod metric;
