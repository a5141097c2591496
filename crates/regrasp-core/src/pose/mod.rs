//! Pose algebra, once: planar poses `[x, z, θ]` ([`planar`], SE(2)) and spatial poses
//! (isometries, [`spatial`], SE(3)) — exponential and logarithm of body twists, relative poses,
//! the change of frame of twists, and the left-invariant metric of the planners.

pub mod planar;
pub mod spatial;
