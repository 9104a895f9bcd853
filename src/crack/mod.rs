//! Explicit cracks (CRAMP: Nairn 2003; Guo & Nairn 2D (2004) section 2.1): massless crack
//! vertices joined into polylines, with top and bottom surface positions for the crack
//! opening; and the table of extra velocity fields on the nodes that see a crack.

use crate::dim::Dim;
use std::collections::HashMap;
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
    /// How the crack faces interact where they touch.
    pub contact: Contact,
}

/// Contact law on a crack's faces (Guo & Nairn 3D (2006) Appendix B).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Law {
    /// Faces pass through each other (open crack).
    None,
    /// Touching faces move together (Eqs. 71-72).
    Stick,
    /// Touching faces cannot interpenetrate but slide freely.
    Frictionless,
    /// Coulomb friction with this coefficient: stick while |f_t| <= mu |f_n|, else slide
    /// with |f_t| = mu |f_n|.
    Coulomb(f64),
}

/// A crack's contact settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Contact {
    /// The law.
    pub law: Law,
    /// Also require the faces to approach (Eq. 70) before the displacement test (Eq. 69).
    pub approach_check: bool,
}

impl Law {
    /// The momentum change of the field above the crack (the field below gets its
    /// negative, so momentum is conserved exactly) for masses `ma`, `mb`, velocities `va`,
    /// `vb` and unit normal `n` pointing into the material above. Stick moves both to their
    /// centre-of-mass velocity (Eqs. 71-72 times dt); frictionless keeps only the normal
    /// part; Coulomb caps the tangential part at mu times the normal one. Faces that are
    /// separating get no normal push (no tension across a contact) unless they stick.
    pub fn momentum_change<D: Dim>(
        self,
        ma: f64,
        va: D::Vec,
        mb: f64,
        vb: D::Vec,
        n: D::Vec,
    ) -> D::Vec {
        let vcm = (va * ma + vb * mb) * (1.0 / (ma + mb));
        let stick = (vcm - va) * ma;
        let dn = D::dot(stick, n);
        let normal = n * dn;
        let tangential = stick - normal;
        match self {
            Law::None => D::zero(),
            Law::Stick => stick,
            _ if dn <= 0.0 => D::zero(),
            Law::Frictionless => normal,
            Law::Coulomb(mu) => {
                let t = D::dot(tangential, tangential).sqrt();
                if t <= mu * dn {
                    stick
                } else {
                    normal + tangential * (mu * dn / t)
                }
            }
        }
    }
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
    /// The last classification, reused while nothing moved far enough to change it.
    pub classified: Classified<D>,
    /// The elements' neighbours, rebuilt by `classify` when the elements change.
    pub links: Links,
    /// Mass-weighted nodal displacements m u of the crack fields' entries this step (for
    /// contact detection).
    pub disp: HashMap<usize, D::Vec>,
    /// Momentum changes made by contact on the scattered momenta this step (entry, change),
    /// which the particles' velocity update must also see.
    pub contact_dp: Vec<(usize, D::Vec)>,
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
    /// Scratch of `classify`, per grid node: the first extra row found there while the
    /// rows are collected (`u32::MAX` outside that).
    pub head: Vec<u32>,
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
            classified: Classified::default(),
            links: Links::default(),
            disp: HashMap::new(),
            contact_dp: Vec::new(),
        }
    }
}

/// What `classify` last found for each particle near a crack, kept so that a step can
/// reuse it while neither the particle nor the crack has moved far enough to change a
/// crossing (a skin, as in Verlet neighbour lists). Reuse gives exactly what a fresh
/// classification would, so the record is not part of a snapshot.
#[derive(Clone, Debug)]
pub struct Classified<D: Dim> {
    /// Classify every particle afresh every step (for checks; off by default).
    pub every_step: bool,
    /// Crack-plane vertex positions at the last full pass (m); empty before the first.
    pub x0: Vec<D::Vec>,
    /// Bound on any particle's displacement since the last full pass (m): `g2p` adds each
    /// step's largest.
    pub drift: f64,
    /// Particles within reach of a crack at the last full pass, in increasing order.
    pub watched: Vec<u32>,
    /// First stencil node of each watched particle when it was classified.
    pub first: Vec<u32>,
    /// A watched particle's record stands while `drift` plus the cracks' movement since the
    /// full pass stays below this (m).
    pub budget: Vec<f64>,
    /// Whether some line from the watched particle to a stencil node crosses a crack (kept
    /// so a step scans only those particles' masks).
    pub crosses: Vec<bool>,
    /// Crack-side mask of every stencil node of each watched particle (`Fields::per` each,
    /// zero weights included).
    pub masks: Vec<u64>,
}

/// Which crack elements share a boundary feature (a vertex in 2D), as `classify` needs it:
/// it depends on the connectivity only, so it is kept from step to step (not part of a
/// snapshot).
#[derive(Clone, Debug, Default)]
pub struct Links {
    /// The elements the table was built for.
    pub elems: Vec<[u32; 3]>,
    /// Per element and feature, the one other element sharing that feature when a
    /// crossing through it is parity-safe, else `u32::MAX` (none).
    pub neighbour: Vec<[u32; 3]>,
}

impl<D: Dim> Default for Classified<D> {
    fn default() -> Self {
        Classified {
            every_step: false,
            x0: Vec::new(),
            drift: 0.0,
            watched: Vec::new(),
            first: Vec::new(),
            budget: Vec::new(),
            crosses: Vec::new(),
            masks: Vec::new(),
        }
    }
}

impl Fields {
    /// Whether particle `p` sees a crack (and so is handled field by field).
    #[inline(always)]
    pub fn is_coded(&self, p: usize) -> bool {
        self.slot[p] != u32::MAX
    }

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
        self.side_entry_in(self.rows_of(n as u32), n, c, side)
    }

    /// [`Fields::side_entry`] given `rows`, node `n`'s [`Fields::rows_of`].
    pub fn side_entry_in(&self, mut rows: Range<usize>, n: usize, c: usize, side: i8) -> usize {
        let bit = side_bit(c, side);
        rows.find(|&r| self.mask[r - self.nodes] & bit != 0)
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
