//! Scenario files: format ([`schema`]), reading with overrides ([`source`]) and building a
//! World from them (`build::build`).

pub mod build;
mod claim;
mod crack_meet;
mod cracks;
mod eta;
mod growth;
mod material;
mod memory;
mod region;
pub mod schema;
pub mod source;
mod surface;
mod traction;

pub use build::{CheckpointPlan, OutputPlan, Scene, build};
pub use source::Source;
