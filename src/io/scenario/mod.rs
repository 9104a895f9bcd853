//! Scenario files: format ([`schema`]), reading with overrides ([`source`]) and building a
//! World from them (`build::build`).

mod bodies;
mod boundaries;
pub mod build;
mod check;
mod claim;
mod crack_front;
mod crack_meet;
mod cracks;
mod eta;
mod expects;
mod grid;
mod growth;
mod loads;
mod material;
mod memory;
mod mesh_body;
mod mesh_outline;
mod mirrors;
mod msh;
mod output;
mod probes;
mod region;
pub mod schema;
mod settings;
pub mod source;
mod statics;
mod surface;
mod traction;

pub use build::{Scene, build, build_share};
pub use check::folder_name_problem;
pub use output::{CheckpointPlan, OutputPlan};
pub use settings::MAX_STEPS;
pub use source::Source;
pub use statics::ignored;
