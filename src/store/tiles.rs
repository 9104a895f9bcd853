//! Spatial tiles: particles binned by tile, tiles grouped into 2^D colour classes; and the
//! particles' stencils, which share the bins' lifetime.
//!
//! Tiles of one colour are at least one tile apart on every axis, and a tile's particles
//! reach at most one node below and two nodes above its cells, so with tiles wider than
//! two cells the node sets touched by tiles of one colour are disjoint. P2G uses this to
//! scatter in parallel without atomics and with a fixed summation order.

use crate::base::dim::Dim;
use crate::physics::shape::StencilCache;
use crate::store::grid::GridGeom;
use bitvec::slice::BitSlice;

/// Tiles wider than this many cells keep same-colour tiles' stencils disjoint.
pub const MIN_TILE: usize = 3;

/// Particle bins by tile (counting sort, stable in particle index).
#[derive(Clone, Debug, Default)]
pub struct Tiles {
    /// Cells per tile edge.
    pub size: usize,
    /// Tiles per axis (1 on the third axis in 2D).
    pub counts: [usize; 3],
    /// `start[t]..start[t + 1]` indexes `order` for tile `t`.
    pub start: Vec<u32>,
    /// Particle indices sorted by tile.
    pub order: Vec<u32>,
    /// Non-empty tiles of each colour class.
    pub colours: Vec<Vec<u32>>,
    /// Scratch: tile of each particle.
    pub tile_of: Vec<u32>,
    /// Whether the bins and stencils match the current particle positions (cleared when
    /// particles move).
    pub fresh: bool,
    /// Every particle's stencil at the binned positions.
    pub stencils: StencilCache,
    /// Per axis, each cell's contribution to its tile's linear index (avoids divisions).
    pub cell_part: [Vec<u32>; 3],
}

impl Tiles {
    /// Tiles of `size` cells per edge covering `cells`; `size` must exceed two cells.
    pub fn new<D: Dim>(size: usize, cells: [usize; 3]) -> Self {
        assert!(size >= MIN_TILE, "tile size below {MIN_TILE} cells");
        let mut counts = [1; 3];
        for a in 0..D::D {
            counts[a] = cells[a].div_ceil(size);
        }
        let n = counts.iter().product::<usize>();
        let stride = [1, counts[0], counts[0] * counts[1]];
        let cell_part = [0, 1, 2].map(|a| {
            (0..cells[a].max(1))
                .map(|c| ((c / size) * stride[a]) as u32)
                .collect()
        });
        Tiles {
            fresh: false,
            stencils: StencilCache::default(),
            cell_part,
            size,
            counts,
            start: vec![0; n + 1],
            order: Vec::new(),
            colours: vec![Vec::new(); D::COLOURS],
            tile_of: Vec::new(),
        }
    }

    /// Linear index of the tile holding the place `x` (m), None when `x` lies outside the
    /// grid `geom` (or is not finite).
    pub fn tile_at<D: Dim>(&self, geom: &GridGeom<D>, x: D::Vec) -> Option<u32> {
        let (t, inside) = self.tile_nearest(geom, x);
        inside.then_some(t)
    }

    /// Linear index of the tile holding the grid cell nearest the place `x` (m), and
    /// whether `x` lies inside the grid `geom` (a non-finite place takes the first cell).
    pub fn tile_nearest<D: Dim>(&self, geom: &GridGeom<D>, x: D::Vec) -> (u32, bool) {
        let mut cell = [0; 3];
        let mut inside = true;
        for a in 0..D::D {
            let c = ((x[a] - geom.origin[a]) * geom.inv_h[a]).floor();
            inside &= c >= 0.0 && c < geom.cells[a] as f64;
            cell[a] = (c.max(0.0) as usize).min(geom.cells[a] - 1);
        }
        (self.tile_of_cell(cell), inside)
    }

    /// Linear index of the tile holding `cell` (which must be inside the grid).
    #[inline(always)]
    pub fn tile_of_cell(&self, cell: [usize; 3]) -> u32 {
        self.cell_part[0][cell[0]] + self.cell_part[1][cell[1]] + self.cell_part[2][cell[2]]
    }

    /// Number of tiles.
    pub fn len(&self) -> usize {
        self.start.len() - 1
    }

    /// Whether there are no tiles.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Colour class (0..2^D) of a tile: parity of its index on each axis.
    pub fn colour(&self, t: usize) -> usize {
        let i = t % self.counts[0];
        let j = (t / self.counts[0]) % self.counts[1];
        let k = t / (self.counts[0] * self.counts[1]);
        (i & 1) | ((j & 1) << 1) | ((k & 1) << 2)
    }

    /// Particles in tile `t`, in ascending index order.
    #[inline(always)]
    pub fn particles(&self, t: u32) -> &[u32] {
        let t = t as usize;
        &self.order[self.start[t] as usize..self.start[t + 1] as usize]
    }

    /// The particles binned in the tiles that hold cells `lo` to `hi` (inclusive, per axis),
    /// in ascending index order, or None while not every particle is binned (before the
    /// first step). Bins date from the last binning: a caller wanting the particles in a
    /// region pads it by the distance they can have moved since (under a cell per step).
    pub fn particles_in_cells(
        &self,
        lo: [usize; 3],
        hi: [usize; 3],
        count: usize,
    ) -> Option<Vec<u32>> {
        if self.order.len() != count {
            return None;
        }
        let [nx, ny, _] = self.counts;
        let mut out = Vec::new();
        for tk in lo[2] / self.size..=hi[2] / self.size {
            for tj in lo[1] / self.size..=hi[1] / self.size {
                for ti in lo[0] / self.size..=hi[0] / self.size {
                    out.extend_from_slice(self.particles((ti + nx * (tj + ny * tk)) as u32));
                }
            }
        }
        out.sort_unstable();
        Some(out)
    }

    /// Number of particles in tile `t`, the work a scatter does there.
    fn weight(&self, t: u32) -> u64 {
        self.particles(t).len() as u64
    }

    /// Runs `f` on every non-empty tile: colour classes one after another, the tiles of a
    /// class in parallel. Tiles of one class never share a node.
    pub fn for_each_coloured(&self, f: impl Fn(u32) + Sync + Send) {
        self.for_each_coloured_then(f, None, |classes, run| {
            (0..classes).for_each(|c| run(c, false));
        });
    }

    /// As [`for_each_coloured`](Self::for_each_coloured), with the classes' order left to
    /// `pass(classes, run)` (where ranks settle the nodes they share): `run(c, held)` runs
    /// class c's tiles that `waits` holds (`held`) or the others, and `pass` calls it once
    /// each way for every class; without `waits`, `run(c, false)` runs the whole class and
    /// `run(c, true)` nothing.
    pub fn for_each_coloured_then(
        &self,
        f: impl Fn(u32) + Sync + Send,
        waits: Option<&BitSlice>,
        pass: impl FnOnce(usize, &mut dyn FnMut(usize, bool)),
    ) {
        self.fold_coloured(&f, (), &|(), ()| (), waits, pass);
    }

    /// As [`for_each_coloured_then`](Self::for_each_coloured_then), returning the largest
    /// value `f` gives (0 when there is none); a maximum does not depend on the order of
    /// the tiles.
    pub fn max_coloured_then(
        &self,
        f: impl Fn(u32) -> f64 + Sync + Send,
        waits: Option<&BitSlice>,
        pass: impl FnOnce(usize, &mut dyn FnMut(usize, bool)),
    ) -> f64 {
        self.fold_coloured(&f, 0.0, &f64::max, waits, pass)
    }

    /// The colour classes in the order `pass` runs them, each run's tiles in parallel
    /// ([`weighted_join`]), folding `f`'s values.
    fn fold_coloured<T: Send + Sync + Copy>(
        &self,
        f: &(impl Fn(u32) -> T + Sync),
        init: T,
        fold: &(impl Fn(T, T) -> T + Sync),
        waits: Option<&BitSlice>,
        pass: impl FnOnce(usize, &mut dyn FnMut(usize, bool)),
    ) -> T {
        let count = |t: u32| self.weight(t);
        let mut acc = init;
        let mut run = |c: usize, held: bool| {
            let class = &self.colours[c];
            let ran = match waits {
                None if held => init,
                None => weighted_join(class, &count, f, init, fold),
                Some(waits) => {
                    let part: Vec<u32> = (class.iter().copied())
                        .filter(|&t| waits[t as usize] == held)
                        .collect();
                    weighted_join(&part, &count, f, init, fold)
                }
            };
            acc = fold(acc, ran);
        };
        pass(self.colours.len(), &mut run);
        acc
    }

    /// Rebuilds `start`, `order` and `colours` from `tile_of` (counting sort).
    pub fn sort(&mut self) {
        let nt = self.len();
        self.start.iter_mut().for_each(|s| *s = 0);
        for &t in &self.tile_of {
            self.start[t as usize + 1] += 1;
        }
        for t in 0..nt {
            self.start[t + 1] += self.start[t];
        }
        self.order.resize(self.tile_of.len(), 0);
        let mut next: Vec<u32> = self.start[..nt].to_vec();
        for (p, &t) in self.tile_of.iter().enumerate() {
            self.order[next[t as usize] as usize] = p as u32;
            next[t as usize] += 1;
        }
        for c in &mut self.colours {
            c.clear();
        }
        for t in 0..nt {
            if self.start[t + 1] > self.start[t] {
                let c = self.colour(t);
                self.colours[c].push(t as u32);
            }
        }
        self.fresh = true;
    }
}

/// Runs `f` on every tile of `class` (in index order) in parallel and folds the values it
/// returns with `fold` from `init`. The tiles are split into contiguous halves of equal
/// particle count (`count` of a tile), recursively, until a piece holds an eighth of a
/// thread's share or one tile; `rayon::join` runs the halves, so an idle thread steals the
/// largest piece left. Halves of equal tile count, where rayon's own split starts, give one
/// of two threads twice the other's particles in the DCB's colour classes, whose tiles are
/// unevenly filled; and contiguous halves, unlike handing out tiles one by one (measured
/// slower), keep each thread on the same tiles, and their particles in its cache, from
/// system to system. Which thread runs a tile changes no result: tiles of one class write disjoint
/// entries, and `fold` must not depend on the order of its values.
fn weighted_join<T: Send + Sync + Copy>(
    class: &[u32],
    count: &(impl Fn(u32) -> u64 + Sync),
    f: &(impl Fn(u32) -> T + Sync),
    init: T,
    fold: &(impl Fn(T, T) -> T + Sync),
) -> T {
    let total: u64 = class.iter().map(|&t| count(t)).sum();
    let grain = total / (8 * rayon::current_num_threads() as u64).max(1);
    split(class, total, grain, count, f, init, fold)
}

/// One level of [`weighted_join`]: `class` holds `weight` particles.
fn split<T: Send + Sync + Copy>(
    class: &[u32],
    weight: u64,
    grain: u64,
    count: &(impl Fn(u32) -> u64 + Sync),
    f: &(impl Fn(u32) -> T + Sync),
    init: T,
    fold: &(impl Fn(T, T) -> T + Sync),
) -> T {
    if class.len() < 2 || weight <= grain {
        return class.iter().fold(init, |acc, &t| fold(acc, f(t)));
    }
    // The first tile that takes the running count to half the weight or beyond ends the
    // left half; there is a tile on each side (weight > 0 and at least two tiles).
    let (mut left, mut k) = (0, 0);
    while k < class.len() - 1 && 2 * left < weight {
        left += count(class[k]);
        k += 1;
    }
    let (a, b) = rayon::join(
        || split(&class[..k], left, grain, count, f, init, fold),
        || split(&class[k..], weight - left, grain, count, f, init, fold),
    );
    fold(a, b)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Mutex;

    /// Every tile is visited exactly once and the fold sees every value, whatever the pool
    /// size and however unevenly the tiles are filled (the sequential loop is the answer).
    #[test]
    fn weighted_join_visits_each_tile_once() {
        let class: Vec<u32> = (0..37).map(|k| 3 * k + 1).collect();
        let count = |t: u32| ((t * 7919) % 13) as u64 * 100 + 1;
        let value = |t: u32| ((t * 104_729) % 1000) as f64;
        let max = class.iter().map(|&t| value(t)).fold(0.0, f64::max);
        let sum: u64 = class.iter().map(|&t| count(t) * t as u64).sum();
        for threads in [1, 2, 3] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("pool");
            pool.install(|| {
                let seen = Mutex::new(Vec::new());
                let got = weighted_join(
                    &class,
                    &count,
                    &|t| {
                        seen.lock().expect("not poisoned").push(t);
                        value(t)
                    },
                    0.0,
                    &f64::max,
                );
                let mut seen = seen.into_inner().expect("not poisoned");
                seen.sort_unstable();
                assert_eq!(seen, class, "{threads} threads");
                assert_eq!(got, max, "{threads} threads");
                let total =
                    weighted_join(&class, &count, &|t| count(t) * t as u64, 0, &|a, b| a + b);
                assert_eq!(total, sum, "{threads} threads");
            });
        }
    }
}
