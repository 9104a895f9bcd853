//! Snapshots for checkpoint and restart: a versioned, checksummed container of named
//! columns (`format`) and the mapping of a run's state onto it (`state`).

pub mod format;
pub mod state;
mod topology;

pub use format::{Reader, SnapshotError};
