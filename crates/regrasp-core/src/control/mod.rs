//! Closed-loop control (thesis §5.2): model-predictive control with motion-cone constraints.

pub mod mpc;
pub mod step_qp;
