//! Sparse direct solves of a static scene's K: assembled on the unknowns particle by
//! particle (V B^T C B, the same stiffness the matrix-free product applies), factorized by
//! faer's sparse Cholesky after an approximate minimum degree ordering (Amestoy, Davis &
//! Duff 1996). The pattern and its symbolic analysis are made once per set of unknowns and
//! serve every factorization on it: each Newton iteration, and the next load steps while
//! the pattern holds.

use super::cholesky::{analyse, factorize};
use super::element::particle_stiffness;
use super::faces::spring_force;
use super::frame::Frame;
use super::operator::{Law, apply};
use super::unknowns::Unknowns;
use super::vectors::Sums;
use super::{each_entry, fields, rigid};
use crate::base::dim::Dim;
use crate::base::error::Unstable;
use crate::record::solve_log::Solved;
use crate::store::disjoint::Disjoint;
use crate::store::mirror::Mirrors;
use crate::store::world::World;
use crate::systems::dilatation::Groups;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::SymbolicSparseColMat;
use faer::sparse::linalg::cholesky::{LltRef, SymbolicCholesky};
use faer::{Conj, MatMut, Par};
use std::collections::HashSet;
use std::sync::{Arc, OnceLock};

/// Most refinement passes (a solve of K d = r with the same factor) after the first solve:
/// a well-posed scene needs none; a stiffness spread over many orders (the ghost on a
/// crack's fields) one.
const REFINEMENTS: usize = 3;

/// Most nodes in a particle's stencil (uGIMP and B-splines in 3D).
const MOST_NODES: usize = 27;

/// The share of the memory the system reports available that a factor may take.
const MEMORY_SHARE: f64 = 0.5;

/// The assembled problem of one set of unknowns: which unknowns make each entry's
/// displacement, K's pattern (lower triangle) and its symbolic factorization.
pub(super) struct Direct<D: Dim> {
    layout: Layout<D>,
    analysis: Analysis,
    /// The factor of the elastic K on these unknowns, once a solve has made it: the
    /// contact rounds of a load step that move only friction forces solve with it again.
    elastic: OnceLock<Vec<f64>>,
}

/// K's pattern and its symbolic factorization, kept from one load step to the next: a
/// step whose unknowns and stencils are the last one's (no crack moved, no face closed)
/// reuses the ordering and the elimination tree.
#[derive(Clone, Debug)]
pub struct Analysis {
    pattern: SymbolicSparseColMat<usize>,
    symbolic: Arc<SymbolicCholesky<usize>>,
}

impl<D: Dim> Direct<D> {
    /// The pattern and symbolic analysis for the unknowns `dofs`, with one component
    /// pinned per free rigid motion in `modes`: `kept`'s (the last analysis made) when the
    /// pattern is its, else a new one, which `kept` then holds. Refuses (with an estimate)
    /// a factor that would take more than half the memory available.
    pub fn new(
        world: &World<D>,
        dofs: &Unknowns<D>,
        modes: &[Vec<D::Vec>],
        kept: &mut Option<Analysis>,
    ) -> Result<Self, String> {
        let layout = Layout::new(dofs, modes);
        let pattern = pattern(world, &layout, dofs.groups.as_ref());
        let same = |a: &&mut Analysis| {
            a.pattern.col_ptr() == pattern.col_ptr() && a.pattern.row_idx() == pattern.row_idx()
        };
        let analysis = match kept.as_mut().filter(same) {
            Some(a) => a.clone(),
            None => {
                let symbolic = analyse(&pattern, "the direct solver")?;
                let a = Analysis {
                    pattern,
                    symbolic: Arc::new(symbolic),
                };
                *kept = Some(a.clone());
                a
            }
        };
        let bytes = 8.0 * analysis.symbolic.len_val() as f64;
        if let Some(free) = available_memory()
            && bytes > MEMORY_SHARE * free
        {
            return Err(format!(
                "the direct solve of {} unknowns needs about {:.1} GiB for its factor, more \
                 than half the {:.1} GiB available: set [simulation] linear = \"cg\"",
                layout.count,
                bytes / GIB,
                free / GIB
            ));
        }
        Ok(Direct {
            layout,
            analysis,
            elastic: OnceLock::new(),
        })
    }

    /// Solves K u = f as [`Frame::solve`] does: assembles K under `law` (with the ghost),
    /// factorizes it, solves, refines against the matrix-free product until the residual
    /// is within `tolerance` of |f| (or [`REFINEMENTS`] passes: the residual it returns
    /// says which), and takes the free rigid motions out.
    pub fn solve(
        &self,
        world: &World<D>,
        law: Law<D>,
        frame: &Frame<D>,
        dofs: &Unknowns<D>,
        f: &[D::Vec],
        tolerance: f64,
    ) -> Result<(Vec<D::Vec>, Solved), Unstable> {
        let failed = |what: String| Unstable {
            step: world.step + 1,
            time: (world.step + 1) as f64 * world.settings.dt,
            what,
        };
        let n = f.len();
        let sums = Sums::of(world);
        let norm_f = sums.dot::<D>(f, f).sqrt();
        if norm_f == 0.0 {
            return Ok((vec![D::zero(); n], Solved::default()));
        }
        let Analysis { pattern, symbolic } = &self.analysis;
        let scratch = symbolic
            .factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default())
            .or(symbolic.solve_in_place_scratch::<f64>(1, Par::Seq));
        let mut memory = MemBuffer::try_new(scratch)
            .map_err(|_| failed("out of memory for the direct solver's workspace".into()))?;
        // The friction tangents change from one contact round to the next.
        let cache = matches!(law, Law::Elastic) && dofs.springs.is_empty();
        let kept = if cache { self.elastic.get() } else { None };
        let owned: Vec<f64>;
        let factorizations = usize::from(kept.is_none());
        let factor: &[f64] = match kept {
            Some(f) => f,
            None => {
                let values = self.assemble(world, law, &frame.ghost, dofs);
                let f = factorize(symbolic, pattern, &values, &mut memory).ok_or_else(|| {
                    failed(
                        "the static solve's stiffness is not positive definite (is the body \
                         held against every rigid motion the loads would start?)"
                            .into(),
                    )
                })?;
                if cache {
                    self.elastic.get_or_init(|| f)
                } else {
                    owned = f;
                    &owned
                }
            }
        };
        let llt = LltRef::<usize, f64>::new(symbolic, factor);
        let mut u = vec![D::zero(); n];
        let mut r = f.to_vec();
        let mut q = vec![D::zero(); n];
        let mut residual = 1.0;
        for pass in 0..=REFINEMENTS {
            let mut rhs = self.layout.restrict(&r);
            let count = rhs.len();
            llt.solve_in_place_with_conj(
                Conj::No,
                MatMut::from_column_major_slice_mut(&mut rhs, count, 1),
                Par::Seq,
                MemStack::new(&mut memory),
            );
            self.layout.extend(&rhs, &mut u);
            rigid::deflate::<D>(sums, &mut u, &frame.modes);
            apply(world, law, &u, dofs, Some(&frame.ghost), &mut q);
            r.iter_mut()
                .zip(f.iter().zip(&q))
                .for_each(|(r, (&f, &q))| *r = f - q);
            rigid::deflate::<D>(sums, &mut r, &frame.modes);
            residual = sums.dot::<D>(&r, &r).sqrt() / norm_f;
            if residual <= tolerance || pass == REFINEMENTS {
                break;
            }
        }
        Ok((
            u,
            Solved {
                residual,
                factorizations,
                factor_entries: symbolic.len_val(),
                ..Solved::default()
            },
        ))
    }

    /// K's lower triangle on the pattern: each particle's V B^T C B under `law` (B-bar
    /// with mean-dilatation `groups`, group by group), free particles tile by tile in
    /// colour classes, then the particles near a crack in order (the same sums in the same
    /// order for any thread count), the ghost stiffness and the friction tangents of
    /// `dofs`' springs.
    fn assemble(
        &self,
        world: &World<D>,
        law: Law<D>,
        ghost: &[D::Vec],
        dofs: &Unknowns<D>,
    ) -> Vec<f64> {
        let groups = dofs.groups.as_ref();
        let mut values = vec![0.0; self.analysis.pattern.compute_nnz()];
        let tiles = &world.tiles;
        let fields = fields(world);
        let writer = Disjoint::new(&mut values);
        let coded = fields.map_or(&[][..], |f| &f.coded[..]);
        match groups {
            None => {
                tiles.for_each_coloured(|t| {
                    for &i in tiles.particles(t) {
                        if crate::systems::is_free(fields, i as usize) {
                            // SAFETY: tiles of one colour class touch disjoint nodes
                            // (tiles.rs), each tile is handled by one thread, and a particle
                            // writes only the columns of its own nodes' unknowns.
                            unsafe { self.add_particle(world, law, i as usize, &writer) };
                        }
                    }
                });
                for &i in coded {
                    // SAFETY: the coloured pass is over; this loop is the only writer.
                    unsafe { self.add_particle(world, law, i as usize, &writer) };
                }
            }
            Some(groups) => {
                // The groups with a member near a crack, in group order, after the others.
                let mut near: Vec<usize> = coded.iter().map(|&i| groups.of(i as usize)).collect();
                near.sort_unstable();
                near.dedup();
                tiles.for_each_coloured(|t| {
                    for &i in tiles.particles(t) {
                        let g = groups.of(i as usize);
                        if groups.leads(i as usize) && near.binary_search(&g).is_err() {
                            // SAFETY: as above; a group's members share a cell, so its
                            // entries are its tile's.
                            unsafe { self.add_group(world, law, groups, g, &writer) };
                        }
                    }
                });
                for g in near {
                    // SAFETY: the coloured pass is over; this loop is the only writer.
                    unsafe { self.add_group(world, law, groups, g, &writer) };
                }
            }
        }
        for (e, own) in self.layout.own.iter().enumerate() {
            for &(i, bi) in own {
                for &(j, bj) in own.iter().filter(|(j, _)| *j <= i) {
                    let g: f64 = (0..D::D).map(|a| ghost[e][a] * bi[a] * bj[a]).sum();
                    // SAFETY: the particle passes are over; this loop is the only writer.
                    unsafe { self.add(&writer, i, j, g) };
                }
            }
        }
        for s in &dofs.springs {
            // The force on entry l per unit motion of entry k along b: -force(e_b) on the
            // same entry, +force(e_b) on the other.
            let mut same = [D::zero(); 3];
            for (b, c) in same.iter_mut().enumerate().take(D::D) {
                let mut e = D::zero();
                e[b] = 1.0;
                *c = -spring_force::<D>(s, e);
            }
            let other = same.map(|c| c * -1.0);
            for l in [s.above, s.below] {
                for k in [s.above, s.below] {
                    let block = if l == k { &same } else { &other };
                    // SAFETY: the particle passes are over; this loop is the only writer.
                    unsafe { self.add_block(&writer, l, k, block) };
                }
            }
        }
        values
    }

    /// Adds particle `i`'s stiffness under `law`, on its own stencil.
    ///
    /// # Safety
    /// No other thread may write the columns of the particle's entries' unknowns.
    unsafe fn add_particle(&self, world: &World<D>, law: Law<D>, i: usize, values: &Disjoint<f64>) {
        let mut support = [(0usize, D::zero()); MOST_NODES];
        let mut count = 0;
        each_entry(world, i, |n, _, g| {
            support[count] = (n, g);
            count += 1;
        });
        // SAFETY: passed on from the caller.
        unsafe { self.add_support(world, law, i, &support[..count], None, values) };
    }

    /// Adds the stiffness of mean-dilatation group `g` ([`Groups`]): each member's V
    /// B-bar^T C B-bar on the entries any member reaches, B-bar built from its own
    /// gradients and the group's volume-weighted mean gradients.
    ///
    /// # Safety
    /// No other thread may write the columns of the group's entries' unknowns.
    unsafe fn add_group(
        &self,
        world: &World<D>,
        law: Law<D>,
        groups: &Groups,
        g: usize,
        values: &Disjoint<f64>,
    ) {
        let members = groups.members(g);
        let mut union: Vec<usize> = Vec::with_capacity(4 * MOST_NODES);
        for &i in members {
            each_entry(world, i as usize, |n, _, _| union.push(n));
        }
        union.sort_unstable();
        union.dedup();
        let width = union.len();
        let volume = &world.particles.volume;
        let mut grads = vec![D::zero(); width * members.len()];
        let mut mean = vec![D::zero(); width];
        for (k, &i) in members.iter().enumerate() {
            each_entry(world, i as usize, |n, _, grad| {
                let at = union.partition_point(|&m| m < n);
                grads[k * width + at] = grad;
                mean[at] += grad * volume[i as usize];
            });
        }
        let v_g = groups.volume(g);
        mean.iter_mut().for_each(|m| *m *= 1.0 / v_g);
        for (k, &i) in members.iter().enumerate() {
            let own = &grads[k * width..(k + 1) * width];
            let support: Vec<(usize, D::Vec)> =
                union.iter().copied().zip(own.iter().copied()).collect();
            // SAFETY: passed on from the caller.
            unsafe { self.add_support(world, law, i as usize, &support, Some(&mean), values) };
        }
    }

    /// Adds particle `i`'s stiffness under `law` on the entries of `support` (entry, grad
    /// S), carried to the unknowns each entry's displacement is made of
    /// ([`particle_stiffness`]; B-bar with the group's `mean` gradients).
    ///
    /// # Safety
    /// No other thread may write the columns of the support's entries' unknowns.
    unsafe fn add_support(
        &self,
        world: &World<D>,
        law: Law<D>,
        i: usize,
        support: &[(usize, D::Vec)],
        mean: Option<&[D::Vec]>,
        values: &Disjoint<f64>,
    ) {
        particle_stiffness(
            world,
            law,
            i,
            support,
            mean,
            |_, _| true,
            |l, k, block| {
                // SAFETY: passed on from the caller.
                unsafe { self.add_block(values, l, k, block) }
            },
        );
    }

    /// Adds the block of K between grid entries `l` and `k` (`block[b]`: the force on `l`
    /// per unit motion of `k` along axis b) to the unknowns each entry is made of, lower
    /// triangle only.
    ///
    /// # Safety
    /// No other thread may write the columns of the entries' unknowns.
    unsafe fn add_block(&self, values: &Disjoint<f64>, l: usize, k: usize, block: &[D::Vec; 3]) {
        let comb = &self.layout.comb;
        for &(r, cr) in &comb[l] {
            for &(c, cc) in comb[k].iter().filter(|(c, _)| *c <= r) {
                let v: f64 = (0..D::D).map(|b| cc[b] * D::dot(cr, block[b])).sum();
                // SAFETY: passed on from the caller.
                unsafe { self.add(values, r, c, v) };
            }
        }
    }

    /// Adds `v` to K's entry at row `r`, column `c` (r >= c).
    ///
    /// # Safety
    /// No other thread may write column `c`.
    #[inline(always)]
    unsafe fn add(&self, values: &Disjoint<f64>, r: u32, c: u32, v: f64) {
        let pattern = &self.analysis.pattern;
        let rows = pattern.row_idx_of_col_raw(c as usize);
        let start = pattern.col_ptr()[c as usize];
        let at = rows.partition_point(|&x| x < r as usize);
        debug_assert!(rows[at] == r as usize);
        // SAFETY: the caller guarantees no other thread writes column c.
        unsafe { values.set(start + at, values.get(start + at) + v) };
    }
}

/// Which unknowns make each grid entry's displacement.
struct Layout<D: Dim> {
    /// Per entry, its own unknowns, each with its unit direction.
    own: Vec<Vec<(u32, D::Vec)>>,
    /// Per entry, every unknown its displacement takes (its own, and through its ties its
    /// partner's), with the vector each contributes per unit.
    comb: Vec<Vec<(u32, D::Vec)>>,
    /// How many unknowns.
    count: usize,
}

impl<D: Dim> Layout<D> {
    /// The unknowns of `dofs`: an entry's free axes (on a closed frictionless face, the
    /// directions along the face), less one component per rigid motion in `modes`,
    /// pinned where the modes are largest and most independent (complete pivoting): the
    /// pinned solve differs from the free one by a rigid motion, which the solve takes out.
    fn new(dofs: &Unknowns<D>, modes: &[Vec<D::Vec>]) -> Self {
        let entries = dofs.free.len();
        let mut normal = vec![None; entries];
        for &(s, _, n) in &dofs.normal_ties {
            normal[s] = Some(n);
        }
        let dirs: Vec<Vec<D::Vec>> = (0..entries)
            .map(|e| directions::<D>(dofs.free[e], normal[e]))
            .collect();
        let pinned = pins::<D>(&dirs, modes);
        let mut count = 0u32;
        let mut next = 0;
        let own: Vec<Vec<(u32, D::Vec)>> = (dirs.iter())
            .map(|d| {
                (d.iter())
                    .filter_map(|&v| {
                        next += 1;
                        (!pinned.contains(&(next - 1))).then(|| {
                            count += 1;
                            (count - 1, v)
                        })
                    })
                    .collect()
            })
            .collect();
        // In the order of `Unknowns::expand`.
        let mut comb = own.clone();
        for &(s, m, n) in &dofs.normal_ties {
            let along: Vec<(u32, D::Vec)> = (comb[m].iter())
                .map(|&(j, c)| (j, n * D::dot(n, c)))
                .collect();
            comb[s].extend(along);
        }
        for &(s, m) in &dofs.ties {
            comb[s] = comb[m].clone();
        }
        for im in &dofs.images {
            let reflect = |&(j, c): &(u32, D::Vec)| (j, Mirrors::<D>::reflect(im.sign, c));
            comb[im.node as usize] = comb[im.source as usize].iter().map(reflect).collect();
        }
        Layout {
            own,
            comb,
            count: count as usize,
        }
    }

    /// The unknowns' components of the per-entry vector `v`.
    fn restrict(&self, v: &[D::Vec]) -> Vec<f64> {
        let mut out = vec![0.0; self.count];
        for (own, &v) in self.own.iter().zip(v) {
            for &(j, d) in own {
                out[j as usize] = D::dot(d, v);
            }
        }
        out
    }

    /// Adds the unknowns `x` to the per-entry vector `u` (each entry's own part).
    fn extend(&self, x: &[f64], u: &mut [D::Vec]) {
        for (own, u) in self.own.iter().zip(u) {
            for &(j, d) in own {
                *u += d * x[j as usize];
            }
        }
    }
}

/// The orthonormal directions an entry moves in: its free axes, less the normal of a
/// closed frictionless face (which its partner gives it).
fn directions<D: Dim>(free: D::Vec, normal: Option<D::Vec>) -> Vec<D::Vec> {
    let axes = (0..D::D).filter(|&a| free[a] != 0.0).map(|a| {
        let mut e = D::zero();
        e[a] = 1.0;
        e
    });
    let Some(n) = normal else {
        return axes.collect();
    };
    // The face's normal within the free axes first; the directions orthogonal to it.
    let mut n_free = n;
    (0..D::D).for_each(|a| n_free[a] *= free[a]);
    let mut basis: Vec<D::Vec> = Vec::new();
    let length = D::dot(n_free, n_free).sqrt();
    if length > 0.0 {
        basis.push(n_free * (1.0 / length));
    }
    let skip = basis.len();
    for mut v in axes {
        for &b in &basis {
            v -= b * D::dot(b, v);
        }
        let l = D::dot(v, v).sqrt();
        if l > 1e-6 {
            basis.push(v * (1.0 / l));
        }
    }
    basis.split_off(skip)
}

/// The unknowns to pin (in order of [`directions`] over the entries), one per rigid motion:
/// Gaussian elimination with complete pivoting on the modes' components picks rows whose
/// square block is as far from singular as the modes allow.
fn pins<D: Dim>(dirs: &[Vec<D::Vec>], modes: &[Vec<D::Vec>]) -> Vec<usize> {
    let k = modes.len();
    if k == 0 {
        return Vec::new();
    }
    // The modes' components, one row of k per unknown.
    let mut rows: Vec<f64> = Vec::new();
    for (e, d) in dirs.iter().enumerate() {
        for &v in d {
            rows.extend(modes.iter().map(|m| D::dot(v, m[e])));
        }
    }
    let mut pinned = Vec::with_capacity(k);
    let mut cols: Vec<usize> = (0..k).collect();
    for _ in 0..k {
        let (mut best, mut at) = (0.0, (0, 0));
        for (r, row) in rows.chunks_exact(k).enumerate() {
            for (ci, &c) in cols.iter().enumerate() {
                if row[c].abs() > best && !pinned.contains(&r) {
                    best = row[c].abs();
                    at = (r, ci);
                }
            }
        }
        if best == 0.0 {
            break;
        }
        let (r, ci) = at;
        let c = cols.swap_remove(ci);
        let pivot = rows[r * k..(r + 1) * k].to_vec();
        for row in rows.chunks_exact_mut(k) {
            let factor = row[c] / pivot[c];
            for &o in &cols {
                row[o] -= factor * pivot[o];
            }
            row[c] = 0.0;
        }
        pinned.push(r);
    }
    pinned
}

/// K's pattern (lower triangle, rows sorted in each column): unknowns i and j are coupled
/// when one particle (with mean-dilatation `groups`, one group) reaches an entry made of
/// i and an entry made of j. Particles of one cell share their stencil's entries, so the
/// distinct stencils are collected first.
fn pattern<D: Dim>(
    world: &World<D>,
    layout: &Layout<D>,
    groups: Option<&Groups>,
) -> SymbolicSparseColMat<usize> {
    let entries = layout.comb.len();
    let mut stencils: HashSet<Vec<u32>> = HashSet::new();
    let mut support = Vec::with_capacity(27);
    let mut add = |support: &mut Vec<u32>| {
        support.sort_unstable();
        support.dedup();
        if !stencils.contains(support) {
            stencils.insert(support.clone());
        }
    };
    match groups {
        None => {
            for i in 0..world.particles.len() {
                support.clear();
                each_entry(world, i, |n, _, _| support.push(n as u32));
                add(&mut support);
            }
        }
        Some(groups) => {
            for g in 0..groups.len() {
                support.clear();
                for &i in groups.members(g) {
                    each_entry(world, i as usize, |n, _, _| support.push(n as u32));
                }
                add(&mut support);
            }
        }
    }
    let mut neighbours: Vec<Vec<u32>> = vec![Vec::new(); entries];
    for s in &stencils {
        for &e in s {
            neighbours[e as usize].extend_from_slice(s);
        }
    }
    neighbours.iter_mut().for_each(|n| {
        n.sort_unstable();
        n.dedup();
    });
    let mut owners: Vec<Vec<u32>> = vec![Vec::new(); layout.count];
    for (e, comb) in layout.comb.iter().enumerate() {
        for &(j, _) in comb {
            owners[j as usize].push(e as u32);
        }
    }
    let mut col_ptr = Vec::with_capacity(layout.count + 1);
    col_ptr.push(0);
    let mut row_idx = Vec::new();
    let mut mark = vec![usize::MAX; layout.count];
    let mut rows = Vec::new();
    for (j, owners) in owners.iter().enumerate() {
        rows.clear();
        for &f in owners {
            for &e in &neighbours[f as usize] {
                for &(i, _) in &layout.comb[e as usize] {
                    let i = i as usize;
                    if i >= j && mark[i] != j {
                        mark[i] = j;
                        rows.push(i);
                    }
                }
            }
        }
        rows.sort_unstable();
        row_idx.extend_from_slice(&rows);
        col_ptr.push(row_idx.len());
    }
    let n = layout.count;
    SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx)
}

/// Bytes in a GiB.
const GIB: f64 = 1024.0 * 1024.0 * 1024.0;

/// The memory the system reports available (bytes), where it says (Linux).
fn available_memory() -> Option<f64> {
    let info = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = info.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024.0)
}
