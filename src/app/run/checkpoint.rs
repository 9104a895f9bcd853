//! When to write snapshots during a run, where, and how many to keep.

use crate::base::dim::Dim;
use crate::base::error::UsageError;
use crate::io::scenario::{CheckpointPlan, Source};
use crate::io::snapshot::state::write;
use crate::record::state::RunState;
use crate::store::world::World;
use anyhow::Context;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Writes the run's snapshots into `<out>/snapshots/` at the scenario's cadence.
pub struct Checkpointer {
    dir: PathBuf,
    plan: CheckpointPlan,
    last_wall: Instant,
    /// The newest snapshot written or resumed from, with its step.
    pub last: Option<(PathBuf, u64)>,
    /// Wall seconds spent writing snapshots.
    pub seconds: f64,
    /// Bytes written.
    pub bytes: u64,
}

/// File name of the snapshot at `step`; zero-padded so names sort by step.
fn file_name(step: u64) -> String {
    format!("step_{step:012}.fsnap")
}

/// The step of a snapshot file named by [`file_name`].
fn step_of(name: &str) -> Option<u64> {
    name.strip_prefix("step_")?
        .strip_suffix(".fsnap")?
        .parse()
        .ok()
}

impl Checkpointer {
    /// Snapshots for a run writing to `out` (the folder `out/snapshots` is made on the first
    /// write). A fresh run removes the snapshots a previous run left there; a resumed run
    /// keeps them (and counts `resumed` as its newest).
    pub fn new(
        out: &Path,
        plan: CheckpointPlan,
        resumed: Option<(PathBuf, u64)>,
    ) -> anyhow::Result<Self> {
        let dir = out.join("snapshots");
        let c = Checkpointer {
            dir,
            plan,
            last_wall: Instant::now(),
            last: resumed,
            seconds: 0.0,
            bytes: 0,
        };
        if c.last.is_none() {
            for (_, path) in c.existing()? {
                std::fs::remove_file(&path)
                    .with_context(|| format!("cannot remove old snapshot {}", path.display()))?;
            }
        }
        c.remove_partial()?;
        Ok(c)
    }

    /// Removes `*.fsnap.tmp` files: snapshot writes cut short by a kill (a write renames
    /// its temporary file only once it is complete, so none of them is a snapshot).
    fn remove_partial(&self) -> anyhow::Result<()> {
        if !self.dir.exists() {
            return Ok(());
        }
        let entries = std::fs::read_dir(&self.dir)
            .with_context(|| format!("cannot list {}", self.dir.display()))?;
        for e in entries.filter_map(Result::ok) {
            if e.file_name().to_string_lossy().ends_with(".fsnap.tmp") {
                let path = e.path();
                std::fs::remove_file(&path).with_context(|| {
                    format!("cannot remove a partial snapshot {}", path.display())
                })?;
            }
        }
        Ok(())
    }

    /// Snapshot files in the folder, by step (none while the folder does not exist).
    fn existing(&self) -> anyhow::Result<Vec<(u64, PathBuf)>> {
        if !self.dir.exists() {
            return Ok(Vec::new());
        }
        let mut found: Vec<(u64, PathBuf)> = std::fs::read_dir(&self.dir)
            .with_context(|| format!("cannot list {}", self.dir.display()))?
            .filter_map(|e| {
                let e = e.ok()?;
                Some((step_of(e.file_name().to_str()?)?, e.path()))
            })
            .collect();
        found.sort();
        Ok(found)
    }

    /// Whether the scenario asks for periodic snapshots (then the last step gets one too,
    /// so a finished run can be extended with `resume --until`).
    pub fn periodic(&self) -> bool {
        let p = &self.plan;
        p.every_steps.is_some() || p.every_time.is_some() || p.every_wall.is_some()
    }

    /// Whether a snapshot is due after the step just taken; advances the time mark.
    pub fn due(&mut self, step: u64, time: f64, state: &mut RunState) -> bool {
        let by_steps = self
            .plan
            .every_steps
            .is_some_and(|n| step.is_multiple_of(n));
        let by_time = time >= state.next_checkpoint * (1.0 - 1e-9);
        if by_time && let Some(t) = self.plan.every_time {
            while state.next_checkpoint <= time * (1.0 + 1e-9) {
                state.next_checkpoint += t;
            }
        }
        let by_wall = self
            .plan
            .every_wall
            .is_some_and(|d| self.last_wall.elapsed() >= d);
        by_steps || by_time || by_wall
    }

    /// Writes a snapshot of the current state and prunes all but the newest `keep` at or
    /// before this step (later ones, from a run that went further before it stopped, are
    /// the same states this deterministic run will reach, and are left alone).
    pub fn write<D: Dim>(
        &mut self,
        src: &Source,
        world: &World<D>,
        state: &RunState,
    ) -> anyhow::Result<PathBuf> {
        let t0 = Instant::now();
        std::fs::create_dir_all(&self.dir)
            .with_context(|| format!("cannot create {}", self.dir.display()))?;
        let path = self.dir.join(file_name(world.step));
        self.bytes += write(&path, src, world, state)
            .with_context(|| format!("cannot write snapshot {}", path.display()))?;
        self.seconds += t0.elapsed().as_secs_f64();
        self.last_wall = Instant::now();
        self.last = Some((path.clone(), world.step));
        let older: Vec<PathBuf> = self
            .existing()?
            .into_iter()
            .filter(|(s, _)| *s <= world.step)
            .map(|(_, p)| p)
            .collect();
        for p in older.iter().rev().skip(self.plan.keep) {
            std::fs::remove_file(p)
                .with_context(|| format!("cannot remove old snapshot {}", p.display()))?;
        }
        Ok(path)
    }
}

/// The snapshot to resume from: `path` itself, or the newest snapshot in a run folder
/// (`path/snapshots/`) or in a snapshots folder.
pub fn resolve(path: &Path) -> anyhow::Result<PathBuf> {
    if !path.is_dir() {
        return Ok(path.to_path_buf());
    }
    let sub = path.join("snapshots");
    let dir = if sub.is_dir() {
        sub
    } else {
        path.to_path_buf()
    };
    let newest = std::fs::read_dir(&dir)
        .with_context(|| format!("cannot list {}", dir.display()))?
        .filter_map(|e| {
            let e = e.ok()?;
            Some((step_of(e.file_name().to_str()?)?, e.path()))
        })
        .max();
    newest.map(|(_, p)| p).ok_or_else(|| {
        UsageError(format!("no snapshot (step_*.fsnap) in {}", dir.display())).into()
    })
}
