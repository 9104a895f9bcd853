//! `mean_stress`: the explicit step's stress update and internal-force scatter under
//! `dilatation = "cell_mean"` ([`dilatation`](crate::systems::dilatation)). Each particle's
//! strain rate takes its group's mean volumetric part, and its stress scatters as
//! B-bar^T sigma (Hughes 1980, Eq. 9), so that the internal forces' power is the stress
//! power the particles store. Unfused, unlike `stress_force` and `stress_bin`: a mean needs
//! every member's gradient, and the force every member's new stress, first.

use crate::base::dim::Dim;
use crate::store::disjoint::Disjoint;
use crate::store::grid::Grid;
use crate::store::world::{CHUNK, World};
use crate::systems::dilatation::Groups;
use crate::systems::entry_gradient;
use crate::systems::p2g::add_internal_force;
use crate::systems::stress::{StressColumns, node_velocities};
use crate::systems::stress_force::close_internal_forces;
use rayon::prelude::*;

/// Updates every particle's stress over `fraction` of the step from grad v gathered off
/// p/m on its side's entries, its in-plane trace replaced by its group's mean; with
/// `force` then scatters the internal forces of the new stresses, on the same groups (as
/// [`force`]).
pub fn run<D: Dim>(world: &mut World<D>, fraction: f64, force: bool) {
    let groups = Groups::new(world);
    update(world, fraction, &groups);
    if force {
        scatter_effective(world, &groups);
    }
}

/// The stress update of [`run`] on `groups`.
fn update<D: Dim>(world: &mut World<D>, fraction: f64, groups: &Groups) {
    node_velocities(world);
    let dt = world.settings.dt * fraction;
    let plane = world.settings.plane;
    let velocity = &world.grid.velocity;
    let l = groups.gradients(world, |i| entry_gradient(world, i, velocity));
    let materials = &world.materials;
    let (columns, material) = StressColumns::of(&mut world.particles);
    l.par_chunks(CHUNK).enumerate().for_each(|(c, l)| {
        for (k, &l) in l.iter().enumerate() {
            let i = c * CHUNK + k;
            let m = &materials[material[i] as usize];
            // SAFETY: the chunks partition the particles and each chunk is one task.
            unsafe { columns.update(i, l, dt, plane, m) };
        }
    });
}

/// Adds every particle's internal force -V sigma_bar . grad S to the loads already in the
/// force column, sigma_bar its stress with its group's mean in-plane trace (Guo & Nairn 2D
/// (2004) Eq. 6 with B-bar), tile by tile in colour classes, then the particles near a
/// crack field by field.
pub fn force<D: Dim>(world: &mut World<D>) {
    scatter_effective(world, &Groups::new(world));
}

/// The internal-force scatter of [`force`] on `groups`.
fn scatter_effective<D: Dim>(world: &mut World<D>, groups: &Groups) {
    let effective = groups.effective(world, &world.particles.stress);
    // The coded scatter reads the stress column: it holds sigma_bar for the scatter only.
    let stress = std::mem::replace(&mut world.particles.stress, effective);
    scatter(world);
    world.particles.stress = stress;
}

/// The internal-force scatter of the particles' stress column.
fn scatter<D: Dim>(world: &mut World<D>) {
    let shape = world.settings.shape;
    let Grid { geom, force, .. } = &mut world.grid;
    let stride = &geom.stride;
    let force_w = Disjoint::new(force);
    let p = &world.particles;
    let (tiles, domain) = (&world.tiles, &world.domain);
    let fields = world.cracks.as_ref().map(|c| &c.scratch.fields);
    tiles.for_each_coloured_then(
        |t| {
            let free = tiles.particles(t).iter().map(|&i| i as usize);
            for_each_free_particle!(D, shape, &tiles.stencils, fields, free, |i, st| {
                let rows = st.rows::<D>(stride);
                // SAFETY: each tile is handled by one thread and tiles of one colour class
                // touch disjoint nodes (tiles.rs).
                unsafe {
                    add_internal_force::<D, N>(&st, &rows, &p.stress[i], p.volume[i], &force_w)
                };
            })
        },
        domain.waits(),
        |classes, run| domain.settle_pass(classes, &[&force_w], run),
    );
    close_internal_forces(world);
}
