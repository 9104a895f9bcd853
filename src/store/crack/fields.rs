//! Per-step scratch of the crack systems: the extra velocity fields `classify` builds, the
//! classification it reuses between steps, the element neighbours it keeps while the
//! topology stands, and what contact measures. None of it is part of a snapshot.

use crate::base::dim::Dim;
use std::ops::Range;

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

/// Which crack elements share a boundary feature (a vertex in 2D, an edge in 3D), as
/// `classify` needs it: it depends on the topology only, so it is rebuilt when the
/// topology's version changes.
#[derive(Clone, Debug, Default)]
pub struct Links {
    /// The topology version the table was built for; None before the first build.
    pub version: Option<u64>,
    /// Per element and feature, the one other element sharing that feature when a
    /// crossing through it is parity-safe, else `u32::MAX` (none).
    pub neighbour: Vec<[u32; 3]>,
}

/// Everything the crack systems rebuild or keep between steps that a snapshot need not
/// hold.
#[derive(Clone, Debug)]
pub struct Scratch<D: Dim> {
    /// Extra velocity fields this step.
    pub fields: Fields,
    /// The last classification, reused while nothing moved far enough to change it.
    pub classified: Classified<D>,
    /// The elements' neighbours, rebuilt when the topology changes.
    pub links: Links,
    /// Each crack's colour (the pair of mask bits its side takes), from `classify`.
    pub colors: Vec<u8>,
    /// Mass-weighted nodal displacements m u of the crack fields' entries this step (for
    /// contact detection).
    pub disp: Displacements<D>,
    /// Momentum changes made by contact on the scattered momenta this step (entry, change),
    /// which the particles' velocity update must also see.
    pub contact_dp: Vec<(usize, D::Vec)>,
    /// The crack and its normal at each field row this step, found by the first contact
    /// pass and reused by the second (the cracks do not move between them); None where
    /// not needed.
    pub contact_normals: Vec<Option<(usize, D::Vec)>>,
}

impl<D: Dim> Scratch<D> {
    /// Crack `c`'s colour (its own index before the first classification).
    pub fn color(&self, c: usize) -> u8 {
        self.colors.get(c).copied().unwrap_or(c as u8)
    }

    /// Drops what refers to particles by index, once they were reordered (particles moved
    /// between ranks): the next classification is a full pass.
    pub fn forget_particles(&mut self) {
        let f = &mut self.fields;
        f.slot.fill(u32::MAX);
        f.coded.clear();
        f.targets.clear();
        self.classified.x0.clear();
    }
}

impl<D: Dim> Default for Scratch<D> {
    fn default() -> Self {
        Scratch {
            fields: Fields::default(),
            classified: Classified::default(),
            links: Links::default(),
            colors: Vec::new(),
            disp: Displacements::default(),
            contact_dp: Vec::new(),
            contact_normals: Vec::new(),
        }
    }
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

/// Sums over the grid entries of the crack fields (a node with extra rows, and each row),
/// in a dense column: one array read finds an entry's sum, where the scatter into them asks
/// for every stencil node of every particle near a crack.
#[derive(Clone, Debug)]
pub struct Displacements<D: Dim> {
    /// Per grid node, the slot of its own field's sum, `u32::MAX` for a node without rows
    /// (sized on first use: scenes without contact keep it empty).
    slot: Vec<u32>,
    /// The nodes whose slots are set, to clear them for the next step's rows.
    marked: Vec<u32>,
    /// The sums: the marked nodes', then one per extra row.
    pub sums: Vec<D::Vec>,
    /// Grid nodes (extra rows start here).
    nodes: usize,
}

impl<D: Dim> Default for Displacements<D> {
    fn default() -> Self {
        Displacements {
            slot: Vec::new(),
            marked: Vec::new(),
            sums: Vec::new(),
            nodes: 0,
        }
    }
}

impl<D: Dim> Displacements<D> {
    /// Zero sums for the entries of this step's `fields`.
    pub fn reset(&mut self, fields: &Fields) {
        for &n in &self.marked {
            self.slot[n as usize] = u32::MAX;
        }
        self.marked.clear();
        self.nodes = fields.nodes;
        if self.slot.len() != fields.nodes {
            self.slot = vec![u32::MAX; fields.nodes];
        }
        for &n in &fields.node {
            if self.slot[n as usize] == u32::MAX {
                self.slot[n as usize] = self.marked.len() as u32;
                self.marked.push(n);
            }
        }
        self.sums.clear();
        self.sums
            .resize(self.marked.len() + fields.node.len(), D::zero());
    }

    /// The slot of grid entry `e` (a node or an extra row), if it is a crack field's.
    #[inline(always)]
    pub fn entry(&self, e: usize) -> Option<usize> {
        if e >= self.nodes {
            Some(self.marked.len() + e - self.nodes)
        } else {
            match self.slot.get(e) {
                Some(&s) if s != u32::MAX => Some(s as usize),
                _ => None,
            }
        }
    }

    /// The sum at grid entry `e` (zero for an entry that is not a crack field's).
    pub fn at(&self, e: usize) -> D::Vec {
        self.entry(e).map_or(D::zero(), |s| self.sums[s])
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

    /// Grid entry of node `n`'s field on `side` (+1 above, -1 below) of the crack of colour
    /// `color` (`Scratch::colors`) near it: the row whose particles crossed the crack from
    /// that side, or else the node's own field.
    pub fn side_entry(&self, n: usize, color: u8, side: i8) -> usize {
        self.side_entry_in(self.rows_of(n as u32), n, color, side)
    }

    /// [`Fields::side_entry`] given `rows`, node `n`'s [`Fields::rows_of`].
    pub fn side_entry_in(&self, mut rows: Range<usize>, n: usize, color: u8, side: i8) -> usize {
        let bit = side_bit(color as usize, side);
        rows.find(|&r| self.mask[r - self.nodes] & bit != 0)
            .unwrap_or(n)
    }

    /// Each node with extra fields and those fields' grid entries, in node order.
    pub fn groups(&self) -> impl Iterator<Item = (u32, Range<usize>)> + '_ {
        let mut k = 0;
        std::iter::from_fn(move || {
            let &n = self.node.get(k)?;
            let start = k;
            while self.node.get(k) == Some(&n) {
                k += 1;
            }
            Some((n, self.nodes + start..self.nodes + k))
        })
    }

    /// The node of grid entry `e`: itself, or the node an extra row belongs to.
    #[inline(always)]
    pub fn node_of(&self, e: usize) -> usize {
        match e.checked_sub(self.nodes) {
            Some(r) if r < self.node.len() => self.node[r] as usize,
            _ => e,
        }
    }

    /// Grid entries of the extra fields of node `n`.
    pub fn rows_of(&self, n: u32) -> Range<usize> {
        let lo = self.node.partition_point(|&m| m < n);
        let hi = self.node.partition_point(|&m| m <= n);
        self.nodes + lo..self.nodes + hi
    }
}

/// Mask bit for a crack of colour `c` crossed with the particle on `side` (+1 above, -1
/// below).
#[inline(always)]
pub fn side_bit(c: usize, side: i8) -> u64 {
    1u64 << (2 * c + usize::from(side < 0))
}
