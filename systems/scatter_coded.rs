//! The scatter of the particles near a crack, each pair into its field's grid entry (Guo &
//! Nairn 2D (2004) Eqs. 3 and 6), after the tiles' colour classes and in particle order.
//!
//! Split across ranks, every rank lists its coded particles' shares and sends those on
//! shared nodes to the peers sharing them; each rank adds its own and the peers' shares in
//! whole-scene particle order, so each entry takes the terms one rank would, in its order.

use crate::base::dim::Dim;
use crate::physics::shape::{ShapeKind, Stencil, StencilCache};
use crate::ranks::domain::Domain;
use crate::store::crack::Fields;
use crate::store::grid::Grid;
use crate::store::particles::Particles;
use crate::with_shape;

/// One coded particle's terms on one grid entry.
#[derive(Clone, Copy, Debug)]
#[repr(C)]
struct Share<D: Dim> {
    /// The particle's index in the whole scene.
    id: u64,
    entry: u64,
    mass: f64,
    momentum: D::Vec,
    /// V sigma . grad S, taken from the entry's force.
    stress: D::Vec,
}

// SAFETY: two u64, an f64 and two vectors of f64 (2 or 3 each): no padding, and every bit
// pattern is valid.
unsafe impl<D: Dim> bytemuck::Zeroable for Share<D> {}
// SAFETY: as above; `D::Vec` is Pod (a DVec2 or DVec3).
unsafe impl<D: Dim> bytemuck::Pod for Share<D> {}

/// Adds the coded particles' mass (`MASS`), momentum (`MOMENTUM`) and internal force
/// (`FORCE`) to their fields' grid entries.
pub(crate) fn run<D: Dim, const MASS: bool, const MOMENTUM: bool, const FORCE: bool>(
    fields: &Fields,
    p: &Particles<D>,
    shape: ShapeKind,
    stencils: &StencilCache,
    domain: &Domain,
    grid: &mut Grid<D>,
) {
    // One rank adds each share as it comes; split, the shares are merged first.
    let split = domain.is_split();
    let stride = grid.geom.stride;
    let mut mine = Vec::new();
    for &i in &fields.coded {
        let i = i as usize;
        let targets = fields.targets_of(i).expect("coded particle");
        let (m, mv, s, vol) = (p.mass[i], p.v[i] * p.mass[i], p.stress[i], p.volume[i]);
        with_shape!(shape, S, N => {
            let st = Stencil::<N>::cached::<D>(S, stencils, i);
            st.for_each_target::<D>(&stride, targets, |n, w, g| {
                let share = Share::<D> {
                    id: p.id.get(i).copied().unwrap_or(i as u64),
                    entry: n as u64,
                    mass: if MASS { m * w } else { 0.0 },
                    momentum: if MOMENTUM { mv * w } else { D::zero() },
                    stress: if FORCE { D::stress_dot(&s, g) * vol } else { D::zero() },
                };
                if split {
                    mine.push(share);
                } else {
                    add::<D, MASS, MOMENTUM, FORCE>(grid, share);
                }
            });
        });
    }
    let node = |s: &Share<D>| fields.node_of(s.entry as usize);
    for share in domain.with_shared(mine, node, |s| s.id) {
        add::<D, MASS, MOMENTUM, FORCE>(grid, share);
    }
}

/// Adds `share` to its grid entry.
#[inline(always)]
fn add<D: Dim, const MASS: bool, const MOMENTUM: bool, const FORCE: bool>(
    grid: &mut Grid<D>,
    s: Share<D>,
) {
    let n = s.entry as usize;
    if MASS {
        grid.mass[n] += s.mass;
    }
    if MOMENTUM {
        grid.momentum[n] += s.momentum;
    }
    if FORCE {
        grid.force[n] -= s.stress;
    }
}
