//! The step: the schedule of systems a scene needs, and the warm worker pool it runs in.

pub mod distribute;
pub mod schedule;
mod warm;
