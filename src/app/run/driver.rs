//! A run under way: [`Run::start`] opens the outputs and records the first row,
//! [`Run::step`] advances one step and writes what is due after it, [`Run::finish`] writes
//! the summary and the figures and says how the run ended.

use super::checkpoint::Checkpointer;
use super::reports;
use super::writers::{self, Contents, Writers};
use super::{Outcome, RunOptions, Stop, check_finite, check_snapshot, row_due, step_count};
use crate::base::error::UsageError;
use crate::fracture::plan::{FracturePlan, Measured};
use crate::io::output::figures::Figures;
use crate::io::output::summary::{
    NodeLineReport, ParticlesOnReport, Status, Summary, TipLinesReport,
};
use crate::io::scenario::{MAX_STEPS, OutputPlan, Scene, Source};
use crate::pipeline::distribute;
use crate::pipeline::schedule::Schedule;
use crate::record::expect::Expect;
use crate::record::probe::Probe;
use crate::record::solve_log::{SolveLog, SolveRow, Solved};
use crate::record::state::RunState;
use crate::store::world::World;
use crate::systems::DimSystems;
use anyhow::Context;
use std::path::{Path, PathBuf};

/// A scene being run: its world and schedule, what it records and where it writes.
pub(super) struct Run<'a, D: DimSystems> {
    src: &'a Source,
    opts: &'a RunOptions,
    name: String,
    /// The state advanced step by step.
    pub world: World<D>,
    probes: Vec<Probe>,
    expects: Vec<Expect>,
    output: OutputPlan,
    dt_limit: f64,
    fracture: Option<FracturePlan>,
    schedule: Schedule,
    /// Steps to the end time, counted from t = 0.
    pub steps: u64,
    state: RunState,
    writers: Option<Writers>,
    checkpoints: Option<Checkpointer>,
    resumed_from: Option<PathBuf>,
    crack_names: Option<Vec<String>>,
    grows: bool,
    node_lines: Vec<NodeLineReport>,
    particles_on_cracks: Vec<ParticlesOnReport>,
    tips_on_lines: Vec<TipLinesReport>,
    /// The step the run started from (0, or the snapshot's).
    pub first_step: u64,
    /// Particles over all ranks.
    particles: usize,
}

impl<'a, D: DimSystems> Run<'a, D> {
    /// Checks the end time, opens the output files (continuing them after a resume) and,
    /// on a fresh run, records the state at t = 0: probes, the first history row, J and K
    /// as the scene stands, the first VTK frame.
    pub fn start(
        src: &'a Source,
        scene: Scene<D>,
        resumed: Option<(RunState, PathBuf)>,
        opts: &'a RunOptions,
    ) -> anyhow::Result<Self> {
        let Scene {
            name,
            mut world,
            mut probes,
            expects,
            duration,
            output,
            dt_limit,
            checkpoint,
            fracture,
        } = scene;
        // What the scene holds, reported before each rank keeps its share of it.
        let node_lines = reports::node_lines(&world);
        let particles_on_cracks = reports::particles_on_cracks(&world);
        let tips_on_lines = reports::tips_on_particle_lines(&world);
        distribute::split(&mut world, &mut probes, opts.comm.clone())?;
        // Only the first rank writes the files (every rank its piece of a VTK frame).
        let out = opts.out.as_ref().filter(|_| opts.comm.is_root());
        let schedule = Schedule::for_world(&world, fracture.clone());
        let steps = end_step(&world, opts.until.unwrap_or(duration))?;
        let resumed_from = resumed.as_ref().map(|r| r.1.clone());
        let state = match resumed {
            Some((s, _)) => s,
            None => RunState::start(
                &world,
                probes.len(),
                steps,
                output.history_interval,
                output.interval,
                checkpoint.every_time,
            ),
        };
        let crack_names: Option<Vec<String>> = (fracture.as_ref().and(world.cracks.as_ref()))
            .map(|c| c.topology.cracks().iter().map(|c| c.name.clone()).collect());
        let growing: Option<(Vec<String>, bool)> = (world.cracks.as_ref())
            .filter(|c| c.topology.cracks().iter().any(|c| c.growth.is_some()))
            .map(|c| {
                let cracks = c.topology.cracks();
                let fatigue = cracks
                    .iter()
                    .any(|c| c.growth.is_some_and(|g| g.paris.is_some()));
                (cracks.iter().map(|c| c.name.clone()).collect(), fatigue)
            });
        let names: Vec<String> = probes.iter().map(|p| p.name.clone()).collect();
        let mut writers = match out {
            Some(dir) => Some(Writers::open(
                dir,
                &names,
                Contents {
                    cracks: crack_names.as_deref(),
                    paths: fracture.as_ref().is_some_and(|f| !f.compare.is_empty()),
                    front_vertices: D::D == 3,
                    growing: growing.as_ref().map(|(n, f)| (n.as_slice(), *f)),
                    solves: world.settings.solver == crate::store::world::Solver::Static,
                },
                &state.history,
            )?),
            None => None,
        };
        // A snapshot lies in <run folder>/snapshots/; frames before it stay in that folder.
        if let (Some(w), Some(from)) = (&mut writers, resumed_from.as_ref())
            && let Some(run_dir) = from.parent().and_then(Path::parent)
        {
            w.frames_in(run_dir, state.frames.len());
        }
        // Split across ranks, every rank writes its piece of each snapshot.
        let checkpoints = match &opts.out {
            Some(dir) => Some(Checkpointer::new(
                dir,
                checkpoint,
                resumed_from.clone().map(|p| (p, world.step)),
                &opts.comm,
            )?),
            None => None,
        };
        let first_step = world.step;
        let particles = (opts
            .comm
            .all_gather(world.particles.len().to_le_bytes().to_vec()))
        .iter()
        .map(|b| usize::from_le_bytes(b[..].try_into().expect("a usize per rank")))
        .sum();
        let mut run = Run {
            src,
            opts,
            name,
            world,
            probes,
            expects,
            output,
            dt_limit,
            fracture,
            schedule,
            steps,
            state,
            writers,
            checkpoints,
            resumed_from,
            crack_names,
            grows: growing.is_some(),
            node_lines,
            particles_on_cracks,
            tips_on_lines,
            first_step,
            particles,
        };
        if run.resumed_from.is_none() {
            run.record_start()?;
        }
        Ok(run)
    }

    /// Whether VTK frames are written.
    fn vtk(&self) -> bool {
        self.output.vtk && self.opts.out.is_some()
    }

    /// Writes a VTK frame: split across ranks, every rank its piece and the first the
    /// `.pvtu` joining them.
    fn frame(&mut self) -> anyhow::Result<()> {
        if let Some(dir) = self
            .opts
            .out
            .as_ref()
            .filter(|_| self.world.domain.is_split())
        {
            writers::piece(dir, self.state.frames.len(), &self.world)?;
        }
        match &mut self.writers {
            Some(w) => w.frame(&self.world, &mut self.state),
            None => {
                self.state.frames.push(self.world.time);
                Ok(())
            }
        }
    }

    /// The state at t = 0: probes, the first history row, J and K, the first frame.
    fn record_start(&mut self) -> anyhow::Result<()> {
        self.state.sample(&self.world, &self.probes);
        let row = *self.state.record(&self.world, self.world.energies());
        let measured = self.schedule.measure_now(&mut self.world)?;
        self.report(measured)?;
        if let Some(w) = &mut self.writers {
            w.row(&row, &self.state.history)?;
        }
        if self.vtk() {
            self.frame()?;
        }
        Ok(())
    }

    /// Writes what a step measured (J and K, paths, growth) to its files and the history.
    fn report(&mut self, m: Measured) -> anyhow::Result<()> {
        if let Some(w) = &mut self.writers {
            w.fracture(&m.tips, &m.paths)?;
            w.growth(&m.growth)?;
        }
        self.state.history.fracture.extend(m.tips);
        self.state.history.paths.extend(m.paths);
        self.state.history.growth.extend(m.growth);
        Ok(())
    }

    /// Advances one step and writes what is due after it: probes, a history row, a VTK
    /// frame, a snapshot. Err says why the run stops here (never [`Stop::Completed`]).
    pub fn step(&mut self) -> Result<(), Stop> {
        // A step that ends at a history row with J to measure keeps its own stencils.
        let next = self.world.step + 1;
        let ends_at_row = row_due(
            next as f64 * self.world.settings.dt,
            self.state.next_history,
            next == self.steps,
        );
        distribute::migrate(&mut self.world, &mut self.probes).map_err(Stop::Unstable)?;
        distribute::rebalance(&mut self.world, &mut self.probes).map_err(Stop::Unstable)?;
        let measured = (self.schedule)
            .step_measuring(&mut self.world, ends_at_row)
            .map_err(Stop::Unstable)?;
        self.state.sample(&self.world, &self.probes);
        self.report(measured).map_err(Stop::Output)?;
        if let Some(mut solved) = self.schedule.take_solved() {
            let last = self.state.history.solves.last();
            if let (true, Some(last)) = (solved.kept(), last) {
                solved = Solved::keeping(&last.solved);
            }
            let row = SolveRow {
                step: self.world.step,
                time: self.world.time,
                solved,
            };
            if let Some(w) = &mut self.writers {
                w.solve(&row).map_err(Stop::Output)?;
            }
            self.state.history.solves.push(row);
        }
        let last = self.world.step == self.steps;
        if row_due(self.world.time, self.state.next_history, last) {
            self.state.next_history += self.output.history_interval;
            let energies = self.world.energies();
            check_finite(&self.world, &energies).map_err(Stop::Unstable)?;
            let row = *self.state.record(&self.world, energies);
            if let Some(w) = &mut self.writers {
                w.row(&row, &self.state.history).map_err(Stop::Output)?;
            }
        }
        if self.vtk() && (self.world.time >= self.state.next_frame * (1.0 - 1e-9) || last) {
            self.state.next_frame += self.output.interval;
            self.frame().map_err(Stop::Output)?;
        }
        let requested =
            self.opts.stop_requested() || self.opts.pause_after == Some(self.world.step);
        // The wall clock and signals differ between ranks: one rank's wish writes on all.
        if let Some(c) = &mut self.checkpoints
            && (self.world.domain).any(
                c.due(self.world.step, self.world.time, &mut self.state)
                    || requested
                    || (last && c.periodic()),
            )
        {
            let checked = check_snapshot(&mut self.world);
            self.world.domain.agree(checked).map_err(Stop::Unstable)?;
            if let Some(w) = &mut self.writers {
                w.flush().map_err(Stop::Output)?;
            }
            c.write(self.src, &self.world, &self.state)
                .map_err(Stop::Output)?;
        }
        if requested && !last {
            return Err(Stop::Interrupted);
        }
        Ok(())
    }

    /// Flushes the files, writes summary.json and the figures, and returns the outcome:
    /// an error for an unstable or failed run (its files kept), else its summary and
    /// history. `early`: stopped during set-up, before any step.
    pub fn finish(mut self, mut stop: Stop, wall: f64, early: bool) -> anyhow::Result<Outcome> {
        // The files must take the last rows before the summary says how the run ended.
        if !matches!(stop, Stop::Output(_))
            && let Some(w) = &mut self.writers
            && let Err(e) = w.flush()
        {
            stop = Stop::Output(e);
        }
        let snapshot = self.checkpoints.as_ref().and_then(|c| c.last.clone());
        let summary = self.summary(&stop, wall, early, snapshot.as_ref());
        let failed = matches!(stop, Stop::Output(_));
        if let Some(w) = &mut self.writers {
            let json = serde_json::to_string_pretty(&summary)?;
            let summary_path = w.dir.join("summary.json");
            if failed {
                // Best effort: the disk that failed may yet take a small file.
                w.flush().ok();
                std::fs::write(&summary_path, json).ok();
            } else {
                std::fs::write(&summary_path, json)
                    .with_context(|| format!("cannot write {}", summary_path.display()))?;
            }
            if self.output.plot && !failed {
                let figures = Figures {
                    name: &self.name,
                    expects: &self.expects,
                    crack_names: self.crack_names.as_deref(),
                    k0: self.fracture.as_ref().and_then(|f| f.k0),
                    grown: self.world.cracks.as_ref().filter(|_| self.grows),
                };
                figures.draw(&w.dir, &self.state.history)?;
            }
        }
        match stop {
            Stop::Output(_) => Err(anyhow::anyhow!(
                "{}",
                summary.message.expect("failed runs have a message")
            )),
            Stop::Unstable(_) => {
                let kept = (self.opts.out.as_ref())
                    .map(|d| format!("; files written so far are kept in {}", d.display()))
                    .unwrap_or_default();
                Err(anyhow::anyhow!(
                    "{}{kept}",
                    summary.message.expect("unstable runs have a message")
                ))
            }
            Stop::Completed | Stop::Interrupted => Ok(Outcome {
                summary,
                snapshot: snapshot.map(|s| s.0),
                history: self.state.history,
            }),
        }
    }

    /// The summary of the run as it ended.
    fn summary(
        &self,
        stop: &Stop,
        wall: f64,
        early: bool,
        snapshot: Option<&(PathBuf, u64)>,
    ) -> Summary {
        let world = &self.world;
        let results = match stop {
            Stop::Completed => (self.expects.iter())
                .map(|e| e.evaluate(&self.state.history, &self.probes))
                .collect(),
            _ => Vec::new(),
        };
        let (status, message) = stop_message(stop, world, snapshot, early);
        let steps_run = world.step - self.first_step;
        let history = &self.state.history;
        let fracture = self.fracture.as_ref();
        Summary {
            scenario: self.name.clone(),
            dimension: D::D,
            status,
            message,
            particles: self.particles,
            nodes: world.grid.geom.node_count(),
            steps: world.step,
            steps_run,
            time: world.time,
            dt: world.settings.dt,
            dt_limit: self.dt_limit,
            wall_seconds: wall,
            particle_steps_per_second: self.particles as f64 * steps_run as f64 / wall.max(1e-12),
            threads: rayon::current_num_threads(),
            schedule: (self.schedule.systems.iter())
                .map(|s| s.name().to_string())
                .collect(),
            system_seconds: (self.schedule.seconds_by_name().into_iter())
                .map(|(n, s)| (n.to_string(), s))
                .collect(),
            bytes_per_particle: world.bytes_per_particle(),
            bytes_per_node: crate::store::grid::Grid::<D>::bytes_per_node(),
            peak_resident_bytes: crate::io::output::summary::peak_resident_bytes(),
            cell_crossings: world.cell_crossings(),
            node_lines: self.node_lines.clone(),
            particles_on_cracks: self.particles_on_cracks.clone(),
            tips_on_lines: self.tips_on_lines.clone(),
            split_boundaries: reports::split_boundaries(world),
            energies: world.energies(),
            static_solve: (world.settings.solver == crate::store::world::Solver::Static).then(
                || SolveLog {
                    coarse_factorizations: self.schedule.coarse_factorizations(),
                    ..SolveLog::from_rows(&history.solves)
                },
            ),
            ranks: reports::ranks(world, steps_run),
            ignored_keys: crate::io::scenario::ignored(self.src),
            probes: reports::probes(&self.probes, history),
            expects: results,
            paths: reports::paths(world, fracture, history),
            tubes: reports::tubes(world, fracture, history),
            contours: reports::contours(world, fracture, history),
            growth: reports::growth(world),
            resumed_from: self.resumed_from.as_ref().map(|p| p.display().to_string()),
            snapshot: snapshot.map(|s| s.0.display().to_string()),
            snapshot_seconds: self.checkpoints.as_ref().map_or(0.0, |c| c.seconds),
            snapshot_bytes: self.checkpoints.as_ref().map_or(0, |c| c.bytes),
        }
    }
}

/// The step a run ends at to reach `end` (s), refused when `end` is not after the current
/// time or needs more than [`MAX_STEPS`] steps.
fn end_step<D: DimSystems>(world: &World<D>, end: f64) -> anyhow::Result<u64> {
    let dt = world.settings.dt;
    if !(end.is_finite() && end > world.time) {
        return Err(UsageError(format!(
            "the end time {end:e} s must be a number after the current time {:e} s",
            world.time
        ))
        .into());
    }
    if end / dt > MAX_STEPS {
        return Err(UsageError(format!(
            "the end time {end:e} s is more than {MAX_STEPS:e} steps of {dt:e} s"
        ))
        .into());
    }
    Ok(step_count(end, dt))
}

/// The status a stop gives the summary, and the message that says why the run ended early
/// and where to go on from.
fn stop_message<D: DimSystems>(
    stop: &Stop,
    world: &World<D>,
    snapshot: Option<&(PathBuf, u64)>,
    early: bool,
) -> (Status, Option<String>) {
    match stop {
        Stop::Completed => (Status::Completed, None),
        Stop::Interrupted => (
            Status::Interrupted,
            Some(match snapshot {
                _ if early => format!(
                    "stopped on request during set-up, before step {}: nothing was run, so \
                     no snapshot",
                    world.step + 1
                ),
                Some((p, _)) => format!(
                    "stopped on request at step {} (t = {:.6e} s); snapshot {}; continue with `fissure resume {}`",
                    world.step,
                    world.time,
                    p.display(),
                    p.display()
                ),
                None => format!(
                    "stopped on request at step {} (t = {:.6e} s); no output folder, so no snapshot",
                    world.step, world.time
                ),
            }),
        ),
        Stop::Unstable(e) => (
            Status::Unstable,
            Some(match snapshot {
                Some((p, s)) => format!("{e}; last good snapshot {} (step {s})", p.display()),
                None => e.to_string(),
            }),
        ),
        Stop::Output(e) => (
            Status::Failed,
            Some(format!(
                "output failed at step {} (t = {:.6e} s): {e:#}; {}",
                world.step,
                world.time,
                match snapshot {
                    Some((p, s)) => format!(
                        "the last snapshot is {} (step {s}): `fissure resume` it into a folder \
                         with room, which rewrites the history files",
                        p.display()
                    ),
                    None => "no snapshot was written".into(),
                }
            )),
        ),
    }
}
