//! `stress`: small-strain constitutive update, d(eps) = sym(grad v) dt, with grad v gathered
//! from the grid velocities p/m, in parallel over particle chunks.

use crate::dim::Dim;
use crate::disjoint::Disjoint;
use crate::grid::Grid;
use crate::particles::Particles;
use crate::shape::Stencil;
use crate::sym::Sym3;
use crate::systems::p2g::{add_internal_force, scatter_coded};
use crate::with_nodes;
use crate::world::{CHUNK, World};
use rayon::prelude::*;

/// Gathers grad v = sum (p_i/m_i) ⊗ grad S into the particles' grad_v column and updates
/// the stress over `fraction` of the step, in parallel over particle chunks. The grid's
/// velocity column is overwritten with p/m first (grid_update rewrites it with end-of-step
/// velocities afterwards).
pub fn run<D: Dim>(world: &mut World<D>, fraction: f64) {
    node_velocities(world);
    let dt = world.settings.dt * fraction;
    let (shape, plane) = (world.settings.shape, world.settings.plane);
    let grid = &world.grid;
    let materials = &world.materials;
    let stencils = &world.tiles.stencils;
    let fields = world.cracks.as_ref().map(|c| &c.fields);
    let Particles {
        grad_v,
        grad_u,
        stress,
        material,
        ..
    } = &mut world.particles;
    let material = &*material;
    let body = |c: usize, gv: &mut [D::Mat], s: &mut [Sym3], gu: &mut [D::Mat]| {
        with_nodes!(shape, N => for k in 0..gv.len() {
            let i = c * CHUNK + k;
            let st = Stencil::<N>::cached::<D>(stencils, i);
            let targets = fields.and_then(|f| f.targets_of(i));
            let l = velocity_gradient::<D, N>(&st, targets, &grid.velocity, &grid.geom.stride);
            gv[k] = l;
            if !gu.is_empty() {
                gu[k] = gu[k] + l * dt;
            }
            materials[material[i] as usize].update(plane, D::sym_part(&l) * dt, &mut s[k]);
        })
    };
    if grad_u.is_empty() {
        (grad_v.par_chunks_mut(CHUNK), stress.par_chunks_mut(CHUNK))
            .into_par_iter()
            .enumerate()
            .for_each(|(c, (gv, s))| body(c, gv, s, &mut []));
    } else {
        (
            grad_v.par_chunks_mut(CHUNK),
            stress.par_chunks_mut(CHUNK),
            grad_u.par_chunks_mut(CHUNK),
        )
            .into_par_iter()
            .enumerate()
            .for_each(|(c, (gv, s, gu))| body(c, gv, s, gu));
    }
}

/// As [`run`], then each particle's internal force -V sigma . grad S from its new stress is
/// scattered to the grid's force column (USF and USAVG), in one pass over the tiles in
/// colour classes: the stencil is read once for both.
pub fn run_with_force<D: Dim>(world: &mut World<D>, fraction: f64) {
    node_velocities(world);
    let dt = world.settings.dt * fraction;
    let (shape, plane) = (world.settings.shape, world.settings.plane);
    let Grid {
        geom,
        mass,
        momentum,
        force,
        velocity,
        ..
    } = &mut world.grid;
    let (geom, velocity) = (&*geom, &*velocity);
    let materials = &world.materials;
    let tiles = &world.tiles;
    let fields = world.cracks.as_ref().map(|c| &c.fields);
    let p = &mut world.particles;
    let track = !p.grad_u.is_empty();
    let (material, volume) = (&p.material, &p.volume);
    let (gv_w, s_w, gu_w, force_w) = (
        Disjoint::new(&mut p.grad_v),
        Disjoint::new(&mut p.stress),
        Disjoint::new(&mut p.grad_u),
        Disjoint::new(force),
    );
    tiles.for_each_coloured(|t| {
        with_nodes!(shape, N => for &i in tiles.particles(t) {
            let i = i as usize;
            let st = Stencil::<N>::cached::<D>(&tiles.stencils, i);
            let targets = fields.and_then(|f| f.targets_of(i));
            let l = velocity_gradient::<D, N>(&st, targets, velocity, &geom.stride);
            // SAFETY: every particle is in exactly one tile and each tile is handled by one
            // thread, so no other thread touches particle i's entries; tiles of one colour
            // class touch disjoint nodes (tiles.rs).
            unsafe {
                gv_w.set(i, l);
                if track {
                    gu_w.set(i, gu_w.get(i) + l * dt);
                }
                let mut s = s_w.get(i);
                materials[material[i] as usize].update(plane, D::sym_part(&l) * dt, &mut s);
                s_w.set(i, s);
                // Particles near a crack are scattered field by field afterwards.
                if targets.is_none() {
                    add_internal_force::<D, N>(&st, &geom.stride, &s, volume[i], &force_w);
                }
            }
        })
    });
    if let Some(f) = fields {
        let columns = (&mut mass[..], &mut momentum[..], &mut force[..]);
        scatter_coded::<D, false, false, true>(f, p, shape, &tiles.stencils, columns, geom);
    }
}

/// grad v of one particle: sum over its stencil of v_i ⊗ grad S_i, row by row
/// (sum_rows (sum_i v_i dw_i) ⊗ q x̂ + (sum_i v_i w_i) ⊗ g_yz); near a crack, over its own
/// field's entries (Guo & Nairn 3D (2006) Eq. 20).
#[inline(always)]
fn velocity_gradient<D: Dim, const N: usize>(
    st: &Stencil<N>,
    targets: Option<&[u32]>,
    velocity: &[D::Vec],
    stride: &[usize; 3],
) -> D::Mat {
    let mut l = D::mat_zero();
    match targets {
        Some(t) => st.for_each_target::<D>(stride, t, |n, _, g| {
            l = l + D::outer(velocity[n], g);
        }),
        None => st.for_each_row::<D>(stride, |row, q, gyz| {
            let (mut vd, mut vw) = (D::zero(), D::zero());
            // One bounds check per row: the slice has N nodes.
            for (a, &v) in velocity[row..row + N].iter().enumerate() {
                vd += v * st.dw[0][a];
                vw += v * st.w[0][a];
            }
            l = l + D::outer(vd, D::unit_x() * q) + D::outer(vw, gyz);
        }),
    }
    l
}

/// Sets the grid velocity column to p/m (zero on nodes lighter than the mass tolerance).
fn node_velocities<D: Dim>(world: &mut World<D>) {
    let tol = world.settings.mass_tol;
    let g = &mut world.grid;
    let (mass, momentum) = (&g.mass, &g.momentum);
    g.velocity
        .par_chunks_mut(CHUNK)
        .enumerate()
        .for_each(|(c, vel)| {
            for (k, v) in vel.iter_mut().enumerate() {
                let n = c * CHUNK + k;
                *v = if mass[n] > tol {
                    momentum[n] * (1.0 / mass[n])
                } else {
                    D::zero()
                };
            }
        });
}
