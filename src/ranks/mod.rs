//! One scene on several processes (MPI ranks): the ranks and their collective operations,
//! and the partition of the tiles among them.

pub mod comm;
pub mod domain;
pub mod partition;

/// A particle-list entry (a load's, a probe's) whose particle another rank holds.
pub const ABSENT: u32 = u32::MAX;
