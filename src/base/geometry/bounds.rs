//! Axis-aligned boxes, and the binning that finds the pairs of them that meet.

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

/// Calls `pair(i, j)`, i < j, once for every two of `boxes` that meet, in no particular
/// order. The boxes are binned on a uniform grid (cells about the mean box size, no more
/// cells than twice the boxes) and only boxes sharing a cell are tried; a pair is reported
/// by the one cell holding the low corner of the two boxes' overlap. Boxes that keep
/// apart cost about their number, whether they spread in a volume or crowd on a surface.
pub fn meeting_pairs<P: Point>(boxes: &[Aabb<P>], mut pair: impl FnMut(usize, usize)) {
    let Some(all) = boxes.iter().copied().reduce(|a, b| a.union(&b)) else {
        return;
    };
    let grid = Bins::new(boxes, &all);
    // Each cell's boxes, as ranges into one list (counted first, then filled).
    let mut start = vec![0usize; grid.count + 1];
    for b in boxes {
        grid.each_cell(b, |c| start[c + 1] += 1);
    }
    for c in 0..grid.count {
        start[c + 1] += start[c];
    }
    let mut next = start.clone();
    let mut members = vec![0u32; start[grid.count]];
    for (i, b) in boxes.iter().enumerate() {
        grid.each_cell(b, |c| {
            members[next[c]] = i as u32;
            next[c] += 1;
        });
    }
    for c in 0..grid.count {
        let here = &members[start[c]..start[c + 1]];
        for (k, &i) in here.iter().enumerate() {
            let a = &boxes[i as usize];
            for &j in &here[k + 1..] {
                let b = &boxes[j as usize];
                if !a.overlaps(b) {
                    continue;
                }
                let mut low = a.lo;
                for d in 0..P::DIM {
                    low[d] = a.lo[d].max(b.lo[d]);
                }
                if grid.cell_of(low) == c {
                    pair(i as usize, j as usize);
                }
            }
        }
    }
}

/// The uniform grid [`meeting_pairs`] bins boxes on.
struct Bins<P> {
    lo: P,
    size: f64,
    cells: [usize; 3],
    count: usize,
}

impl<P: Point> Bins<P> {
    fn new(boxes: &[Aabb<P>], all: &Aabb<P>) -> Self {
        let n = boxes.len() as f64;
        let extent = |b: &Aabb<P>| (0..P::DIM).map(|k| b.hi[k] - b.lo[k]).fold(0.0, f64::max);
        let mean = boxes.iter().map(extent).sum::<f64>() / n;
        let widest = extent(all);
        let cells_at =
            |s: f64| (0..P::DIM).map(move |k| ((all.hi[k] - all.lo[k]) / s).floor() + 1.0);
        let mut size = if mean > 0.0 {
            mean
        } else if widest > 0.0 {
            widest / n
        } else {
            1.0
        };
        while cells_at(size).product::<f64>() > 2.0 * n + 1.0 {
            size *= 1.25;
        }
        let mut cells = [1; 3];
        for (k, c) in cells_at(size).enumerate() {
            cells[k] = c as usize;
        }
        Bins {
            lo: all.lo,
            size,
            cells,
            count: cells.iter().product(),
        }
    }

    /// The cell index of `x` along axis `k`, clamped to the grid.
    fn axis(&self, x: &P, k: usize) -> usize {
        (((x[k] - self.lo[k]) / self.size) as usize).min(self.cells[k] - 1)
    }

    fn cell_of(&self, x: P) -> usize {
        (0..P::DIM).fold(0, |c, k| c * self.cells[k] + self.axis(&x, k))
    }

    /// Calls `f` with every cell the box `b` covers.
    fn each_cell(&self, b: &Aabb<P>, mut f: impl FnMut(usize)) {
        let (mut lo, mut hi) = ([0; 3], [0; 3]);
        for k in 0..P::DIM {
            lo[k] = self.axis(&b.lo, k);
            hi[k] = self.axis(&b.hi, k);
        }
        for i in lo[0]..=hi[0] {
            for j in lo[1]..=hi[1] {
                for l in lo[2]..=hi[2] {
                    let c = if P::DIM == 2 {
                        i * self.cells[1] + j
                    } else {
                        (i * self.cells[1] + j) * self.cells[2] + l
                    };
                    f(c);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec2;

    /// A small deterministic generator (xorshift) for the boxes below.
    fn boxes<P: Point>(n: usize, zero: P, flat: bool) -> Vec<Aabb<P>> {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        (0..n)
            .map(|_| {
                let (mut lo, mut hi) = (zero, zero);
                for k in 0..P::DIM {
                    lo[k] = if flat && k == 0 { 0.5 } else { next() };
                    hi[k] = lo[k] + 0.05 * next() * next();
                }
                Aabb { lo, hi }
            })
            .collect()
    }

    /// Every meeting pair found once, none that keeps apart: against trying all pairs, in
    /// 2D and 3D, with boxes spread in a volume and crowded on one plane (a part's face).
    #[test]
    fn finds_every_meeting_pair_once() {
        fn check<P: Point>(b: &[Aabb<P>]) {
            let mut found = Vec::new();
            meeting_pairs(b, |i, j| found.push((i, j)));
            found.sort_unstable();
            let mut all = Vec::new();
            for i in 0..b.len() {
                for j in i + 1..b.len() {
                    if b[i].overlaps(&b[j]) {
                        all.push((i, j));
                    }
                }
            }
            assert!(!all.is_empty());
            assert_eq!(found, all);
        }
        for flat in [false, true] {
            check(&boxes(600, DVec2::ZERO, flat));
            check(&boxes(600, DVec3::ZERO, flat));
        }
        let point = vec![Aabb::at(DVec3::ONE); 5];
        let mut found = 0;
        meeting_pairs(&point, |_, _| found += 1);
        assert_eq!(found, 10);
    }
}
