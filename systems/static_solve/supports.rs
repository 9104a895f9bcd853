//! Supports that move: a static scene's boundary with a `velocity` prescribes the
//! displacement that velocity would give by each load step's time (the same motion an
//! explicit run of the scene imposes), and does work on the body through its reaction.

use super::scatter::entry_sums;
use super::{entries, fields};
use crate::base::dim::Dim;
use crate::base::exact_sum::ExactSum;
use crate::physics::loads::VelocityBc;
use crate::store::crack::Fields;
use crate::store::world::World;
use crate::systems::{mirror, p2g};

/// Per grid entry, the displacement the moving supports prescribe at time `t` on their
/// held components (zero elsewhere; an image node its source's, reflected); None when no
/// support moves.
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
    mirror::reflect_images::<D>(&world.grid.mirrors.images, &mut u);
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
/// last step left ([`entry_forces`] at `t_start`, summed over each node's entries). The
/// particles' stresses are in every snapshot, so a resumed run finds the same forces. Zero
/// on the first step, which starts from the unloaded body, and where no support moves (a
/// still support does no work): no pass over the particles then.
pub(super) fn start_forces<D: Dim>(world: &World<D>, t_start: f64) -> Vec<Vec<D::Vec>> {
    if world.step == 0 || !world.bcs.iter().any(moves) {
        return (world.bcs.iter())
            .map(|bc| vec![D::zero(); bc.nodes.len()])
            .collect();
    }
    let (r, _) = entry_forces(world, t_start);
    let fields = fields(world);
    (world.bcs.iter())
        .map(|bc| {
            (bc.nodes.iter())
                .map(|&n| node_sum::<D>(&r, n, fields))
                .collect()
        })
        .collect()
}

/// Sets each support's reaction from the state the particles hold, at time `t` (a load
/// step that solved nothing): [`entry_forces`], summed over each node's entries.
pub(super) fn reactions_at_rest<D: Dim>(world: &mut World<D>, t: f64) {
    if world.bcs.is_empty() {
        return;
    }
    let (r, images) = entry_forces(world, t);
    let fields = world.cracks.as_ref().map(|c| &c.scratch.fields);
    set_reactions(&mut world.bcs, |n| node_sum::<D>(&r, n, fields));
    mirror::credit_reactions(&world.grid.mirrors, &mut world.bcs, |k| images[k]);
}

/// Sets each support's reaction at its nodes to `force(node)` on the components it holds.
pub(super) fn set_reactions<D: Dim>(bcs: &mut [VelocityBc<D>], force: impl Fn(u32) -> D::Vec) {
    for bc in bcs {
        for (r, &n) in bc.reaction.iter_mut().zip(&bc.nodes) {
            let f = force(n);
            *r = D::zero();
            (0..D::D).filter(|&a| bc.axes[a]).for_each(|a| r[a] = f[a]);
        }
    }
}

/// Each grid entry's force on the body from the particles' state: K u (their stresses,
/// scattered as the internal force) less the loads and gravity at `t`, with each image's
/// folded into its source as the solve folds them; and each image's own force before the
/// fold (for [`mirror::credit_reactions`]).
fn entry_forces<D: Dim>(world: &World<D>, t: f64) -> (Vec<D::Vec>, Vec<D::Vec>) {
    let p = &world.particles;
    let mut r = entry_sums(world, |i, _, g| {
        D::stress_dot(&p.stress[i], g) * p.volume[i]
    });
    let loads = p2g::load_forces(world, t);
    let g = world.settings.gravity;
    for (e, r) in r.iter_mut().enumerate() {
        *r -= loads[e] + g * world.grid.mass[e];
    }
    // An image's mass is its source's by now: its own weight is taken here, and the fold
    // gives the source the mirror half's reflected weight in place of g m_image.
    let m = &world.grid.mirrors;
    let images = (m.images.iter().zip(&m.shares))
        .map(|(im, s)| r[im.node as usize] - g * s.mass)
        .collect();
    mirror::fold_images::<D>(&m.images, &mut r);
    for (im, s) in m.images.iter().zip(&m.shares) {
        r[im.source as usize] -= mirror::reflected_gravity::<D>(im, g, s.mass);
    }
    (r, images)
}

/// The sum of `r` over node `n`'s entries.
fn node_sum<D: Dim>(r: &[D::Vec], n: u32, fields: Option<&Fields>) -> D::Vec {
    entries(n, fields).fold(D::zero(), |s, e| s + r[e])
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
