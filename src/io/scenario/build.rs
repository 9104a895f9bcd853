//! The scene a scenario describes: each table built by its own builder, in an order that
//! lets each use what the ones before it made (the grid before the bodies, the bodies
//! before the loads and probes, the time step before the cracks).

use super::check::{R, to_vec};
use super::output::{CheckpointPlan, OutputPlan, checkpoint_plan, output_plan};
use super::source::Source;
use crate::base::dim::Dim;
use crate::fracture::plan::FracturePlan;
use crate::ranks::comm::Comm;
use crate::ranks::domain::Domain;
use crate::record::expect::Expect;
use crate::record::probe::Probe;
use crate::store::grid::Grid;
use crate::store::world::{STATIC_TOLERANCE, Settings, Work, World};

/// A World ready to run, with what the run records and checks.
#[derive(Clone, Debug)]
pub struct Scene<D: Dim> {
    /// Scenario name.
    pub name: String,
    /// Initial state.
    pub world: World<D>,
    /// Probes.
    pub probes: Vec<Probe>,
    /// Expectations.
    pub expects: Vec<Expect>,
    /// Simulated duration (s).
    pub duration: f64,
    /// Output cadence.
    pub output: OutputPlan,
    /// Stability limit h_min / c_max (s).
    pub dt_limit: f64,
    /// Snapshot cadence.
    pub checkpoint: CheckpointPlan,
    /// J and K measurement, when the scenario asks for it.
    pub fracture: Option<FracturePlan>,
}

/// Builds the scene described by `src` in dimension `D`, whole, on this process.
pub fn build<D: Dim>(src: &Source) -> R<Scene<D>> {
    build_share(src, Comm::single())
}

/// Builds this rank's share of the scene described by `src` in dimension `D`: split across
/// the ranks of `comm`, its own tiles' particles (their `id` each one's number in the
/// whole scene) and the partition, with the loads and probes listing their particles by
/// those numbers, every check made on the whole scene; on one rank, the whole scene. Every
/// rank calls it, and all return the same error.
pub fn build_share<D: Dim>(src: &Source, comm: Comm) -> R<Scene<D>> {
    let sim = super::settings::simulation::<D>(src)?;
    let grid = super::grid::grid::<D>(src)?;
    let materials = super::material::materials(src, &src.scenario.materials)?;
    let mut domain = Domain {
        comm,
        ..Domain::default()
    };
    let filled =
        super::bodies::bodies::<D>(src, &grid, &materials, sim.thickness, sim.tile, &domain)?;
    domain.partition = filled.partition;
    super::statics::check(src)?;
    let geom = grid.geom;
    let mut particles = filled.particles;
    let ppc = &filled.ppc;
    let (dt, dt_limit) =
        super::settings::time_step::<D>(src, &sim, &materials, &filled.used, &geom)?;
    let mut bcs = super::boundaries::boundaries::<D>(src, &geom)?;
    let mirrors = super::mirrors::mirrors::<D>(src, &geom, &particles.x, &domain, &mut bcs)?;
    let loads = super::loads::loads::<D>(src, &geom, &particles, ppc, &domain)?;
    let probes =
        super::probes::probes::<D>(src, &geom, &particles, ppc, &domain, &bcs, &materials)?;
    let expects =
        super::expects::expects::<D>(src, &probes, &geom, &materials, sim.plane, sim.thickness)?;
    let output = output_plan(src, sim.duration)?;
    let checkpoint = checkpoint_plan(src)?;
    let cracks = super::cracks::build::<D>(
        src,
        &particles,
        &domain,
        &filled.claims,
        &materials,
        &geom,
        dt,
    )?;
    let fracture = super::cracks::fracture_plan(src, cracks.as_ref(), &geom)?;
    super::cracks::check_front_expects(src, &expects, cracks.as_ref(), geom.min_cell())?;
    if fracture.is_some() {
        particles.grad_u = vec![D::mat_zero(); particles.len()];
        particles.grad_v = vec![D::mat_zero(); particles.len()];
    }
    // Plastic state is kept only when a body is made of a plastic material.
    if (materials.iter().zip(&filled.used)).any(|(m, &u)| u && m.j2.is_some()) {
        particles.make_plastic();
    }
    let min_mass = domain.min(particles.mass.iter().copied().fold(f64::INFINITY, f64::min));
    let s = &src.scenario.simulation;
    let p = &particles;
    let shape =
        super::settings::solve_shape::<D>(s.solver, s.shape, &p.x0, &p.half, &geom, &domain);
    let world = World {
        tiles: filled.tiles,
        grid: Grid {
            mirrors,
            ..Grid::new(geom)
        },
        particles,
        materials,
        settings: Settings {
            solver: s.solver,
            tolerance: s.tolerance.unwrap_or(STATIC_TOLERANCE),
            linear: s.linear.unwrap_or_default(),
            shape,
            dilatation: s.dilatation,
            update: s.update,
            plane: sim.plane,
            damping: s.damping,
            gravity: to_vec::<D>(sim.gravity),
            dt,
            mass_tol: 1e-12 * min_mass,
            sliver_mass: 1e-3 * min_mass,
            thickness: sim.thickness,
        },
        loads,
        bcs,
        time: 0.0,
        step: 0,
        work: Work::default(),
        cracks,
        domain,
    };
    Ok(Scene {
        name: src.name(),
        world,
        probes,
        expects,
        duration: sim.duration,
        output,
        dt_limit,
        checkpoint,
        fracture,
    })
}
