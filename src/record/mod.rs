//! What a run records and checks: probes, the history, `[[expect]]` evaluation, and the
//! run-loop state a snapshot keeps.

pub mod expect;
pub mod history;
pub mod probe;
pub mod solve_log;
pub mod state;
