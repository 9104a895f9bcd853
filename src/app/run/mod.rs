//! Running a scene: the step loop, instability checks, output and checkpoint cadence, and
//! the summary. A run starts from a scenario ([`run`]) or from a snapshot ([`resume`]).

pub mod checkpoint;
mod driver;
mod reports;
pub use reports::{node_lines, particles_on_cracks, tips_on_particle_lines};
pub mod stop;
pub mod writers;

use crate::base::dim::{D2, D3, Dim};
use crate::base::error::Unstable;
use crate::base::sym::SymTensor;
use crate::io::output::summary::Summary;
use crate::io::scenario::{Scene, Source, build_share};
use crate::io::snapshot::Reader;
use crate::io::snapshot::state::restore_share;
use crate::ranks::comm::Comm;
use crate::record::history::History;
use crate::record::state::RunState;
use crate::store::world::{Energies, World};
use crate::systems::DimSystems;
use crate::systems::bin;
use anyhow::Context;
use driver::Run;
use indicatif::{ProgressBar, ProgressStyle};
use std::path::{Path, PathBuf};
use std::time::Instant;
use stop::StopFlag;

/// How to run a scenario.
#[derive(Clone, Debug, Default)]
pub struct RunOptions {
    /// Output folder; None writes nothing (tests, validate without --out).
    pub out: Option<PathBuf>,
    /// Worker threads (0: rayon's default, the number of cores).
    pub threads: usize,
    /// Show a progress bar on stderr.
    pub progress: bool,
    /// Simulated end time (s) instead of the scenario's duration.
    pub until: Option<f64>,
    /// Stop cleanly after this step, as on Ctrl-C.
    pub pause_after: Option<u64>,
    /// Shared with a signal handler: a stop asked stops the run cleanly after the current
    /// step; the run says when it begins to write.
    pub stop: Option<StopFlag>,
    /// The MPI ranks the run is split across (one by default).
    pub comm: Comm,
}

impl RunOptions {
    /// Whether a signal has asked the run to stop.
    pub fn stop_requested(&self) -> bool {
        (self.stop.as_ref()).is_some_and(StopFlag::is_asked)
    }

    /// Tells a signal handler whether the run writes yet (see [`stop`]).
    fn writing(&self, on: bool) {
        if let Some(s) = &self.stop {
            s.set_writing(on);
        }
    }
}

/// Result of a run: its summary and the recorded history.
#[derive(Debug)]
pub struct Outcome {
    /// The summary (also written to summary.json).
    pub summary: Summary,
    /// Recorded history.
    pub history: History,
    /// The newest snapshot written (or resumed from), if any.
    pub snapshot: Option<PathBuf>,
}

fn pool(opts: &RunOptions) -> anyhow::Result<rayon::ThreadPool> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(thread_count(opts.threads))
        .build()
        .context("cannot build the thread pool")
}

/// The pool size for `asked` threads (0: one per core): at most one per core, since the
/// workers spin between a step's parallel regions (`warm.rs`) and more of them than cores
/// starve the step (1000 threads on 2 cores made no progress). Results are bitwise the
/// same for any thread count, so the cap changes only the speed.
pub fn thread_count(asked: usize) -> usize {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    if asked == 0 {
        return cores;
    }
    if asked > cores {
        eprintln!("warning: {asked} threads asked, {cores} cores: using {cores}");
    }
    asked.min(cores)
}

/// Runs `src` with `opts` in a thread pool of the requested size.
pub fn run(src: &Source, opts: &RunOptions) -> anyhow::Result<Outcome> {
    opts.writing(false);
    pool(opts)?.install(|| match src.scenario.simulation.dimension {
        2 => drive::<D2>(src, build_share::<D2>(src, opts.comm.clone())?, None, opts),
        3 => drive::<D3>(src, build_share::<D3>(src, opts.comm.clone())?, None, opts),
        _ => Err(src.error("simulation.dimension", "must be 2 or 3").into()),
    })
}

/// Continues the run stored in the snapshot at `path` (a file, or a run folder whose
/// newest snapshot is taken), on as many ranks as `opts.comm` has, whatever the number
/// that wrote it.
pub fn resume(path: &Path, opts: &RunOptions) -> anyhow::Result<Outcome> {
    opts.writing(false);
    let opened = checkpoint::resolve(path).and_then(|f| Ok((Reader::open(&f)?, f)));
    let (mut reader, file) = agreed(&opts.comm, opened)?;
    fn go<D: DimSystems>(
        r: &mut Reader,
        file: &Path,
        opts: &RunOptions,
    ) -> anyhow::Result<Outcome> {
        let restored = agreed(&opts.comm, restore_share::<D>(r, opts.comm.clone()))?;
        let resumed = (restored.state, file.to_path_buf());
        drive::<D>(&restored.source, restored.scene, Some(resumed), opts)
    }
    pool(opts)?.install(|| match reader.header.dimension {
        2 => go::<D2>(&mut reader, &file, opts),
        3 => go::<D3>(&mut reader, &file, opts),
        d => Err(reader
            .invalid(format!("dimension {d} in the header (corrupt)"))
            .into()),
    })
}

/// `done` as every rank sees it: split across ranks, a failure on one (a file it cannot
/// read) fails all, with the lowest failing rank's message.
fn agreed<T>(comm: &Comm, done: anyhow::Result<T>) -> anyhow::Result<T> {
    match comm.first_error(done.as_ref().err().map(|e| format!("{e:#}"))) {
        Some((rank, why)) if done.is_ok() => Err(anyhow::anyhow!("rank {rank}: {why}")),
        _ => done,
    }
}

/// Steps of `dt` that reach `end`: the fewest whose end is not short of it by more than
/// round-off (4.5e-5 / 1e-7 is 450.00000000000006 in floating point: 450 steps, not 451).
pub fn step_count(end: f64, dt: f64) -> u64 {
    ((end / dt) * (1.0 - 1e-12)).ceil() as u64
}

/// Whether a step ending at `time` records a history row: the next row is due (to
/// round-off) or it is the last step.
fn row_due(time: f64, next_history: f64, last: bool) -> bool {
    time >= next_history * (1.0 - 1e-9) || last
}

/// Checks the energies `e` for NaN and names the first particle with a non-finite state.
fn check_finite<D: Dim>(world: &World<D>, e: &Energies) -> Result<(), Unstable> {
    if (e.kinetic + e.strain).is_finite() {
        return Ok(());
    }
    let p = &world.particles;
    let bad = (0..p.len())
        .find(|&i| !(D::dot(p.v[i], p.v[i]).is_finite() && p.stress[i].max_abs().is_finite()))
        .unwrap_or(0);
    Err(Unstable {
        step: world.step,
        time: world.time,
        what: format!("particle {bad} has a non-finite velocity or stress (NaN)"),
    })
}

/// Checks that the state is worth a snapshot: finite, and every particle inside the grid.
/// The check bins the particles, which the next step would do first anyway, so a run with
/// snapshots takes exactly the same steps as one without.
fn check_snapshot<D: Dim>(world: &mut World<D>) -> Result<(), Unstable> {
    check_finite(world, &world.energies())?;
    bin::run(world)
}

/// How the step loop ended.
enum Stop {
    /// Reached the end time.
    Completed,
    /// Stopped on request, with a snapshot when there is an output folder.
    Interrupted,
    /// Went unstable.
    Unstable(Unstable),
    /// An output file could not be written (a full disk, a folder gone).
    Output(anyhow::Error),
}

/// A step's outcome as every rank sees it: split across ranks, an error on any rank stops
/// them all, with the lowest failing rank's message.
fn agree<D: Dim>(comm: &Comm, world: &World<D>, stepped: Result<(), Stop>) -> Result<(), Stop> {
    if !comm.is_split() {
        return stepped;
    }
    let mine = stepped.as_ref().err().map(|s| match s {
        Stop::Interrupted => String::new(),
        Stop::Unstable(u) => u.to_string(),
        Stop::Output(e) => format!("{e:#}"),
        Stop::Completed => String::new(),
    });
    match comm.first_error(mine) {
        None => Ok(()),
        Some(_) if stepped.is_err() => stepped,
        Some((_, text)) if text.is_empty() => Err(Stop::Interrupted),
        Some((rank, text)) => Err(Stop::Unstable(Unstable {
            step: world.step,
            time: world.time,
            what: format!("rank {rank} stopped: {text}"),
        })),
    }
}

/// Runs `scene` to its end time (or `opts.until`), with a progress bar when asked, and
/// stops cleanly on a signal, an instability or a failed output.
fn drive<D: DimSystems>(
    src: &Source,
    scene: Scene<D>,
    resumed: Option<(RunState, PathBuf)>,
    opts: &RunOptions,
) -> anyhow::Result<Outcome> {
    opts.writing(true);
    let mut run = Run::start(src, scene, resumed, opts)?;
    let bar = if opts.progress {
        let b = ProgressBar::new(run.steps);
        b.set_style(
            ProgressStyle::with_template("{bar:40} step {pos}/{len}  t = {msg}  ETA {eta}")
                .expect("valid template"),
        );
        b.set_position(run.world.step);
        b.reset_eta();
        b
    } else {
        ProgressBar::hidden()
    };
    // A signal during set-up stops the run before its first step: nothing to save.
    let early = opts.stop_requested();
    let mut stop = if early {
        Stop::Interrupted
    } else {
        Stop::Completed
    };
    let t0 = Instant::now();
    while !early && run.world.step < run.steps {
        let stepped = run.step();
        if let Err(s) = agree(&opts.comm, &run.world, stepped) {
            stop = s;
            break;
        }
        if run.world.step % 64 == 0 {
            bar.set_message(format!("{:.4e} s", run.world.time));
            bar.set_position(run.world.step);
        }
    }
    let wall = t0.elapsed().as_secs_f64();
    bar.finish_and_clear();
    run.finish(stop, wall, early)
}

#[cfg(test)]
mod tests {
    use super::step_count;

    /// A duration that is a whole number of steps takes exactly that many, although the
    /// quotient rounds a hair above it; one a little longer takes one more.
    #[test]
    fn whole_durations_take_no_extra_step() {
        let (end, dt) = (std::hint::black_box(4.5e-5), 1e-7);
        assert!(end / dt > 450.0, "the quotient rounds above 450");
        assert_eq!(step_count(end, dt), 450);
        assert_eq!(step_count(4.5e-5 + 1e-10, 1e-7), 451);
        assert_eq!(step_count(3e-6, 1e-6), 3);
    }
}
