//! Node sums of particle terms for the static solve, in the order one process adds them:
//! tile by tile in colour classes, then the particles near a crack in particle order.
//! Split across ranks, each class's shared nodes are settled (`Domain::settle`) and the
//! near-crack terms on shared nodes merged in whole-scene particle order, as the explicit
//! scatter does (`scatter_coded`).

use super::{each_entry, fields};
use crate::base::dim::Dim;
use crate::store::disjoint::Disjoint;
use crate::store::world::World;
use crate::systems::is_free;

/// One near-crack particle's term on one grid entry, for the merge across ranks.
#[derive(Clone, Copy, Debug)]
#[repr(C)]
struct Term<D: Dim> {
    /// The particle's index in the whole scene.
    id: u64,
    entry: u64,
    value: D::Vec,
}

// SAFETY: two u64 and a vector of f64 (2 or 3): no padding, and every bit pattern is valid.
unsafe impl<D: Dim> bytemuck::Zeroable for Term<D> {}
// SAFETY: as above; `D::Vec` is Pod (a DVec2 or DVec3).
unsafe impl<D: Dim> bytemuck::Pod for Term<D> {}

/// Every grid entry's sum of `term(particle, weight, grad S)` over the particles whose
/// stencil reaches it (on their side's entries near a crack).
pub(super) fn entry_sums<D: Dim>(
    world: &World<D>,
    term: impl Fn(usize, f64, D::Vec) -> D::Vec + Sync,
) -> Vec<D::Vec> {
    let mut y = vec![D::zero(); world.grid.mass.len()];
    {
        let y_w = Disjoint::new(&mut y);
        let (tiles, domain, fields) = (&world.tiles, &world.domain, fields(world));
        tiles.for_each_coloured_then(
            |t| {
                let free = tiles.particles(t).iter().map(|&i| i as usize);
                for i in free.filter(|&i| is_free(fields, i)) {
                    each_entry(world, i, |n, w, g| {
                        // SAFETY: tiles of one colour class touch disjoint nodes (tiles.rs),
                        // each tile is handled by one thread, and a particle away from the
                        // cracks reaches only its nodes' own entries.
                        unsafe { y_w.set(n, y_w.get(n) + term(i, w, g)) }
                    });
                }
            },
            domain.waits(),
            |classes, run| domain.settle_pass(classes, &[&y_w], run),
        );
    }
    near_crack_sums(world, &mut y, |i, emit| {
        each_entry(world, i, |n, w, g| emit(n, term(i, w, g)))
    });
    y
}

/// Adds the terms of the particles near a crack to `y`: `terms(i, emit)` calls `emit(entry,
/// value)` for each of particle `i`'s entries. One process adds them in particle order;
/// split, each rank adds its own and its peers' on the nodes it shares, in whole-scene
/// particle order: the same terms in the same order.
pub(super) fn near_crack_sums<D: Dim>(
    world: &World<D>,
    y: &mut [D::Vec],
    mut terms: impl FnMut(usize, &mut dyn FnMut(usize, D::Vec)),
) {
    let Some(fields) = fields(world) else {
        return;
    };
    let domain = &world.domain;
    if !domain.is_split() {
        for &i in &fields.coded {
            terms(i as usize, &mut |n, v| y[n] += v);
        }
        return;
    }
    let ids = &world.particles.id;
    let mut mine = Vec::new();
    for &i in &fields.coded {
        let id = ids[i as usize];
        terms(i as usize, &mut |n, value| {
            mine.push(Term::<D> {
                id,
                entry: n as u64,
                value,
            })
        });
    }
    let node = |t: &Term<D>| fields.node_of(t.entry as usize);
    for t in domain.with_shared(mine, node, |t| t.id) {
        y[t.entry as usize] += t.value;
    }
}

/// Whether each grid entry is reached by at most one particle. Two or more such entries of
/// one particle move in ways its strain does not see (more unknowns than the strain has
/// components): near a crack, where the classification gives a particle fields of its own
/// at nodes next to the front, they are zero-energy modes that only the ghost holds.
pub(super) fn lone_entries<D: Dim>(world: &World<D>) -> Vec<bool> {
    let count = entry_sums(
        world,
        |_, w, _| if w > 0.0 { D::unit_x() } else { D::zero() },
    );
    count.iter().map(|c| D::to_xyz(*c)[0] <= 1.0).collect()
}
