//! `stress`: small-strain constitutive update, d(eps) = sym(grad v) dt, in parallel over
//! particle chunks. Under USF/USAVG it first gathers grad v from the extrapolated momenta.

use crate::dim::Dim;
use crate::particles::Particles;
use crate::shape::Stencil;
use crate::world::{CHUNK, World};
use rayon::prelude::*;

/// Updates stress and strain over `fraction` of the step. When `gather`, grad v is first
/// gathered from the grid velocities p/m; otherwise the particles' stored grad v is used.
pub fn run<D: Dim>(world: &mut World<D>, gather: bool, fraction: f64) {
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
        strain,
        material,
        ..
    } = &mut world.particles;
    let (x, half, material) = (&*x, &*half, &*material);
    (
        grad_v.par_chunks_mut(CHUNK),
        stress.par_chunks_mut(CHUNK),
        strain.par_chunks_mut(CHUNK),
    )
        .into_par_iter()
        .enumerate()
        .for_each(|(c, (gv, s, e))| {
            for k in 0..gv.len() {
                let i = c * CHUNK + k;
                if gather {
                    let hw = if half.is_empty() { D::zero() } else { half[i] };
                    let st = Stencil::new::<D>(shape, geom, x[i], hw);
                    let mut l = D::mat_zero();
                    st.for_each::<D>(&geom.stride, |n, _, g| {
                        let m = grid.mass[n];
                        if m > tol {
                            l = l + D::outer(grid.momentum[n] * (1.0 / m), g);
                        }
                    });
                    gv[k] = l;
                }
                let de = D::sym_part(&gv[k]) * dt;
                materials[material[i] as usize].update(plane, de, &mut s[k], &mut e[k]);
            }
        });
}
