//! `grid_update`: nodal velocities and accelerations from momenta and forces, damping
//! (Guo & Nairn 2D (2004) Eq. 5), gravity and prescribed velocities.

use crate::crack::Fields;
use crate::dim::Dim;
use crate::grid::Grid;
use crate::world::{CHUNK, World};
use rayon::prelude::*;

/// Overwrites prescribed components of the extrapolated momenta so that p/m equals the
/// prescribed velocity at the start of the step, or at its end when `end` (after a remap).
pub fn momentum_bc<D: Dim>(world: &mut World<D>, end: bool) {
    let t = world.time + if end { world.settings.dt } else { 0.0 };
    let g = &mut world.grid;
    let fields = world.cracks.as_ref().map(|c| &c.fields);
    for bc in &world.bcs {
        for &node in &bc.nodes {
            for n in entries(node, fields) {
                for a in 0..D::D {
                    if bc.axes[a] {
                        g.momentum[n][a] = g.mass[n] * bc.value(a, t);
                    }
                }
            }
        }
    }
}

/// Integrates nodal momenta over the step: a = (f - alpha p + m g)/m, v' = p/m + a dt; then
/// prescribed components are set to their end-of-step values with the matching acceleration.
pub fn run<D: Dim>(world: &mut World<D>) {
    let s = &world.settings;
    let (dt, alpha, gravity, tol) = (s.dt, s.damping, s.gravity, s.mass_tol);
    let Grid {
        mass,
        momentum,
        force,
        velocity,
        accel,
        ..
    } = &mut world.grid;
    let (mass, momentum, force) = (&*mass, &*momentum, &*force);
    let sums: Vec<(f64, f64)> = (velocity.par_chunks_mut(CHUNK), accel.par_chunks_mut(CHUNK))
        .into_par_iter()
        .enumerate()
        .map(|(c, (vel, acc))| {
            let (mut damp, mut grav) = (0.0, 0.0);
            for k in 0..vel.len() {
                let n = c * CHUNK + k;
                let m = mass[n];
                if m > tol {
                    let v0 = momentum[n] * (1.0 / m);
                    let f = force[n] - momentum[n] * alpha + gravity * m;
                    let a = f * (1.0 / m);
                    let v1 = v0 + a * dt;
                    let vmid = (v0 + v1) * 0.5;
                    damp += alpha * D::dot(momentum[n], vmid) * dt;
                    grav += m * D::dot(gravity, vmid) * dt;
                    vel[k] = v1;
                    acc[k] = a;
                } else {
                    vel[k] = D::zero();
                    acc[k] = D::zero();
                }
            }
            (damp, grav)
        })
        .collect();
    for (damp, grav) in sums {
        world.work.damping += damp;
        world.work.external += grav;
    }
    let t1 = world.time + dt;
    let g = &mut world.grid;
    let fields = world.cracks.as_ref().map(|c| &c.fields);
    for bc in &world.bcs {
        for &node in &bc.nodes {
            for n in entries(node, fields) {
                if g.mass[n] <= tol {
                    continue;
                }
                let v0 = g.momentum[n] * (1.0 / g.mass[n]);
                for a in 0..D::D {
                    if bc.axes[a] {
                        g.velocity[n][a] = bc.value(a, t1);
                        g.accel[n][a] = (g.velocity[n][a] - v0[a]) / dt;
                    }
                }
            }
        }
    }
}

/// Grid entries of `node`: the node and its crack fields' rows (every field obeys the
/// node's boundary conditions).
fn entries(node: u32, fields: Option<&Fields>) -> impl Iterator<Item = usize> {
    let extra = fields.map_or(0..0, |f| f.rows_of(node));
    std::iter::once(node as usize).chain(extra)
}
