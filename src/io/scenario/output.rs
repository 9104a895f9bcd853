//! The `[output]` and `[checkpoint]` tables: what a run writes, and how often.

use super::check::{R, positive};
use super::source::Source;

/// Output cadence of a run.
#[derive(Clone, Debug)]
pub struct OutputPlan {
    /// Simulated time between VTK frames (s).
    pub interval: f64,
    /// Simulated time between history rows (s).
    pub history_interval: f64,
    /// Write VTK files.
    pub vtk: bool,
    /// Write PNG plots.
    pub plot: bool,
}

/// When a run writes snapshots.
#[derive(Clone, Debug)]
pub struct CheckpointPlan {
    /// Every this many steps.
    pub every_steps: Option<u64>,
    /// Every this much simulated time (s).
    pub every_time: Option<f64>,
    /// Every this much wall-clock time.
    pub every_wall: Option<std::time::Duration>,
    /// Newest snapshots kept.
    pub keep: usize,
}

/// The `[output]` table, checked: VTK frames every `duration / 20` and history rows every
/// `duration / 400` unless given.
pub(super) fn output_plan(src: &Source, duration: f64) -> R<OutputPlan> {
    let out = &src.scenario.output;
    let interval = match out.interval {
        Some(v) => positive(src, "output.interval", v, "s")?,
        None => duration / 20.0,
    };
    let history_interval = match out.history_interval {
        Some(v) => positive(src, "output.history_interval", v, "s")?,
        None => duration / 400.0,
    };
    Ok(OutputPlan {
        interval,
        history_interval,
        vtk: out.vtk.unwrap_or(true),
        plot: out.plot.unwrap_or(true),
    })
}

/// The `[checkpoint]` table, checked.
pub(super) fn checkpoint_plan(src: &Source) -> R<CheckpointPlan> {
    let c = &src.scenario.checkpoint;
    if c.every_steps == Some(0) {
        return Err(src.error("checkpoint.every_steps", "must be at least 1"));
    }
    let every_time = c
        .every_time
        .map(|t| positive(src, "checkpoint.every_time", t, "s"))
        .transpose()?;
    let every_wall = c
        .every_wall_minutes
        .map(|m| positive(src, "checkpoint.every_wall_minutes", m, "min"))
        .transpose()?
        .map(|m| std::time::Duration::from_secs_f64((m * 60.0).min(1e12)));
    if c.keep == Some(0) {
        return Err(src.error("checkpoint.keep", "must keep at least 1 snapshot"));
    }
    Ok(CheckpointPlan {
        every_steps: c.every_steps,
        every_time,
        every_wall,
        keep: c.keep.unwrap_or(2),
    })
}
