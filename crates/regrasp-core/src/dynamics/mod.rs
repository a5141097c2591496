//! Quasi-static complementarity dynamics (thesis §3.2): the mixed NCP of one object against
//! finger and pusher contacts ([`mncp`]: forward, inverse, residuals) and time stepping of pushes,
//! planar ([`planar`]) and spatial ([`spatial`]), over one stepping loop (`stepping`).

pub mod mncp;
pub mod planar;
pub mod spatial;
mod stepping;
