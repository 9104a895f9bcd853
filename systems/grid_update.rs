//! `grid_update`: nodal velocities and accelerations from momenta and forces, damping
//! (Guo & Nairn 2D (2004) Eq. 5), gravity and prescribed velocities; image nodes take their
//! sources' values ([`mirror`]).

use crate::base::dim::Dim;
use crate::base::exact_sum::ExactSum;
use crate::ranks::domain::Domain;
use crate::store::crack::Fields;
use crate::store::grid::Grid;
use crate::store::world::{CHUNK, World};
use crate::systems::mirror;
use rayon::prelude::*;

/// Overwrites prescribed components of the extrapolated momenta so that p/m equals the
/// prescribed velocity at the start of the step, or at its end when `end` (after a remap).
/// This sets what the grid computes with, not the particles' velocities, so it does no
/// work; the support's reaction is booked in [`run`].
pub fn momentum_bc<D: Dim>(world: &mut World<D>, end: bool) {
    let t = world.time + if end { world.settings.dt } else { 0.0 };
    let g = &mut world.grid;
    let fields = world.cracks.as_ref().map(|c| &c.scratch.fields);
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
/// prescribed components are set to their end-of-step values with the matching acceleration,
/// and the support's reaction is kept per node and its work booked as external work.
pub fn run<D: Dim>(world: &mut World<D>) {
    let s = &world.settings;
    let (dt, alpha, gravity, tol) = (s.dt, s.damping, s.gravity, s.mass_tol);
    let Grid {
        mass,
        momentum,
        force,
        velocity,
        accel,
        geom,
        ..
    } = &mut world.grid;
    let (mass, momentum, force) = (&*mass, &*momentum, &*force);
    let (damped, weighed) = (alpha != 0.0, D::dot(gravity, gravity) != 0.0);
    let fields = world.cracks.as_ref().map(|c| &c.scratch.fields);
    // Split across ranks, each entry's work is booked by the rank that owns its node.
    let domain = &world.domain;
    let books = |n: usize| domain.owns_node(fields.map_or(n, |f| f.node_of(n)));
    let mut work = [ExactSum::new(), ExactSum::new()];
    for span in domain.spans(velocity.len(), geom.node_count()) {
        let first = span.start;
        let (velocity, accel) = (&mut velocity[span.clone()], &mut accel[span]);
        let [damp, grav] = (velocity.par_chunks_mut(CHUNK), accel.par_chunks_mut(CHUNK))
            .into_par_iter()
            .enumerate()
            .map(|(c, (vel, acc))| {
                let [mut damp, mut grav] = [ExactSum::new(), ExactSum::new()];
                for k in 0..vel.len() {
                    let n = first + c * CHUNK + k;
                    let m = mass[n];
                    if m > tol {
                        let v0 = momentum[n] * (1.0 / m);
                        let f = force[n] - momentum[n] * alpha + gravity * m;
                        let a = f * (1.0 / m);
                        let v1 = v0 + a * dt;
                        let vmid = (v0 + v1) * 0.5;
                        // Zero terms are skipped: an undamped, weightless scene pays nothing.
                        if damped && books(n) {
                            damp.add(alpha * D::dot(momentum[n], vmid) * dt);
                        }
                        if weighed && books(n) {
                            grav.add(m * D::dot(gravity, vmid) * dt);
                        }
                        vel[k] = v1;
                        acc[k] = a;
                    } else {
                        vel[k] = D::zero();
                        acc[k] = D::zero();
                    }
                }
                [damp, grav]
            })
            .reduce(Default::default, |[mut d, mut g], [d2, g2]| {
                d.merge(&d2);
                g.merge(&g2);
                [d, g]
            });
        work[0].merge(&damp);
        work[1].merge(&grav);
    }
    let [mut damp, mut grav] = work;
    if let Some(f) = fields {
        let work = [&mut damp, &mut grav];
        merge_slivers(&mut world.grid, work, f, &world.settings, domain);
    }
    let t1 = world.time + dt;
    let g = &mut world.grid;
    for bc in &mut world.bcs {
        for k in 0..bc.nodes.len() {
            let (node, mut reaction) = (bc.nodes[k], D::zero());
            for n in entries(node, fields) {
                let m = g.mass[n];
                if m <= tol {
                    continue;
                }
                // Every rank holding the node sets it; its owner books the reaction.
                let books = domain.owns_node(node as usize);
                let v0 = g.momentum[n] * (1.0 / m);
                for a in 0..D::D {
                    if bc.axes[a] {
                        // The support's reaction m (a_bc - a_free) works over the step at
                        // the mean of the start and prescribed end velocities.
                        let v1 = bc.value(a, t1);
                        let a_bc = (v1 - v0[a]) / dt;
                        let r = m * (a_bc - g.accel[n][a]);
                        if books {
                            reaction[a] += r;
                            grav.add(r * 0.5 * (v0[a] + v1) * dt);
                        }
                        g.velocity[n][a] = v1;
                        g.accel[n][a] = a_bc;
                    }
                }
            }
            bc.reaction[k] = reaction;
        }
    }
    if !g.mirrors.is_empty() {
        mirror::reflect_velocity(g, true);
        let m = &g.mirrors;
        mirror::credit_reactions(m, &mut world.bcs, |k| {
            let (share, node) = (&m.shares[k], m.images[k].node as usize);
            let f = share.force - share.momentum * alpha + gravity * share.mass;
            g.accel[node] * share.mass - f
        });
    }
    let mut sums = [damp, grav];
    domain.sum(&mut sums);
    world.work.damping += sums[0].value();
    world.work.external += sums[1].value();
}

/// A node's crack field that holds a sliver of mass (at most `sliver_mass`: a particle
/// whose line to the node crosses the crack while the node is at the edge of its support)
/// would get the acceleration f/m of a tiny mass, which explicit integration cannot follow:
/// the particle's velocity grew by metres per second while the damping held everything
/// else at rest. Such fields move with the node's heaviest field instead: their masses,
/// momenta and forces are summed with it and all get the sum's velocity and acceleration,
/// which conserves momentum; the sliver's force then acts across the crack, a thousandth
/// of a particle's share at most.
fn merge_slivers<D: Dim>(
    grid: &mut Grid<D>,
    [damping, external]: [&mut ExactSum; 2],
    fields: &Fields,
    settings: &crate::store::world::Settings<D>,
    domain: &Domain,
) {
    let (dt, alpha, gravity, tol) = (
        settings.dt,
        settings.damping,
        settings.gravity,
        settings.mass_tol,
    );
    let sliver = settings.sliver_mass;
    for (node, rows) in fields.groups() {
        let group = || std::iter::once(node as usize).chain(rows.clone());
        let light = |n: usize| grid.mass[n] > tol && grid.mass[n] <= sliver;
        if !group().any(light) {
            continue;
        }
        // Split across ranks, the node's owner books the work.
        let books = domain.owns_node(node as usize);
        let heavy = group()
            .max_by(|&a, &b| grid.mass[a].total_cmp(&grid.mass[b]))
            .expect("a node's own entry");
        let (mut m, mut p, mut f) = (0.0, D::zero(), D::zero());
        for n in group().filter(|&n| n == heavy || light(n)) {
            // Take back the damping and gravity work booked for the entry alone.
            let (m0, p0) = (grid.mass[n], grid.momentum[n]);
            let vmid = p0 * (1.0 / m0) + grid.accel[n] * (0.5 * dt);
            if books {
                damping.add(-alpha * D::dot(p0, vmid) * dt);
                external.add(-m0 * D::dot(gravity, vmid) * dt);
            }
            m += m0;
            p += p0;
            f += grid.force[n];
        }
        let a = (f - p * alpha + gravity * m) * (1.0 / m);
        let v1 = p * (1.0 / m) + a * dt;
        let vmid = p * (1.0 / m) + a * (0.5 * dt);
        if books {
            damping.add(alpha * D::dot(p, vmid) * dt);
            external.add(m * D::dot(gravity, vmid) * dt);
        }
        for n in group().filter(|&n| n == heavy || light(n)) {
            grid.velocity[n] = v1;
            grid.accel[n] = a;
        }
    }
}

/// Grid entries of `node`: the node and its crack fields' rows (every field obeys the
/// node's boundary conditions).
fn entries(node: u32, fields: Option<&Fields>) -> impl Iterator<Item = usize> {
    let extra = fields.map_or(0..0, |f| f.rows_of(node));
    std::iter::once(node as usize).chain(extra)
}
