//! Supports that move: a static scene's boundary with a `velocity` prescribes the
//! displacement that velocity would give by each load step's time (the same motion an
//! explicit run of the scene imposes), and does work on the body through its reaction.

use super::scatter::entry_sums;
use super::{entries, fields};
use crate::base::dim::Dim;
use crate::base::exact_sum::ExactSum;
use crate::physics::loads::VelocityBc;
use crate::store::world::World;
use crate::systems::p2g;

/// Per grid entry, the displacement the moving supports prescribe at time `t` on their
/// held components (zero elsewhere); None when no support moves.
pub(super) fn prescribed<D: Dim>(world: &World<D>, t: f64) -> Option<Vec<D::Vec>> {
    if !world.bcs.iter().any(moves) {
        return None;
    }
    let mut u = vec![D::zero(); world.grid.mass.len()];
    for bc in world.bcs.iter().filter(|bc| moves(bc)) {
        let d = displacement(bc, t);
        for &n in &bc.nodes {
            for e in entries(n, fields(world)) {
                (0..D::D)
                    .filter(|&a| bc.axes[a])
                    .for_each(|a| u[e][a] = d[a]);
            }
        }
    }
    Some(u)
}

/// Whether support `bc` prescribes a non-zero velocity on a component it holds.
pub(super) fn moves<D: Dim>(bc: &VelocityBc<D>) -> bool {
    (0..D::D).any(|a| bc.axes[a] && bc.velocity[a] != 0.0)
}

/// The displacement support `bc` prescribes by time `t` on its held components: its
/// velocity times the integral of its time function from 0.
fn displacement<D: Dim>(bc: &VelocityBc<D>, t: f64) -> D::Vec {
    let mut d = D::zero();
    let scale = bc.time.integral(t);
    (0..D::D)
        .filter(|&a| bc.axes[a])
        .for_each(|a| d[a] = bc.velocity[a] * scale);
    d
}

/// Each support's force on the body per node at the start of the step, from the state the
/// last step left ([`node_forces`] at `t_start`). The particles' stresses are in every
/// snapshot, so a resumed run finds the same forces. Zero on the first step, which starts
/// from the unloaded body, and where no support moves (a still support does no work): no
/// pass over the particles then.
pub(super) fn start_forces<D: Dim>(world: &World<D>, t_start: f64) -> Vec<Vec<D::Vec>> {
    if world.step == 0 || !world.bcs.iter().any(moves) {
        return (world.bcs.iter())
            .map(|bc| vec![D::zero(); bc.nodes.len()])
            .collect();
    }
    node_forces(world, t_start)
}

/// Sets each support's reaction from the state the particles hold, at time `t`: its
/// [`node_forces`] on the components it holds (a load step that solved nothing).
pub(super) fn reactions_at_rest<D: Dim>(world: &mut World<D>, t: f64) {
    let forces = node_forces(world, t);
    for (bc, f) in world.bcs.iter_mut().zip(forces) {
        for (r, f) in bc.reaction.iter_mut().zip(f) {
            *r = D::zero();
            (0..D::D).filter(|&a| bc.axes[a]).for_each(|a| r[a] = f[a]);
        }
    }
}

/// Each support's force on the body per node from the particles' state: K u (their
/// stresses, scattered as the internal force) less the loads and gravity at `t`, summed
/// over the node's entries.
fn node_forces<D: Dim>(world: &World<D>, t: f64) -> Vec<Vec<D::Vec>> {
    if world.bcs.is_empty() {
        return Vec::new();
    }
    let p = &world.particles;
    let mut r = entry_sums(world, |i, _, g| {
        D::stress_dot(&p.stress[i], g) * p.volume[i]
    });
    let loads = p2g::load_forces(world, t);
    let g = world.settings.gravity;
    for (e, r) in r.iter_mut().enumerate() {
        *r -= loads[e] + g * world.grid.mass[e];
    }
    (world.bcs.iter())
        .map(|bc| {
            (bc.nodes.iter())
                .map(|&n| entries(n, fields(world)).fold(D::zero(), |s, e| s + r[e]))
                .collect()
        })
        .collect()
}

/// The work the moving supports did on the body over the step: each node's force, the
/// mean of its values at the step's ends (`start` and the reactions now in the world:
/// exact for a linear response), times its prescribed displacement over the step.
pub(super) fn work<D: Dim>(
    world: &World<D>,
    start: &[Vec<D::Vec>],
    t_start: f64,
    t_end: f64,
) -> f64 {
    let mut work = ExactSum::new();
    for (bc, start) in world.bcs.iter().zip(start) {
        let step = displacement(bc, t_end) - displacement(bc, t_start);
        for ((r0, r1), &n) in start.iter().zip(&bc.reaction).zip(&bc.nodes) {
            // Split across ranks, the node's owner books its work.
            if world.domain.owns_node(n as usize) {
                work.add(D::dot((*r0 + *r1) * 0.5, step));
            }
        }
    }
    world.domain.sum(std::slice::from_mut(&mut work));
    work.value()
}
