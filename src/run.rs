//! Running a scene: the step loop, instability checks, output cadence and the summary.

use crate::dim::{D2, D3, Dim};
use crate::error::Unstable;
use crate::measure::{History, Row};
use crate::output::plot::{self, Series};
use crate::output::summary::Summary;
use crate::output::vtk;
use crate::scenario::{Scene, Source, build};
use crate::schedule::Schedule;
use crate::world::{Energies, World};
use anyhow::Context;
use indicatif::{ProgressBar, ProgressStyle};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// How to run a scenario.
#[derive(Clone, Debug, Default)]
pub struct RunOptions {
    /// Output folder; None writes nothing (tests, validate without --out).
    pub out: Option<PathBuf>,
    /// Worker threads (0: rayon's default, the number of cores).
    pub threads: usize,
    /// Show a progress bar on stderr.
    pub progress: bool,
}

/// Result of a run: its summary and the recorded history.
#[derive(Debug)]
pub struct Outcome {
    /// The summary (also written to summary.json).
    pub summary: Summary,
    /// Recorded history.
    pub history: History,
}

/// Runs `src` with `opts` in a thread pool of the requested size.
pub fn run(src: &Source, opts: &RunOptions) -> anyhow::Result<Outcome> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(opts.threads)
        .build()
        .context("cannot build the thread pool")?;
    pool.install(|| match src.scenario.simulation.dimension {
        2 => drive::<D2>(build::<D2>(src)?, opts),
        3 => drive::<D3>(build::<D3>(src)?, opts),
        _ => Err(src.error("simulation.dimension", "must be 2 or 3").into()),
    })
}

/// Files a run appends to as it goes, so a run that stops early keeps what it wrote.
struct Writers {
    dir: PathBuf,
    energy: std::io::BufWriter<std::fs::File>,
    probes: std::io::BufWriter<std::fs::File>,
    frames: Vec<(f64, String)>,
}

impl Writers {
    fn open(dir: &Path, probe_names: &[String]) -> anyhow::Result<Self> {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("cannot create output folder {}", dir.display()))?;
        let create = |name: &str| -> anyhow::Result<_> {
            let path = dir.join(name);
            Ok(std::io::BufWriter::new(
                std::fs::File::create(&path)
                    .with_context(|| format!("cannot create {}", path.display()))?,
            ))
        };
        let mut energy = create("energy.csv")?;
        writeln!(
            energy,
            "step,time,kinetic,strain,external_work,damping_work"
        )?;
        let mut probes = create("probes.csv")?;
        writeln!(
            probes,
            "step,time{}",
            probe_names
                .iter()
                .map(|n| format!(",{n}"))
                .collect::<String>()
        )?;
        Ok(Writers {
            dir: dir.to_path_buf(),
            energy,
            probes,
            frames: Vec::new(),
        })
    }

    fn frame<D: Dim>(&mut self, world: &World<D>) -> anyhow::Result<()> {
        let name = format!("particles_{:05}.vtu", self.frames.len());
        vtk::write_particles(&self.dir.join(&name), &world.particles)?;
        self.frames.push((world.time, name));
        vtk::write_collection(&self.dir.join("particles.pvd"), &self.frames)?;
        Ok(())
    }
}

/// Appends a history row with energies `e` (and the probes' latest samples to probes.csv).
fn record<D: Dim>(
    world: &World<D>,
    e: Energies,
    centre: D::Vec,
    history: &mut History,
    w: &mut Option<Writers>,
) -> anyhow::Result<()> {
    let p = &world.particles;
    let scale = (0..p.len())
        .map(|i| p.mass[i] * D::dot(p.v[i], p.v[i]).sqrt())
        .sum();
    history.rows.push(Row {
        step: world.step,
        time: world.time,
        energies: e,
        momentum: D::to_xyz(world.momentum()),
        momentum_scale: scale,
        angular: world.angular_momentum(centre),
    });
    if let Some(w) = w {
        writeln!(
            w.energy,
            "{},{:.9e},{:.9e},{:.9e},{:.9e},{:.9e}",
            world.step, world.time, e.kinetic, e.strain, e.external_work, e.damping_work
        )?;
        let last = history.time.len() - 1;
        write!(w.probes, "{},{:.9e}", world.step, world.time)?;
        for s in &history.probes {
            write!(w.probes, ",{:.9e}", s[last])?;
        }
        writeln!(w.probes)?;
    }
    Ok(())
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
        particle: bad,
        what: "has a non-finite velocity or stress (NaN)".into(),
    })
}

fn drive<D: Dim>(scene: Scene<D>, opts: &RunOptions) -> anyhow::Result<Outcome> {
    let Scene {
        name,
        mut world,
        probes,
        expects,
        duration,
        output,
        dt_limit,
    } = scene;
    let mut schedule = Schedule::for_world(&world);
    let dt = world.settings.dt;
    let steps = (duration / dt).ceil() as u64;
    let names: Vec<String> = probes.iter().map(|p| p.name.clone()).collect();
    let mut writers = match &opts.out {
        Some(dir) => Some(Writers::open(dir, &names)?),
        None => None,
    };
    let total_mass: f64 = world.particles.mass.iter().sum();
    let mut centre = D::zero();
    for i in 0..world.particles.len() {
        centre += world.particles.x[i] * (world.particles.mass[i] / total_mass);
    }
    let mut history = History {
        probes: vec![Vec::with_capacity((steps as usize + 1).min(1 << 20)); probes.len()],
        ..History::default()
    };
    let sample = |world: &World<D>, h: &mut History| {
        h.time.push(world.time);
        for (k, p) in probes.iter().enumerate() {
            h.probes[k].push(p.sample(&world.particles, &world.materials));
        }
    };
    sample(&world, &mut history);
    record(&world, world.energies(), centre, &mut history, &mut writers)?;
    let vtk = output.vtk && writers.is_some();
    if vtk && let Some(w) = &mut writers {
        w.frame(&world)?;
    }
    let bar = if opts.progress {
        let b = ProgressBar::new(steps);
        b.set_style(
            ProgressStyle::with_template("{bar:40} step {pos}/{len}  t = {msg}  ETA {eta}")
                .expect("valid template"),
        );
        b
    } else {
        ProgressBar::hidden()
    };
    let mut next_history = output.history_interval;
    let mut next_frame = output.interval;
    let mut failure = None;
    let t0 = Instant::now();
    while world.step < steps {
        if let Err(e) = schedule.step(&mut world) {
            failure = Some(e);
            break;
        }
        sample(&world, &mut history);
        let last = world.step == steps;
        if world.time >= next_history * (1.0 - 1e-9) || last {
            next_history += output.history_interval;
            let energies = world.energies();
            if let Err(e) = check_finite(&world, &energies) {
                failure = Some(e);
                break;
            }
            record(&world, energies, centre, &mut history, &mut writers)?;
        }
        if vtk && (world.time >= next_frame * (1.0 - 1e-9) || last) {
            next_frame += output.interval;
            if let Some(w) = &mut writers {
                w.frame(&world)?;
            }
        }
        if world.step % 64 == 0 {
            bar.set_message(format!("{:.4e} s", world.time));
            bar.set_position(world.step);
        }
    }
    let wall = t0.elapsed().as_secs_f64();
    bar.finish_and_clear();
    let results = if failure.is_none() {
        expects
            .iter()
            .map(|e| e.evaluate(&history, &probes))
            .collect()
    } else {
        Vec::new()
    };
    let summary = Summary {
        scenario: name.clone(),
        dimension: D::D,
        status: if failure.is_some() {
            "unstable"
        } else {
            "completed"
        }
        .into(),
        message: failure.as_ref().map(|e| e.to_string()),
        particles: world.particles.len(),
        nodes: world.grid.geom.node_count(),
        steps: world.step,
        time: world.time,
        dt,
        dt_limit,
        wall_seconds: wall,
        particle_steps_per_second: world.particles.len() as f64 * world.step as f64
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
        energies: world.energies(),
        expects: results,
    };
    if let Some(w) = &mut writers {
        w.energy.flush()?;
        w.probes.flush()?;
        let json = serde_json::to_string_pretty(&summary)?;
        std::fs::write(w.dir.join("summary.json"), json)?;
        if output.plot {
            plot_energies(&w.dir.join("energy.png"), &name, &history)
                .map_err(|e| anyhow::anyhow!("cannot draw energy.png: {e}"))?;
        }
    }
    if let Some(e) = failure {
        let kept = opts
            .out
            .as_ref()
            .map(|d| format!("; files written so far are kept in {}", d.display()))
            .unwrap_or_default();
        return Err(anyhow::anyhow!("{e}{kept}"));
    }
    Ok(Outcome { summary, history })
}

fn plot_energies(path: &Path, name: &str, h: &History) -> Result<(), String> {
    let pick = |f: &dyn Fn(&Row) -> f64| h.rows.iter().map(|r| (r.time, f(r))).collect();
    let series = [
        Series {
            label: "kinetic",
            points: pick(&|r| r.energies.kinetic),
        },
        Series {
            label: "strain",
            points: pick(&|r| r.energies.strain),
        },
        Series {
            label: "external work",
            points: pick(&|r| r.energies.external_work),
        },
        Series {
            label: "damping work",
            points: pick(&|r| r.energies.damping_work),
        },
        Series {
            label: "K + W - W_ext + W_damp",
            points: pick(&|r| {
                let e = &r.energies;
                e.kinetic + e.strain - e.external_work + e.damping_work
            }),
        },
    ];
    plot::lines(
        path,
        &format!("{name}: energies"),
        "time (s)",
        "energy (J)",
        &series,
    )
}
