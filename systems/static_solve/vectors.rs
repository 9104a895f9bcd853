//! Sums over the grid entries' vectors that every static solve shares.

use super::fields;
use crate::base::dim::Dim;
use crate::base::exact_sum::ExactSum;
use crate::ranks::domain::Domain;
use crate::store::crack::Fields;
use crate::store::world::{CHUNK, World};
use rayon::prelude::*;

/// Two per-entry vectors whose dot product is wanted.
pub(super) type DotPair<'v, D> = (&'v [<D as Dim>::Vec], &'v [<D as Dim>::Vec]);

/// Sums of per-entry terms with the same bits for any thread count and any split across
/// ranks: each term added exactly ([`ExactSum`]) by the rank owning the entry's node (a
/// node shared between ranks holds the same value on each), the ranks' sums added.
#[derive(Clone, Copy)]
pub(super) struct Sums<'a> {
    domain: &'a Domain,
    fields: Option<&'a Fields>,
}

impl<'a> Sums<'a> {
    /// The sums of `world`'s grid entries (a node's own and its crack fields' rows).
    pub fn of<D: Dim>(world: &'a World<D>) -> Self {
        Sums {
            domain: &world.domain,
            fields: fields(world),
        }
    }

    /// Whether this rank adds entry `e`'s terms.
    #[inline]
    pub fn owns(&self, e: usize) -> bool {
        if !self.domain.is_split() {
            return true;
        }
        let node = match self.fields {
            Some(f) if e >= f.nodes => f.node[e - f.nodes] as usize,
            _ => e,
        };
        self.domain.owns_node(node)
    }

    /// The sum of `term(e)` over the entries 0..len.
    pub fn total(&self, len: usize, term: impl Fn(usize) -> f64 + Sync) -> f64 {
        let starts: Vec<usize> = (0..len).step_by(CHUNK).collect();
        let parts: Vec<ExactSum> = starts
            .par_iter()
            .map(|&s| {
                let mut sum = ExactSum::new();
                (s..(s + CHUNK).min(len))
                    .filter(|&e| self.owns(e))
                    .for_each(|e| sum.add(term(e)));
                sum
            })
            .collect();
        let mut sum = ExactSum::new();
        parts.iter().for_each(|p| sum.merge(p));
        self.domain.sum(std::slice::from_mut(&mut sum));
        sum.value()
    }

    /// The sum of a * b over all components.
    pub fn dot<D: Dim>(&self, a: &[D::Vec], b: &[D::Vec]) -> f64 {
        self.total(a.len(), |e| D::dot(a[e], b[e]))
    }

    /// The sums of a * b for each pair `(a, b)` of vectors (all of one length), in one pass
    /// and one exchange between ranks: each the same bits as its own [`dot`](Self::dot).
    pub fn dots<D: Dim>(&self, pairs: &[DotPair<D>]) -> Vec<f64> {
        let len = pairs.first().map_or(0, |p| p.0.len());
        let starts: Vec<usize> = (0..len).step_by(CHUNK).collect();
        let parts: Vec<Vec<ExactSum>> = starts
            .par_iter()
            .map(|&s| {
                let mut sums = vec![ExactSum::new(); pairs.len()];
                for e in (s..(s + CHUNK).min(len)).filter(|&e| self.owns(e)) {
                    for (sum, (a, b)) in sums.iter_mut().zip(pairs) {
                        sum.add(D::dot(a[e], b[e]));
                    }
                }
                sums
            })
            .collect();
        let mut sums = vec![ExactSum::new(); pairs.len()];
        for part in &parts {
            sums.iter_mut().zip(part).for_each(|(s, p)| s.merge(p));
        }
        self.domain.sum(&mut sums);
        sums.iter().map(ExactSum::value).collect()
    }

    /// Every rank's rows of `width` added ([`Domain::add_rows`]; `values` on one rank).
    pub fn add_rows(&self, values: &mut [f64], width: usize) {
        self.domain.add_rows(values, width);
    }

    /// The sum of every rank's count `n`.
    pub fn count(&self, n: usize) -> usize {
        let mut sum = ExactSum::new();
        sum.add(n as f64);
        self.domain.sum(std::slice::from_mut(&mut sum));
        sum.value() as usize
    }

    /// The largest of every rank's `x`.
    pub fn max(&self, x: f64) -> f64 {
        self.domain.max(x)
    }
}
