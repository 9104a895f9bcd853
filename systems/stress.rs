//! `stress`: small-strain constitutive update, d(eps) = sym(grad v) dt, with grad v gathered
//! from the grid velocities p/m, in parallel over particle chunks.

use crate::dim::Dim;
use crate::particles::Particles;
use crate::shape::Stencil;
use crate::with_nodes;
use crate::world::{CHUNK, World};
use rayon::prelude::*;

/// Gathers grad v = sum (p_i/m_i) ⊗ grad S into the particles' grad_v column and updates
/// the stress over `fraction` of the step.
pub fn run<D: Dim>(world: &mut World<D>, fraction: f64) {
    let dt = world.settings.dt * fraction;
    let (shape, plane, tol) = (
        world.settings.shape,
        world.settings.plane,
        world.settings.mass_tol,
    );
    let grid = &world.grid;
    let geom = &grid.geom;
    let materials = &world.materials;
    let Particles {
        x,
        half,
        grad_v,
        stress,
        material,
        ..
    } = &mut world.particles;
    let (x, half, material) = (&*x, &*half, &*material);
    (grad_v.par_chunks_mut(CHUNK), stress.par_chunks_mut(CHUNK))
        .into_par_iter()
        .enumerate()
        .for_each(|(c, (gv, s))| {
            with_nodes!(shape, N => for k in 0..gv.len() {
                let i = c * CHUNK + k;
                let hw = if half.is_empty() { D::zero() } else { half[i] };
                let st = Stencil::<N>::new::<D>(shape, geom, x[i], hw);
                let mut l = D::mat_zero();
                st.for_each::<D>(&geom.stride, |n, _, g| {
                    let m = grid.mass[n];
                    if m > tol {
                        l = l + D::outer(grid.momentum[n] * (1.0 / m), g);
                    }
                });
                gv[k] = l;
                let de = D::sym_part(&gv[k]) * dt;
                materials[material[i] as usize].update(plane, de, &mut s[k]);
            })
        });
}
