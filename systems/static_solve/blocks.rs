//! Block Jacobi on the weakly supported entries: the entries next to a body's surface that
//! particles reach with only the tails of their stencils (quadratic B-splines put a layer
//! of them outside every face), each solved together with the entries their few particles
//! tie them to.
//!
//! Such an entry's shape function, over the particles it reaches, is nearly a combination
//! of its inward neighbours' (the ill-conditioning of small cut supports that de Prenter,
//! Verhoosel, van Zwieten & van Brummelen 2017 analyse for immersed B-splines): K scaled by
//! its diagonal has eigenvalues a hundred times below the body's at the corners and edges,
//! which neither Jacobi nor the coarse grid reaches, and conjugate gradients took ten times
//! the iterations of uGIMP's stencils. Each block is a weak node with the three nodes inward
//! of it along every axis across which the support changes (one either side along the others),
//! their K block factorized densely: an additive Schwarz preconditioner on non-overlapping
//! blocks in place of Jacobi on their entries (Smith, Bjørstad & Gropp 1996, ch. 1).

use super::element::particle_stiffness;
use super::operator::Law;
use super::unknowns::Unknowns;
use super::{each_entry, entries, fields};
use crate::base::dim::Dim;
use crate::physics::shape::ShapeKind;
use crate::store::world::World;
use bitvec::vec::BitVec;
use faer::linalg::solvers::{Llt, Solve};
use faer::{Mat, Side};
use rayon::prelude::*;

/// A node is weakly supported when its stencil weights hold less than this share of a cell's
/// volume of particles: B-spline nodes a cell outside a face hold about 0.016, at the edges
/// and corners far less, while the nodes on a face hold 0.25 or more.
const WEAK: f64 = 0.1;

/// How many nodes inward of a weak node its block takes along an axis across the surface:
/// a cell past a face aligned with the grid needs two (the cube of `tests/static_solver.rs`:
/// 435 iterations to 53; three, 49), a surface that cuts the cells obliquely three (a
/// sphere: 531 to 148 with two, 77 with three; four, 77).
const DEPTH: i64 = 3;

/// Neighbours whose supports differ by less than this share of the larger lie along the
/// surface, not across it.
const LEVEL: f64 = 0.05;

/// The blocks of one set of unknowns.
pub(super) struct Blocks<D: Dim> {
    blocks: Vec<Block<D>>,
}

/// One block: its entries and the factor of K on their components.
struct Block<D: Dim> {
    /// Its entries, in increasing order.
    entries: Vec<u32>,
    /// Each entry's free components.
    free: Vec<D::Vec>,
    /// The Cholesky factor of K on the entries' components (held ones as identity),
    /// component a of the j-th entry at j * D + a.
    factor: Llt<f64>,
}

impl<D: Dim> Blocks<D> {
    /// The blocks of the unknowns `dofs` with the `ghost` stiffness on B-spline stencils,
    /// or None where no node is weakly supported, on other stencils (uGIMP reaches past a
    /// surface only through slivers of cells, where the blocks did not save an iteration)
    /// and where the body is split across ranks (a block would span them).
    pub fn new(world: &World<D>, dofs: &Unknowns<D>, ghost: &[D::Vec]) -> Option<Self> {
        if world.settings.shape != ShapeKind::Bspline || world.domain.is_split() {
            return None;
        }
        let blockable = blockable(dofs);
        let groups = aggregate(world, &blockable);
        if groups.is_empty() {
            return None;
        }
        // Where each blocked entry sits: (block, position), u32::MAX elsewhere.
        let mut slot = vec![(u32::MAX, 0u32); dofs.free.len()];
        for (b, g) in groups.iter().enumerate() {
            for (j, &e) in g.iter().enumerate() {
                slot[e as usize] = (b as u32, j as u32);
            }
        }
        let d = D::D;
        let mut dense: Vec<Vec<f64>> = groups
            .iter()
            .map(|g| vec![0.0; (g.len() * d).pow(2)])
            .collect();
        let mut support: Vec<(usize, D::Vec)> = Vec::with_capacity(27);
        // In particle order: the same sums for any thread count.
        for i in 0..world.particles.len() {
            support.clear();
            each_entry(world, i, |n, _, g| support.push((n, g)));
            let block = |k: usize| slot[support[k].0].0;
            if !(0..support.len()).any(|k| block(k) != u32::MAX) {
                continue;
            }
            let same = |l: usize, k: usize| block(l) != u32::MAX && block(l) == block(k);
            particle_stiffness(world, Law::Elastic, i, &support, None, same, |l, k, f| {
                let (b, jl) = slot[l];
                let jk = slot[k].1 as usize;
                let (m, a) = (groups[b as usize].len() * d, &mut dense[b as usize]);
                for (bk, f) in f.iter().enumerate().take(d) {
                    for al in 0..d {
                        a[(jl as usize * d + al) * m + jk * d + bk] += f[al];
                    }
                }
            });
        }
        // A block whose K does not factorize (a held component's row aside, it is a sum of
        // the particles' stiffness and the ghost's: it should) keeps Jacobi.
        let blocks: Vec<Block<D>> = (groups.into_par_iter().zip(dense))
            .filter_map(|(entries, a)| {
                let free: Vec<D::Vec> = entries.iter().map(|&e| dofs.free[e as usize]).collect();
                let m = entries.len() * d;
                let k = Mat::from_fn(m, m, |r, c| {
                    let (er, ar, ec, ac) = (r / d, r % d, c / d, c % d);
                    let (held_r, held_c) = (free[er][ar] == 0.0, free[ec][ac] == 0.0);
                    match (r == c, held_r || held_c) {
                        (true, true) => 1.0,
                        (false, true) => 0.0,
                        (true, false) => a[r * m + c] + ghost[entries[er] as usize][ar],
                        (false, false) => a[r * m + c],
                    }
                });
                let factor = k.llt(Side::Lower).ok()?;
                Some(Block {
                    entries,
                    free,
                    factor,
                })
            })
            .collect();
        (!blocks.is_empty()).then_some(Blocks { blocks })
    }

    /// Overwrites `z` on the blocked entries with each block's solve of K z = r.
    pub fn solve(&self, r: &[D::Vec], z: &mut [D::Vec]) {
        let d = D::D;
        let solved: Vec<Mat<f64>> = (self.blocks.par_iter())
            .map(|b| {
                let rhs = Mat::from_fn(b.entries.len() * d, 1, |row, _| {
                    let (j, a) = (row / d, row % d);
                    r[b.entries[j] as usize][a] * b.free[j][a]
                });
                b.factor.solve(rhs)
            })
            .collect();
        for (b, x) in self.blocks.iter().zip(&solved) {
            for (j, &e) in b.entries.iter().enumerate() {
                for a in 0..d {
                    z[e as usize][a] = x[(j * d + a, 0)] * b.free[j][a];
                }
            }
        }
    }
}

/// The entries a block may hold: free on some component and tied to no other (nor a
/// symmetry plane's image to its source).
fn blockable<D: Dim>(dofs: &Unknowns<D>) -> BitVec {
    let mut ok: BitVec = dofs.free.iter().map(|&f| f != D::zero()).collect();
    for &(s, m) in &dofs.ties {
        ok.set(s, false);
        ok.set(m, false);
    }
    for &(s, m, _) in &dofs.normal_ties {
        ok.set(s, false);
        ok.set(m, false);
    }
    for im in &dofs.images {
        ok.set(im.node as usize, false);
        ok.set(im.source as usize, false);
    }
    ok
}

/// The blocks' entries: each weakly supported node, the lightest first, with the nodes up
/// to [`DEPTH`] steps inward along each axis across which the support rises and one step
/// either way along the others, that no earlier block took, with every blockable entry of
/// each.
fn aggregate<D: Dim>(world: &World<D>, blockable: &BitVec) -> Vec<Vec<u32>> {
    let geom = &world.grid.geom;
    let volume = &world.particles.volume;
    let held = super::scatter::entry_sums(world, |i, w, _| {
        let mut v = D::zero();
        v[0] = w * volume[i];
        v
    });
    let fields = fields(world);
    let cell: f64 = (0..D::D).map(|a| geom.h[a]).product();
    let nodes = geom.node_count();
    let support: Vec<f64> = (0..nodes as u32)
        .map(|n| entries(n, fields).map(|e| held[e][0]).sum::<f64>() / cell)
        .collect();
    let usable = |n: usize| entries(n as u32, fields).any(|e| blockable[e]);
    let mut weak: Vec<usize> = (0..nodes)
        .filter(|&n| support[n] > 0.0 && support[n] < WEAK && usable(n))
        .collect();
    weak.sort_by(|&a, &b| support[a].total_cmp(&support[b]).then(a.cmp(&b)));
    let neighbour = |n: usize, a: usize, step: i64| -> Option<usize> {
        let ijk = geom.node_ijk(n);
        let to = ijk[a] as i64 + step;
        (0..geom.nodes[a] as i64)
            .contains(&to)
            .then(|| (n as i64 + step * geom.stride[a] as i64) as usize)
    };
    let support_at =
        |n: usize, a: usize, step: i64| neighbour(n, a, step).map_or(0.0, |m| support[m]);
    let mut taken: BitVec = BitVec::repeat(false, nodes);
    let mut groups = Vec::new();
    for &n in &weak {
        if taken[n] {
            continue;
        }
        // The steps along each axis: inward across the surface, either way along it.
        let mut box_nodes = vec![n];
        for a in 0..D::D {
            let (up, down) = (support_at(n, a, 1), support_at(n, a, -1));
            let steps: Vec<i64> = if (up - down).abs() <= LEVEL * up.max(down) {
                vec![-1, 1]
            } else {
                let inward = if up > down { 1 } else { -1 };
                (1..=DEPTH).map(|s| s * inward).collect()
            };
            let grown: Vec<usize> = (box_nodes.iter())
                .flat_map(|&m| steps.iter().filter_map(move |&s| neighbour(m, a, s)))
                .collect();
            box_nodes.extend(grown);
        }
        box_nodes.sort_unstable();
        box_nodes.dedup();
        let mut group: Vec<u32> = Vec::new();
        for m in box_nodes {
            if taken[m] || support[m] == 0.0 {
                continue;
            }
            taken.set(m, true);
            group.extend(
                entries(m as u32, fields)
                    .filter(|&e| blockable[e])
                    .map(|e| e as u32),
            );
        }
        if !group.is_empty() {
            group.sort_unstable();
            groups.push(group);
        }
    }
    groups
}
