//! Axis-aligned boxes, and the sweep that finds the pairs of them that meet.

use super::Point;
use glam::DVec3;

/// An axis-aligned box, inclusive, in the space of its point type (2D or 3D).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb<P> {
    /// Lower corner (m).
    pub lo: P,
    /// Upper corner (m).
    pub hi: P,
}

impl<P: Point> Aabb<P> {
    /// The box of the single point `x`.
    pub fn at(x: P) -> Self {
        Aabb { lo: x, hi: x }
    }

    /// The box spanned by two points.
    pub fn span(a: P, b: P) -> Self {
        let (mut lo, mut hi) = (a, a);
        for k in 0..P::DIM {
            lo[k] = a[k].min(b[k]);
            hi[k] = a[k].max(b[k]);
        }
        Aabb { lo, hi }
    }

    /// The smallest box holding both.
    pub fn union(&self, other: &Self) -> Self {
        Aabb {
            lo: Aabb::span(self.lo, other.lo).lo,
            hi: Aabb::span(self.hi, other.hi).hi,
        }
    }

    /// The box widened by `by` (m) on every side.
    pub fn grown(&self, by: f64) -> Self {
        let (mut lo, mut hi) = (self.lo, self.hi);
        for k in 0..P::DIM {
            lo[k] -= by;
            hi[k] += by;
        }
        Aabb { lo, hi }
    }

    /// The box in three dimensions (z = 0 at both ends in 2D).
    pub fn padded(&self) -> Aabb<DVec3> {
        Aabb {
            lo: DVec3::from(self.lo.xyz()),
            hi: DVec3::from(self.hi.xyz()),
        }
    }

    /// Whether two boxes meet (touching counts).
    pub fn overlaps(&self, other: &Self) -> bool {
        (0..P::DIM).all(|k| self.lo[k] <= other.hi[k] && other.lo[k] <= self.hi[k])
    }

    /// Squared distance between two boxes (zero where they meet): at most that between any
    /// point of one and any point of the other.
    pub fn gap_sq(&self, other: &Self) -> f64 {
        (0..P::DIM)
            .map(|k| {
                (self.lo[k] - other.hi[k])
                    .max(other.lo[k] - self.hi[k])
                    .max(0.0)
                    .powi(2)
            })
            .sum()
    }
}

/// Calls `pair(i, j)`, i < j, for every two of `boxes` that meet, found by a sweep along x
/// (boxes sorted by their low x, each tried only against those starting before it ends),
/// so boxes that keep apart cost about their number rather than its square.
pub fn meeting_pairs<P: Point>(boxes: &[Aabb<P>], mut pair: impl FnMut(usize, usize)) {
    let mut by_x: Vec<usize> = (0..boxes.len()).collect();
    by_x.sort_by(|&a, &b| boxes[a].lo[0].total_cmp(&boxes[b].lo[0]).then(a.cmp(&b)));
    for (k, &a) in by_x.iter().enumerate() {
        for &b in by_x[k + 1..]
            .iter()
            .take_while(|&&b| boxes[b].lo[0] <= boxes[a].hi[0])
        {
            if boxes[a].overlaps(&boxes[b]) {
                pair(a.min(b), a.max(b));
            }
        }
    }
}
