//! A coarse grid under the conjugate gradients' Jacobi preconditioner (`linear =
//! "two_level"`, the 3D default): the two-level additive Schwarz method (Dryja & Widlund
//! 1987; Smith, Bjørstad & Gropp 1996, ch. 2). The grid of [`RATIO`] times the cell size
//! (more on large 3D bodies) carries each fine entry's displacement by multilinear
//! interpolation P; its stiffness is the Galerkin P^T K P, summed particle by particle and
//! factorized (faer's sparse Cholesky) once per set of held components the particles see:
//! a grown crack keeps it.
//! Its sums (P^T K P, and P^T r in each iteration) round their terms to a power of two
//! per row and so add exactly: split across ranks, each adds its own particles and
//! entries, the ranks' rows are added, and every rank solves the coarse system of one.
//! The preconditioner is z = D^-1 r + P (P^T K P)^-1 P^T r: Jacobi damps the short waves
//! of the error, the coarse solve the long ones that take Jacobi-preconditioned conjugate
//! gradients hundreds of iterations.
//!
//! The coarse field is one per node whatever the cracks (a crack's faces move together on
//! it): the opening is left to Jacobi and the iteration. Held components are held on P
//! (each fine entry's interpolated value is cleared where the entry is held), so P^T K P
//! has the supports' stiffness; a body free of supports leaves P^T K P its rigid motions,
//! on which the right-hand side vanishes: a relative [`SHIFT`] on the diagonal keeps the
//! factorization defined there, and the solve's deflation takes the motions out.

use super::cholesky::{analyse, factorize};
use super::operator::elastic;
use super::unknowns::Unknowns;
use super::vectors::Sums;
use super::{each_entry, entry_node, fields};
use crate::base::dim::Dim;
use crate::physics::material::Material;
use crate::store::disjoint::Disjoint;
use crate::store::world::World;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::SymbolicSparseColMat;
use faer::sparse::linalg::cholesky::{LltRef, SymbolicCholesky};
use faer::{Conj, MatMut, Par};
use rayon::prelude::*;
use std::sync::Arc;

/// The coarse nodes a fine node interpolates from, their weights, and how many (2^D at
/// most).
#[derive(Clone, Copy, Debug)]
struct Parents {
    node: [u32; 8],
    weight: [f64; 8],
    /// Per parent, the axes along which it is the upper of two (bit a for axis a).
    upper: [u8; 8],
    count: u8,
    /// The lowest parent's index per axis.
    low: [u32; 3],
}

/// Coupled coarse nodes lie at most this many coarse cells apart on an axis: a particle's
/// stencil spans at most two fine cells, whose nodes take coarse nodes at most two coarse
/// cells apart.
const REACH: usize = 2;

/// Coupling offsets per axis (-REACH..=REACH).
const SPAN: usize = 2 * REACH + 1;

/// Fine cells per coarse cell along each axis, at least. On the penny cube of 10^6
/// particles (55^3 nodes) a ratio of 2 took 38 iterations against Jacobi's 308, but its
/// coarse factor held 64 million entries (11 s to factorize, a third of an iteration's time
/// to apply); 4 takes 55 iterations with a factor of 4.3 million entries (0.2 s).
const RATIO: usize = 4;

/// In 3D the ratio doubles while more coarse cells than this hold particles: a 3D factor
/// fills in as n^(4/3), and past about 8,000 cells its factorization and its solve in
/// every iteration cost more than the iterations a finer coarse grid saves (a steel cube of
/// 7.5 million particles, 2 mm cells: 15,625 coarse cells at 4 cells, 47 iterations, 99 s
/// and 5.6 GB; 2,197 at 8 cells, 87 iterations, 63 s and 3.6 GB; at 6,859 the two break
/// even: docs/static-solver.md).
const MOST_COARSE_CELLS_3D: usize = 8_000;

/// The relative stiffness added to the coarse diagonal (see the module's doc). Coarse
/// nodes that reach a body's surface through slivers of their cells make P^T K P nearly
/// singular as well: the tube of `cylinder_surface_3d` stopped its factorization at 1e-8
/// and factorizes from 1e-7; 1e-4 leaves a margin and changes no iteration count measured
/// (the tube's 85, the penny's 55).
const SHIFT: f64 = 1e-4;

/// A coarse component is an unknown when its diagonal holds at least this many of its
/// row's quanta ([`quanta`]). The rounding of a row's terms adds up to about the square
/// root of their number (10^4 particles by 375 entries in 3D: about 10^3 quanta), which
/// 2^24 quanta keep under [`SHIFT`]. Below it, a node that only the tails of a B-spline
/// stencil reach (a diagonal of a few quanta on the penny's cube) is rounding, not
/// stiffness, and made P^T K P indefinite; uGIMP's lightest rows on that cube hold 2^30.
const LEAST_QUANTA: f64 = (1u64 << 24) as f64;

/// The coarse grid: the interpolation to the fine entries and its stiffness's factor,
/// which a set of unknowns whose particles see the same held components shares with the
/// last one (a crack that grows changes the entries, not P^T K P: [`Coarse::new`]).
#[derive(Debug)]
pub struct Coarse {
    /// Per fine entry, the coarse nodes it interpolates from.
    parents: Vec<Parents>,
    /// Per coarse node, `children[start[c]..start[c + 1]]`: the fine entries that take it
    /// and their weights, in entry order.
    start: Vec<usize>,
    children: Vec<(u32, f64)>,
    /// Per fine entry, bit a set where the interpolation moves component a (the unknowns'
    /// free ones; a sliver's, its partner's).
    keep: Vec<u8>,
    /// The entries the particles near a crack took when it was made: with `keep`, what
    /// decides P^T K P on a static scene's fixed particles.
    layout: Layout,
    /// P^T K P's factor.
    stiffness: Arc<Stiffness>,
    /// Fine cells per coarse cell along each axis.
    ratio: usize,
}

/// The coarse stiffness P^T K P on its unknowns, factorized.
#[derive(Debug)]
struct Stiffness {
    /// Per coarse node and axis, its unknown (u32::MAX: none: no particle moves it).
    unknown: Vec<u32>,
    /// How many unknowns.
    count: usize,
    symbolic: SymbolicCholesky<usize>,
    factor: Vec<f64>,
}

/// Which grid entry each particle near a crack takes at each node of its stencil (the
/// others take their nodes' own entries).
#[derive(Debug, Default)]
struct Layout {
    /// Grid nodes (the crack fields' rows are the entries from here on).
    nodes: usize,
    /// Stencil nodes per particle.
    per: usize,
    /// The particles near a crack, in increasing order, and their entries (`per` each).
    coded: Vec<u32>,
    targets: Vec<u32>,
    /// The node of each crack field's row.
    rows: Vec<u32>,
}

impl Layout {
    /// The entries of `world`'s particles after `classify`.
    fn of<D: Dim>(world: &World<D>) -> Self {
        let nodes = world.grid.geom.node_count();
        fields(world).map_or_else(
            || Layout {
                nodes,
                ..Layout::default()
            },
            |f| Layout {
                nodes,
                per: f.per,
                coded: f.coded.clone(),
                targets: f.targets.clone(),
                rows: f.node.clone(),
            },
        )
    }

    /// Whether this is the layout of `world`'s particles ([`Layout::of`], without the copy).
    fn is_of<D: Dim>(&self, world: &World<D>) -> bool {
        self.nodes == world.grid.geom.node_count()
            && match fields(world) {
                None => self.coded.is_empty() && self.rows.is_empty(),
                Some(f) => {
                    (self.per, &self.coded, &self.targets, &self.rows)
                        == (f.per, &f.coded, &f.targets, &f.node)
                }
            }
    }

    /// The node of entry `e`.
    fn node_of(&self, e: u32) -> u32 {
        match (e as usize).checked_sub(self.nodes) {
            Some(r) => self.rows[r],
            None => e,
        }
    }

    /// Whether every particle, at every node of its stencil, takes an entry with the same
    /// `keep` bits here as in `last` with `last_keep`: then P^T K P is the same, bit for
    /// bit (each particle's interpolated gradients are).
    fn sees_as(&self, keep: &[u8], last: &Layout, last_keep: &[u8]) -> bool {
        let n = self.nodes;
        if n != last.nodes || keep.get(..n) != last_keep.get(..n) || self.per != last.per {
            return false;
        }
        let per = self.per;
        let (mut i, mut j) = (0, 0);
        while i < self.coded.len() || j < last.coded.len() {
            // A particle of one list only takes its nodes' own entries in the other.
            let (mine, theirs) = match (self.coded.get(i), last.coded.get(j)) {
                (Some(a), Some(b)) => (a <= b, b <= a),
                (a, b) => (a.is_some(), b.is_some()),
            };
            for k in 0..per {
                let here = || self.targets[i * per + k];
                let there = || last.targets[j * per + k];
                let e = if mine { here() } else { last.node_of(there()) };
                let f = if theirs {
                    there()
                } else {
                    self.node_of(here())
                };
                if keep[e as usize] != last_keep[f as usize] {
                    return false;
                }
            }
            i += usize::from(mine);
            j += usize::from(theirs);
        }
        true
    }
}

/// The coarse grid's shape: nodes per axis and linear strides.
#[derive(Clone, Copy)]
struct Shape {
    nodes: [usize; 3],
    stride: [usize; 3],
    /// Fine cells per coarse cell along each axis.
    ratio: usize,
}

impl Shape {
    /// The coarse grid of `ratio` fine cells a coarse one over a fine grid of `cells`.
    fn of<D: Dim>(cells: [usize; 3], ratio: usize) -> Self {
        let mut nodes = [1usize; 3];
        for (n, &c) in nodes.iter_mut().zip(&cells).take(D::D) {
            *n = c.div_ceil(ratio) + 1;
        }
        Shape {
            nodes,
            stride: [1, nodes[0], nodes[0] * nodes[1]],
            ratio,
        }
    }

    /// Coarse node `c`'s index per axis.
    fn ijk(&self, mut c: usize) -> [usize; 3] {
        let mut out = [0; 3];
        for a in (0..3).rev() {
            out[a] = c / self.stride[a];
            c %= self.stride[a];
        }
        out
    }
}

impl Coarse {
    /// The coarse grid of `world`'s grid with its stiffness on the unknowns `dofs`: the
    /// elastic P^T K P (without the ghost's, whose share is 1e-11), taken from `last` (the
    /// last load step's) where every particle sees the same held components through its
    /// entries (a grown crack gives particles new entries of the same nodes, whose values
    /// P interpolates alike), else assembled and factorized. Its ratio is `last`'s, or
    /// [`RATIO`] doubled in 3D while more than [`MOST_COARSE_CELLS_3D`] coarse cells hold
    /// particles, halved back while P^T K P is not positive definite (a wall thinner than
    /// two coarse cells can leave coarse nodes whose fine entries all lie on one plane).
    /// Says why when the factorization fails at [`RATIO`].
    pub(super) fn new<D: Dim>(
        world: &World<D>,
        dofs: &Unknowns<D>,
        last: Option<&Coarse>,
    ) -> Result<Self, String> {
        let mut ratio = match last {
            Some(c) => c.ratio,
            None => {
                let mut ratio = RATIO;
                while D::D == 3 && occupied(world, ratio) > MOST_COARSE_CELLS_3D {
                    ratio *= 2;
                }
                ratio
            }
        };
        loop {
            match Self::with_ratio(world, dofs, last, ratio) {
                Err(_) if ratio > RATIO => ratio /= 2,
                made => return made,
            }
        }
    }

    /// [`Coarse::new`] at `ratio` fine cells a coarse one.
    fn with_ratio<D: Dim>(
        world: &World<D>,
        dofs: &Unknowns<D>,
        last: Option<&Coarse>,
        ratio: usize,
    ) -> Result<Self, String> {
        let geom = &world.grid.geom;
        let shape = Shape::of::<D>(geom.cells, ratio);
        let parents: Vec<Parents> = (0..dofs.free.len())
            .into_par_iter()
            .map(|e| parents_of::<D>(geom.stride, shape, entry_node(world, e)))
            .collect();
        let (start, children) = invert(&parents, shape.nodes.iter().product());
        let keep = keep_bits(dofs);
        let layout = Layout::of(world);
        // Split across ranks, each sees its own particles: all keep the factor or none.
        let sees = |c: &Coarse| !world.domain.any(!layout.sees_as(&keep, &c.layout, &c.keep));
        let stiffness = match last {
            Some(c) if c.ratio == ratio && sees(c) => c.stiffness.clone(),
            _ => Arc::new(Stiffness::new::<D>(world, shape, &parents, &keep)?),
        };
        Ok(Coarse {
            parents,
            start,
            children,
            keep,
            layout,
            stiffness,
            ratio,
        })
    }

    /// Whether this is the coarse grid of the unknowns `dofs` of `world`: the same held
    /// components and the same crack fields under the particles (a static scene's
    /// particles, volumes and materials do not change), so that a load step whose cracks
    /// and supports are the last one's reuses it. Split across ranks, it fits where it
    /// fits every rank's particles.
    pub(super) fn fits<D: Dim>(&self, world: &World<D>, dofs: &Unknowns<D>) -> bool {
        let mine = self.keep == keep_bits(dofs) && self.layout.is_of(world);
        !world.domain.any(!mine)
    }

    /// Whether this coarse grid shares its factor with `other` (made by [`Coarse::new`]
    /// from it).
    pub(super) fn shares_factor(&self, other: &Coarse) -> bool {
        Arc::ptr_eq(&self.stiffness, &other.stiffness)
    }

    /// Adds the coarse correction P (P^T K P)^-1 P^T r to `z`. P^T r sums its terms
    /// rounded to a quantum per coarse node ([`quantum`]) over the entries each rank owns
    /// ([`Sums`]): exact sums, so that every rank, and one rank alone, solves the same
    /// coarse system.
    pub(super) fn correct<D: Dim>(&self, sums: Sums, r: &[D::Vec], z: &mut [D::Vec]) {
        let (d, s) = (D::D, &*self.stiffness);
        let largest = (r.par_iter().enumerate())
            .filter(|&(e, _)| sums.owns(e))
            .map(|(e, r)| {
                (0..d)
                    .filter(|&a| self.keep[e] >> a & 1 == 1)
                    .fold(0.0, |m, a| r[a].abs().max(m))
            })
            .reduce(|| 0.0, f64::max);
        let largest = sums.max(largest);
        let mut restricted = vec![0.0; (self.start.len() - 1) * d];
        restricted
            .par_chunks_mut(d)
            .enumerate()
            .for_each(|(c, sum)| {
                let terms = &self.children[self.start[c]..self.start[c + 1]];
                let (q, inv) = quantum(terms.len() as f64 * largest);
                for &(e, w) in terms {
                    let (e, k) = (e as usize, self.keep[e as usize]);
                    if k == 0 || !sums.owns(e) {
                        continue;
                    }
                    for (a, sum) in sum.iter_mut().enumerate() {
                        if k >> a & 1 == 1 {
                            *sum += quantized(w * r[e][a], q, inv);
                        }
                    }
                }
            });
        sums.add_rows(&mut restricted, d);
        let mut x = vec![0.0; s.count];
        for (u, &v) in s.unknown.iter().zip(&restricted) {
            if *u != u32::MAX {
                x[*u as usize] = v;
            }
        }
        let llt = LltRef::<usize, f64>::new(&s.symbolic, &s.factor);
        let scratch = s.symbolic.solve_in_place_scratch::<f64>(1, Par::Seq);
        let mut memory = MemBuffer::new(scratch);
        llt.solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(&mut x, s.count, 1),
            Par::Seq,
            MemStack::new(&mut memory),
        );
        z.par_iter_mut().enumerate().for_each(|(e, z)| {
            let p = &self.parents[e];
            let k = mask::<D>(self.keep[e]);
            for j in 0..p.count as usize {
                let c = p.node[j] as usize;
                for a in 0..d {
                    let u = s.unknown[c * d + a];
                    if u != u32::MAX {
                        z[a] += p.weight[j] * k[a] * x[u as usize];
                    }
                }
            }
        });
    }
}

impl Stiffness {
    /// P^T K P assembled on the interpolation `parents` with the `keep` bits, factorized.
    fn new<D: Dim>(
        world: &World<D>,
        shape: Shape,
        parents: &[Parents],
        keep: &[u8],
    ) -> Result<Self, String> {
        let (blocks, quanta) = assemble(world, shape, parents, keep);
        let (unknown, count, pattern, values) = lower_triangle::<D>(shape, &blocks, &quanta);
        let symbolic = analyse(&pattern, "the coarse grid")?;
        let scratch = symbolic.factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default());
        let mut memory = MemBuffer::try_new(scratch)
            .map_err(|_| "out of memory for the coarse grid's factorization".to_string())?;
        let factor = factorize(&symbolic, &pattern, &values, &mut memory).ok_or_else(|| {
            "the coarse grid's stiffness is not positive definite: set [simulation] linear = \
             \"cg\""
                .to_string()
        })?;
        Ok(Stiffness {
            unknown,
            count,
            symbolic,
            factor,
        })
    }
}

/// How many coarse cells of `ratio` fine cells hold a particle (at its initial place, where
/// a static solve takes it), over every rank.
fn occupied<D: Dim>(world: &World<D>, ratio: usize) -> usize {
    let geom = &world.grid.geom;
    let cell = |x: &D::Vec| {
        let (fine, _) = geom.cell_range(*x, *x);
        (0..D::D).rev().fold(0u64, |at, a| {
            at * geom.cells[a].div_ceil(ratio) as u64 + (fine[a] / ratio) as u64
        })
    };
    let mut cells: Vec<u64> = world.particles.x0.par_iter().map(cell).collect();
    cells.par_sort_unstable();
    cells.dedup();
    world.domain.union(cells).len()
}

/// Per entry, the bits of the components the interpolation moves: the free ones, a
/// sliver's its partner's.
fn keep_bits<D: Dim>(dofs: &Unknowns<D>) -> Vec<u8> {
    let bits = |k: D::Vec| (0..D::D).fold(0u8, |b, a| b | (u8::from(k[a] != 0.0) << a));
    let mut keep: Vec<u8> = dofs.free.iter().map(|&k| bits(k)).collect();
    for &(s, m) in &dofs.ties {
        keep[s] = keep[m];
    }
    keep
}

/// The vector with 1 on the components of `bits`, 0 elsewhere.
#[inline(always)]
fn mask<D: Dim>(bits: u8) -> D::Vec {
    let mut k = D::zero();
    (0..D::D).for_each(|a| k[a] = f64::from(bits >> a & 1));
    k
}

/// The coarse nodes fine node `n` interpolates from: per axis the coarse node at an even
/// index, or the two around an odd one, at half weight each.
fn parents_of<D: Dim>(fine_stride: [usize; 3], shape: Shape, mut n: usize) -> Parents {
    let mut ijk = [0usize; 3];
    for a in (0..3).rev() {
        ijk[a] = n / fine_stride[a];
        n %= fine_stride[a];
    }
    let mut p = Parents {
        node: [0; 8],
        weight: [0.0; 8],
        upper: [0; 8],
        count: 1,
        low: [0; 3],
    };
    p.weight[0] = 1.0;
    for (a, &i) in ijk.iter().enumerate().take(D::D) {
        let (c0, t) = (i / shape.ratio, i % shape.ratio);
        let odd = t != 0;
        let upper = t as f64 / shape.ratio as f64;
        p.low[a] = c0 as u32;
        let count = p.count as usize;
        for k in 0..count {
            let (c, w) = (p.node[k] as usize, p.weight[k]);
            p.node[k] = (c + c0 * shape.stride[a]) as u32;
            if odd {
                p.weight[k] = (1.0 - upper) * w;
                p.node[k + count] = (c + (c0 + 1) * shape.stride[a]) as u32;
                p.weight[k + count] = upper * w;
                p.upper[k + count] = p.upper[k] | (1 << a);
            }
        }
        if odd {
            p.count *= 2;
        }
    }
    p
}

/// The fine entries (with weights) that take each of `nodes` coarse nodes, in entry order.
fn invert(parents: &[Parents], nodes: usize) -> (Vec<usize>, Vec<(u32, f64)>) {
    let mut start = vec![0usize; nodes + 1];
    for p in parents {
        p.node[..p.count as usize]
            .iter()
            .for_each(|&c| start[c as usize + 1] += 1);
    }
    for c in 0..nodes {
        start[c + 1] += start[c];
    }
    let mut fill = start.clone();
    let mut children = vec![(0u32, 0.0); start[nodes]];
    for (e, p) in parents.iter().enumerate() {
        for j in 0..p.count as usize {
            let c = p.node[j] as usize;
            children[fill[c]] = (e as u32, p.weight[j]);
            fill[c] += 1;
        }
    }
    (start, children)
}

/// Offsets of coupled coarse nodes in a row's blocks (SPAN^D).
fn span<D: Dim>() -> usize {
    SPAN.pow(D::D as u32)
}

/// The index among a row's blocks of the coupling from coarse node `row` to `col`
/// (indices per axis, at most REACH apart).
#[inline(always)]
fn offset<D: Dim>(row: [usize; 3], col: [usize; 3]) -> usize {
    let mut o = 0;
    for a in (0..D::D).rev() {
        o = o * SPAN + (col[a] + REACH - row[a]);
    }
    o
}

/// P^T K P under the elastic law, as D x D blocks per coarse node and coupling offset
/// ([`offset`]), on and below the diagonal (a row's couplings to nodes of no larger
/// index). A particle's stencil reaches three planes of coarse nodes along the last axis
/// from its lowest: the particles are binned by that plane and the bins taken in three
/// passes (bins 0, 3, 6, ..., then 1, 4, ..., then 2, 5, ...), the bins of a pass in
/// parallel on disjoint rows. Each term is rounded to its row's [`quanta`], so that the
/// sums are exact: the same bits in any order, for any thread count and any split of the
/// particles across ranks, whose rows are then added. Returns the blocks and the quanta.
fn assemble<D: Dim>(
    world: &World<D>,
    shape: Shape,
    parents: &[Parents],
    keep: &[u8],
) -> (Vec<f64>, Vec<(f64, f64)>) {
    let last = D::D - 1;
    let planes = shape.nodes[last];
    let p = &world.particles;
    let (lowest, bound): (Vec<[u32; 3]>, Vec<f64>) = (0..p.len())
        .into_par_iter()
        .map(|i| {
            let mut low = [u32::MAX; 3];
            // The sum of the stencil's gradients' 1-norms bounds every interpolated one.
            let mut grads = 0.0;
            each_entry(world, i, |e, _, g| {
                let q = &parents[e].low;
                (0..3).for_each(|a| low[a] = low[a].min(q[a]));
                grads += (0..D::D).map(|a| g[a].abs()).sum::<f64>();
            });
            let m = &world.materials[p.material[i] as usize];
            (low, p.volume[i] * stiffest(m) * grads * grads)
        })
        .unzip();
    let plane_of = |i: usize| lowest[i][last] as usize;
    let mut bin_start = vec![0usize; planes + 1];
    let reached = || (0..p.len()).filter(|&i| plane_of(i) < planes);
    reached().for_each(|i| bin_start[plane_of(i) + 1] += 1);
    for z in 0..planes {
        bin_start[z + 1] += bin_start[z];
    }
    let mut fill = bin_start.clone();
    let mut binned = vec![0u32; bin_start[planes]];
    for i in reached() {
        binned[fill[plane_of(i)]] = i as u32;
        fill[plane_of(i)] += 1;
    }
    let quanta = quanta::<D>(world, shape, reached().map(|i| lowest[i]), &bound);
    let (dd, span) = (D::D * D::D, span::<D>());
    let mut blocks = vec![0.0; shape.nodes.iter().product::<usize>() * span * dd];
    let writer = Disjoint::new(&mut blocks);
    let support = Support {
        shape,
        parents,
        keep,
        quanta: &quanta,
    };
    for pass in 0..=REACH {
        (pass..planes)
            .step_by(REACH + 1)
            .par_bridge()
            .for_each(|z| {
                for &i in &binned[bin_start[z]..bin_start[z + 1]] {
                    let i = i as usize;
                    // SAFETY: a particle of bin z writes the rows of planes z to z + REACH
                    // only; the bins of one pass are REACH + 1 planes apart, so no two
                    // threads write one row.
                    unsafe { add_particle(world, &support, i, lowest[i], &writer) };
                }
            });
    }
    world.domain.add_rows(&mut blocks, span * dd);
    (blocks, quanta)
}

/// A bound on the elastic law's stiffness: |C : e| <= stiffest |e| (Frobenius norms) for
/// any strain e, with room for the plane-stress zz strain (at most as large as e).
fn stiffest(m: &Material) -> f64 {
    2.0 * (3.0 * m.lambda.abs() + 2.0 * m.mu)
}

/// Per coarse row, the power of two its terms are rounded to: 2^-50 of a bound on the sum
/// of their magnitudes (the particles reaching the row, on every rank, times the largest
/// particle's `bound` on a term), so that every partial sum is a multiple of it well
/// inside the doubles' 53 bits, and exact. A term keeps about 50 bits less the bound's
/// slack (a few bits): far more than a preconditioner needs.
fn quanta<D: Dim>(
    world: &World<D>,
    shape: Shape,
    lowest: impl Iterator<Item = [u32; 3]>,
    bound: &[f64],
) -> Vec<(f64, f64)> {
    let most = world.domain.max(bound.iter().copied().fold(0.0, f64::max));
    let mut count = vec![0.0; shape.nodes.iter().product()];
    for low in lowest {
        for slot in 0..3usize.pow(D::D as u32) {
            let (mut node, mut rest, mut inside) = (0, slot, true);
            for (a, &l) in low.iter().enumerate().take(D::D) {
                let x = l as usize + rest % 3;
                rest /= 3;
                inside &= x < shape.nodes[a];
                node += x * shape.stride[a];
            }
            if inside {
                count[node] += 1.0;
            }
        }
    }
    world.domain.add_rows(&mut count, 1);
    count.iter().map(|&n| quantum(n * most)).collect()
}

/// The power of two 2^-50 of `bound` (a bound on the magnitudes of a sum's terms added
/// up), with its inverse: the sum of terms [`quantized`] to it is exact (1 for a bound
/// of 0: the terms are 0).
fn quantum(bound: f64) -> (f64, f64) {
    if bound > 0.0 {
        let e = bound.log2().ceil() as i32 - 50;
        (2f64.powi(e), 2f64.powi(-e))
    } else {
        (1.0, 1.0)
    }
}

/// `t` rounded to a multiple of the power of two `q` (`inv` = 1 / q; |t| / q under 2^51:
/// adding 1.5 2^52 rounds to an integer, to nearest, without a call to `round`).
#[inline(always)]
fn quantized(t: f64, q: f64, inv: f64) -> f64 {
    const INTEGER: f64 = 6_755_399_441_055_744.0;
    ((t * inv + INTEGER) - INTEGER) * q
}

/// What every particle's share of P^T K P reads: the coarse grid, the interpolation, the
/// held components and the rows' quanta.
struct Support<'a> {
    shape: Shape,
    parents: &'a [Parents],
    keep: &'a [u8],
    quanta: &'a [(f64, f64)],
}

/// Slots of a particle's coarse support: 3 per axis from its lowest node.
const SLOTS: usize = 27;

/// Adds particle `i`'s V B^T C B on the coarse nodes (B made of the interpolated fine
/// gradients, held components cleared) to the rows of its coarse support (lowest node
/// `low`), each term rounded to its row's quantum.
///
/// # Safety
/// No other thread may write the rows of the particle's coarse support.
unsafe fn add_particle<D: Dim>(
    world: &World<D>,
    support: &Support,
    i: usize,
    low: [u32; 3],
    rows: &Disjoint<f64>,
) {
    let Support {
        shape,
        parents,
        keep,
        quanta,
    } = *support;
    // Per slot, the gradient its unit motion along each axis gives.
    let mut grads = [[D::zero(); 3]; SLOTS];
    let mut used = 0u32;
    // Whether every entry moves on every axis (so each slot's gradients are one).
    let mut whole = true;
    each_entry(world, i, |e, _, g| {
        let q = &parents[e];
        let k = mask::<D>(keep[e]);
        whole &= (0..D::D).all(|a| k[a] == 1.0);
        for j in 0..q.count as usize {
            let slot = (0..D::D).rev().fold(0, |s, a| {
                let x = q.low[a] - low[a] + u32::from(q.upper[j] >> a & 1);
                s * 3 + x as usize
            });
            used |= 1 << slot;
            for a in 0..D::D {
                grads[slot][a] += g * (q.weight[j] * k[a]);
            }
        }
    });
    let p = &world.particles;
    let m = &world.materials[p.material[i] as usize];
    let (v, plane) = (p.volume[i], world.settings.plane);
    let (dd, span) = (D::D * D::D, span::<D>());
    let slots: Vec<usize> = (0..SLOTS).filter(|s| used >> s & 1 == 1).collect();
    let ijk = |slot: usize| {
        let mut out = [0usize; 3];
        let mut rest = slot;
        for a in 0..D::D {
            out[a] = low[a] as usize + rest % 3;
            rest /= 3;
        }
        out
    };
    let node = |x: [usize; 3]| (0..D::D).map(|a| x[a] * shape.stride[a]).sum::<usize>();
    // stress[k][b]: the stress of a unit motion of slot k along b.
    let mut stress = [[D::Sym::default(); 3]; SLOTS];
    for &k in &slots {
        for b in 0..D::D {
            let mut eb = D::zero();
            eb[b] = 1.0;
            stress[k][b] = elastic::<D>(m, plane, &D::outer(eb, grads[k][b]));
        }
    }
    for &l in &slots {
        let (il, gl) = (ijk(l), &grads[l]);
        let cl = node(il);
        let (q, inv) = quanta[cl];
        for &k in &slots {
            let ik = ijk(k);
            if node(ik) > cl {
                continue;
            }
            let base = (cl * span + offset::<D>(il, ik)) * dd;
            for (b, s) in stress[k].iter().enumerate().take(D::D) {
                let all = whole.then(|| D::stress_dot(s, gl[0]));
                for a in 0..D::D {
                    let at = base + a * D::D + b;
                    let f = match all {
                        Some(f) => f[a],
                        None => D::stress_dot(s, gl[a])[a],
                    };
                    // SAFETY: passed on from the caller.
                    unsafe { rows.set(at, rows.get(at) + quantized(v * f, q, inv)) };
                }
            }
        }
    }
}

/// The coarse unknowns (each node's components whose stiffness stands above the rounding
/// of its row's `quanta`: [`LEAST_QUANTA`]) and P^T K P's lower triangle on them (column
/// by column, rows sorted), the diagonal raised by [`SHIFT`].
fn lower_triangle<D: Dim>(
    shape: Shape,
    blocks: &[f64],
    quanta: &[(f64, f64)],
) -> (Vec<u32>, usize, SymbolicSparseColMat<usize>, Vec<f64>) {
    let (d, dd, span) = (D::D, D::D * D::D, span::<D>());
    let total = shape.nodes.iter().product::<usize>();
    let centre = offset::<D>([REACH; 3], [REACH; 3]);
    let mut unknown = vec![u32::MAX; total * d];
    let mut count = 0usize;
    for c in 0..total {
        for a in 0..d {
            if blocks[(c * span + centre) * dd + a * d + a] > LEAST_QUANTA * quanta[c].0 {
                unknown[c * d + a] = count as u32;
                count += 1;
            }
        }
    }
    let mut col_ptr = vec![0usize];
    let (mut row_idx, mut values) = (Vec::new(), Vec::new());
    for c in 0..total {
        let at = shape.ijk(c);
        for b in 0..d {
            let j = unknown[c * d + b];
            if j == u32::MAX {
                continue;
            }
            // Rows r >= c, nearest first along the last axis: increasing index.
            for o in 0..span {
                let mut rest = o;
                let mut r = [0usize; 3];
                let mut inside = true;
                for a in 0..d {
                    let x = at[a] + rest % SPAN;
                    rest /= SPAN;
                    inside &= x >= REACH && x - REACH < shape.nodes[a];
                    r[a] = x.wrapping_sub(REACH);
                }
                let rc: usize = (0..d).map(|a| r[a] * shape.stride[a]).sum();
                if !inside || rc < c {
                    continue;
                }
                let base = (rc * span + offset::<D>(r, at)) * dd;
                for a in 0..d {
                    let i = unknown[rc * d + a];
                    if i == u32::MAX || i < j {
                        continue;
                    }
                    let value = blocks[base + a * d + b];
                    if i == j {
                        row_idx.push(i as usize);
                        values.push(value * (1.0 + SHIFT));
                    } else if value != 0.0 {
                        row_idx.push(i as usize);
                        values.push(value);
                    }
                }
            }
            col_ptr.push(row_idx.len());
        }
    }
    let pattern = SymbolicSparseColMat::new_checked(count, count, col_ptr, None, row_idx);
    (unknown, count, pattern, values)
}

#[cfg(test)]
mod tests {
    use super::{quantized, quantum};

    /// Terms rounded to the quantum of their bound add exactly: any order, and any split
    /// into partial sums added afterwards, gives the same bits, within half a quantum per
    /// term of the exact sum.
    #[test]
    fn quantized_sums_do_not_depend_on_the_order() {
        // Terms over 12 orders of magnitude and both signs (a deterministic sequence).
        let terms: Vec<f64> = (0..10_000)
            .map(|i| {
                let x = (i as f64 * 0.618_033_988_749_895).fract();
                (x - 0.5) * 10f64.powi((i % 13) - 6)
            })
            .collect();
        let bound = terms.iter().map(|t| t.abs()).sum::<f64>();
        let (q, inv) = quantum(bound);
        let sum =
            |ts: &mut dyn Iterator<Item = &f64>| ts.map(|&t| quantized(t, q, inv)).sum::<f64>();
        let forward = sum(&mut terms.iter());
        let backward = sum(&mut terms.iter().rev());
        let (odd, even): (Vec<f64>, Vec<f64>) = terms.iter().partition(|t| t.to_bits() % 2 == 1);
        let split = sum(&mut even.iter()) + sum(&mut odd.iter());
        assert_eq!(forward.to_bits(), backward.to_bits());
        assert_eq!(forward.to_bits(), split.to_bits());
        let exact = crate::base::exact_sum::ExactSum::of(terms.iter().copied());
        assert!((forward - exact).abs() <= terms.len() as f64 * q / 2.0);
        // The quantum is 2^-50 of the bound, up to a factor of 2.
        assert!(q >= bound * 2f64.powi(-50) && q < bound * 2f64.powi(-49));
    }
}
