//! `p2g`: particle-to-grid scatter of mass, momentum and forces (Guo & Nairn 2D (2004)
//! Eqs. 3-6, single velocity field), tile by tile in colour classes.

use crate::base::dim::Dim;
use crate::physics::shape::{Rows, Stencil};
use crate::ranks::ABSENT;
use crate::store::disjoint::Disjoint;
use crate::store::world::{CHUNK, World};
use crate::systems::{mirror, scatter_coded};
use crate::with_shape;
use rayon::prelude::*;

/// Scatters mass and momentum (and, when `internal`, the internal force -V sigma . grad S)
/// to a zeroed grid, then adds the external particle loads.
pub fn run<D: Dim>(world: &mut World<D>, internal: bool) {
    let g = &mut world.grid;
    // One pass zeroes the three scattered columns (they have one entry per grid entry),
    // where this rank's particles reach.
    for span in world.domain.spans(g.mass.len(), g.geom.node_count()) {
        (
            g.mass[span.clone()].par_chunks_mut(CHUNK),
            g.momentum[span.clone()].par_chunks_mut(CHUNK),
            g.force[span].par_chunks_mut(CHUNK),
        )
            .into_par_iter()
            .for_each(|(m, p, f)| {
                m.fill(0.0);
                p.fill(D::zero());
                f.fill(D::zero());
            });
    }
    if internal {
        scatter::<D, true>(world);
    } else {
        scatter::<D, false>(world);
    }
    scatter_loads(world);
    if !world.grid.mirrors.is_empty() {
        mirror::fold_scatter(&mut world.grid, world.settings.gravity);
    }
}

/// One scatter pass over the tiles, colour class by colour class (Guo & Nairn 2D (2004)
/// Eqs. 3 and 6, single velocity field) onto zeroed columns: mass and momentum, and the
/// internal force -V sigma . grad S when `FORCE` (a compile-time flag keeps the hot loop
/// free of branches).
fn scatter<D: Dim, const FORCE: bool>(world: &mut World<D>) {
    let grid = &mut world.grid;
    let (mass_w, momentum_w, force_w) = (
        Disjoint::new(&mut grid.mass),
        Disjoint::new(&mut grid.momentum),
        Disjoint::new(&mut grid.force),
    );
    let p = &world.particles;
    let shape = world.settings.shape;
    let geom = &grid.geom;
    let fields = world.cracks.as_ref().map(|c| &c.scratch.fields);
    let (tiles, domain) = (&world.tiles, &world.domain);
    tiles.for_each_coloured_then(
        |t| {
            let free = tiles.particles(t).iter().map(|&i| i as usize);
            for_each_free_particle!(D, shape, &tiles.stencils, fields, free, |i, st| {
                let (m, mv) = (p.mass[i], p.v[i] * p.mass[i]);
                let rows = st.rows::<D>(&geom.stride);
                // SAFETY: tiles of one colour class touch disjoint nodes (tiles.rs), and each
                // tile is handled by one thread.
                unsafe {
                    mass_w.add_weighted::<N>(&rows, &st.w[0], m);
                    momentum_w.add_weighted::<N>(&rows, &st.w[0], mv);
                }
                if FORCE {
                    // SAFETY: as above.
                    unsafe {
                        add_internal_force::<D, N>(&st, &rows, &p.stress[i], p.volume[i], &force_w)
                    };
                }
            })
        },
        domain.waits(),
        |classes, run| {
            if FORCE {
                domain.settle_pass(classes, &[&mass_w, &momentum_w, &force_w], run);
            } else {
                domain.settle_pass(classes, &[&mass_w, &momentum_w], run);
            }
        },
    );
    if let Some(f) = fields {
        scatter_coded::run::<D, true, true, FORCE>(f, p, shape, &tiles.stencils, domain, grid);
    }
}

/// Adds particle `i`'s internal force -V sigma . grad S to its stencil's nodes (Guo & Nairn
/// 2D (2004) Eq. 6), row by row (see [`Stencil::row`]).
///
/// # Safety
/// No other thread may access the stencil's nodes of `force` during the call.
#[inline(always)]
pub(crate) unsafe fn add_internal_force<D: Dim, const N: usize>(
    st: &Stencil<N>,
    rows: &Rows,
    s: &D::Sym,
    volume: f64,
    force: &Disjoint<D::Vec>,
) {
    let vol = -volume;
    let sx = D::stress_dot(s, D::unit_x()) * vol;
    // SAFETY: the caller guarantees exclusive access to these nodes.
    unsafe {
        force.add_rows(rows, |r| {
            let sxq = sx * rows.q[r];
            let syz = D::stress_dot_yz(s, rows.gy[r], rows.gz[r]) * vol;
            std::array::from_fn::<_, N, _>(|a| sxq * st.dw[0][a] + syz * st.w[0][a])
        })
    };
}

/// Adds external particle forces to the grid (sequential, in load order); `g2p` books
/// their work over the step. Split across ranks, every rank adds every loaded particle's
/// share, gathered from the ranks holding them, in that same order.
fn scatter_loads<D: Dim>(world: &mut World<D>) {
    if world.loads.is_empty() {
        return;
    }
    // Stable: each particle's shares stay in stencil order.
    let shares = (world.domain).in_order(load_shares(world, world.time), |s| (s.load, s.entry));
    for s in &shares {
        world.grid.force[s.node as usize] += s.force;
    }
}

/// The particle loads' forces on the grid entries at time `t`, added as [`scatter_loads`]
/// adds them (the static solve's supports need them at a step's start).
pub(crate) fn load_forces<D: Dim>(world: &World<D>, t: f64) -> Vec<D::Vec> {
    let mut f = vec![D::zero(); world.grid.mass.len()];
    for s in (world.domain).in_order(load_shares(world, t), |s| (s.load, s.entry)) {
        f[s.node as usize] += s.force;
    }
    f
}

/// One loaded particle's force on one grid entry: load `load`'s entry `entry`.
#[derive(Clone, Copy, Debug)]
#[repr(C)]
struct LoadShare<D: Dim> {
    load: u32,
    entry: u32,
    node: u64,
    force: D::Vec,
}

// SAFETY: two u32, a u64 and a vector of f64 (2 or 3), with no padding and no invalid bit
// patterns.
unsafe impl<D: Dim> bytemuck::Zeroable for LoadShare<D> {}
// SAFETY: as above; `D::Vec` is Pod (a DVec2 or DVec3).
unsafe impl<D: Dim> bytemuck::Pod for LoadShare<D> {}

/// The loads' shares on this rank's particles, in load, entry and stencil order.
fn load_shares<D: Dim>(world: &World<D>, t: f64) -> Vec<LoadShare<D>> {
    let geom = &world.grid.geom;
    let shape = world.settings.shape;
    let mut out = Vec::new();
    for (k, load) in world.loads.iter().enumerate() {
        let scale = load.time.at(t);
        for (j, (&i, &f)) in load.particles.iter().zip(&load.forces).enumerate() {
            if i == ABSENT {
                continue;
            }
            let (i, f) = (i as usize, f * scale);
            let mut share = |n: usize, w: f64| {
                out.push(LoadShare {
                    load: k as u32,
                    entry: j as u32,
                    node: n as u64,
                    force: f * w,
                })
            };
            let targets = world
                .cracks
                .as_ref()
                .and_then(|c| c.scratch.fields.targets_of(i));
            with_shape!(shape, S, N => {
                let st = Stencil::<N>::cached::<D>(S, &world.tiles.stencils, i);
                match targets {
                    Some(t) => st.for_each_target::<D>(&geom.stride, t, |n, w, _| share(n, w)),
                    None => st.for_each::<D>(&geom.stride, |n, w, _| share(n, w)),
                }
            });
        }
    }
    out
}
