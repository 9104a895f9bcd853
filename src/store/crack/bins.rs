//! Crack elements binned on a uniform lattice, for the element nearest a point: a search
//! over rings of bins around it instead of a scan of every element (contact asks this of
//! every node with a crack field, twice a step).

use crate::base::dim::Dim;
use crate::base::geometry::{Aabb, Element};
use glam::DVec3;

/// One crack's elements on a lattice of bins (compressed rows: the elements of bin `b` are
/// `items[start[b]..start[b + 1]]`, in increasing element order).
pub struct ElementBins {
    origin: [f64; 3],
    size: [f64; 3],
    counts: [usize; 3],
    start: Vec<u32>,
    items: Vec<u32>,
    /// Each element's box (indexed by element; meaningful for the binned ones), a cheap
    /// lower bound on its distance that spares most exact ones.
    boxes: Vec<Aabb<DVec3>>,
}

impl ElementBins {
    /// Bins of edge `size` (m per axis; the grid cell) over the elements `elems[e]` for
    /// which `keep(e)` holds, with a margin of `margin` bins around them.
    pub fn new<D: Dim>(
        x: &[D::Vec],
        elems: &[D::Elem],
        keep: impl Fn(usize) -> bool,
        size: [f64; 3],
        margin: usize,
    ) -> Self {
        let dims = D::D;
        let boxes: Vec<(usize, Aabb<DVec3>)> = (elems.iter().enumerate())
            .filter(|&(e, _)| keep(e))
            .map(|(e, el)| (e, el.bounds(x).padded()))
            .collect();
        let (mut origin, mut counts) = ([0.0; 3], [1usize; 3]);
        if !boxes.is_empty() {
            for k in 0..dims {
                let lo = boxes
                    .iter()
                    .map(|b| b.1.lo[k])
                    .fold(f64::INFINITY, f64::min);
                let hi = boxes
                    .iter()
                    .map(|b| b.1.hi[k])
                    .fold(f64::NEG_INFINITY, f64::max);
                origin[k] = lo - margin as f64 * size[k];
                counts[k] = ((hi - origin[k]) / size[k]) as usize + margin + 1;
            }
        }
        let mut bins = ElementBins {
            origin,
            size,
            counts,
            start: Vec::new(),
            items: Vec::new(),
            boxes: vec![Aabb::at(DVec3::ZERO); elems.len()],
        };
        // Each element goes into every bin its box meets, the box widened by a millionth of
        // a bin so that rounding in the bin index never leaves an element out of one.
        let range = |b: &ElementBins, bx: &Aabb<DVec3>| {
            let mut r = [(0usize, 0usize); 3];
            for (k, r) in r.iter_mut().enumerate().take(dims) {
                let slack = 1e-6 * b.size[k];
                *r = (b.index(k, bx.lo[k] - slack), b.index(k, bx.hi[k] + slack));
            }
            r
        };
        let total = counts.iter().product::<usize>();
        let mut count = vec![0u32; total + 1];
        for (_, bx) in &boxes {
            bins.for_each_bin(range(&bins, bx), |b| count[b + 1] += 1);
        }
        for b in 0..total {
            count[b + 1] += count[b];
        }
        let mut fill = count.clone();
        let mut items = vec![0u32; count[total] as usize];
        for (e, bx) in &boxes {
            bins.for_each_bin(range(&bins, bx), |b| {
                items[fill[b] as usize] = *e as u32;
                fill[b] += 1;
            });
        }
        for (e, bx) in boxes {
            bins.boxes[e] = bx;
        }
        bins.start = count;
        bins.items = items;
        bins
    }

    /// The bin index along axis `k` of coordinate `c`, clamped to the lattice.
    fn index(&self, k: usize, c: f64) -> usize {
        let i = ((c - self.origin[k]) / self.size[k]).floor();
        (i.max(0.0) as usize).min(self.counts[k] - 1)
    }

    /// Calls `f` with every bin of the inclusive index ranges `r` (unused axes are 0..=0).
    fn for_each_bin(&self, r: [(usize, usize); 3], mut f: impl FnMut(usize)) {
        for k in r[2].0..=r[2].1 {
            for j in r[1].0..=r[1].1 {
                for i in r[0].0..=r[0].1 {
                    f(i + self.counts[0] * (j + self.counts[1] * k));
                }
            }
        }
    }

    /// Whether a binned element lies within `tol` of `x` (`tol` under a millionth of a bin,
    /// so such an element is binned where `x` is).
    pub fn touches<D: Dim>(
        &self,
        x: D::Vec,
        verts: &[D::Vec],
        elems: &[D::Elem],
        tol: f64,
    ) -> bool {
        let p = D::to_xyz(x);
        let dims = D::D;
        if (0..dims).any(|k| {
            let c = (p[k] - self.origin[k]) / self.size[k];
            !(c >= 0.0 && c < self.counts[k] as f64)
        }) || self.items.is_empty()
        {
            return false;
        }
        let mut r = [(0usize, 0usize); 3];
        for (k, r) in r.iter_mut().enumerate().take(dims) {
            let i = self.index(k, p[k]);
            *r = (i, i);
        }
        let mut near = false;
        self.for_each_bin(r, |b| {
            let (s, t) = (self.start[b] as usize, self.start[b + 1] as usize);
            near |= self.items[s..t]
                .iter()
                .any(|&e| elems[e as usize].distance_sq(x, verts) <= tol * tol);
        });
        near
    }

    /// The binned element nearest to `x` (by [`Dim::elem_distance_sq`]), the lowest index
    /// among equally near ones, as a scan of all of them in order would find; None without
    /// elements.
    pub fn nearest<D: Dim>(&self, x: D::Vec, verts: &[D::Vec], elems: &[D::Elem]) -> Option<u32> {
        if self.items.is_empty() {
            return None;
        }
        let dims = D::D;
        let p = D::to_xyz(x);
        let inside = (0..dims).all(|k| {
            let c = (p[k] - self.origin[k]) / self.size[k];
            c >= 0.0 && c < self.counts[k] as f64
        });
        let mut best: Option<(f64, u32)> = None;
        let consider = |best: &mut Option<(f64, u32)>, e: u32| {
            if let Some((bd, _)) = *best {
                let bx = &self.boxes[e as usize];
                let gap = (0..dims)
                    .map(|k| (bx.lo[k] - p[k]).max(p[k] - bx.hi[k]).max(0.0).powi(2))
                    .sum::<f64>();
                // Strictly farther than the best even at its box: not a candidate.
                if gap > bd * (1.0 + 1e-12) {
                    return;
                }
            }
            let d = elems[e as usize].distance_sq(x, verts);
            if best.is_none_or(|(bd, be)| d < bd || (d == bd && e < be)) {
                *best = Some((d, e));
            }
        };
        if !inside {
            // Off the lattice (farther than its margin from every element): every element.
            self.items.iter().for_each(|&e| consider(&mut best, e));
            return best.map(|b| b.1);
        }
        let centre: [usize; 3] = std::array::from_fn(|k| self.index(k, p[k]));
        let widest = (0..dims).map(|k| self.counts[k]).max().unwrap_or(1);
        for r in 0..widest {
            let mut range = [(0usize, 0usize); 3];
            for k in 0..dims {
                range[k] = (
                    centre[k].saturating_sub(r),
                    (centre[k] + r).min(self.counts[k] - 1),
                );
            }
            // The ring: the bins of the block at Chebyshev distance exactly r.
            self.for_each_bin(range, |b| {
                let ijk = [
                    b % self.counts[0],
                    b / self.counts[0] % self.counts[1],
                    b / (self.counts[0] * self.counts[1]),
                ];
                if (0..dims).any(|k| ijk[k].abs_diff(centre[k]) == r) {
                    let (s, t) = (self.start[b] as usize, self.start[b + 1] as usize);
                    self.items[s..t]
                        .iter()
                        .for_each(|&e| consider(&mut best, e));
                }
            });
            // An element outside the block is at least as far as the block's nearest face
            // (a face on the lattice's edge has nothing beyond it).
            let mut clear = f64::INFINITY;
            for k in 0..dims {
                if range[k].0 > 0 {
                    let face = self.origin[k] + range[k].0 as f64 * self.size[k];
                    clear = clear.min(p[k] - face);
                }
                if range[k].1 + 1 < self.counts[k] {
                    let face = self.origin[k] + (range[k].1 + 1) as f64 * self.size[k];
                    clear = clear.min(face - p[k]);
                }
            }
            if let Some((d, _)) = best
                && d < clear * clear
            {
                break;
            }
            if clear == f64::INFINITY {
                break;
            }
        }
        best.map(|b| b.1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::base::dim::{D2, D3};
    use glam::{DVec2, DVec3};

    /// Brute force: the first of the nearest elements in element order.
    fn scan<D: Dim>(x: D::Vec, verts: &[D::Vec], elems: &[D::Elem]) -> Option<u32> {
        let mut best: Option<(f64, u32)> = None;
        for (e, &el) in elems.iter().enumerate() {
            let d = el.distance_sq(x, verts);
            if best.is_none_or(|b| d < b.0) {
                best = Some((d, e as u32));
            }
        }
        best.map(|b| b.1)
    }

    /// A deterministic sequence in [0, 1).
    fn lcg(s: &mut u64) -> f64 {
        *s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (*s >> 11) as f64 / (1u64 << 53) as f64
    }

    /// The ring search finds the same element as a scan of all of them, for points on,
    /// near and far from a slanted triangulated square and a zig-zag polyline, including
    /// grid points equidistant from several elements.
    #[test]
    fn nearest_matches_a_full_scan() {
        let n = 12;
        let mut verts = Vec::new();
        for j in 0..=n {
            for i in 0..=n {
                let (u, v) = (i as f64 / n as f64, j as f64 / n as f64);
                verts.push(DVec3::new(
                    0.3 + 0.4 * u,
                    0.2 + 0.5 * u + 0.1 * v,
                    0.1 + 0.7 * v,
                ));
            }
        }
        let mut tris = Vec::new();
        for j in 0..n {
            for i in 0..n {
                let a = (j * (n + 1) + i) as u32;
                tris.push([a, a + 1, a + n as u32 + 2]);
                tris.push([a, a + n as u32 + 2, a + n as u32 + 1]);
            }
        }
        let bins = ElementBins::new::<D3>(&verts, &tris, |_| true, [0.05; 3], 2);
        let mut s = 7;
        for k in 0..2000 {
            let x = if k % 2 == 0 {
                DVec3::new(lcg(&mut s), lcg(&mut s), lcg(&mut s)) * 1.4 - DVec3::splat(0.2)
            } else {
                DVec3::new(k as f64 % 11.0, (k / 11) as f64 % 11.0, (k / 121) as f64) * 0.1
            };
            assert_eq!(
                bins.nearest::<D3>(x, &verts, &tris),
                scan::<D3>(x, &verts, &tris)
            );
        }
        let pts: Vec<DVec2> = (0..40)
            .map(|i| DVec2::new(0.02 * i as f64, if i % 2 == 0 { 0.0 } else { 0.03 }))
            .collect();
        let segs: Vec<[u32; 2]> = (0..39).map(|i| [i, i + 1]).collect();
        let bins = ElementBins::new::<D2>(&pts, &segs, |e| e % 3 != 0, [0.01; 3], 2);
        let kept: Vec<[u32; 2]> = (segs.iter().enumerate())
            .map(|(e, &s)| if e % 3 != 0 { s } else { [0, 0] })
            .collect();
        for _ in 0..2000 {
            let x = DVec2::new(lcg(&mut s) * 1.0 - 0.1, lcg(&mut s) * 0.3 - 0.1);
            let found = bins.nearest::<D2>(x, &pts, &segs);
            let want = (kept.iter().enumerate())
                .filter(|(e, _)| e % 3 != 0)
                .map(|(e, &el)| (el.distance_sq(x, &pts), e as u32))
                .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)))
                .map(|b| b.1);
            assert_eq!(found, want);
        }
    }
}
