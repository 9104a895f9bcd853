//! What the launcher drives: running a scene (or resuming it from a snapshot) and
//! parameter sweeps.

pub mod run;
pub mod sweep;
