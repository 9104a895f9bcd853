//! Stop requests (Ctrl-C, SIGTERM): the first asks the run to stop cleanly after the
//! current step and write a snapshot; a later one means "abort now", so it leaves a
//! summary.json saying so before the process exits.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

/// The stop flag a run polls, and where an abort leaves its summary.
#[derive(Clone, Debug)]
pub struct StopRequests {
    flag: Arc<AtomicBool>,
    summary: Option<PathBuf>,
}

/// The summary an abort leaves: the run had no chance to write its own.
const ABORT_SUMMARY: &str = "{\n  \"status\": \"interrupted\",\n  \"message\": \"aborted by a \
                             second signal, without a clean stop: no snapshot of this \
                             invocation\"\n}\n";

impl StopRequests {
    /// Requests for a run writing into `out`.
    pub fn new(out: &Path) -> Self {
        Self {
            flag: Arc::new(AtomicBool::new(false)),
            summary: Some(out.join("summary.json")),
        }
    }

    /// Requests for work that writes no summary of its own (a sweep's runs): an abort
    /// leaves none either.
    pub fn without_summary() -> Self {
        Self {
            flag: Arc::new(AtomicBool::new(false)),
            summary: None,
        }
    }

    /// The flag to hand to the run ([`super::RunOptions::stop`]).
    pub fn flag(&self) -> Arc<AtomicBool> {
        self.flag.clone()
    }

    /// Records one request. Returns true when it is not the first: the abort summary is
    /// then written (if the output folder exists) and the caller should exit at once.
    pub fn request(&self) -> bool {
        if !self.flag.swap(true, Ordering::SeqCst) {
            return false;
        }
        if let Some(summary) = self
            .summary
            .as_ref()
            .filter(|s| s.parent().is_some_and(Path::is_dir))
        {
            std::fs::write(summary, ABORT_SUMMARY).ok();
        }
        true
    }
}
