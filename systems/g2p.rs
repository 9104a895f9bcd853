//! `g2p`: grid-to-particle gather (FLIP velocity update, position update), and
//! `g2p_remap`, the same followed by the momentum remap of USL and USAVG.

use crate::base::dim::Dim;
use crate::base::exact_sum::ExactSum;
use crate::physics::shape::{Rows, Stencil};
use crate::ranks::ABSENT;
use crate::store::disjoint::Disjoint;
use crate::store::particles::Particles;
use crate::store::world::{CHUNK, World};
use crate::systems::{mirror, scatter_coded};
use crate::with_shape;
use rayon::prelude::*;

/// Updates particle velocities (v += dt sum S a_i) and positions (x += dt sum S v_i'), in
/// parallel over particle chunks (USF), the particles near a crack afterwards from their
/// fields' entries; the particles' bins are stale afterwards.
pub fn run<D: Dim>(world: &mut World<D>) {
    let (dt, alpha) = (world.settings.dt, world.settings.damping);
    let shape = world.settings.shape;
    let grid = &world.grid;
    let stencils = &world.tiles.stencils;
    let fields = world.cracks.as_ref().map(|c| &c.scratch.fields);
    let track = fields.is_some();
    let nodal = (&grid.accel[..], &grid.velocity[..]);
    let Particles { x, v, .. } = &mut world.particles;
    let fastest = (x.par_chunks_mut(CHUNK), v.par_chunks_mut(CHUNK))
        .into_par_iter()
        .enumerate()
        .map(|(c, (x, v))| {
            let mut fastest = 0.0f64;
            let chunk = c * CHUNK..c * CHUNK + x.len();
            for_each_free_particle!(D, shape, stencils, fields, chunk, |i, st| {
                let k = i - c * CHUNK;
                let (dv, vn) = gather::<D, N>(&st, &st.rows::<D>(&grid.geom.stride), nodal);
                v[k] = flip::<D>(v[k], dv, vn, dt, alpha);
                x[k] += vn * dt;
                if track {
                    fastest = fastest.max(D::dot(vn, vn));
                }
            });
            fastest
        })
        .reduce(|| 0.0, f64::max);
    let fastest = fastest.max(move_coded(world));
    finish(world, fastest);
}

/// As [`run`], then each particle's updated momentum m v is scattered back to the zeroed
/// grid momenta with the start-of-step shape functions (USL and USAVG), in one pass over
/// the tiles in colour classes (the particles near a crack afterwards, sequentially, field
/// by field). The final stress update then reads grid velocities that
/// are mass-weighted averages of particle velocities (the modified USL of Sulsky, Zhou &
/// Schreyer 1995); without this remap, nodes with a tiny share of mass get huge velocities
/// and linear shape functions go unstable. The nodal masses stay those of `p2g`.
pub fn run_with_remap<D: Dim>(world: &mut World<D>) {
    let (dt, alpha) = (world.settings.dt, world.settings.damping);
    let shape = world.settings.shape;
    let grid = &mut world.grid;
    for span in (world.domain).spans(grid.momentum.len(), grid.geom.node_count()) {
        (grid.momentum[span].par_iter_mut()).for_each(|m| *m = D::zero());
    }
    let nodal = (&grid.accel[..], &grid.velocity[..]);
    let tiles = &world.tiles;
    let fields = world.cracks.as_ref().map(|c| &c.scratch.fields);
    let track = fields.is_some();
    let p = &mut world.particles;
    let pmass = &p.mass;
    let (x_w, v_w, momentum_w) = (
        Disjoint::new(&mut p.x),
        Disjoint::new(&mut p.v),
        Disjoint::new(&mut grid.momentum),
    );
    let stride = &grid.geom.stride;
    let fastest = tiles.max_coloured_then(
        |t| {
            let mut fastest = 0.0f64;
            let free = tiles.particles(t).iter().map(|&i| i as usize);
            for_each_free_particle!(D, shape, &tiles.stencils, fields, free, |i, st| {
                let rows = st.rows::<D>(stride);
                let (dv, vn) = gather::<D, N>(&st, &rows, nodal);
                // SAFETY: every particle is in exactly one tile and each tile is handled by one
                // thread, so no other thread touches particle i's entries; tiles of one colour
                // class touch disjoint nodes (tiles.rs).
                unsafe {
                    let v = flip::<D>(v_w.get(i), dv, vn, dt, alpha);
                    v_w.set(i, v);
                    x_w.set(i, x_w.get(i) + vn * dt);
                    let mv = v * pmass[i];
                    momentum_w.add_weighted::<N>(&rows, &st.w[0], mv);
                }
                if track {
                    fastest = fastest.max(D::dot(vn, vn));
                }
            });
            fastest
        },
        world.domain.waits(),
        |classes, run| world.domain.settle_pass(classes, &[&momentum_w], run),
    );
    let fastest = fastest.max(move_coded(world));
    if let Some(c) = world.cracks.as_ref() {
        let p = &world.particles;
        scatter_coded::run::<D, false, true, false>(
            &c.scratch.fields,
            p,
            shape,
            &world.tiles.stencils,
            &world.domain,
            &mut world.grid,
        );
    }
    if !world.grid.mirrors.is_empty() {
        mirror::fold_momentum(&mut world.grid);
    }
    finish(world, fastest);
}

/// A particle's new velocity: the FLIP update v + dt sum S a_i, less the damping of the
/// part of v that the grid does not see. The grid's damping (-alpha p, Guo & Nairn 2D
/// (2004) Eq. 5) only reaches what a particle's velocity adds to its nodes' momenta; the
/// rest, v - sum S v_i (v_i = v_i' - a_i dt the nodal velocities the step started from),
/// is relaxed at the same rate alpha here. Without it a damped run kept particles moving
/// at metres per second against each other next to a loaded edge while the grid was at
/// rest (a FLIP null-space mode). Undamped (alpha = 0) this is the plain FLIP update.
#[inline(always)]
fn flip<D: Dim>(v: D::Vec, dv: D::Vec, vn: D::Vec, dt: f64, alpha: f64) -> D::Vec {
    if alpha == 0.0 {
        return v + dv * dt;
    }
    let unseen = v - (vn - dv * dt);
    v + dv * dt - unseen * (alpha * dt)
}

/// The velocity change per unit time and the velocity moving one particle away from
/// cracks: the stencil's sums of a_i S and v_i' S, row by row.
#[inline(always)]
fn gather<D: Dim, const N: usize>(
    st: &Stencil<N>,
    rows: &Rows,
    (accel, velocity): (&[D::Vec], &[D::Vec]),
) -> (D::Vec, D::Vec) {
    let (mut dv, mut vn) = (D::zero(), D::zero());
    for r in 0..rows.len {
        let row = rows.first[r];
        let (mut da, mut dn) = (D::zero(), D::zero());
        // One bounds check per row and column: each slice has N nodes.
        let (acc, vel) = (&accel[row..row + N], &velocity[row..row + N]);
        for a in 0..N {
            let w = st.w[0][a];
            da += acc[a] * w;
            dn += vel[a] * w;
        }
        dv += da * rows.q[r];
        vn += dn * rows.q[r];
    }
    (dv, vn)
}

/// Moves the particles near a crack, each from its own field's entries (v += dt sum S a_i,
/// x += dt sum S v_i'), sequentially; returns the largest squared velocity moving
/// one of them (zero without cracks).
fn move_coded<D: Dim>(world: &mut World<D>) -> f64 {
    let Some(c) = world.cracks.as_ref() else {
        return 0.0;
    };
    let (dt, shape, alpha) = (
        world.settings.dt,
        world.settings.shape,
        world.settings.damping,
    );
    let (grid, p) = (&world.grid, &mut world.particles);
    let mut fastest = 0.0f64;
    for &i in &c.scratch.fields.coded {
        let i = i as usize;
        let targets = c.scratch.fields.targets_of(i).expect("coded particle");
        let (mut dv, mut vn) = (D::zero(), D::zero());
        with_shape!(shape, S, N => {
            let st = Stencil::<N>::cached::<D>(S, &world.tiles.stencils, i);
            st.for_each_target::<D>(&grid.geom.stride, targets, |n, w, _| {
                dv += grid.accel[n] * w;
                vn += grid.velocity[n] * w;
            });
        });
        p.v[i] = flip::<D>(p.v[i], dv, vn, dt, alpha);
        p.x[i] += vn * dt;
        fastest = fastest.max(D::dot(vn, vn));
    }
    fastest
}

/// After the particles moved: the crack record's drift (when cracks need the bound; the
/// largest squared velocity is `fastest`), stale bins, the load work.
fn finish<D: Dim>(world: &mut World<D>, fastest: f64) {
    if let Some(c) = world.cracks.as_mut() {
        c.scratch.classified.drift += fastest.sqrt() * world.settings.dt;
    }
    world.tiles.fresh = false;
    load_work_end(world);
}

/// Books the work of the external loads over the step: each load's force (constant over
/// the step, as `p2g` scattered it) times the displacement its particle just made,
/// dt sum S v_i' over its own fields. The particle velocity, which FLIP updates with
/// accelerations the particle does not move with, is not the rate of that displacement.
fn load_work_end<D: Dim>(world: &mut World<D>) {
    let (t, dt) = (world.time, world.settings.dt);
    let shape = world.settings.shape;
    let grid = &world.grid;
    let fields = world.cracks.as_ref().map(|c| &c.scratch.fields);
    let mut work = ExactSum::new();
    for load in &world.loads {
        let scale = load.time.at(t);
        for (&i, &f) in load.particles.iter().zip(&load.forces) {
            if i == ABSENT {
                continue;
            }
            let i = i as usize;
            let mut vn = D::zero();
            with_shape!(shape, S, N => {
                let st = Stencil::<N>::cached::<D>(S, &world.tiles.stencils, i);
                match fields.and_then(|c| c.targets_of(i)) {
                    Some(t) => st.for_each_target::<D>(&grid.geom.stride, t, |n, w, _| {
                        vn += grid.velocity[n] * w
                    }),
                    None => st.for_each::<D>(&grid.geom.stride, |n, w, _| {
                        vn += grid.velocity[n] * w
                    }),
                }
            });
            work.add(dt * scale * D::dot(f, vn));
        }
    }
    world.domain.sum(std::slice::from_mut(&mut work));
    world.work.external += work.value();
}
