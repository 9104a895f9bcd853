//! `fissure`: the scenario launcher.

use clap::{Parser, Subcommand};
use fissure::dim::{D2, D3};
use fissure::error::ScenarioError;
use fissure::run::{RunOptions, run};
use fissure::scenario::{Source, build};
use fissure::schedule::Schedule;
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
    },
    /// Validate a scenario without running it.
    Check {
        /// Scenario file (TOML).
        scenario: PathBuf,
        /// Override a key (repeatable).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        overrides: Vec<String>,
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
    match cli.command {
        Command::Run {
            scenario,
            out,
            threads,
            overrides,
        } => cmd_run(&scenario, out, threads, &overrides),
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
    }
}

/// Exit code for bad input.
const BAD_INPUT: u8 = 2;

fn bad_input(e: &ScenarioError) -> ExitCode {
    eprintln!("error: {e}");
    ExitCode::from(BAD_INPUT)
}

/// Runs an error through: scenario problems exit 2, anything else 1.
fn report(e: anyhow::Error) -> ExitCode {
    match e.downcast_ref::<ScenarioError>() {
        Some(s) => bad_input(s),
        None => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

fn cmd_run(path: &Path, out: Option<PathBuf>, threads: usize, overrides: &[String]) -> ExitCode {
    let src = match Source::load(path, overrides) {
        Ok(s) => s,
        Err(e) => return bad_input(&e),
    };
    let out = out.unwrap_or_else(|| PathBuf::from("out").join(src.name()));
    let opts = RunOptions {
        out: Some(out.clone()),
        threads,
        progress: true,
    };
    match run(&src, &opts) {
        Ok(o) => {
            let s = &o.summary;
            println!(
                "{}: {} particles, {} steps in {:.2} s ({:.3e} particle-steps/s, {} threads); outputs in {}",
                s.scenario,
                s.particles,
                s.steps,
                s.wall_seconds,
                s.particle_steps_per_second,
                s.threads,
                out.display()
            );
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
                    let sched = Schedule::for_world(w);
                    let names: Vec<&str> = sched.systems.iter().map(|s| s.name()).collect();
                    println!(
                        "{}: ok. {}D, {} particles, {} nodes, dt {:.4e} s (limit {:.4e} s), {} steps, schedule: {}",
                        scene.name,
                        src.scenario.simulation.dimension,
                        w.particles.len(),
                        w.grid.geom.node_count(),
                        w.settings.dt,
                        scene.dt_limit,
                        (scene.duration / w.settings.dt).ceil(),
                        names.join(" -> ")
                    );
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
    let files = collect(paths);
    let mut failed = 0usize;
    let mut passed = 0usize;
    println!(
        "{:<28} {:<24} {:>13} {:>13} {:>10} {:>9} {:<5} {:>9}",
        "scenario", "quantity", "reference", "obtained", "error", "tolerance", "pass", "wall (s)"
    );
    for file in &files {
        let t0 = Instant::now();
        let src = match Source::load(file, overrides) {
            Ok(s) => s,
            Err(e) => {
                println!("{:<28} error: {e}", file.display());
                failed += 1;
                continue;
            }
        };
        let opts = RunOptions {
            out: out.as_ref().map(|o| o.join(src.name())),
            threads,
            progress: false,
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
                    println!(
                        "{:<28} {:<24} {:>13.5e} {:>13} {:>10} {:>9.2e} {:<5} {:>9.2}",
                        o.summary.scenario,
                        format!("{} {}", e.quantity, e.probes.join(",")),
                        e.reference,
                        e.value.map_or("-".into(), |v| format!("{v:.5e}")),
                        e.error.map_or("-".into(), |v| format!("{v:.3e}")),
                        e.tolerance,
                        if e.pass { "yes" } else { "NO" },
                        wall
                    );
                }
            }
            Err(e) => {
                println!("{:<28} error: {e:#}", src.name());
                failed += 1;
            }
        }
    }
    println!("{passed} passed, {failed} failed");
    if failed == 0 {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    }
}
