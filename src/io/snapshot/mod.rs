//! Snapshots for checkpoint and restart: a versioned, checksummed container of named
//! columns (`format`), the mapping of a run's state onto it (`state`), and a split run's
//! pieces and manifest (`pieces`).

mod columns;
pub mod format;
pub mod pieces;
pub mod state;
mod topology;

pub use format::{Reader, SnapshotError};
