//! `g2p`: grid-to-particle gather. FLIP velocity update, position and displacement update.

use crate::dim::Dim;
use crate::particles::Particles;
use crate::shape::Stencil;
use crate::with_nodes;
use crate::world::{CHUNK, World};
use rayon::prelude::*;

/// Updates particle velocities (v += dt sum S a_i), positions and displacements
/// (x += dt sum S v_i'); the particles' bins are stale afterwards.
pub fn run<D: Dim>(world: &mut World<D>) {
    let dt = world.settings.dt;
    let shape = world.settings.shape;
    let grid = &world.grid;
    let geom = &grid.geom;
    let stencils = &world.tiles.stencils;
    let fields = world.cracks.as_ref().map(|c| &c.fields);
    let track = fields.is_some();
    let Particles { x, v, u, .. } = &mut world.particles;
    // Largest squared velocity moving a particle, when cracks need the bound on drift.
    let fastest = (
        x.par_chunks_mut(CHUNK),
        v.par_chunks_mut(CHUNK),
        u.par_chunks_mut(CHUNK),
    )
        .into_par_iter()
        .enumerate()
        .map(|(c, (x, v, u))| {
            let mut fastest = 0.0f64;
            with_nodes!(shape, N => for k in 0..x.len() {
                let i = c * CHUNK + k;
                let st = Stencil::<N>::cached::<D>(stencils, i);
                let (mut dv, mut vn) = (D::zero(), D::zero());
                match fields.and_then(|f| f.targets_of(i)) {
                    // Near a crack: each node's entry for this particle's field.
                    Some(t) => st.for_each_target::<D>(&geom.stride, t, |n, w, _| {
                        dv += grid.accel[n] * w;
                        vn += grid.velocity[n] * w;
                    }),
                    None => st.for_each_row::<D>(&geom.stride, |row, q, _| {
                        let (mut da, mut dn) = (D::zero(), D::zero());
                        // One bounds check per row and column: each slice has N nodes.
                        let (acc, vel) = (&grid.accel[row..row + N], &grid.velocity[row..row + N]);
                        for a in 0..N {
                            let w = st.w[0][a];
                            da += acc[a] * w;
                            dn += vel[a] * w;
                        }
                        dv += da * q;
                        vn += dn * q;
                    }),
                }
                v[k] += dv * dt;
                x[k] += vn * dt;
                u[k] += vn * dt;
                if track {
                    fastest = fastest.max(D::dot(vn, vn));
                }
            });
            fastest
        })
        .reduce(|| 0.0, f64::max);
    if let Some(c) = world.cracks.as_mut() {
        c.classified.drift += fastest.sqrt() * dt;
    }
    world.tiles.fresh = false;
    load_work_end(world);
}

/// Books the second half of the external loads' work over the step (trapezoidal rule).
fn load_work_end<D: Dim>(world: &mut World<D>) {
    let (t, dt) = (world.time, world.settings.dt);
    let mut work = 0.0;
    for load in &world.loads {
        let scale = load.time.at(t);
        for (&i, &f) in load.particles.iter().zip(&load.forces) {
            work += 0.5 * dt * scale * D::dot(f, world.particles.v[i as usize]);
        }
    }
    world.work.external += work;
}
