//! Crack elements per dimension: a segment of two vertices in 2D, a triangle of three in
//! 3D. [`crate::dim::Dim::Elem`] picks one, so code written for one shape of element
//! does not compile for the other.

use crate::dim::Dim;
use std::fmt::Debug;

/// An axis-aligned box (min, max) in x, y, z (m); a 2D box has z = 0 at both ends.
pub type Bounds = ([f64; 3], [f64; 3]);

/// The box of element `e` of the vertices `v`.
pub fn bounds<D: Dim>(v: &[D::Vec], e: &D::Elem) -> Bounds {
    let mut b = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for &k in e.vertices() {
        for (a, x) in D::to_xyz(v[k as usize]).into_iter().enumerate() {
            b.0[a] = b.0[a].min(x);
            b.1[a] = b.1[a].max(x);
        }
    }
    b
}

/// Whether two boxes meet (touching counts).
pub fn overlap(a: &Bounds, b: &Bounds) -> bool {
    (0..3).all(|k| a.0[k] <= b.1[k] && b.0[k] <= a.1[k])
}

/// Calls `pair(i, j)`, i < j, for every two of `boxes` that meet, found by a sweep along x
/// (boxes sorted by their low x, each tried only against those starting before it ends),
/// so boxes that keep apart cost about their number rather than its square.
pub fn meeting_pairs(boxes: &[Bounds], mut pair: impl FnMut(usize, usize)) {
    let mut by_x: Vec<usize> = (0..boxes.len()).collect();
    by_x.sort_by(|&a, &b| boxes[a].0[0].total_cmp(&boxes[b].0[0]).then(a.cmp(&b)));
    for (k, &a) in by_x.iter().enumerate() {
        for &b in by_x[k + 1..]
            .iter()
            .take_while(|&&b| boxes[b].0[0] <= boxes[a].1[0])
        {
            if overlap(&boxes[a], &boxes[b]) {
                pair(a.min(b), a.max(b));
            }
        }
    }
}

/// A crack element: a fixed number of vertex indices into the crack store.
pub trait Element: Copy + Debug + PartialEq + Send + Sync + 'static {
    /// Vertices per element.
    const VERTICES: usize;
    /// Boundary features per element: end points of a segment, edges of a triangle.
    const FEATURES: usize;
    /// The element's vertex indices.
    fn vertices(&self) -> &[u32];
    /// The element of these vertices (exactly [`Element::VERTICES`] of them).
    fn from_vertices(v: &[u32]) -> Self;
    /// Vertex indices of boundary feature `k` (a segment's end point twice, a triangle's
    /// edge from vertex k to k + 1).
    fn feature(&self, k: usize) -> [u32; 2];
}

/// A 2D crack element: the segment from vertex 0 to vertex 1.
pub type Segment = [u32; 2];

/// A 3D crack element: the triangle of vertices 0, 1, 2, counterclockwise seen from above.
pub type Triangle = [u32; 3];

impl Element for Segment {
    const VERTICES: usize = 2;
    const FEATURES: usize = 2;
    fn vertices(&self) -> &[u32] {
        self
    }
    fn from_vertices(v: &[u32]) -> Self {
        [v[0], v[1]]
    }
    fn feature(&self, k: usize) -> [u32; 2] {
        [self[k], self[k]]
    }
}

impl Element for Triangle {
    const VERTICES: usize = 3;
    const FEATURES: usize = 3;
    fn vertices(&self) -> &[u32] {
        self
    }
    fn from_vertices(v: &[u32]) -> Self {
        [v[0], v[1], v[2]]
    }
    fn feature(&self, k: usize) -> [u32; 2] {
        [self[k], self[(k + 1) % 3]]
    }
}
