//! Files in and out: scenario files, snapshots, and the run's outputs.

pub mod output;
pub mod scenario;
pub mod snapshot;
