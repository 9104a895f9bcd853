//! Running a scene: the step loop, instability checks, output and checkpoint cadence, and
//! the summary. A run starts from a scenario ([`run`]) or from a snapshot ([`resume`]).

pub mod checkpoint;
mod reports;
pub use reports::node_lines;
pub mod state;
pub mod stop;
pub mod writers;

use crate::crack::Cracks;
use crate::dim::{D2, D3, Dim};
use crate::error::{Unstable, UsageError};
use crate::fracture::{Measured, TipResult};
use crate::geometry::Element;
use crate::measure::{Expect, History, Measure, Row, balance_drift};
use crate::output::plot::{self, Panel, Series};
use crate::output::summary::Summary;
use crate::scenario::MAX_STEPS;
use crate::scenario::{Scene, Source, build};
use crate::schedule::Schedule;
use crate::snapshot::Reader;
use crate::snapshot::state::restore;
use crate::sym::SymTensor;
use crate::systems::DimSystems;
use crate::systems::bin;
use crate::world::{Energies, World};
use anyhow::Context;
use checkpoint::Checkpointer;
use indicatif::{ProgressBar, ProgressStyle};
use state::RunState;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;
use writers::Writers;

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
    /// When set (by a signal handler), stop cleanly after the current step.
    pub stop: Option<Arc<AtomicBool>>,
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
    pool(opts)?.install(|| match src.scenario.simulation.dimension {
        2 => drive::<D2>(src, build::<D2>(src)?, None, opts),
        3 => drive::<D3>(src, build::<D3>(src)?, None, opts),
        _ => Err(src.error("simulation.dimension", "must be 2 or 3").into()),
    })
}

/// Continues the run stored in the snapshot at `path` (a file, or a run folder whose
/// newest snapshot is taken).
pub fn resume(path: &Path, opts: &RunOptions) -> anyhow::Result<Outcome> {
    let file = checkpoint::resolve(path)?;
    let mut reader = Reader::open(&file)?;
    fn go<D: DimSystems>(
        r: &mut Reader,
        file: &Path,
        opts: &RunOptions,
    ) -> anyhow::Result<Outcome> {
        let restored = restore::<D>(r)?;
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

fn drive<D: DimSystems>(
    src: &Source,
    scene: Scene<D>,
    resumed: Option<(RunState, PathBuf)>,
    opts: &RunOptions,
) -> anyhow::Result<Outcome> {
    let Scene {
        name,
        mut world,
        probes,
        expects,
        duration,
        output,
        dt_limit,
        checkpoint,
        fracture,
    } = scene;
    let mut schedule = Schedule::for_world(&world, fracture.clone());
    let dt = world.settings.dt;
    let end = opts.until.unwrap_or(duration);
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
    let steps = step_count(end, dt);
    let names: Vec<String> = probes.iter().map(|p| p.name.clone()).collect();
    let resumed_from = resumed.as_ref().map(|r| r.1.clone());
    let mut state = match resumed {
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
    let crack_names: Option<Vec<String>> = fracture
        .as_ref()
        .and(world.cracks.as_ref())
        .map(|c| c.topology.cracks().iter().map(|c| c.name.clone()).collect());
    let node_lines = reports::node_lines(&world);
    let growing: Option<(Vec<String>, bool)> = world
        .cracks
        .as_ref()
        .filter(|c| c.topology.cracks().iter().any(|c| c.growth.is_some()))
        .map(|c| {
            let cracks = c.topology.cracks();
            let fatigue = cracks
                .iter()
                .any(|c| c.growth.is_some_and(|g| g.paris.is_some()));
            (cracks.iter().map(|c| c.name.clone()).collect(), fatigue)
        });
    let mut writers = match &opts.out {
        Some(dir) => Some(Writers::open(
            dir,
            &names,
            crack_names.as_deref(),
            fracture.as_ref().is_some_and(|f| !f.compare.is_empty()),
            D::D == 3,
            growing.as_ref().map(|(n, f)| (n.as_slice(), *f)),
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
    // Writes what a step measured (J and K, paths, growth) to its files and the history.
    let report = |m: Measured, state: &mut RunState, w: &mut Option<Writers>| {
        if let Some(w) = w {
            w.fracture(&m.tips, &m.paths)?;
            w.growth(&m.growth)?;
        }
        state.history.fracture.extend(m.tips);
        state.history.paths.extend(m.paths);
        state.history.growth.extend(m.growth);
        Ok(())
    };
    let mut checkpoints = match &opts.out {
        Some(dir) => Some(Checkpointer::new(
            dir,
            checkpoint,
            resumed_from.clone().map(|p| (p, world.step)),
        )?),
        None => None,
    };
    let vtk = output.vtk && writers.is_some();
    if resumed_from.is_none() {
        state.sample(&world, &probes);
        let row = *state.record(&world, world.energies());
        let measured = schedule.measure_now(&mut world)?;
        report(measured, &mut state, &mut writers)?;
        if let Some(w) = &mut writers {
            w.row(&row, &state.history)?;
            if vtk {
                w.frame(&world, &mut state)?;
            }
        }
    }
    let bar = if opts.progress {
        let b = ProgressBar::new(steps);
        b.set_style(
            ProgressStyle::with_template("{bar:40} step {pos}/{len}  t = {msg}  ETA {eta}")
                .expect("valid template"),
        );
        b.set_position(world.step);
        b.reset_eta();
        b
    } else {
        ProgressBar::hidden()
    };
    let first_step = world.step;
    // A signal during set-up stops the run before its first step: nothing to save.
    let early = opts
        .stop
        .as_ref()
        .is_some_and(|s| s.load(Ordering::Relaxed));
    let mut stop = if early {
        Stop::Interrupted
    } else {
        Stop::Completed
    };
    let t0 = Instant::now();
    // An output error ends the run as failed, keeping the history for summary.json.
    macro_rules! or_stop {
        ($e:expr) => {
            if let Err(e) = $e {
                stop = Stop::Output(e);
                break;
            }
        };
    }
    while !early && world.step < steps {
        // A step that ends at a history row with J to measure keeps its own stencils.
        let next = world.step + 1;
        let ends_at_row = row_due(
            next as f64 * world.settings.dt,
            state.next_history,
            next == steps,
        );
        let measured = match schedule.step_measuring(&mut world, ends_at_row) {
            Ok(m) => m,
            Err(e) => {
                stop = Stop::Unstable(e);
                break;
            }
        };
        state.sample(&world, &probes);
        or_stop!(report(measured, &mut state, &mut writers));
        let last = world.step == steps;
        if row_due(world.time, state.next_history, last) {
            state.next_history += output.history_interval;
            let energies = world.energies();
            if let Err(e) = check_finite(&world, &energies) {
                stop = Stop::Unstable(e);
                break;
            }
            let row = *state.record(&world, energies);
            if let Some(w) = &mut writers {
                or_stop!(w.row(&row, &state.history));
            }
        }
        if vtk && (world.time >= state.next_frame * (1.0 - 1e-9) || last) {
            state.next_frame += output.interval;
            if let Some(w) = &mut writers {
                or_stop!(w.frame(&world, &mut state));
            }
        }
        let requested = opts
            .stop
            .as_ref()
            .is_some_and(|s| s.load(Ordering::Relaxed))
            || opts.pause_after == Some(world.step);
        if let Some(c) = &mut checkpoints
            && (c.due(world.step, world.time, &mut state) || requested || (last && c.periodic()))
        {
            if let Err(e) = check_snapshot(&mut world) {
                stop = Stop::Unstable(e);
                break;
            }
            if let Some(w) = &mut writers {
                or_stop!(w.flush());
            }
            or_stop!(c.write(src, &world, &state));
        }
        if requested && !last {
            stop = Stop::Interrupted;
            break;
        }
        if world.step % 64 == 0 {
            bar.set_message(format!("{:.4e} s", world.time));
            bar.set_position(world.step);
        }
    }
    // The files must take the last rows before the summary says how the run ended.
    if !matches!(stop, Stop::Output(_))
        && let Some(w) = &mut writers
        && let Err(e) = w.flush()
    {
        stop = Stop::Output(e);
    }
    let wall = t0.elapsed().as_secs_f64();
    bar.finish_and_clear();
    let snapshot = checkpoints.as_ref().and_then(|c| c.last.clone());
    let results = match stop {
        Stop::Completed => expects
            .iter()
            .map(|e| e.evaluate(&state.history, &probes))
            .collect(),
        _ => Vec::new(),
    };
    let (status, message) = match &stop {
        Stop::Completed => ("completed", None),
        Stop::Interrupted => (
            "interrupted",
            Some(match &snapshot {
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
            "unstable",
            Some(match &snapshot {
                Some((p, s)) => format!("{e}; last good snapshot {} (step {s})", p.display()),
                None => e.to_string(),
            }),
        ),
        Stop::Output(e) => (
            "failed",
            Some(format!(
                "output failed at step {} (t = {:.6e} s): {e:#}; {}",
                world.step,
                world.time,
                match &snapshot {
                    Some((p, s)) => format!(
                        "the last snapshot is {} (step {s}): `fissure resume` it into a folder \
                         with room, which rewrites the history files",
                        p.display()
                    ),
                    None => "no snapshot was written".into(),
                }
            )),
        ),
    };
    let summary = Summary {
        scenario: name.clone(),
        dimension: D::D,
        status: status.into(),
        message: message.clone(),
        particles: world.particles.len(),
        nodes: world.grid.geom.node_count(),
        steps: world.step,
        steps_run: world.step - first_step,
        time: world.time,
        dt,
        dt_limit,
        wall_seconds: wall,
        particle_steps_per_second: world.particles.len() as f64 * (world.step - first_step) as f64
            / wall.max(1e-12),
        threads: rayon::current_num_threads(),
        schedule: schedule
            .systems
            .iter()
            .map(|s| s.name().to_string())
            .collect(),
        system_seconds: schedule
            .seconds_by_name()
            .into_iter()
            .map(|(n, s)| (n.to_string(), s))
            .collect(),
        bytes_per_particle: world.bytes_per_particle(),
        bytes_per_node: crate::grid::Grid::<D>::bytes_per_node(),
        peak_resident_bytes: crate::output::summary::peak_resident_bytes(),
        cell_crossings: world.cell_crossings(),
        node_lines,
        energies: world.energies(),
        probes: reports::probes(&probes, &state.history),
        expects: results,
        paths: reports::paths(&world, fracture.as_ref(), &state.history),
        tubes: reports::tubes(&world, fracture.as_ref(), &state.history),
        contours: reports::contours(&world, fracture.as_ref(), &state.history),
        growth: reports::growth(&world),
        resumed_from: resumed_from.map(|p| p.display().to_string()),
        snapshot: snapshot.as_ref().map(|s| s.0.display().to_string()),
        snapshot_seconds: checkpoints.as_ref().map_or(0.0, |c| c.seconds),
        snapshot_bytes: checkpoints.as_ref().map_or(0, |c| c.bytes),
    };
    let failed = matches!(stop, Stop::Output(_));
    if let Some(w) = &mut writers {
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
        if output.plot && !failed {
            plot_energies(&w.dir.join("energy.png"), &name, &state.history)
                .map_err(|e| anyhow::anyhow!("cannot draw energy.png: {e}"))?;
            if let Some(cracks) = &crack_names {
                let path = w.dir.join("fracture.png");
                let k0 = fracture.as_ref().and_then(|f| f.k0);
                let drawn = if D::D == 3 {
                    plot_front(&path, &name, &state.history, cracks, k0)
                } else {
                    plot_fracture(&path, &name, &state.history, &expects, cracks, k0)
                };
                drawn.map_err(|e| anyhow::anyhow!("cannot draw fracture.png: {e}"))?;
            }
            if growing.is_some()
                && let Some(cracks) = &world.cracks
            {
                plot_paths(&w.dir.join("growth.png"), &name, cracks)
                    .map_err(|e| anyhow::anyhow!("cannot draw growth.png: {e}"))?;
            }
        }
    }
    if failed {
        return Err(anyhow::anyhow!(
            "{}",
            message.expect("failed runs have a message")
        ));
    }
    if let Stop::Unstable(_) = stop {
        let kept = opts
            .out
            .as_ref()
            .map(|d| format!("; files written so far are kept in {}", d.display()))
            .unwrap_or_default();
        return Err(anyhow::anyhow!(
            "{}{kept}",
            message.expect("unstable runs have a message")
        ));
    }
    Ok(Outcome {
        summary,
        history: state.history,
        snapshot: snapshot.map(|s| s.0),
    })
}

/// K_I and K_II over time at every tip, with each K expect's reference (a flat line, or a
/// curve through the references at given times); divided by `k0` when given. When a crack
/// grows, a panel below draws the crack lengths.
fn plot_fracture(
    path: &Path,
    name: &str,
    h: &History,
    expects: &[Expect],
    cracks: &[String],
    k0: Option<f64>,
) -> Result<(), String> {
    let scale = 1.0 / k0.unwrap_or(1.0);
    let mut tips: Vec<(u32, u32)> = h.fracture.iter().map(|t| (t.crack, t.tip)).collect();
    tips.sort_unstable();
    tips.dedup();
    let t_end = h.fracture.last().map_or(0.0, |t| t.time);
    let label =
        |c: u32, tip: u32| format!("{} {}", cracks[c as usize], ["start", "end"][tip as usize]);
    let mut labels = Vec::new();
    let mut points = Vec::new();
    for &(c, tip) in &tips {
        for (k, mode) in ["KI", "KII"].iter().enumerate() {
            labels.push(format!("{mode} {}", label(c, tip)));
            points.push(
                h.fracture
                    .iter()
                    .filter(|t| (t.crack, t.tip) == (c, tip))
                    .map(|t| (t.time, t.k[k] * scale))
                    .collect::<Vec<_>>(),
            );
        }
    }
    // A reference for the last value is a level line; references at times join up into a
    // curve, one per crack tip and quantity.
    for e in expects {
        let Measure::Tip {
            crack,
            tip,
            qty,
            at,
        } = e.measure
        else {
            continue;
        };
        if qty >= 2 {
            continue;
        }
        let name = format!("{} reference {}", e.quantity, label(crack, tip));
        match at {
            None => {
                labels.push(name);
                points.push(vec![
                    (0.0, e.reference * scale),
                    (t_end, e.reference * scale),
                ]);
            }
            Some(t) => match labels.iter().position(|l| *l == name) {
                Some(k) => points[k].push((t, e.reference * scale)),
                None => {
                    labels.push(name);
                    points.push(vec![(t, e.reference * scale)]);
                }
            },
        }
    }
    let title = format!("{name}: stress intensity factors");
    if h.growth.is_empty() {
        return k_plot(path, &title, "time (s)", &labels, points, k0);
    }
    // A growing crack: its length below K, on the same time axis.
    let length_labels: Vec<String> = (tips.iter())
        .map(|&(c, tip)| format!("length {}", label(c, tip)))
        .collect();
    let lengths = (tips.iter())
        .map(|&(c, tip)| {
            (h.fracture.iter())
                .filter(|t| (t.crack, t.tip) == (c, tip))
                .map(|t| (t.time, t.length))
                .collect()
        })
        .collect();
    let axis = k_axis(k0);
    let panels = [
        Panel {
            y_label: &axis,
            series: series(&labels, points),
        },
        Panel {
            y_label: "crack length (m)",
            series: series(&length_labels, lengths),
        },
    ];
    plot::panels(path, &title, "time (s)", &panels, 0.62)
}

/// Draws K series (over `k0` when given, which the y axis then says) into a PNG.
fn k_plot(
    path: &Path,
    title: &str,
    x_label: &str,
    labels: &[String],
    points: Vec<Vec<(f64, f64)>>,
    k0: Option<f64>,
) -> Result<(), String> {
    let series = series(labels, points);
    plot::lines(path, title, x_label, &k_axis(k0), &series)
}

/// The K axis's label: K, or K over `k0` when given.
fn k_axis(k0: Option<f64>) -> String {
    match k0 {
        Some(k0) => format!("K / K0 (K0 = {k0:.4e} Pa sqrt(m))"),
        None => "K (Pa sqrt(m))".to_string(),
    }
}

/// Series from labels and their points.
fn series(labels: &[String], points: Vec<Vec<(f64, f64)>>) -> Vec<Series<'_>> {
    (labels.iter().zip(points))
        .map(|(l, p)| Series {
            label: l,
            points: p,
        })
        .collect()
}

/// K_I, K_II and K_III along every 3D crack front at the last measurement, against the
/// front vertex's ordinal; divided by `k0` when given.
fn plot_front(
    path: &Path,
    name: &str,
    h: &History,
    cracks: &[String],
    k0: Option<f64>,
) -> Result<(), String> {
    let scale = 1.0 / k0.unwrap_or(1.0);
    let last = h.fracture.last().map_or(0, |t| t.step);
    let rows: Vec<&TipResult> = h.fracture.iter().filter(|t| t.step == last).collect();
    let mut labels = Vec::new();
    let mut points = Vec::new();
    for (c, crack) in cracks.iter().enumerate() {
        for (k, mode) in ["KI", "KII", "KIII"].iter().enumerate() {
            labels.push(format!("{mode} {crack}"));
            points.push(
                (rows.iter())
                    .filter(|t| t.crack as usize == c)
                    .map(|t| (f64::from(t.tip), t.k[k] * scale))
                    .collect::<Vec<_>>(),
            );
        }
    }
    let time = rows.first().map_or(0.0, |t| t.time);
    k_plot(
        path,
        &format!("{name}: K along the front at {time:.4e} s"),
        "front vertex",
        &labels,
        points,
        k0,
    )
}

/// growth.png: every growing crack's path (its whole polyline) at the end of the run; in
/// 3D its fronts at the end, seen along the global axis nearest its mean normal.
fn plot_paths<D: Dim>(path: &Path, name: &str, cracks: &Cracks<D>) -> Result<(), String> {
    let topo = &cracks.topology;
    let x = &cracks.geometry.x;
    let growing = |c: usize| topo.cracks()[c].growth.is_some();
    if D::D == 2 {
        let series: Vec<Series> = (topo.cracks().iter())
            .filter(|c| c.growth.is_some())
            .map(|c| Series {
                label: &c.name,
                points: (c.vertices.iter())
                    .map(|&v| {
                        let p = D::to_xyz(x[v as usize]);
                        (p[0], p[1])
                    })
                    .collect(),
            })
            .collect();
        return plot::plane(
            path,
            &format!("{name}: crack paths"),
            ["x (m)", "y (m)"],
            &series,
        );
    }
    // The axis the cracks face most: the largest component of their summed area normals.
    let mut normal = [0.0f64; 3];
    for (e, &c) in topo.elems().iter().zip(topo.elem_crack()) {
        if growing(c as usize) {
            let n = D::to_xyz(e.normal(x));
            (0..3).for_each(|a| normal[a] += n[a].abs());
        }
    }
    let facing = (0..3).fold(0, |b, a| if normal[a] > normal[b] { a } else { b });
    let axes = [(facing + 1) % 3, (facing + 2) % 3];
    let series: Vec<Series> = (topo.fronts().iter())
        .filter(|f| growing(f.crack as usize))
        .map(|f| {
            let ring = f.vertices.first().filter(|_| topo.is_closed(f));
            Series {
                label: &topo.cracks()[f.crack as usize].name,
                points: (f.vertices.iter().chain(ring))
                    .map(|&v| {
                        let p = D::to_xyz(x[v as usize]);
                        (p[axes[0]], p[axes[1]])
                    })
                    .collect(),
            }
        })
        .collect();
    let label = |a: usize| ["x (m)", "y (m)", "z (m)"][a];
    plot::plane(
        path,
        &format!("{name}: crack fronts at the end"),
        [label(axes[0]), label(axes[1])],
        &series,
    )
}

/// energy.png: the energies and works on top; below, the energy balance's drift
/// (E(t) - E(0)) over the largest energy or work of the run, the scale `energy_drift`
/// uses, so a drift too small to see on the energies' scale still shows.
fn plot_energies(path: &Path, name: &str, h: &History) -> Result<(), String> {
    let pick = |f: &dyn Fn(&Row) -> f64| h.rows.iter().map(|r| (r.time, f(r))).collect();
    let mut energies = Panel {
        y_label: "energy (J)",
        series: vec![
            Series {
                label: "kinetic K",
                points: pick(&|r| r.energies.kinetic),
            },
            Series {
                label: "strain W",
                points: pick(&|r| r.energies.strain),
            },
            Series {
                label: "external work W_ext",
                points: pick(&|r| r.energies.external_work),
            },
            Series {
                label: "damping work W_damp",
                points: pick(&|r| r.energies.damping_work),
            },
        ],
    };
    if h.rows.iter().any(|r| r.energies.plastic_work != 0.0) {
        energies.series.push(Series {
            label: "plastic work W_p",
            points: pick(&|r| r.energies.plastic_work),
        });
    }
    if h.rows.iter().any(|r| r.energies.friction_work != 0.0) {
        energies.series.push(Series {
            label: "friction work W_f",
            points: pick(&|r| r.energies.friction_work),
        });
    }
    let balance = Panel {
        y_label: "balance drift (relative)",
        series: vec![Series {
            label: "(K + W + W_p - W_ext + W_damp + W_f - E(0)) / largest energy or work",
            points: balance_drift(h).unwrap_or_default(),
        }],
    };
    plot::panels(
        path,
        &format!("{name}: energies"),
        "time (s)",
        &[energies, balance],
        0.62,
    )
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
