//! Scenes: the object, the grasp and the pushers read from the TOML contract
//! (`docs/scene-file.md`), planar ([`planar::Scene`]) and spatial ([`spatial::Scene3`]).

pub mod bounds;
mod exact;
pub mod perturb;
pub mod planar;
pub mod planar_file;
pub mod spatial;
pub mod spatial_file;

pub use planar::Scene;
pub use spatial::Scene3;
