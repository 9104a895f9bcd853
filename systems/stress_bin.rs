//! `stress_bin`: the stress update that closes a USL or USAVG step fused with the binning
//! of the moved particles for the next step, in one pass over particle chunks: each
//! particle's old stencil is read for its velocity gradient just before its new one is
//! written in its place.

use crate::base::dim::Dim;
use crate::base::error::Unstable;
use crate::physics::material::{Material, Plane};
use crate::physics::shape::{ShapeKind, Stencil};
use crate::store::crack::Fields;
use crate::store::particles::Particles;
use crate::store::world::World;
use crate::systems::bin::{BeforeBin, outside, place};
use crate::systems::is_free;
use crate::systems::stress::{StressColumns, node_velocities, update_coded, velocity_gradient};

/// Updates every particle's stress over `fraction` of the step (as
/// [`stress::run`](crate::systems::stress::run)), then bins the particles at their new
/// positions (as [`bin::run`](crate::systems::bin::run)). A particle whose stencil leaves
/// the grid stops the run at the step these positions close.
pub fn run<D: Dim>(world: &mut World<D>, fraction: f64) -> Result<(), Unstable> {
    node_velocities(world);
    let dt = world.settings.dt * fraction;
    // The particles near a crack first, while the cached stencils match their fields.
    update_coded(world, dt);
    let grid = &world.grid;
    let Particles {
        x,
        half,
        stress,
        grad_v,
        grad_u,
        material,
        plastic_strain,
        hardened,
        ..
    } = &mut world.particles;
    let work = ClosingStress::<D> {
        dt,
        plane: world.settings.plane,
        velocity: &grid.velocity,
        stride: grid.geom.stride,
        inv_h: world.tiles.stencils.inv_h,
        material,
        materials: &world.materials,
        fields: world.cracks.as_ref().map(|c| &c.scratch.fields),
        columns: StressColumns::new(stress, grad_v, grad_u, plastic_strain, hardened),
    };
    let shape = world.settings.shape;
    match place(x, half, &grid.geom, shape, &mut world.tiles, &work) {
        Ok(()) => Ok(()),
        Err(i) => {
            let step = world.step + 1;
            Err(outside(world, i, step, step as f64 * world.settings.dt))
        }
    }
}

/// The stress update `place` runs on each particle's old stencil.
struct ClosingStress<'a, D: Dim> {
    dt: f64,
    plane: Plane,
    velocity: &'a [D::Vec],
    stride: [usize; 3],
    inv_h: [f64; 3],
    material: &'a [u16],
    materials: &'a [Material],
    fields: Option<&'a Fields>,
    columns: StressColumns<'a, D>,
}

impl<D: Dim> BeforeBin for ClosingStress<'_, D> {
    #[inline(always)]
    fn before<const N: usize>(&self, s: ShapeKind, i: usize, first: u32, params: &[f64]) {
        // Particles near a crack were updated from their fields' entries already.
        if !is_free(self.fields, i) {
            return;
        }
        let st = Stencil::<N>::from_cache::<D>(s, first, params, &self.inv_h);
        let l = velocity_gradient::<D, N>(&st, &st.rows::<D>(&self.stride), self.velocity);
        let (dt, plane) = (self.dt, self.plane);
        let m = &self.materials[self.material[i] as usize];
        // SAFETY: `place` visits every particle once, on one thread.
        unsafe { self.columns.update(i, l, dt, plane, m) };
    }
}
