//! A run's state as snapshot columns, and back. The scene is rebuilt from the stored scenario
//! text (loads, boundaries, probes, grid, crack names and contact laws) and the evolving
//! state is then put back from the columns (particles, crack topology, vertices and
//! surfaces, work, history); grid scratch, particle bins and crack velocity fields are
//! rebuilt by the first step.

use super::columns::{add_particles, header};
use super::format::{ColumnSet, Header, Reader, SnapshotError};
use super::pieces::{self, Piece, Table};
use super::topology::{self, Encoded};
use crate::base::dim::Dim;
use crate::fracture::plan::{PathResult, TipResult};
use crate::io::scenario::{Scene, Source, build_share};
use crate::physics::growth::{GrowthRow, TipState};
use crate::physics::material::Material;
use crate::ranks::comm::Comm;
use crate::record::history::{History, Row};
use crate::record::solve_log::SolveRow;
use crate::record::state::RunState;
use crate::store::crack::Cracks;
use crate::store::world::{Energies, Work, World};
use std::path::Path;
use xxhash_rust::xxh3::xxh3_64;

/// Scalars per history row in the `history.rows.data` column.
const ROW_WIDTH: usize = 12;

fn row_data(r: &Row) -> [f64; ROW_WIDTH] {
    let e = &r.energies;
    [
        r.time,
        e.kinetic,
        e.strain,
        e.external_work,
        e.damping_work,
        r.momentum[0],
        r.momentum[1],
        r.momentum[2],
        r.momentum_scale,
        r.angular[0],
        r.angular[1],
        r.angular[2],
    ]
}

/// A crack tip's id in the `history.fracture.tip` and `history.paths.id` columns: the crack
/// in the high 32 bits, the tip (2D: its end; 3D: its front vertex's ordinal) in the low
/// ones.
fn tip_id(crack: u32, tip: u32) -> u64 {
    (u64::from(crack) << 32) | u64::from(tip)
}

/// Scalars per crack-tip result in the `history.fracture.data` column.
const TIP_WIDTH: usize = 1 + TipResult::VALUES;

fn tip_data(t: &TipResult) -> impl Iterator<Item = f64> {
    std::iter::once(t.time).chain(t.values())
}

/// Scalars per path result in the `history.paths.data` column.
const PATH_WIDTH: usize = 5;

fn path_data(p: &PathResult) -> [f64; PATH_WIDTH] {
    [p.time, p.line[0], p.line[1], p.area[0], p.area[1]]
}

fn row_from(step: u64, d: &[f64], plastic_work: f64, friction_work: f64) -> Row {
    Row {
        step,
        time: d[0],
        energies: Energies {
            kinetic: d[1],
            strain: d[2],
            external_work: d[3],
            damping_work: d[4],
            plastic_work,
            friction_work,
        },
        momentum: [d[5], d[6], d[7]],
        momentum_scale: d[8],
        angular: [d[9], d[10], d[11]],
    }
}

/// Writes `world` and `state` of the run of `src` to `path` (atomically); returns the bytes.
pub fn write<D: Dim>(
    path: &Path,
    src: &Source,
    world: &World<D>,
    state: &RunState,
) -> std::io::Result<u64> {
    write_with(path, src, world, state, None)
}

/// Writes the manifest of a split run's snapshot: everything but the particles, which are
/// in `pieces`; returns the bytes.
pub fn write_manifest<D: Dim>(
    path: &Path,
    src: &Source,
    world: &World<D>,
    state: &RunState,
    pieces: &[Piece],
) -> std::io::Result<u64> {
    write_with(path, src, world, state, Some(pieces))
}

/// Writes the snapshot; with `pieces`, the manifest of a split run, whose particles are in
/// the pieces it names.
fn write_with<D: Dim>(
    path: &Path,
    src: &Source,
    world: &World<D>,
    state: &RunState,
    pieces: Option<&[Piece]>,
) -> std::io::Result<u64> {
    let p = &world.particles;
    let table = pieces.map(Table::new);
    let m = &world.materials;
    let youngs: Vec<f64> = m.iter().map(|m| m.youngs).collect();
    let poisson: Vec<f64> = m.iter().map(|m| m.poisson).collect();
    let density: Vec<f64> = m.iter().map(|m| m.density).collect();
    let run = [world.work.external, world.work.damping];
    let friction = [world.work.friction];
    let cadence = [state.next_history, state.next_frame, state.next_checkpoint];
    let h = &state.history;
    let row_steps: Vec<u64> = h.rows.iter().map(|r| r.step).collect();
    let rows: Vec<f64> = h.rows.iter().flat_map(row_data).collect();
    let rows_plastic: Vec<f64> = h.rows.iter().map(|r| r.energies.plastic_work).collect();
    let rows_friction: Vec<f64> = h.rows.iter().map(|r| r.energies.friction_work).collect();
    let tip_steps: Vec<u64> = h.fracture.iter().map(|t| t.step).collect();
    let tip_ids: Vec<u64> = h.fracture.iter().map(|t| tip_id(t.crack, t.tip)).collect();
    let tip_data: Vec<f64> = h.fracture.iter().flat_map(tip_data).collect();
    let path_steps: Vec<u64> = h.paths.iter().map(|p| p.step).collect();
    let path_ids: Vec<u64> = h.paths.iter().map(|p| tip_id(p.crack, p.tip)).collect();
    let path_contours: Vec<u64> = h.paths.iter().map(|p| u64::from(p.contour)).collect();
    let path_data: Vec<f64> = h.paths.iter().flat_map(path_data).collect();
    let path_directions: Vec<f64> = h.paths.iter().flat_map(|p| p.direction).collect();
    let growth_steps: Vec<u64> = h.growth.iter().map(|g| g.step).collect();
    let growth_ids: Vec<u64> = h.growth.iter().map(|g| tip_id(g.crack, g.tip)).collect();
    let growth_data: Vec<f64> = h.growth.iter().flat_map(|g| g.values()).collect();
    let solve_steps: Vec<u64> = h.solves.iter().map(|r| r.step).collect();
    let solve_data: Vec<f64> = h.solves.iter().flat_map(|r| r.values()).collect();
    let probe_names: Vec<String> = (0..h.probes.len())
        .map(|k| format!("history.probe.{k}"))
        .collect();

    let topology = world.cracks.as_ref().map(|cr| Encoded::new(&cr.topology));
    let tips: Vec<f64> = (world.cracks.iter())
        .flat_map(|cr| cr.tips.iter().flat_map(|t| t.values()))
        .collect();
    let solved: Vec<u64> = (world.cracks.iter()).flat_map(|cr| cr.solved).collect();
    let mut c = ColumnSet::default();
    c.add("scenario.toml", src.text.as_bytes());
    c.add("scenario.file", src.file.as_bytes());
    match &table {
        Some(t) => t.add(&mut c),
        None => add_particles(&mut c, p),
    }
    c.add("materials.youngs", &youngs);
    c.add("materials.poisson", &poisson);
    c.add("materials.density", &density);
    c.add("run.work", &run[..]);
    c.add("run.cadence", &cadence[..]);
    c.add("run.centre", &state.centre[..]);
    c.add("run.frames", &state.frames);
    c.add("history.time", &h.time);
    for (name, series) in probe_names.iter().zip(&h.probes) {
        c.add(name, series);
    }
    if let (Some(cr), Some(t)) = (&world.cracks, &topology) {
        t.add(&mut c);
        c.add("cracks.x", &cr.geometry.x);
        c.add("cracks.top", &cr.geometry.top);
        c.add("cracks.bottom", &cr.geometry.bottom);
        c.add("cracks.x0", &cr.geometry.x0);
        c.add("cracks.tips", &tips);
        c.add("cracks.solved", &solved);
    }
    c.add("history.fracture.step", &tip_steps);
    c.add("history.fracture.tip", &tip_ids);
    c.add("history.fracture.data", &tip_data);
    c.add("history.paths.step", &path_steps);
    c.add("history.paths.id", &path_ids);
    c.add("history.paths.contour", &path_contours);
    c.add("history.paths.data", &path_data);
    c.add("history.paths.direction", &path_directions);
    c.add("history.growth.step", &growth_steps);
    c.add("history.growth.id", &growth_ids);
    c.add("history.growth.data", &growth_data);
    c.add("history.solves.step", &solve_steps);
    c.add("history.solves.data", &solve_data);
    c.add("history.rows.step", &row_steps);
    c.add("history.rows.data", &rows);
    c.add("history.rows.plastic", &rows_plastic);
    c.add("history.rows.friction", &rows_friction);
    c.add("run.friction", &friction);
    let particles = table.as_ref().map_or(p.len() as u64, Table::particles);
    let bytes = c.bytes();
    c.write(path, header(src, world, particles))?;
    Ok(bytes)
}

/// A run put back together from a snapshot.
pub struct Restored<D: Dim> {
    /// The stored scenario.
    pub source: Source,
    /// The scene rebuilt from it, with the stored state in its World.
    pub scene: Scene<D>,
    /// The run-loop state.
    pub state: RunState,
}

/// Rebuilds the run stored in `r` as a `D`-dimensional run: the scene from the stored
/// scenario, then each store's columns in the order [`write`] adds them.
pub fn restore<D: Dim>(r: &mut Reader) -> anyhow::Result<Restored<D>> {
    restore_share(r, Comm::single())
}

/// [`restore`] on the ranks of `comm`: split across them, each rank builds its share of
/// the scene and keeps its share of the stored particles (`pieces::read`), never the
/// whole store. Every rank calls it, and all return the same error.
pub fn restore_share<D: Dim>(r: &mut Reader, comm: Comm) -> anyhow::Result<Restored<D>> {
    let h = r.header.clone();
    let (source, mut scene) = stored_scene::<D>(r, &h, comm)?;
    let w = &mut scene.world;
    pieces::read(r, w)?;
    read_materials(r, &mut w.materials)?;
    read_work(r, &mut w.work)?;
    if let Some(cr) = &mut w.cracks {
        read_cracks(r, cr)?;
    }
    w.time = h.time;
    w.step = h.step;
    w.tiles.fresh = false;
    let history = read_history(r, h.step, scene.probes.len())?;
    let state = read_run_state(r, history)?;
    Ok(Restored {
        source,
        scene,
        state,
    })
}

/// The stored scenario, checked against the header (dimension, build, hash), and the scene
/// it builds, which must have the snapshot's particle and node counts and time step.
fn stored_scene<D: Dim>(
    r: &mut Reader,
    h: &Header,
    comm: Comm,
) -> anyhow::Result<(Source, Scene<D>)> {
    if h.dimension as usize != D::D {
        return Err(r
            .invalid(format!(
                "the snapshot is from a {}D run; it cannot be resumed as {}D",
                h.dimension,
                D::D
            ))
            .into());
    }
    let build_version = env!("CARGO_PKG_VERSION");
    if h.build != build_version {
        return Err(r
            .invalid(format!(
                "written by fissure {}, this is {build_version}; resume with the build that wrote it \
                 (a bit-exact continuation needs the same code)",
                h.build
            ))
            .into());
    }
    let text = utf8(r, "scenario.toml")?;
    if xxh3_64(text.as_bytes()) != h.scenario_hash {
        return Err(r
            .invalid("the stored scenario does not match its hash in the header")
            .into());
    }
    let file = utf8(r, "scenario.file")?;
    let source = Source::parse(&file, &text, &[])?;
    let scene = build_share::<D>(&source, comm)?;
    let w = &scene.world;
    // Particles over every rank (whole numbers, so the sum is exact).
    let mut n = [w.particles.len() as f64];
    w.domain.add_rows(&mut n, 1);
    let n = n[0] as usize;
    if n as u64 != h.particles || w.grid.geom.node_count() as u64 != h.nodes {
        return Err(r
            .invalid(format!(
                "the stored scenario builds {n} particles and {} nodes, the snapshot holds {} and {}",
                w.grid.geom.node_count(),
                h.particles,
                h.nodes
            ))
            .into());
    }
    if w.settings.dt.to_bits() != h.dt.to_bits() {
        return Err(r
            .invalid(format!(
                "the stored scenario gives dt = {:e} s, the snapshot {:e} s",
                w.settings.dt, h.dt
            ))
            .into());
    }
    Ok((source, scene))
}

/// The elastic constants of every material.
fn read_materials(r: &mut Reader, materials: &mut [Material]) -> Result<(), SnapshotError> {
    let nm = materials.len();
    let youngs: Vec<f64> = r.column("materials.youngs", nm)?;
    let poisson: Vec<f64> = r.column("materials.poisson", nm)?;
    let density: Vec<f64> = r.column("materials.density", nm)?;
    for (k, m) in materials.iter_mut().enumerate() {
        *m = m.with_elastic(youngs[k], poisson[k], density[k]);
    }
    Ok(())
}

/// The external, damping and friction work done so far.
fn read_work(r: &mut Reader, work: &mut Work) -> Result<(), SnapshotError> {
    let run: Vec<f64> = r.column("run.work", 2)?;
    work.external = run[0];
    work.damping = run[1];
    // A snapshot from a build that did not book friction has none to resume.
    if r.offset_of("run.friction").is_some() {
        work.friction = r.column::<f64>("run.friction", 1)?[0];
    }
    Ok(())
}

/// The crack topology (grown cracks have more vertices than the scenario builds), the
/// vertex and surface positions, and each front's growth state.
fn read_cracks<D: Dim>(r: &mut Reader, cr: &mut Cracks<D>) -> Result<(), SnapshotError> {
    cr.topology = topology::read(r, &cr.topology)?;
    let nv = cr.topology.vertex_count();
    cr.geometry.x = r.column("cracks.x", nv)?;
    cr.geometry.top = r.column("cracks.top", nv)?;
    cr.geometry.bottom = r.column("cracks.bottom", nv)?;
    // A static scene's undeformed places; none in an explicit run, or in a snapshot from a
    // build that did not keep them (the next load step takes the crack where it is).
    cr.geometry.x0 = match r.offset_of("cracks.x0") {
        Some(_) => {
            let x0: Vec<D::Vec> = r.column_any("cracks.x0")?;
            if !x0.is_empty() && x0.len() != nv {
                return Err(r.invalid(format!(
                    "cracks.x0 holds {} places for {nv} crack vertices",
                    x0.len()
                )));
            }
            x0
        }
        None => Vec::new(),
    };
    // A snapshot from a build without crack growth has no tip states: none grew.
    let fronts = cr.topology.fronts().len();
    cr.tips = if r.offset_of("cracks.tips").is_some() {
        let tips: Vec<f64> = r.column("cracks.tips", fronts * TipState::VALUES)?;
        (tips.chunks_exact(TipState::VALUES))
            .map(TipState::from_values)
            .collect::<Option<_>>()
            .ok_or_else(|| r.invalid("cracks.tips: a tip's growth state is not one"))?
    } else {
        vec![TipState::default(); fronts]
    };
    // None: no static solve yet, or a snapshot from a build that did not keep it (the
    // next load step solves).
    cr.solved = match r.offset_of("cracks.solved") {
        Some(_) => r.column_any::<u64>("cracks.solved")?.first().copied(),
        None => None,
    };
    Ok(())
}

/// The history up to `step`: probe samples, history rows, J and K at the tips, the path
/// record and the growth rows.
fn read_history(r: &mut Reader, step: u64, probes: usize) -> Result<History, SnapshotError> {
    let samples = step
        .checked_add(1)
        .ok_or_else(|| r.invalid("step count overflows"))? as usize;
    let mut history = History {
        time: r.column("history.time", samples)?,
        ..History::default()
    };
    for k in 0..probes {
        history
            .probes
            .push(r.column(&format!("history.probe.{k}"), samples)?);
    }
    history.rows = read_rows(r)?;
    history.fracture = read_tips(r)?;
    history.paths = read_paths(r)?;
    // A snapshot from a build without crack growth has no growth rows.
    if r.offset_of("history.growth.step").is_some() {
        let steps: Vec<u64> = r.column_any("history.growth.step")?;
        let ids: Vec<u64> = r.column("history.growth.id", steps.len())?;
        let data: Vec<f64> = r.column("history.growth.data", steps.len() * GrowthRow::VALUES)?;
        history.growth = (steps.iter().zip(&ids))
            .zip(data.chunks_exact(GrowthRow::VALUES))
            .map(|((&step, &id), d)| GrowthRow::from_values(step, (id >> 32) as u32, id as u32, d))
            .collect();
    }
    // A snapshot from a build without the solve log has no load-step rows.
    if r.offset_of("history.solves.step").is_some() {
        let steps: Vec<u64> = r.column_any("history.solves.step")?;
        let data: Vec<f64> = r.column("history.solves.data", steps.len() * SolveRow::VALUES)?;
        history.solves = (steps.iter().zip(data.chunks_exact(SolveRow::VALUES)))
            .map(|(&step, d)| SolveRow::from_values(step, d))
            .collect();
    }
    Ok(history)
}

/// The history rows (energies, momenta), with the plastic and friction work of builds
/// that booked them.
fn read_rows(r: &mut Reader) -> Result<Vec<Row>, SnapshotError> {
    let steps: Vec<u64> = r.column_any("history.rows.step")?;
    let data: Vec<f64> = r.column("history.rows.data", steps.len() * ROW_WIDTH)?;
    // A snapshot from a build without plasticity has no plastic work: there was none.
    let plastic: Vec<f64> = if r.offset_of("history.rows.plastic").is_some() {
        r.column("history.rows.plastic", steps.len())?
    } else {
        vec![0.0; steps.len()]
    };
    let friction: Vec<f64> = if r.offset_of("history.rows.friction").is_some() {
        r.column("history.rows.friction", steps.len())?
    } else {
        vec![0.0; steps.len()]
    };
    Ok((steps.iter().zip(plastic.iter().zip(&friction)))
        .zip(data.chunks_exact(ROW_WIDTH))
        .map(|((&s, (&wp, &wf)), d)| row_from(s, d, wp, wf))
        .collect())
}

/// J and K at the tips over time.
fn read_tips(r: &mut Reader) -> Result<Vec<TipResult>, SnapshotError> {
    let tip_steps: Vec<u64> = r.column_any("history.fracture.step")?;
    let tip_ids: Vec<u64> = r.column("history.fracture.tip", tip_steps.len())?;
    // A snapshot from a build without the length and speed columns has two values fewer
    // per row: the length is then unknown and the tip was still.
    let data: Vec<f64> = r.column_any("history.fracture.data")?;
    let width = [TIP_WIDTH, TIP_WIDTH - 2]
        .into_iter()
        .find(|w| data.len() == tip_steps.len() * w)
        .ok_or_else(|| r.invalid("history.fracture.data: rows of an unknown width"))?;
    Ok(tip_steps
        .iter()
        .zip(&tip_ids)
        .zip(data.chunks_exact(width))
        .map(|((&step, &id), d)| {
            let mut v = [f64::NAN; TipResult::VALUES];
            v[..width - 1].copy_from_slice(&d[1..]);
            if width < TIP_WIDTH {
                v[TipResult::VALUES - 1] = 0.0;
            }
            TipResult::from_values(step, d[0], (id >> 32) as u32, id as u32, &v)
        })
        .collect())
}

/// J on the compared contours over time.
fn read_paths(r: &mut Reader) -> Result<Vec<PathResult>, SnapshotError> {
    let path_steps: Vec<u64> = r.column_any("history.paths.step")?;
    let path_ids: Vec<u64> = r.column("history.paths.id", path_steps.len())?;
    let contours: Vec<u64> = r.column("history.paths.contour", path_steps.len())?;
    let data: Vec<f64> = r.column("history.paths.data", path_steps.len() * PATH_WIDTH)?;
    let directions: Vec<f64> = r.column("history.paths.direction", path_steps.len() * 2)?;
    Ok(path_steps
        .iter()
        .zip(path_ids.iter().zip(&contours))
        .zip(
            data.chunks_exact(PATH_WIDTH)
                .zip(directions.chunks_exact(2)),
        )
        .map(|((&step, (&id, &contour)), (d, t))| PathResult {
            step,
            time: d[0],
            crack: (id >> 32) as u32,
            tip: id as u32,
            contour: contour as u32,
            line: [d[1], d[2]],
            area: [d[3], d[4]],
            direction: [t[0], t[1]],
        })
        .collect())
}

/// The run-loop state: output and checkpoint cadence, frames written, the centre of mass
/// angular momentum is taken about.
fn read_run_state(r: &mut Reader, history: History) -> Result<RunState, SnapshotError> {
    let cadence: Vec<f64> = r.column("run.cadence", 3)?;
    let centre: Vec<f64> = r.column("run.centre", 3)?;
    Ok(RunState {
        history,
        next_history: cadence[0],
        next_frame: cadence[1],
        next_checkpoint: cadence[2],
        frames: r.column_any("run.frames")?,
        centre: [centre[0], centre[1], centre[2]],
    })
}

fn utf8(r: &mut Reader, name: &str) -> Result<String, SnapshotError> {
    let bytes: Vec<u8> = r.column_any(name)?;
    String::from_utf8(bytes).map_err(|_| r.invalid(format!("column `{name}` is not UTF-8 text")))
}
