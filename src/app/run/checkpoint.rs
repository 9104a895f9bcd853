//! When to write snapshots during a run, where, and how many to keep. Split across ranks,
//! every rank writes its piece and the first rank the manifest, and alone removes files.

use crate::base::dim::Dim;
use crate::base::error::UsageError;
use crate::io::scenario::{CheckpointPlan, Source};
use crate::io::snapshot::Reader;
use crate::io::snapshot::pieces::{self, Piece};
use crate::io::snapshot::state::{write, write_manifest};
use crate::ranks::comm::Comm;
use crate::record::state::RunState;
use crate::store::world::World;
use anyhow::Context;
use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Writes the run's snapshots into `<out>/snapshots/` at the scenario's cadence.
pub struct Checkpointer {
    dir: PathBuf,
    plan: CheckpointPlan,
    /// Whether this process tidies the folder (the first rank of a split run).
    tidies: bool,
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
    /// keeps them (and counts `resumed` as its newest). Split across ranks, only the first
    /// rank removes files, here before the run's first collective call, so before any rank
    /// can write a piece.
    pub fn new(
        out: &Path,
        plan: CheckpointPlan,
        resumed: Option<(PathBuf, u64)>,
        comm: &Comm,
    ) -> anyhow::Result<Self> {
        let dir = out.join("snapshots");
        let c = Checkpointer {
            dir,
            plan,
            tidies: comm.is_root(),
            last_wall: Instant::now(),
            last: resumed,
            seconds: 0.0,
            bytes: 0,
        };
        if !c.tidies {
            return Ok(c);
        }
        if c.last.is_none() {
            for (_, path) in c.existing()? {
                std::fs::remove_file(&path)
                    .with_context(|| format!("cannot remove old snapshot {}", path.display()))?;
            }
        }
        c.remove_partial()?;
        c.remove_unlisted_pieces()?;
        Ok(c)
    }

    /// Removes `*.fsnap.tmp` and `*.fpiece.tmp` files: snapshot writes cut short by a kill
    /// (a write renames its temporary file only once it is complete, so none of them is a
    /// snapshot).
    fn remove_partial(&self) -> anyhow::Result<()> {
        for (name, path) in self.files()? {
            if name
                .strip_suffix(".tmp")
                .is_some_and(|n| n.ends_with(".fsnap") || pieces::is_piece(n))
            {
                std::fs::remove_file(&path).with_context(|| {
                    format!("cannot remove a partial snapshot {}", path.display())
                })?;
            }
        }
        Ok(())
    }

    /// Removes the pieces no snapshot in the folder names: those of sets pruned or cut
    /// short before their manifest was written.
    fn remove_unlisted_pieces(&self) -> anyhow::Result<()> {
        let files = self.files()?;
        if !files.iter().any(|(name, _)| pieces::is_piece(name)) {
            return Ok(());
        }
        let mut listed = HashSet::new();
        for (_, manifest) in self.existing()? {
            // A snapshot that cannot be read names nothing; resuming it says why.
            if let Ok(mut r) = Reader::open(&manifest)
                && let Ok(list) = pieces::listing(&mut r)
            {
                listed.extend(list.into_iter().map(|p| p.name));
            }
        }
        for (name, path) in files {
            if pieces::is_piece(&name) && !listed.contains(&name) {
                std::fs::remove_file(&path).with_context(|| {
                    format!("cannot remove an unused snapshot piece {}", path.display())
                })?;
            }
        }
        Ok(())
    }

    /// Every file in the folder, by name (none while the folder does not exist).
    fn files(&self) -> anyhow::Result<Vec<(String, PathBuf)>> {
        if !self.dir.exists() {
            return Ok(Vec::new());
        }
        let entries = std::fs::read_dir(&self.dir)
            .with_context(|| format!("cannot list {}", self.dir.display()))?;
        Ok(entries
            .filter_map(Result::ok)
            .map(|e| (e.file_name().to_string_lossy().into_owned(), e.path()))
            .collect())
    }

    /// Snapshot files in the folder, by step (none while the folder does not exist).
    fn existing(&self) -> anyhow::Result<Vec<(u64, PathBuf)>> {
        let mut found: Vec<(u64, PathBuf)> = (self.files()?.into_iter())
            .filter_map(|(name, path)| Some((step_of(&name)?, path)))
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
    /// the same states this deterministic run will reach, and are left alone). Split
    /// across ranks, every rank calls it at the same point of the step.
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
        self.bytes += if world.domain.is_split() {
            self.write_set(&path, src, world, state)?
        } else {
            write(&path, src, world, state)
                .with_context(|| format!("cannot write snapshot {}", path.display()))?
        };
        self.seconds += t0.elapsed().as_secs_f64();
        self.last_wall = Instant::now();
        self.last = Some((path.clone(), world.step));
        if self.tidies {
            self.prune(world.step)?;
        }
        Ok(path)
    }

    /// A split run's snapshot: every rank's piece, then, once all are written, the
    /// manifest naming them. Returns the bytes of the whole set.
    fn write_set<D: Dim>(
        &self,
        path: &Path,
        src: &Source,
        world: &World<D>,
        state: &RunState,
    ) -> anyhow::Result<u64> {
        let comm = &world.domain.comm;
        let stem = file_name(world.step);
        let stem = stem.trim_end_matches(".fsnap");
        let mine = pieces::write(&self.dir, stem, comm.rank(), src, world);
        if let Some((rank, why)) = comm.first_error(mine.as_ref().err().map(|e| e.to_string())) {
            anyhow::bail!(
                "rank {rank} cannot write its piece of snapshot {}: {why}",
                path.display()
            );
        }
        let mine = postcard::to_stdvec(&mine?).context("cannot encode a snapshot piece")?;
        let all: Vec<Piece> = (comm.all_gather(mine).iter())
            .map(|b| postcard::from_bytes(b).expect("a piece from every rank"))
            .collect();
        let manifest = if comm.is_root() {
            write_manifest(path, src, world, state, &all)
                .map_err(|e| format!("cannot write snapshot {}: {e}", path.display()))
        } else {
            Ok(0)
        };
        if let Some((_, why)) = comm.first_error(manifest.as_ref().err().cloned()) {
            anyhow::bail!("{why}");
        }
        Ok(all.iter().map(|p| p.bytes).sum::<u64>() + manifest.unwrap_or(0))
    }

    /// Removes all but the newest `keep` snapshots at or before `step`, then the pieces
    /// that no snapshot left names. The other ranks cannot write the next set before this
    /// rank has joined the next step's collective calls, so no new piece is removed.
    fn prune(&self, step: u64) -> anyhow::Result<()> {
        let older: Vec<PathBuf> = self
            .existing()?
            .into_iter()
            .filter(|(s, _)| *s <= step)
            .map(|(_, p)| p)
            .collect();
        for p in older.iter().rev().skip(self.plan.keep) {
            std::fs::remove_file(p)
                .with_context(|| format!("cannot remove old snapshot {}", p.display()))?;
        }
        self.remove_unlisted_pieces()
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
