//! Regrasp planning (thesis ch. 4): T-RRT* over object poses in the grasp, with motion-cone steps
//! (planar) or inverse-dynamics steps (spatial), sharing one search tree.

pub mod guide;
pub mod planar;
pub mod point_step;
pub mod reachability;
pub mod spatial;
pub mod tree;
pub mod trrt;
