//! Stop requests (Ctrl-C, SIGTERM). Until a run begins to write, a signal ends the process
//! at once: nothing is written yet, and building a large scene can take minutes. Once it
//! writes, the first signal asks the run to stop cleanly after the current step and write
//! a snapshot; a later one means "abort now", so it leaves a summary.json saying so before
//! the process exits.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

/// What a run shares with the signal handler: whether a stop was asked, and whether the
/// run has begun to write its outputs.
#[derive(Clone, Debug, Default)]
pub struct StopFlag {
    asked: Arc<AtomicBool>,
    writing: Arc<AtomicBool>,
}

impl StopFlag {
    /// Asks the run to stop; returns whether that had been asked before.
    pub fn ask(&self) -> bool {
        self.asked.swap(true, Ordering::SeqCst)
    }

    /// Whether a stop was asked.
    pub fn is_asked(&self) -> bool {
        self.asked.load(Ordering::SeqCst)
    }

    /// Set by a run as it opens its outputs (true) and as it starts to build a scene
    /// (false).
    pub fn set_writing(&self, writing: bool) {
        self.writing.store(writing, Ordering::SeqCst);
    }

    /// Whether the run has begun to write.
    pub fn is_writing(&self) -> bool {
        self.writing.load(Ordering::SeqCst)
    }
}

/// What a signal means where the run is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Request {
    /// Nothing is written yet: the caller should exit at once.
    SetUp,
    /// The first request once the run writes: it stops cleanly after its current step.
    Stop,
    /// A later request: the abort summary is written and the caller should exit at once.
    Abort,
}

/// The stop flag a run polls, and where an abort leaves its summary.
#[derive(Clone, Debug)]
pub struct StopRequests {
    flag: StopFlag,
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
            flag: StopFlag::default(),
            summary: Some(out.join("summary.json")),
        }
    }

    /// Requests for work that writes no summary of its own (a sweep's runs): an abort
    /// leaves none either.
    pub fn without_summary() -> Self {
        Self {
            flag: StopFlag::default(),
            summary: None,
        }
    }

    /// The flag to hand to the run ([`super::RunOptions::stop`]).
    pub fn flag(&self) -> StopFlag {
        self.flag.clone()
    }

    /// Records one request and says what it means; on [`Request::Abort`] the abort summary
    /// has been written (if the output folder exists).
    pub fn request(&self) -> Request {
        if !self.flag.is_writing() {
            return Request::SetUp;
        }
        if !self.flag.ask() {
            return Request::Stop;
        }
        if let Some(summary) = self
            .summary
            .as_ref()
            .filter(|s| s.parent().is_some_and(Path::is_dir))
        {
            std::fs::write(summary, ABORT_SUMMARY).ok();
        }
        Request::Abort
    }
}
