//! `stress`: small-strain constitutive update, d(eps) = sym(grad v) dt, with grad v gathered
//! from the grid velocities p/m, in parallel over particle chunks (the particles near a
//! crack afterwards, from their fields' entries).

use crate::dim::Dim;
use crate::material::{Elastic, Plane};
use crate::particles::Particles;
use crate::shape::Stencil;
use crate::sym::Sym3;
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
    let stride = &grid.geom.stride;
    let body = |c: usize, gv: &mut [D::Mat], s: &mut [Sym3], gu: &mut [D::Mat]| {
        with_nodes!(shape, N => for k in 0..gv.len() {
            let i = c * CHUNK + k;
            // Particles near a crack are updated from their fields' entries afterwards.
            if fields.is_some_and(|f| f.is_coded(i)) {
                continue;
            }
            let st = Stencil::<N>::cached::<D>(stencils, i);
            let l = velocity_gradient::<D, N>(&st, &grid.velocity, stride);
            let m = &materials[material[i] as usize];
            apply::<D>(l, dt, plane, m, &mut gv[k], &mut s[k], gu.get_mut(k));
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
    // The particles near a crack: grad v over each stencil node's entry for the particle's
    // side (Guo & Nairn 3D (2006) Eq. 20), sequentially.
    let Some(f) = fields else { return };
    for &i in &f.coded {
        let i = i as usize;
        let targets = f.targets_of(i).expect("coded particle");
        let mut l = D::mat_zero();
        with_nodes!(shape, N => {
            let st = Stencil::<N>::cached::<D>(stencils, i);
            st.for_each_target::<D>(stride, targets, |n, _, g| {
                l = l + D::outer(grid.velocity[n], g);
            });
        });
        let m = &materials[material[i] as usize];
        apply::<D>(
            l,
            dt,
            plane,
            m,
            &mut grad_v[i],
            &mut stress[i],
            grad_u.get_mut(i),
        );
    }
}

/// One particle's update from its velocity gradient `l`: grad v, grad u (when kept) and the
/// stress over `dt`.
#[inline(always)]
fn apply<D: Dim>(
    l: D::Mat,
    dt: f64,
    plane: Plane,
    m: &Elastic,
    gv: &mut D::Mat,
    s: &mut Sym3,
    gu: Option<&mut D::Mat>,
) {
    *gv = l;
    if let Some(gu) = gu {
        *gu = *gu + l * dt;
    }
    m.update(plane, D::sym_part(&l) * dt, s);
}

/// grad v of one particle away from cracks: sum over its stencil of v_i ⊗ grad S_i, row by
/// row (sum_rows (sum_i v_i dw_i) ⊗ q x̂ + (sum_i v_i w_i) ⊗ g_yz).
#[inline(always)]
fn velocity_gradient<D: Dim, const N: usize>(
    st: &Stencil<N>,
    velocity: &[D::Vec],
    stride: &[usize; 3],
) -> D::Mat {
    let mut l = D::mat_zero();
    for r in 0..Stencil::<N>::rows::<D>() {
        let (row, q, gyz) = st.row::<D>(stride, r);
        let (mut vd, mut vw) = (D::zero(), D::zero());
        // One bounds check per row: the slice has N nodes.
        for (a, &v) in velocity[row..row + N].iter().enumerate() {
            vd += v * st.dw[0][a];
            vw += v * st.w[0][a];
        }
        l = D::add_row(l, vd, q, vw, gyz);
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
