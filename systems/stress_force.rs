//! `stress_force`: the stress update that opens a USF or USAVG step and the scatter of the
//! internal forces it gives, fused in one pass over the tiles so each particle's stencil is
//! read once (the particles near a crack afterwards, field by field).

use crate::base::dim::Dim;
use crate::store::disjoint::Disjoint;
use crate::store::grid::Grid;
use crate::store::particles::Particles;
use crate::store::world::World;
use crate::systems::p2g::add_internal_force;
use crate::systems::stress::{StressColumns, node_velocities, update_coded, velocity_gradient};
use crate::systems::{mirror, scatter_coded};

/// Updates every particle's stress over `fraction` of the step from grad v gathered off
/// p/m (as [`stress::run`](crate::systems::stress::run)), then adds its internal force
/// -V sigma . grad S to the loads already in the force column (Guo & Nairn 2D (2004)
/// Eq. 6), tile by tile in colour classes.
pub fn run<D: Dim>(world: &mut World<D>, fraction: f64) {
    node_velocities(world);
    let dt = world.settings.dt * fraction;
    let (shape, plane) = (world.settings.shape, world.settings.plane);
    let Grid {
        geom,
        velocity,
        force,
        ..
    } = &mut world.grid;
    let (velocity, stride) = (&*velocity, &geom.stride);
    let force_w = Disjoint::new(force);
    let Particles {
        stress,
        grad_v,
        grad_u,
        volume,
        material,
        plastic_strain,
        hardened,
        ..
    } = &mut world.particles;
    let columns = StressColumns::<D>::new(stress, grad_v, grad_u, plastic_strain, hardened);
    let (tiles, materials, domain) = (&world.tiles, &world.materials, &world.domain);
    let fields = world.cracks.as_ref().map(|c| &c.scratch.fields);
    tiles.for_each_coloured_then(
        |t| {
            let free = tiles.particles(t).iter().map(|&i| i as usize);
            for_each_free_particle!(D, shape, &tiles.stencils, fields, free, |i, st| {
                let rows = st.rows::<D>(stride);
                let l = velocity_gradient::<D, N>(&st, &rows, velocity);
                let m = &materials[material[i] as usize];
                // SAFETY: every particle is in exactly one tile and each tile is handled by one
                // thread, so no other thread touches particle i's entries; tiles of one colour
                // class touch disjoint nodes (tiles.rs).
                unsafe {
                    let s = columns.update(i, l, dt, plane, m);
                    add_internal_force::<D, N>(&st, &rows, &s, volume[i], &force_w);
                }
            })
        },
        domain.waits(),
        |classes, run| domain.settle_pass(classes, &[&force_w], run),
    );
    if world.cracks.is_some() {
        update_coded(world, dt);
    }
    close_internal_forces(world);
}

/// Closes an internal-force scatter over the tiles: the particles near a crack field by
/// field, from their stress column, then the image nodes' forces folded onto their sources.
pub(crate) fn close_internal_forces<D: Dim>(world: &mut World<D>) {
    if let Some(c) = world.cracks.as_ref() {
        scatter_coded::run::<D, false, false, true>(
            &c.scratch.fields,
            &world.particles,
            world.settings.shape,
            &world.tiles.stencils,
            &world.domain,
            &mut world.grid,
        );
    }
    if !world.grid.mirrors.is_empty() {
        mirror::fold_force(&mut world.grid);
    }
}
