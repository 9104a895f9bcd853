//! Sums over the grid entries' vectors that every static solve shares.

use crate::base::dim::Dim;
use crate::store::world::CHUNK;
use rayon::prelude::*;

/// The sum of a * b over all components, in fixed chunks (the same bits for any thread
/// count).
pub(super) fn dot<D: Dim>(a: &[D::Vec], b: &[D::Vec]) -> f64 {
    let parts: Vec<f64> = a
        .par_chunks(CHUNK)
        .zip(b.par_chunks(CHUNK))
        .map(|(a, b)| a.iter().zip(b).map(|(&x, &y)| D::dot(x, y)).sum())
        .collect();
    parts.iter().sum()
}
