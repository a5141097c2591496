//! Motion cones (thesis §3.3, RSS 2018): the twists a pusher can impose on a grasped object,
//! their exact test and projection, robust and fixtureless variants (§5.1), and batches.

pub mod batch;
pub mod frame;
pub mod motion_cone;
pub mod point_pusher;
pub mod polyhedral;
pub mod projection;
pub mod robust;
