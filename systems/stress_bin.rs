//! `stress_bin`: the stress update that closes a USL or USAVG step fused with the binning
//! of the moved particles for the next step, in one pass over particle chunks: each
//! particle's old stencil is read for its velocity gradient just before its new one is
//! written in its place.

use crate::dim::Dim;
use crate::disjoint::Disjoint;
use crate::error::Unstable;
use crate::particles::Particles;
use crate::shape::Stencil;
use crate::systems::bin::{outside, place};
use crate::systems::stress::{apply, node_velocities, update_coded, velocity_gradient};
use crate::with_shape;
use crate::world::World;

/// Updates every particle's stress over `fraction` of the step (as
/// [`stress::run`](crate::systems::stress::run)), then bins the particles at their new
/// positions (as [`bin::run`](crate::systems::bin::run)). A particle whose stencil leaves
/// the grid stops the run at the step these positions close.
pub fn run<D: Dim>(world: &mut World<D>, fraction: f64) -> Result<(), Unstable> {
    node_velocities(world);
    let dt = world.settings.dt * fraction;
    // The particles near a crack first, while the cached stencils match their fields.
    update_coded(world, dt);
    let (shape, plane) = (world.settings.shape, world.settings.plane);
    let grid = &world.grid;
    let (velocity, stride) = (&grid.velocity[..], &grid.geom.stride);
    let Particles {
        x,
        half,
        stress,
        grad_v,
        grad_u,
        material,
        ..
    } = &mut world.particles;
    let keep = !grad_u.is_empty();
    let (stress_w, grad_v_w, grad_u_w) = (
        Disjoint::new(stress),
        Disjoint::new(grad_v),
        Disjoint::new(grad_u),
    );
    let (material, materials) = (&*material, &world.materials);
    let fields = world.cracks.as_ref().map(|c| &c.fields);
    let inv_h = &world.tiles.stencils.inv_h.clone();
    let update = |i: usize, b: [u32; 3], params: &[f64]| {
        if fields.is_some_and(|f| f.is_coded(i)) {
            return;
        }
        with_shape!(shape, S, N => {
            let st = Stencil::<N>::from_cache::<D>(S, b, params, inv_h);
            let l = velocity_gradient::<D, N>(&st, &st.rows::<D>(stride), velocity);
            let m = &materials[material[i] as usize];
            // SAFETY: `place` visits every particle once, on one thread.
            unsafe {
                let mut s = stress_w.get(i);
                if keep {
                    let (mut gv, mut gu) = (grad_v_w.get(i), grad_u_w.get(i));
                    apply::<D>(l, dt, plane, m, &mut s, Some((&mut gv, &mut gu)));
                    grad_v_w.set(i, gv);
                    grad_u_w.set(i, gu);
                } else {
                    apply::<D>(l, dt, plane, m, &mut s, None);
                }
                stress_w.set(i, s);
            }
        })
    };
    match place(x, half, &grid.geom, shape, &mut world.tiles, update) {
        Ok(()) => Ok(()),
        Err(i) => {
            let step = world.step + 1;
            Err(outside(world, i, step, step as f64 * world.settings.dt))
        }
    }
}
