//! `fissure`: the scenario launcher.

use clap::{Parser, Subcommand};
use fissure::app::run::checkpoint::resolve;
use fissure::app::run::stop::{Request, StopFlag, StopRequests};
use fissure::app::run::{Outcome, RunOptions, resume, run};
use fissure::app::sweep::{Swept, Vary, sweep};
use fissure::base::dim::{D2, D3};
use fissure::base::error::{ScenarioError, UsageError};
use fissure::io::output::summary::{Status, Summary};
use fissure::io::scenario::{Source, build, folder_name_problem};
use fissure::io::snapshot::pieces::verify as verify_pieces;
use fissure::io::snapshot::{Reader, SnapshotError};
use fissure::pipeline::schedule::Schedule;
use fissure::ranks::comm::start;
use fissure::record::expect::ExpectResult;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

/// Dynamic fracture with the material point method.
#[derive(Parser)]
#[command(version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run a scenario and write its outputs.
    Run {
        /// Scenario file (TOML).
        scenario: PathBuf,
        /// Output folder (default: out/<scenario name>).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Worker threads (default: all cores).
        #[arg(long, default_value_t = 0)]
        threads: usize,
        /// Override a key: --set simulation.duration=1e-3 (repeatable).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        overrides: Vec<String>,
        /// Simulated end time in seconds (default: the scenario's duration).
        #[arg(long)]
        until: Option<f64>,
    },
    /// Continue a run from a snapshot (a .fsnap file, or a run folder: its newest snapshot).
    Resume {
        /// Snapshot file or run folder.
        snapshot: PathBuf,
        /// Output folder (default: the run folder the snapshot is in).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Worker threads (default: all cores).
        #[arg(long, default_value_t = 0)]
        threads: usize,
        /// Simulated end time in seconds (default: the scenario's duration).
        #[arg(long)]
        until: Option<f64>,
    },
    /// Print a snapshot's header and column table, and verify every checksum.
    Inspect {
        /// Snapshot file or run folder.
        snapshot: PathBuf,
    },
    /// Validate a scenario without running it.
    Check {
        /// Scenario file (TOML).
        scenario: PathBuf,
        /// Override a key (repeatable).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        overrides: Vec<String>,
    },
    /// Run a scenario over every combination of values of some keys (sweep.csv: size, cost
    /// and every expect's error per run); a stopped sweep resumes where it stopped.
    Sweep {
        /// Scenario file (TOML).
        scenario: PathBuf,
        /// A key and its values, as --set takes them: --vary grid.cell=[2e-3,2e-3],[1e-3,1e-3]
        /// (repeatable: every combination runs).
        #[arg(long, value_name = "KEY=V1,V2,...", required = true)]
        vary: Vec<String>,
        /// Worker threads (default: all cores).
        #[arg(long, default_value_t = 0)]
        threads: usize,
        /// Output folder (default: out/<scenario name>-sweep).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Run more than 1,000 combinations.
        #[arg(long)]
        yes: bool,
    },
    /// Run scenarios and check every [[expect]]; exits non-zero if any fails.
    Validate {
        /// Scenario files or folders of them.
        #[arg(required = true)]
        paths: Vec<PathBuf>,
        /// Worker threads (default: all cores).
        #[arg(long, default_value_t = 0)]
        threads: usize,
        /// Also write each run's outputs under this folder.
        #[arg(long)]
        out: Option<PathBuf>,
        /// Override a key in every scenario (repeatable).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        overrides: Vec<String>,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    if let Some(name) = one_process(&cli.command) {
        // Started by mpirun on several ranks, every rank would do the whole job.
        match start() {
            Ok((c, _)) if c.is_split() && !c.is_root() => return ExitCode::FAILURE,
            Ok((c, _)) if c.is_split() => {
                return report(anyhow::anyhow!(
                    "`fissure {name}` runs on one process: start it without mpirun (only \
                     `run` divides a scene among MPI ranks)"
                ));
            }
            Ok(_) => {}
            Err(e) => return report(e),
        }
    }
    match cli.command {
        Command::Run {
            scenario,
            out,
            threads,
            overrides,
            until,
        } => cmd_run(&scenario, out, threads, until, &overrides),
        Command::Resume {
            snapshot,
            out,
            threads,
            until,
        } => cmd_resume(&snapshot, out, threads, until),
        Command::Inspect { snapshot } => cmd_inspect(&snapshot),
        Command::Check {
            scenario,
            overrides,
        } => cmd_check(&scenario, &overrides),
        Command::Validate {
            paths,
            threads,
            out,
            overrides,
        } => cmd_validate(&paths, threads, out, &overrides),
        Command::Sweep {
            scenario,
            vary,
            threads,
            out,
            yes,
        } => cmd_sweep(&scenario, &vary, threads, out, yes),
    }
}

/// The name of a command that runs on one process only, None for those that divide their
/// scenes among MPI ranks (`run`, `resume`, `validate`).
fn one_process(command: &Command) -> Option<&'static str> {
    match command {
        Command::Run { .. } => None,
        Command::Resume { .. } => None,
        Command::Inspect { .. } => Some("inspect"),
        Command::Check { .. } => Some("check"),
        Command::Validate { .. } => None,
        Command::Sweep { .. } => Some("sweep"),
    }
}

/// `sweep`: the runs one line each as they finish; sweep.csv holds the figures.
fn cmd_sweep(
    scenario: &Path,
    vary: &[String],
    threads: usize,
    out: Option<PathBuf>,
    yes: bool,
) -> ExitCode {
    let vary = match vary
        .iter()
        .map(|v| Vary::parse(v))
        .collect::<Result<Vec<_>, _>>()
    {
        Ok(v) => v,
        Err(e) => return report(e.into()),
    };
    let out = out.unwrap_or_else(|| {
        let stem = scenario
            .file_stem()
            .map_or("scenario".into(), |s| s.to_string_lossy());
        PathBuf::from("out").join(format!("{stem}-sweep"))
    });
    let stop = stop_flag(
        StopRequests::without_summary(),
        "stopping the sweep: the run under way stops at its next step and leaves no row",
    );
    let done = sweep(scenario, &vary, threads, &out, yes, Some(stop), |r| {
        let (k, n) = r.index;
        let what = r.set.join(" ");
        match (r.summary, &r.error) {
            (Some(s), _) => {
                let worst = (s.expects.iter())
                    .filter_map(|e| e.error.map(|x| x / e.tolerance))
                    .fold(0.0, f64::max);
                println!(
                    "[{k}/{n}] {what}: {}, {} particles, {:.2} s, worst error {worst:.2} of its \
                     tolerance",
                    s.status, s.particles, s.wall_seconds
                );
                for note in node_line_notes(&s.node_lines, s.dimension) {
                    println!("  warning: {note}");
                }
                for note in on_particle_notes(&s.particles_on_cracks) {
                    println!("  warning: {note}");
                }
                for note in tip_line_notes(&s.tips_on_lines) {
                    println!("  warning: {note}");
                }
                for note in split_boundary_notes(&s.split_boundaries) {
                    println!("  warning: {note}");
                }
            }
            (None, Some(e)) => println!("[{k}/{n}] {what}: {e}"),
            (None, None) => {}
        }
    });
    match done {
        Ok(Swept::Complete) => {
            println!("sweep.csv in {}", out.display());
            ExitCode::SUCCESS
        }
        Ok(Swept::Stopped) => {
            eprintln!(
                "sweep stopped: the finished runs are in {}; sweep again with the same --vary \
                 to run the rest",
                out.join("sweep.csv").display()
            );
            ExitCode::from(INTERRUPTED)
        }
        Err(e) => report(e),
    }
}

/// Exit code for bad input.
const BAD_INPUT: u8 = 2;

fn bad_input(e: &ScenarioError) -> ExitCode {
    eprintln!("error: {e}");
    ExitCode::from(BAD_INPUT)
}

/// What a run says on the first stop signal.
const AFTER_THIS_STEP: &str = "stopping after this step";

/// Exit code of a run stopped on request (128 + SIGINT, as shells report it).
const INTERRUPTED: u8 = 130;

/// Runs an error through: scenario and snapshot problems exit 2, anything else 1.
fn report(e: anyhow::Error) -> ExitCode {
    if let Some(s) = e.downcast_ref::<ScenarioError>() {
        return bad_input(s);
    }
    eprintln!("error: {e:#}");
    if is_bad_input(&e) {
        ExitCode::from(BAD_INPUT)
    } else {
        ExitCode::FAILURE
    }
}

/// Whether an error is the input's (a scenario, snapshot or usage problem) rather than the
/// run's (an instability, a failed output).
fn is_bad_input(e: &anyhow::Error) -> bool {
    e.downcast_ref::<ScenarioError>().is_some()
        || e.downcast_ref::<SnapshotError>().is_some()
        || e.downcast_ref::<UsageError>().is_some()
}

/// A flag set by Ctrl-C or SIGTERM. Before the run writes anything (building the scene), a
/// signal exits at once; after, the first stops the run cleanly after the current step with
/// a snapshot, saying `first`, and a second exits at once (leaving, for a run, a
/// summary.json that says so).
fn stop_flag(requests: StopRequests, first: &'static str) -> StopFlag {
    let flag = requests.flag();
    let installed = ctrlc::set_handler(move || match requests.request() {
        Request::SetUp => {
            eprintln!("\ninterrupted during set-up, before anything was written");
            std::process::exit(i32::from(INTERRUPTED));
        }
        Request::Stop => eprintln!("\n{first} (signal again to abort at once)"),
        Request::Abort => std::process::exit(i32::from(INTERRUPTED)),
    });
    if let Err(e) = installed {
        eprintln!("warning: no clean stop on Ctrl-C: {e}");
    }
    flag
}

/// The stop flag of a run writing to `out`; split across ranks (mpirun passes a signal to
/// every rank), only the first says it stops and leaves an abort's summary.
fn rank_stop_flag(root: bool, out: &Path) -> StopFlag {
    if root {
        return stop_flag(StopRequests::new(out), AFTER_THIS_STEP);
    }
    let requests = StopRequests::without_summary();
    let flag = requests.flag();
    let installed = ctrlc::set_handler(move || {
        if requests.request() != Request::Stop {
            std::process::exit(i32::from(INTERRUPTED));
        }
    });
    if let Err(e) = installed {
        eprintln!("warning: no clean stop on Ctrl-C: {e}");
    }
    flag
}

/// Prints a finished run's line and its expects; the exit code says how it ended.
fn finish(o: &Outcome, out: &Path) -> ExitCode {
    let s = &o.summary;
    if s.status == Status::Interrupted {
        eprintln!("{}", s.message.as_deref().unwrap_or("interrupted"));
        return ExitCode::from(INTERRUPTED);
    }
    let steps = if s.steps_run == s.steps {
        format!("{} steps", s.steps)
    } else {
        format!("{} steps (to step {})", s.steps_run, s.steps)
    };
    println!(
        "{}: {} particles, {steps} in {:.2} s ({:.3e} particle-steps/s, {} thread{}); outputs in {}",
        s.scenario,
        s.particles,
        s.wall_seconds,
        s.particle_steps_per_second,
        s.threads,
        if s.threads == 1 { "" } else { "s" },
        out.display()
    );
    if let Some(p) = &s.snapshot {
        println!(
            "  newest snapshot {p}; snapshots of this invocation: {:.1} MB in {:.2} s",
            s.snapshot_bytes as f64 / 1e6,
            s.snapshot_seconds
        );
    }
    if let Some(n) = s.cell_crossings.filter(|&n| n > 0) {
        println!(
            "  note: {n} of {} particles ended in another cell than they started in; with \
             linear shape functions each crossing jumps the internal force, which can feed \
             energy in (uGIMP does not)",
            s.particles
        );
    }
    for note in node_line_notes(&s.node_lines, s.dimension) {
        println!("  note: {note}");
    }
    for note in on_particle_notes(&s.particles_on_cracks) {
        println!("  note: {note}");
    }
    for note in tip_line_notes(&s.tips_on_lines) {
        println!("  note: {note}");
    }
    for note in split_boundary_notes(&s.split_boundaries) {
        println!("  note: {note}");
    }
    if let Some(note) = ignored_note(&s.ignored_keys) {
        println!("  note: {note}");
    }
    if let Some(n) = s.static_solve.map(|l| l.too_large).filter(|&n| n > 0) {
        println!(
            "  note: {n} load steps went to conjugate gradients: the direct solve's factor \
             would have taken more than half the memory available"
        );
    }
    if let Some(note) = k_withheld_note(s) {
        println!("  note: {note}");
    }
    for t in &s.contours {
        println!(
            "  note: crack `{}`, tip `{}`: no J or K (the contour of {} cells around the tip's \
             nearest node does not cross the crack: the crack is shorter than the contour, \
             or the tip lies within the contour's size of the grid's edge)",
            t.crack, t.tip, t.cells
        );
    }
    for t in &s.tubes {
        let part = |what: &str, v: &str| (!v.is_empty()).then(|| format!("{what} at vertices {v}"));
        let parts: Vec<String> = [
            part("no tube fits inside the body (J and K NaN)", &t.unfitted),
            part("the tube was shrunk", &t.shrunk),
        ]
        .into_iter()
        .flatten()
        .collect();
        println!(
            "  note: crack `{}` ({} front vertices, tubes of {:.3e} m): {}",
            t.crack,
            t.vertices,
            t.radius,
            parts.join("; ")
        );
    }
    for g in &s.growth {
        if let Some(why) = &g.stopped {
            let part = match g.tip.as_str() {
                "front" => "front".to_string(),
                end => format!("{end} tip"),
            };
            println!(
                "  note: the {part} of crack `{}` {why} at ({:.4e}, {:.4e}) m after growing \
                 {:.4e} m, and stopped there",
                g.crack, g.x[0], g.x[1], g.grown
            );
        }
    }
    for e in &s.expects {
        println!(
            "  {} {:<22} value {:>12} reference {:>12.5e} error {:>10} tol {:.2e}",
            if e.pass { "pass" } else { "FAIL" },
            e.quantity,
            e.value.map_or("-".into(), |v| format!("{v:.5e}")),
            e.reference,
            e.error.map_or("-".into(), |v| format!("{v:.3e}")),
            e.tolerance
        );
    }
    if s.expects.iter().all(|e| e.pass) {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    }
}

fn cmd_run(
    path: &Path,
    out: Option<PathBuf>,
    threads: usize,
    until: Option<f64>,
    overrides: &[String],
) -> ExitCode {
    // Under mpirun: one process per rank, the first one writing and reporting.
    let (comm, _mpi) = match start() {
        Ok(c) => c,
        Err(e) => return report(e),
    };
    let root = comm.is_root();
    let src = match Source::load(path, overrides) {
        Ok(s) => s,
        Err(e) if root => return bad_input(&e),
        Err(_) => return ExitCode::from(BAD_INPUT),
    };
    let out = out.unwrap_or_else(|| PathBuf::from("out").join(src.name()));
    let opts = RunOptions {
        out: Some(out.clone()),
        threads,
        progress: root,
        until,
        pause_after: None,
        stop: Some(rank_stop_flag(root, &out)),
        comm,
    };
    on_root(root, run(&src, &opts), &out)
}

fn cmd_resume(path: &Path, out: Option<PathBuf>, threads: usize, until: Option<f64>) -> ExitCode {
    // Under mpirun: one process per rank, as many as wanted, the first one reporting.
    let (comm, _mpi) = match start() {
        Ok(c) => c,
        Err(e) => return report(e),
    };
    let root = comm.is_root();
    let out = match out.map_or_else(|| default_out(path), Ok) {
        Ok(o) => o,
        Err(e) => return on_root(root, Err(e), Path::new("")),
    };
    let opts = RunOptions {
        out: Some(out.clone()),
        threads,
        progress: root,
        until,
        pause_after: None,
        stop: Some(rank_stop_flag(root, &out)),
        comm,
    };
    on_root(root, resume(path, &opts), &out)
}

/// How a run ends for the process: the first rank reports it (every rank reaches the same
/// end), the others only exit with success or failure.
fn on_root(root: bool, done: anyhow::Result<Outcome>, out: &Path) -> ExitCode {
    match done {
        Ok(o) if root => finish(&o, out),
        Err(e) if root => report(e),
        Ok(_) => ExitCode::SUCCESS,
        Err(e) if is_bad_input(&e) => ExitCode::from(BAD_INPUT),
        Err(_) => ExitCode::FAILURE,
    }
}

/// The run folder a snapshot belongs to: the parent of its `snapshots/` folder, or else
/// out/<scenario name>.
fn default_out(path: &Path) -> anyhow::Result<PathBuf> {
    let file = resolve(path)?;
    let dir = file
        .parent()
        .filter(|d| d.file_name() == Some("snapshots".as_ref()));
    match dir.and_then(|d| d.parent()) {
        Some(run) => Ok(run.to_path_buf()),
        None => {
            // The name comes from the file: a damaged or crafted one must not lead out of out/.
            let name = Reader::open(&file)?.header.scenario;
            match folder_name_problem(&name) {
                Some(why) => Err(UsageError(format!(
                    "{}: the snapshot is not in a run's snapshots/ folder, and its scenario name \
                     `{}` cannot name an output folder (it {why}): give --out DIR",
                    file.display(),
                    name.escape_debug()
                ))
                .into()),
                None => Ok(PathBuf::from("out").join(name)),
            }
        }
    }
}

fn cmd_inspect(path: &Path) -> ExitCode {
    let inspect = || -> anyhow::Result<bool> {
        let file = resolve(path)?;
        let mut r = Reader::open(&file)?;
        let h = r.header.clone();
        let size = std::fs::metadata(&file)?.len();
        println!(
            "snapshot   {} ({:.3} MB)",
            file.display(),
            size as f64 / 1e6
        );
        println!(
            "format     version {}, written by fissure {}",
            fissure::io::snapshot::format::FORMAT_VERSION,
            h.build
        );
        println!(
            "scenario   {} (text hash {:016x})",
            h.scenario, h.scenario_hash
        );
        println!(
            "counts     {}D, {} particles, {} nodes",
            h.dimension, h.particles, h.nodes
        );
        println!(
            "time       step {}, t = {:.9e} s, dt = {:.6e} s",
            h.step, h.time, h.dt
        );
        println!(
            "{:<24} {:>5} {:>12} {:>14} {:>16}  checksum",
            "column", "type", "scalars", "offset", "xxh3"
        );
        let checks = r.verify()?;
        for (c, (_, ok)) in h.columns.iter().zip(&checks) {
            println!(
                "{:<24} {:>5} {:>12} {:>14} {:>16x}  {}",
                c.name,
                format!("{:?}", c.elem).to_lowercase(),
                c.len,
                r.offset_of(&c.name).unwrap_or(c.offset),
                c.checksum,
                if *ok { "ok" } else { "MISMATCH" }
            );
        }
        let bad = checks.iter().filter(|c| !c.1).count();
        if bad == 0 {
            println!("all {} column checksums ok", checks.len());
        } else {
            println!("{bad} column(s) fail their checksum");
        }
        // A split run's manifest: its particles are in one piece per rank.
        let pieces = verify_pieces(&mut r)?;
        for (k, (p, problem)) in pieces.iter().enumerate() {
            println!(
                "piece {k:<5} {} {:>12} particles  {}",
                p.name,
                p.particles,
                problem.as_deref().unwrap_or("ok")
            );
        }
        let broken = pieces.iter().filter(|p| p.1.is_some()).count();
        if !pieces.is_empty() {
            println!("{} of {} pieces ok", pieces.len() - broken, pieces.len());
        }
        Ok(bad == 0 && broken == 0)
    };
    match inspect() {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::from(BAD_INPUT),
        Err(e) => report(e),
    }
}

fn cmd_check(path: &Path, overrides: &[String]) -> ExitCode {
    let src = match Source::load(path, overrides) {
        Ok(s) => s,
        Err(e) => return bad_input(&e),
    };
    macro_rules! describe {
        ($d:ty) => {
            match build::<$d>(&src) {
                Ok(scene) => {
                    let w = &scene.world;
                    let sched = Schedule::for_world(w, scene.fracture.clone());
                    let names: Vec<&str> = sched.systems.iter().map(|s| s.name()).collect();
                    println!(
                        "{}: ok. {}D, {} particles, {} nodes, dt {:.4e} s (limit {:.4e} s), {} steps, schedule: {}",
                        scene.name,
                        src.scenario.simulation.dimension,
                        w.particles.len(),
                        w.grid.geom.node_count(),
                        w.settings.dt,
                        scene.dt_limit,
                        fissure::app::run::step_count(scene.duration, w.settings.dt),
                        names.join(" -> ")
                    );
                    let dim = usize::from(src.scenario.simulation.dimension);
                    for note in node_line_notes(&fissure::app::run::node_lines(w), dim) {
                        println!("  note: {note}");
                    }
                    let on = fissure::app::run::particles_on_cracks(w);
                    for note in on_particle_notes(&on) {
                        println!("  note: {note}");
                    }
                    let tips = fissure::app::run::tips_on_particle_lines(w);
                    for note in tip_line_notes(&tips) {
                        println!("  note: {note}");
                    }
                    if let Some(note) = ignored_note(&fissure::io::scenario::ignored(&src)) {
                        println!("  note: {note}");
                    }
                    ExitCode::SUCCESS
                }
                Err(e) => bad_input(&e),
            }
        };
    }
    match src.scenario.simulation.dimension {
        3 => describe!(D3),
        _ => describe!(D2),
    }
}

fn collect(paths: &[PathBuf]) -> Vec<PathBuf> {
    let mut files = Vec::new();
    for p in paths {
        if p.is_dir() {
            let mut inner: Vec<PathBuf> = std::fs::read_dir(p)
                .map(|d| d.filter_map(|e| e.ok().map(|e| e.path())).collect())
                .unwrap_or_default();
            inner.retain(|f| f.extension().is_some_and(|e| e == "toml"));
            inner.sort();
            files.extend(inner);
        } else {
            files.push(p.clone());
        }
    }
    files
}

fn cmd_validate(
    paths: &[PathBuf],
    threads: usize,
    out: Option<PathBuf>,
    overrides: &[String],
) -> ExitCode {
    // Under mpirun: every scenario runs on all the ranks, the first one reporting.
    let (comm, _mpi) = match start() {
        Ok(c) => c,
        Err(e) => return report(e),
    };
    let root = comm.is_root();
    let say = |line: String| {
        if root {
            println!("{line}");
        }
    };
    let files = collect(paths);
    if files.is_empty() {
        let list: Vec<String> = paths.iter().map(|p| p.display().to_string()).collect();
        if root {
            eprintln!("error: no scenario (*.toml) in {}", list.join(", "));
        }
        return ExitCode::from(BAD_INPUT);
    }
    let (mut failed, mut passed, mut refused) = (0usize, 0usize, 0usize);
    say(format!(
        "{:<28} {:<24} {:>13} {:>13} {:>10} {:>9} {:<5} {:>9}",
        "scenario", "quantity", "reference", "obtained", "error", "tolerance", "pass", "wall (s)"
    ));
    for file in &files {
        let t0 = Instant::now();
        let src = match Source::load(file, overrides) {
            Ok(s) => s,
            Err(e) => {
                say(format!("{:<28} error: {e}", file.display()));
                refused += 1;
                continue;
            }
        };
        let opts = RunOptions {
            out: out.as_ref().map(|o| o.join(src.name())),
            threads,
            comm: comm.clone(),
            ..RunOptions::default()
        };
        match run(&src, &opts) {
            Ok(o) => {
                let wall = t0.elapsed().as_secs_f64();
                for e in &o.summary.expects {
                    if e.pass {
                        passed += 1;
                    } else {
                        failed += 1;
                    }
                    say(format!(
                        "{:<28} {:<24} {:>13.5e} {:>13} {:>10} {:>9.2e} {:<5} {:>9.2}",
                        o.summary.scenario,
                        format!("{} {}", e.quantity, e.probes.join(",")),
                        e.reference,
                        e.value.map_or("-".into(), |v| format!("{v:.5e}")),
                        e.error.map_or("-".into(), |v| format!("{v:.3e}")),
                        e.tolerance,
                        if e.pass { "yes" } else { "NO" },
                        wall
                    ));
                }
                if o.summary.expects.is_empty() {
                    say(format!(
                        "{:<28} ran ({}) in {wall:.2} s; it has no [[expect]] to check",
                        o.summary.scenario, o.summary.status
                    ));
                }
                if let Some(note) = k_withheld_note(&o.summary) {
                    say(format!("{:<28} note: {note}", o.summary.scenario));
                }
            }
            Err(e) => {
                say(format!("{:<28} error: {e:#}", src.name()));
                if is_bad_input(&e) {
                    refused += 1;
                } else {
                    failed += 1;
                }
            }
        }
    }
    if refused > 0 {
        say(format!(
            "{passed} passed, {failed} failed, {refused} refused as bad input"
        ));
        return ExitCode::from(BAD_INPUT);
    }
    say(format!("{passed} passed, {failed} failed"));
    if failed == 0 {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    }
}

/// Why a K expect has no value in a body that yielded (None when that is not the case).
fn k_withheld_note(s: &Summary) -> Option<&'static str> {
    let k_missing = |e: &ExpectResult| e.quantity.starts_with('K') && e.value.is_none();
    (s.energies.plastic_work > 0.0 && s.expects.iter().any(k_missing)).then_some(
        "the body yielded and a K expect has no value: K is NaN wherever yielded material \
         lies near the J contour or tube (K comes from J only where the response is \
         elastic); J is reported there",
    )
}

/// What the launcher says of the keys a static scene ignores, if any.
fn ignored_note(keys: &[String]) -> Option<String> {
    (!keys.is_empty()).then(|| {
        format!(
            "a static scene ignores {} (they apply to explicit runs only)",
            keys.join(", ")
        )
    })
}

/// What the launcher says of each crack that passes through particle centres.
fn on_particle_notes(on: &[fissure::io::output::summary::ParticlesOnReport]) -> Vec<String> {
    on.iter()
        .map(|o| {
            format!(
                "crack `{}` passes through {} particle centres: round-off decides their side \
                 of it, and J and K with it (a few %); set it a fraction of a particle \
                 spacing off them",
                o.crack, o.particles
            )
        })
        .collect()
}

/// What the launcher says of each boundary that drove nodes with a field per crack side.
fn split_boundary_notes(
    split: &[fissure::io::output::summary::SplitBoundaryReport],
) -> Vec<String> {
    split
        .iter()
        .map(|b| {
            format!(
                "boundary[{}] prescribes {} node(s) whose support a crack cut at the last \
                 step: it drives the material on both sides of the crack there (to drive \
                 one side only, stop its region one node row short of the crack)",
                b.boundary, b.nodes
            )
        })
        .collect()
}

/// What the launcher says of each crack whose tips lie on particle-node lines.
fn tip_line_notes(on: &[fissure::io::output::summary::TipLinesReport]) -> Vec<String> {
    on.iter()
        .map(|o| {
            format!(
                "crack `{}` ends on {} line(s) from particles to their nodes: round-off \
                 decides whether each crosses the crack, and J and K with it (about 1.5 % \
                 in J); move its tips a fraction of a cell",
                o.crack, o.lines
            )
        })
        .collect()
}

/// What the launcher says of each crack that lies on a line or plane of grid nodes.
fn node_line_notes(
    lines: &[fissure::io::output::summary::NodeLineReport],
    dimension: usize,
) -> Vec<String> {
    let what = if dimension == 2 { "line" } else { "plane" };
    lines
        .iter()
        .map(|n| {
            format!(
                "crack `{}` lies on the node {what} {} = {:.4e} m ({:.0} % of its elements): J \
                 and K read less accurately there and its classification is redone every \
                 step; set it half a cell off (e.g. with `[grid] anchor`)",
                n.crack,
                n.axis,
                n.at,
                100.0 * n.share
            )
        })
        .collect()
}
