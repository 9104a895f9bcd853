//! Where each body claims its particles. Bodies fill a shared lattice, so where two overlap
//! each would put its particles on the same points and double the mass there: a point
//! inside several bodies belongs to the first listed (an inclusion listed before the plate
//! around it keeps its own material).

use super::region::Region;
use crate::physics::bodies::Solid;

/// A body's region: its geometry, inside its clip, outside its holes.
pub(super) struct Claim {
    /// The geometry.
    pub geometry: Solid,
    /// The clip region, if any.
    pub clip: Option<Region>,
    /// The holes' centres and radii (m).
    pub holes: Vec<([f64; 3], f64)>,
    /// The geometry's bounding box (m).
    pub bounds: ([f64; 3], [f64; 3]),
}

impl Claim {
    /// Whether `x` (padded to three components, `dims` of them used) is the body's.
    pub fn contains(&self, x: [f64; 3], dims: usize) -> bool {
        self.geometry.contains(x) && self.keeps(x, dims)
    }

    /// Whether the clip and the holes leave `x` to the body (its geometry aside).
    pub fn keeps(&self, x: [f64; 3], dims: usize) -> bool {
        let outside_holes = (self.holes.iter())
            .all(|(c, r)| (0..dims).map(|a| (x[a] - c[a]).powi(2)).sum::<f64>() >= r * r);
        self.clip.as_ref().is_none_or(|c| c.contains(x, dims, 0.0)) && outside_holes
    }

    /// Whether its bounding box meets the box `lo`..`hi` on the first `dims` axes.
    pub fn reaches(&self, (lo, hi): ([f64; 3], [f64; 3]), dims: usize) -> bool {
        (0..dims).all(|a| self.bounds.0[a] <= hi[a] && lo[a] <= self.bounds.1[a])
    }
}
