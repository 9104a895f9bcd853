//! Frictionless crack faces that close in a static load step. Where a node carries a field
//! on each side of a crack with frictionless contact, the two fields may not overlap along
//! the crack's normal (Guo & Nairn 3D (2006) Appendix B, Eq. 69, as a constraint): a closed
//! pair moves together along the normal and freely along the face. Which pairs are closed
//! is found by an active set: solve, close the pairs that overlap, open the closed pairs
//! whose faces pull on each other, and solve again until neither changes.

use super::fields;
use crate::base::dim::Dim;
use crate::store::crack::{COLORS, ElementBins, Law};
use crate::store::world::World;
use crate::systems::contact::nearest;

/// A node's pair of fields across one crack with a contact law.
#[derive(Clone, Copy, Debug)]
pub(super) struct Pair<V> {
    /// The crack field's row (the tied entry).
    pub row: usize,
    /// The node's own entry.
    pub own: usize,
    /// Whether the row holds the side above the crack.
    pub row_above: bool,
    /// The crack's unit normal, pointing above.
    pub normal: V,
}

impl<V> Pair<V> {
    /// The entries above and below the crack.
    pub fn above_below(&self) -> (usize, usize) {
        if self.row_above {
            (self.row, self.own)
        } else {
            (self.own, self.row)
        }
    }
}

/// Every pair of fields across a crack with frictionless contact whose entries both carry
/// mass, in row order (a row behind two cracks at once has no single normal and is left
/// open, as in the explicit solver).
pub(super) fn pairs<D: Dim>(world: &World<D>) -> Vec<Pair<D::Vec>> {
    let (Some(cracks), Some(f)) = (world.cracks.as_ref(), fields(world)) else {
        return Vec::new();
    };
    let topo = &cracks.topology;
    let mut acts = [false; COLORS];
    for (c, crack) in topo.cracks().iter().enumerate() {
        acts[cracks.scratch.color(c) as usize] |= crack.contact.law == Law::Frictionless;
    }
    let g = &world.grid;
    let tol = world.settings.mass_tol;
    let h = D::to_xyz(g.geom.h);
    let cell = std::array::from_fn(|k| if k < D::D { h[k] } else { 1.0 });
    let mut bins: Vec<Option<ElementBins>> = Vec::new();
    bins.resize_with(COLORS, || None);
    let mut out = Vec::new();
    for (r, &mask) in f.mask.iter().enumerate() {
        if mask.count_ones() != 1 {
            continue;
        }
        let bit = mask.trailing_zeros() as usize;
        let (color, row_above) = (bit / 2, bit.is_multiple_of(2));
        let (own, row) = (f.node[r] as usize, f.nodes + r);
        if !acts[color] || g.mass[own] <= tol || g.mass[row] <= tol {
            continue;
        }
        let at = g.geom.node_position(own);
        let Some((c, normal)) = nearest::<D>(&mut bins, cracks, cell, color as u8, at) else {
            continue;
        };
        if topo.cracks()[c].contact.law != Law::Frictionless {
            continue;
        }
        out.push(Pair {
            row,
            own,
            row_above,
            normal,
        });
    }
    out
}

/// What an active-set round changed: pairs closed (they overlapped) and opened (they
/// pulled).
#[derive(Default)]
pub(super) struct Changes {
    pub closed: usize,
    pub opened: usize,
}

/// Updates `closed` (one flag per pair) from the solution `u` (every entry's displacement)
/// and `ku_less_f`, K u - f_ext per entry without ties folded: a pair whose fields overlap
/// along the normal by more than `gap_tol` closes; a closed pair whose above field the
/// other pulls (the constraint's force on it, K u - f_ext, the rest of its equilibrium,
/// against the normal beyond `force_tol`) opens. Counts the changes of the pairs
/// `counted` takes.
pub(super) fn update<D: Dim>(
    pairs: &[Pair<D::Vec>],
    closed: &mut [bool],
    u: &[D::Vec],
    ku_less_f: &[D::Vec],
    (gap_tol, force_tol): (f64, f64),
    counted: impl Fn(&Pair<D::Vec>) -> bool,
) -> Changes {
    let mut changes = Changes::default();
    for (p, c) in pairs.iter().zip(closed.iter_mut()) {
        let (a, b) = p.above_below();
        let count = counted(p) as usize;
        if *c {
            let push = D::dot(ku_less_f[a], p.normal);
            if push < -force_tol {
                *c = false;
                changes.opened += count;
            }
        } else if D::dot(u[a] - u[b], p.normal) < -gap_tol {
            *c = true;
            changes.closed += count;
        }
    }
    changes
}
