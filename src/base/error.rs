//! Error types: scenario problems located by file, line and key; unusable command-line
//! values; run instabilities.

use thiserror::Error;

/// A run that went unstable: the step and time where it was detected, and what happened
/// (naming the particle or crack tip).
#[derive(Debug, Error, Clone)]
#[error("run went unstable at step {step} (t = {time:.6e} s): {what}")]
pub struct Unstable {
    /// Step at which the problem was detected.
    pub step: u64,
    /// Simulated time (s).
    pub time: f64,
    /// What happened, to what.
    pub what: String,
}

/// A command-line value that cannot be used (an end time, a folder without snapshots):
/// bad input like a scenario error, so the launcher exits with code 2.
#[derive(Debug, Error, Clone)]
#[error("{0}")]
pub struct UsageError(pub String);

/// A problem with a scenario file, located as precisely as possible.
#[derive(Debug, Error, Clone)]
pub struct ScenarioError {
    /// Scenario file.
    pub file: String,
    /// 1-based line, when known.
    pub line: Option<usize>,
    /// Dotted key path (e.g. `material[0].E`), when known.
    pub key: Option<String>,
    /// What is wrong.
    pub message: String,
}

impl std::fmt::Display for ScenarioError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.file)?;
        if let Some(line) = self.line {
            write!(f, ":{line}")?;
        }
        if let Some(key) = &self.key {
            write!(f, ": key `{key}`")?;
        }
        write!(f, ": {}", self.message)
    }
}
