//! The schedule: the ordered systems a scene needs, with per-system wall-clock timing.

use crate::dim::Dim;
use crate::error::Unstable;
use crate::systems::{bin, g2p, grid_update, p2g, stress};
use crate::world::{Update, World};
use std::time::Instant;

/// One scheduled system invocation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum System {
    /// Bin particles into tiles.
    Bin,
    /// Scatter mass and momentum (and internal forces when `internal`) plus loads.
    P2g {
        /// Also scatter the internal force.
        internal: bool,
    },
    /// Set prescribed components of the extrapolated momenta.
    MomentumBc,
    /// Constitutive update over `fraction` of the step.
    Stress {
        /// Gather grad v from extrapolated momenta first.
        gather: bool,
        /// Fraction of the step.
        fraction: f64,
    },
    /// Scatter the internal force alone.
    InternalForce,
    /// Integrate nodal momenta, apply damping, gravity and prescribed velocities.
    GridUpdate,
    /// Gather to particles.
    G2p {
        /// Also gather grad v from the new grid velocities.
        gradient: bool,
    },
}

impl System {
    /// Name used in reports.
    pub fn name(&self) -> &'static str {
        match self {
            System::Bin => "bin",
            System::P2g { .. } => "p2g",
            System::MomentumBc => "grid_bc",
            System::Stress { .. } => "stress",
            System::InternalForce => "internal_force",
            System::GridUpdate => "grid_update",
            System::G2p { .. } => "g2p",
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
}

impl Schedule {
    /// The systems this scene needs, in order: USF, USL and USAVG differ in where the
    /// stress update sits; prescribed velocities add `grid_bc`.
    pub fn for_world<D: Dim>(world: &World<D>) -> Self {
        use System::*;
        let bc = !world.bcs.is_empty();
        let mut systems = vec![Bin];
        let first = |s: &mut Vec<System>, fraction| {
            s.push(P2g { internal: false });
            if bc {
                s.push(MomentumBc);
            }
            s.push(Stress {
                gather: true,
                fraction,
            });
            s.push(InternalForce);
        };
        match world.settings.update {
            Update::Usf => first(&mut systems, 1.0),
            Update::Usavg => first(&mut systems, 0.5),
            Update::Usl => {
                systems.push(P2g { internal: true });
                if bc {
                    systems.push(MomentumBc);
                }
            }
        }
        systems.push(GridUpdate);
        match world.settings.update {
            Update::Usf => systems.push(G2p { gradient: false }),
            Update::Usl | Update::Usavg => {
                systems.push(G2p { gradient: true });
                systems.push(Stress {
                    gather: false,
                    fraction: if world.settings.update == Update::Usl {
                        1.0
                    } else {
                        0.5
                    },
                });
            }
        }
        let seconds = vec![0.0; systems.len()];
        Schedule { systems, seconds }
    }

    /// Advances the world one time step.
    pub fn step<D: Dim>(&mut self, world: &mut World<D>) -> Result<(), Unstable> {
        for (k, sys) in self.systems.iter().enumerate() {
            let t0 = Instant::now();
            match *sys {
                System::Bin => bin::run(world)?,
                System::P2g { internal } => p2g::run(world, internal),
                System::MomentumBc => grid_update::momentum_bc(world),
                System::Stress { gather, fraction } => stress::run(world, gather, fraction),
                System::InternalForce => p2g::internal_force(world),
                System::GridUpdate => grid_update::run(world),
                System::G2p { gradient } => g2p::run(world, gradient),
            }
            self.seconds[k] += t0.elapsed().as_secs_f64();
        }
        world.step += 1;
        world.time = world.step as f64 * world.settings.dt;
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
