//! Explicit cracks (CRAMP: Nairn 2003; Guo & Nairn 2D (2004) section 2.1): massless crack
//! vertices joined into polylines, with top and bottom surface positions for the crack
//! opening; and the table of extra velocity fields on the nodes that see a crack.

use crate::dim::Dim;
use std::ops::Range;

/// Most cracks a scene may hold (each takes two bits of a node field's side mask).
pub const MAX_CRACKS: usize = 32;

/// One crack: a polyline over a range of the store's vertices.
#[derive(Clone, Debug)]
pub struct Crack {
    /// Name from the scenario.
    pub name: String,
    /// Its vertices, `first..first + count` in the store.
    pub vertices: Range<usize>,
    /// Whether the first and the last vertex are crack tips.
    pub tips: [bool; 2],
}

/// The crack store: vertices (struct of arrays), elements and cracks, and the field table.
#[derive(Clone, Debug)]
pub struct Cracks<D: Dim> {
    /// Crack-plane position of each vertex (m); moves with the centre-of-mass field.
    pub x: Vec<D::Vec>,
    /// Top-surface position (m); moves with the field above the crack.
    pub top: Vec<D::Vec>,
    /// Bottom-surface position (m); moves with the field below the crack.
    pub bottom: Vec<D::Vec>,
    /// Elements as vertex indices (2D segments use the first two).
    pub elems: Vec<[u32; 3]>,
    /// Crack of each element.
    pub elem_crack: Vec<u16>,
    /// The cracks.
    pub cracks: Vec<Crack>,
    /// Extra velocity fields this step.
    pub fields: Fields,
}

/// Which grid entry each particle-node pair of a particle near a crack uses, and the extra
/// field rows appended to the grid columns (Guo & Nairn 2D (2004) Eqs. 3-6 per field).
///
/// A particle whose stencil line to some node crosses a crack is *coded*: each of its
/// stencil nodes maps to a grid entry, the node itself (field 0, the node's own side) or an
/// extra row `nodes + r` for the node's field with crack-side mask `mask[r]`. Bits `2c` and
/// `2c + 1` of a mask say that the line crossed crack `c` with the particle above or below
/// it. Most particles are not coded and use their stencil's nodes directly.
#[derive(Clone, Debug, Default)]
pub struct Fields {
    /// Stencil nodes per particle.
    pub per: usize,
    /// Per particle: its index in `coded`, or `u32::MAX` if it sees no crack.
    pub slot: Vec<u32>,
    /// Coded particles in increasing index order.
    pub coded: Vec<u32>,
    /// Grid entry of every stencil node of each coded particle (`per` each).
    pub targets: Vec<u32>,
    /// Node of each extra row, in increasing order.
    pub node: Vec<u32>,
    /// Crack-side mask of each extra row.
    pub mask: Vec<u64>,
    /// Grid nodes (extra rows start here).
    pub nodes: usize,
}

impl<D: Dim> Default for Cracks<D> {
    fn default() -> Self {
        Cracks {
            x: Vec::new(),
            top: Vec::new(),
            bottom: Vec::new(),
            elems: Vec::new(),
            elem_crack: Vec::new(),
            cracks: Vec::new(),
            fields: Fields::default(),
        }
    }
}

impl Fields {
    /// Grid entries of coded particle `p`'s stencil nodes, if it is coded.
    #[inline(always)]
    pub fn targets_of(&self, p: usize) -> Option<&[u32]> {
        match self.slot.get(p) {
            Some(&s) if s != u32::MAX => {
                let s = s as usize * self.per;
                Some(&self.targets[s..s + self.per])
            }
            _ => None,
        }
    }

    /// Grid entry of node `n`'s field on `side` (+1 above, -1 below) of crack `c`: the row
    /// whose particles crossed the crack from that side, or else the node's own field.
    pub fn side_entry(&self, n: usize, c: usize, side: i8) -> usize {
        let bit = side_bit(c, side);
        self.rows_of(n as u32)
            .find(|&r| self.mask[r - self.nodes] & bit != 0)
            .unwrap_or(n)
    }

    /// Grid entries of the extra fields of node `n`.
    pub fn rows_of(&self, n: u32) -> Range<usize> {
        let lo = self.node.partition_point(|&m| m < n);
        let hi = self.node.partition_point(|&m| m <= n);
        self.nodes + lo..self.nodes + hi
    }
}

/// Mask bit for crack `c` crossed with the particle on `side` (+1 above, -1 below).
#[inline(always)]
pub fn side_bit(c: usize, side: i8) -> u64 {
    1u64 << (2 * c + usize::from(side < 0))
}
