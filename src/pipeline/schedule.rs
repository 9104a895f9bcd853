//! The schedule: the ordered systems a scene needs, with per-system wall-clock timing.

use crate::base::dim::Dim;
use crate::base::error::Unstable;
use crate::fracture::plan::{FracturePlan, Measured};
use crate::pipeline::warm::with_warm_workers;
use crate::record::solve_log::Solved;
use crate::store::world::{Dilatation, Solver, Update, World};
use crate::systems::{
    DimSystems, bin, classify, contact, crack_advect, g2p, grid_update, grow, mean_stress, p2g,
    static_solve, stress, stress_bin, stress_force,
};
use std::time::Instant;

/// One scheduled system invocation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum System {
    /// Bin particles into tiles (skipped when the bins are still fresh).
    Bin,
    /// Assign particle-node pairs near cracks to velocity fields.
    Classify,
    /// Move crack vertices and surfaces.
    CrackAdvect,
    /// Crack-face contact on momenta (`update` false) or on updated velocities.
    Contact {
        /// After the grid update.
        update: bool,
    },
    /// Scatter mass and momentum (and internal forces when `internal`) plus loads.
    P2g {
        /// Also scatter the internal force.
        internal: bool,
    },
    /// Set prescribed components of the grid momenta.
    MomentumBc {
        /// Use end-of-step values (after a remap).
        end: bool,
    },
    /// The closing stress update of USL and USAVG fused with the binning for the next step.
    StressBin {
        /// Fraction of the step.
        fraction: f64,
    },
    /// The opening stress update of USF and USAVG fused with the internal-force scatter.
    StressForce {
        /// Fraction of the step.
        fraction: f64,
    },
    /// A stress update with each particle's dilatation its cell's mean (`dilatation =
    /// "cell_mean"`), in place of `StressForce` (with `force`) and `StressBin`.
    MeanStress {
        /// Fraction of the step.
        fraction: f64,
        /// Also scatter the internal forces of the B-bar stresses (the opening update).
        force: bool,
    },
    /// The internal-force scatter of the cell-mean dilatation's B-bar stresses after the
    /// scatter of momenta (USL).
    MeanForce,
    /// Integrate nodal momenta, apply damping, gravity and prescribed velocities.
    GridUpdate,
    /// Gather to particles: velocities, positions, displacements (USF).
    G2p,
    /// As `G2p`, then re-scatter the updated particle momenta for the final stress update
    /// (USL and USAVG), in one pass.
    G2pRemap,
    /// J and K at the crack fronts, on the steps that end at an output row.
    Fracture,
    /// Advance the growing crack tips, after the step and its measurement.
    Grow,
    /// A static scene's load step: equilibrium on the grid, the particles set to it.
    StaticSolve,
}

impl System {
    /// Name used in reports.
    pub fn name(&self) -> &'static str {
        match self {
            System::Bin => "bin",
            System::Classify => "classify",
            System::CrackAdvect => "crack_advect",
            System::Contact { .. } => "contact",
            System::P2g { .. } => "p2g",
            System::MomentumBc { .. } => "grid_bc",
            System::StressForce { .. } => "stress_force",
            System::StressBin { .. } => "stress_bin",
            System::MeanStress { .. } => "mean_stress",
            System::MeanForce => "mean_force",
            System::GridUpdate => "grid_update",
            System::G2p => "g2p",
            System::G2pRemap => "g2p_remap",
            System::Fracture => "fracture",
            System::Grow => "grow",
            System::StaticSolve => "static_solve",
        }
    }
}

/// The ordered systems of a scene and the time spent in each.
#[derive(Clone, Debug)]
pub struct Schedule {
    /// Systems in execution order.
    pub systems: Vec<System>,
    /// Wall seconds spent in each entry of `systems`.
    pub seconds: Vec<f64>,
    /// What the fracture system measures (None: the scene measures nothing at its cracks).
    fracture: Option<FracturePlan>,
    /// Whether some crack grows.
    grows: bool,
    /// What the last load step's solves took (static scenes), until taken.
    solved: Option<Solved>,
    /// What the static solver keeps from one load step to the next.
    kept: static_solve::Kept,
}

impl Schedule {
    /// The systems this scene needs, in order. USF updates stress before the internal
    /// forces; USL after the particles move (on momenta remapped with the start-of-step
    /// shape functions); USAVG does half of each.
    /// Prescribed velocities add `grid_bc` after each scatter of momenta; cracks add
    /// `classify` after binning and `crack_advect` after the particles move; a fracture
    /// plan adds `fracture` at the end of the steps that end at an output row. The cell's
    /// mean dilatation trades the fused updates for `mean_stress` (the next step's `bin`
    /// then bins the moved particles), USL's internal forces for `mean_force`.
    pub fn for_world<D: Dim>(world: &World<D>, fracture: Option<FracturePlan>) -> Self {
        use System::*;
        if world.settings.solver == Solver::Static {
            // Open cracks are the solve's own affair; J and K are measured on its result.
            let fracture = fracture.filter(|_| world.cracks.is_some());
            let mut systems = vec![StaticSolve];
            if fracture.is_some() {
                systems.push(Fracture);
            }
            let grows = grows(world);
            if grows {
                systems.push(Grow);
            }
            return Schedule {
                seconds: vec![0.0; systems.len()],
                systems,
                fracture,
                grows,
                solved: None,
                kept: Default::default(),
            };
        }
        let bc = !world.bcs.is_empty();
        let update = world.settings.update;
        let cracks = world.cracks.is_some();
        let contact = world.cracks.as_ref().is_some_and(|c| {
            c.topology
                .cracks()
                .iter()
                .any(|c| c.contact.law != crate::store::crack::Law::None)
        });
        let mean = world.settings.dilatation == Dilatation::CellMean;
        let mut s = vec![Bin];
        if cracks {
            s.push(Classify);
        }
        s.push(P2g {
            internal: update == Update::Usl && !mean,
        });
        if bc {
            s.push(MomentumBc { end: false });
        }
        if contact {
            s.push(Contact { update: false });
        }
        if update != Update::Usl {
            let fraction = if update == Update::Usf { 1.0 } else { 0.5 };
            s.push(if mean {
                MeanStress {
                    fraction,
                    force: true,
                }
            } else {
                StressForce { fraction }
            });
        } else if mean {
            s.push(MeanForce);
        }
        s.push(GridUpdate);
        if contact {
            s.push(Contact { update: true });
        }
        s.push(if update == Update::Usf { G2p } else { G2pRemap });
        if cracks {
            s.push(CrackAdvect);
        }
        if update != Update::Usf {
            if bc {
                s.push(MomentumBc { end: true });
            }
            let fraction = if update == Update::Usl { 1.0 } else { 0.5 };
            // The closing update also bins the particles for the next step (see
            // `step_measuring` for the steps after which J is measured).
            s.push(if mean {
                MeanStress {
                    fraction,
                    force: false,
                }
            } else {
                StressBin { fraction }
            });
        }
        let fracture = fracture.filter(|_| cracks);
        if fracture.is_some() {
            s.push(Fracture);
        }
        let grows = grows(world);
        if grows {
            s.push(Grow);
        }
        let seconds = vec![0.0; s.len()];
        Schedule {
            systems: s,
            seconds,
            fracture,
            grows,
            solved: None,
            kept: Default::default(),
        }
    }

    /// The static solve's coarse-grid factorizations so far (see
    /// [`static_solve::Kept::coarse_factorizations`]).
    pub fn coarse_factorizations(&self) -> u64 {
        self.kept.coarse_factorizations()
    }

    /// What the last load step's solves took (a static scene; None once taken, and in an
    /// explicit scene).
    pub fn take_solved(&mut self) -> Option<Solved> {
        self.solved.take()
    }

    /// Whether the schedule measures J and K.
    pub fn measures(&self) -> bool {
        self.fracture.is_some()
    }

    /// Advances the world one time step, measuring nothing (a growing crack still reports
    /// its growth rows).
    pub fn step<D: DimSystems>(&mut self, world: &mut World<D>) -> Result<Measured, Unstable> {
        self.step_measuring(world, false)
    }

    /// Advances the world one time step; with `measure` the fracture system (if any) runs
    /// at its end, and the closing stress update leaves the binning to the next step, so
    /// that the particles' stencils are still the step's own, matching the crack fields,
    /// as the J-integral reads them (the results are bitwise the same either way). Returns
    /// what the step measured: J and K at the fronts, and the growth rows.
    pub fn step_measuring<D: DimSystems>(
        &mut self,
        world: &mut World<D>,
        measure: bool,
    ) -> Result<Measured, Unstable> {
        let measure = measure && self.measures();
        self.advance(world, measure, measure)
    }

    /// Advances the world one time step measuring nothing; with `keep_stencils` the
    /// closing stress update leaves the binning to the next step as on a measuring step
    /// (the results are bitwise the same either way, which the tests check).
    pub fn step_keeping<D: DimSystems>(
        &mut self,
        world: &mut World<D>,
        keep_stencils: bool,
    ) -> Result<Measured, Unstable> {
        self.advance(world, keep_stencils, false)
    }

    /// One step. Kept out of line (one call per step costs nothing) so that profiles count
    /// the step's instructions apart from the run's outputs. The pool's other workers wait
    /// for work spinning through the step, not sleeping (`warm.rs`).
    #[inline(never)]
    fn advance<D: DimSystems>(
        &mut self,
        world: &mut World<D>,
        keep_stencils: bool,
        measure: bool,
    ) -> Result<Measured, Unstable> {
        // A step whose end a growing tip reads K at keeps its stencils, as a measured one.
        let reads = self.grows && grow::needs_k(world, world.step + 1);
        with_warm_workers(|| self.run_systems(world, keep_stencils || reads))?;
        world.step += 1;
        world.time = world.step as f64 * world.settings.dt;
        // The fracture system measures the state at the step's end, so it runs once the
        // clock has moved to it; then the tips grow from what it saw.
        let mut measured = if measure {
            self.fracture_system(world)
        } else {
            Measured::default()
        };
        if self.grows {
            let t0 = Instant::now();
            measured.growth = D::grow(world, self.fracture.as_ref())?;
            if let Some(k) = self.systems.iter().position(|s| *s == System::Grow) {
                self.seconds[k] += t0.elapsed().as_secs_f64();
            }
        }
        Ok(measured)
    }

    /// Measures J and K on the world as it stands (before the first step): bins the
    /// particles and classifies them near the cracks, as a step would, then runs the
    /// fracture system and returns what it measured. Nothing to do without a fracture plan.
    pub fn measure_now<D: DimSystems>(
        &mut self,
        world: &mut World<D>,
    ) -> Result<Measured, Unstable> {
        if !self.measures() {
            return Ok(Measured::default());
        }
        bin::run(world)?;
        classify::run(world)?;
        Ok(self.fracture_system(world))
    }

    /// Runs the fracture system, timing it under its schedule entry.
    fn fracture_system<D: DimSystems>(&mut self, world: &World<D>) -> Measured {
        let Some(plan) = &self.fracture else {
            return Measured::default();
        };
        let t0 = Instant::now();
        let measured = D::fracture(world, plan);
        if let Some(k) = self.systems.iter().position(|s| *s == System::Fracture) {
            self.seconds[k] += t0.elapsed().as_secs_f64();
        }
        measured
    }

    /// Runs the step's systems once, in order, timing each (the fracture system apart).
    fn run_systems<D: Dim>(
        &mut self,
        world: &mut World<D>,
        keep_stencils: bool,
    ) -> Result<(), Unstable> {
        for k in 0..self.systems.len() {
            let t0 = Instant::now();
            match self.systems[k] {
                System::Bin => {
                    let binned = bin::run(world);
                    world.domain.agree(binned)?;
                }
                System::Classify => classify::run(world)?,
                System::CrackAdvect => crack_advect::run(world),
                System::Contact { update } => contact::run(world, update),
                System::P2g { internal } => p2g::run(world, internal),
                System::MomentumBc { end } => grid_update::momentum_bc(world, end),
                System::StressForce { fraction } => stress_force::run(world, fraction),
                System::StressBin { fraction } if keep_stencils => stress::run(world, fraction),
                System::StressBin { fraction } => {
                    let binned = stress_bin::run(world, fraction);
                    world.domain.agree(binned)?;
                }
                System::MeanStress { fraction, force } => mean_stress::run(world, fraction, force),
                System::MeanForce => mean_stress::force(world),
                System::GridUpdate => grid_update::run(world),
                System::G2p => g2p::run(world),
                System::G2pRemap => g2p::run_with_remap(world),
                System::StaticSolve => {
                    self.solved = Some(static_solve::run(world, &mut self.kept)?);
                }
                System::Fracture | System::Grow => continue,
            }
            self.seconds[k] += t0.elapsed().as_secs_f64();
        }
        Ok(())
    }

    /// Seconds per system name, in first-appearance order.
    pub fn seconds_by_name(&self) -> Vec<(&'static str, f64)> {
        let mut out: Vec<(&'static str, f64)> = Vec::new();
        for (sys, s) in self.systems.iter().zip(&self.seconds) {
            match out.iter_mut().find(|(n, _)| *n == sys.name()) {
                Some(e) => e.1 += s,
                None => out.push((sys.name(), *s)),
            }
        }
        out
    }
}

/// Whether some crack of the world grows.
fn grows<D: Dim>(world: &World<D>) -> bool {
    (world.cracks.as_ref()).is_some_and(|c| c.topology.cracks().iter().any(|c| c.growth.is_some()))
}
