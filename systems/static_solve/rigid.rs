//! The rigid motions a static scene leaves free: translations and rotations of the grid
//! entries that the supports do not hold and the stiffness does not resist. A body held by
//! no support (loaded by balanced tractions or pins) has them; equilibrium then fixes the
//! displacement only up to them, and the loads' discrete imbalance, however small, has no
//! solution along them. The solve removes that imbalance and keeps its iterates clear of
//! them (deflation), and reports the part of the load it removed.

use super::entry_node;
use super::operator::{Law, apply};
use super::unknowns::Unknowns;
use super::vectors::{DotPair, Sums};
use crate::base::dim::Dim;
use crate::store::world::{CHUNK, World};
use rayon::prelude::*;

/// A rigid motion is free when its stiffness, over the largest diagonal entry of K, is
/// below this: the ghost stiffness leaves about 1e-11, round-off 1e-16; the weakest held
/// motion of a body on a small support is many orders above (3e-5 for the rotated DCB's
/// clamp).
const FREE_STIFFNESS: f64 = 1e-10;

/// An orthonormal basis (in the free components) of the rigid motions K does not resist.
pub(super) fn free_motions<D: Dim>(
    world: &World<D>,
    dofs: &Unknowns<D>,
    ghost: &[D::Vec],
    largest_diagonal: f64,
) -> Vec<Vec<D::Vec>> {
    let free = &dofs.free;
    let sums = Sums::of(world);
    let mut candidates = rigid_candidates(world, free);
    candidates.iter_mut().for_each(|c| dofs.project(c));
    let basis = orthonormal::<D>(sums, candidates);
    if basis.is_empty() {
        return basis;
    }
    // The stiffness of the candidates among themselves, G = B^T K B, and its eigenvectors.
    let k = basis.len();
    let mut q = vec![D::zero(); free.len()];
    let mut g = [[0.0; 6]; 6];
    for (j, bj) in basis.iter().enumerate() {
        apply(world, Law::Elastic, bj, dofs, Some(ghost), &mut q);
        // K is symmetric: the upper triangle, mirrored.
        for (i, bi) in basis.iter().enumerate().take(j + 1) {
            let v = sums.dot::<D>(bi, &q);
            g[i][j] = v;
            g[j][i] = v;
        }
    }
    let (values, vectors) = symmetric_eigen(g, k);
    (0..k)
        .filter(|&m| values[m].abs() <= FREE_STIFFNESS * largest_diagonal)
        .map(|m| combine::<D>(&basis, &vectors, m))
        .collect()
}

/// v less its components along the orthonormal `modes` (their projections in one
/// exchange between ranks).
pub(super) fn deflate<D: Dim>(sums: Sums, v: &mut [D::Vec], modes: &[Vec<D::Vec>]) {
    if modes.is_empty() {
        return;
    }
    let pairs: Vec<DotPair<D>> = modes.iter().map(|m| (&v[..], &m[..])).collect();
    let along = sums.dots::<D>(&pairs);
    remove::<D>(v, modes, &along);
}

/// v less `along[m]` times each of the `modes`, in one pass.
pub(super) fn remove<D: Dim>(v: &mut [D::Vec], modes: &[Vec<D::Vec>], along: &[f64]) {
    if modes.is_empty() {
        return;
    }
    v.par_chunks_mut(CHUNK).enumerate().for_each(|(k, v)| {
        let start = k * CHUNK;
        for (i, v) in v.iter_mut().enumerate() {
            for (m, &c) in modes.iter().zip(along) {
                *v -= m[start + i] * c;
            }
        }
    });
}

/// The D translations and the rotations (1 in 2D, 3 in 3D) about the entries' mass centre,
/// each on the free components only.
fn rigid_candidates<D: Dim>(world: &World<D>, free: &[D::Vec]) -> Vec<Vec<D::Vec>> {
    let geom = &world.grid.geom;
    let at = |e: usize| geom.node_position(entry_node(world, e));
    let mass = &world.grid.mass;
    let sums = Sums::of(world);
    let total = sums.total(mass.len(), |e| mass[e]).max(f64::MIN_POSITIVE);
    let mut centre = D::zero();
    for a in 0..D::D {
        centre[a] = sums.total(mass.len(), |e| at(e)[a] * mass[e]) / total;
    }
    let field = |f: &dyn Fn(D::Vec) -> D::Vec| -> Vec<D::Vec> {
        (0..free.len())
            .map(|e| {
                let mut v = f(at(e) - centre);
                for a in 0..D::D {
                    v[a] *= free[e][a];
                }
                v
            })
            .collect()
    };
    let mut out = Vec::new();
    for a in 0..D::D {
        out.push(field(&|_| {
            let mut t = D::zero();
            t[a] = 1.0;
            t
        }));
    }
    // Rotation about axis k: e_k x r, i.e. components (i, j) = (-r_j, r_i) for the two
    // axes i, j after k in turn.
    let axes: &[(usize, usize)] = if D::D == 2 {
        &[(0, 1)]
    } else {
        &[(1, 2), (2, 0), (0, 1)]
    };
    for &(i, j) in axes {
        out.push(field(&|r| {
            let mut v = D::zero();
            v[i] = -r[j];
            v[j] = r[i];
            v
        }));
    }
    out
}

/// Modified Gram-Schmidt, twice for round-off; a vector that loses all but 1e-8 of its
/// length to the others (a motion the supports hold entirely) is dropped.
fn orthonormal<D: Dim>(sums: Sums, vectors: Vec<Vec<D::Vec>>) -> Vec<Vec<D::Vec>> {
    let mut basis: Vec<Vec<D::Vec>> = Vec::new();
    for mut v in vectors {
        let start = sums.dot::<D>(&v, &v).sqrt();
        if start == 0.0 {
            continue;
        }
        for _ in 0..2 {
            deflate::<D>(sums, &mut v, &basis);
        }
        let left = sums.dot::<D>(&v, &v).sqrt();
        if left > 1e-8 * start {
            v.iter_mut().for_each(|x| *x *= 1.0 / left);
            basis.push(v);
        }
    }
    basis
}

/// Mode `m` of the eigenvectors, as a grid vector: sum over i of vectors[i][m] basis[i].
fn combine<D: Dim>(basis: &[Vec<D::Vec>], vectors: &[[f64; 6]; 6], m: usize) -> Vec<D::Vec> {
    let mut out = vec![D::zero(); basis[0].len()];
    for (i, b) in basis.iter().enumerate() {
        let c = vectors[i][m];
        out.iter_mut().zip(b).for_each(|(o, &b)| *o += b * c);
    }
    out
}

/// Eigenvalues and eigenvectors (columns) of the symmetric leading k x k block of `a`, by
/// cyclic Jacobi rotations (Golub & Van Loan 2013, section 8.5): small, exact to
/// round-off, and the same bits every time.
fn symmetric_eigen(mut a: [[f64; 6]; 6], k: usize) -> ([f64; 6], [[f64; 6]; 6]) {
    let mut v = [[0.0; 6]; 6];
    (0..k).for_each(|i| v[i][i] = 1.0);
    for _sweep in 0..50 {
        let off: f64 = (0..k)
            .flat_map(|i| (0..k).filter(move |&j| j != i).map(move |j| (i, j)))
            .map(|(i, j)| a[i][j] * a[i][j])
            .sum();
        if off == 0.0 {
            break;
        }
        for p in 0..k {
            for q in p + 1..k {
                if a[p][q] == 0.0 {
                    continue;
                }
                let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
                let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
                let t = if theta == 0.0 { 1.0 } else { t };
                let (c, s) = (1.0 / (t * t + 1.0).sqrt(), t / (t * t + 1.0).sqrt());
                for row in a.iter_mut().take(k) {
                    let (arp, arq) = (row[p], row[q]);
                    row[p] = c * arp - s * arq;
                    row[q] = s * arp + c * arq;
                }
                let (ap, aq) = (a[p], a[q]);
                for r in 0..k {
                    a[p][r] = c * ap[r] - s * aq[r];
                    a[q][r] = s * ap[r] + c * aq[r];
                }
                for row in v.iter_mut().take(k) {
                    let (vp, vq) = (row[p], row[q]);
                    row[p] = c * vp - s * vq;
                    row[q] = s * vp + c * vq;
                }
            }
        }
    }
    let mut values = [0.0; 6];
    (0..k).for_each(|i| values[i] = a[i][i]);
    (values, v)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A symmetric 3 x 3 with a known spectrum: A = Q diag(4, 1, 0) Q^T for a rotation Q;
    /// the eigen-pairs come back to round-off.
    #[test]
    fn jacobi_finds_the_spectrum() {
        let (c, s) = (0.6f64, 0.8f64);
        let q = [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]];
        let d = [4.0, 1.0, 0.0];
        let mut a = [[0.0; 6]; 6];
        for i in 0..3 {
            for j in 0..3 {
                a[i][j] = (0..3).map(|m| q[i][m] * d[m] * q[j][m]).sum();
            }
        }
        let (values, vectors) = symmetric_eigen(a, 3);
        let mut sorted: Vec<f64> = values[..3].to_vec();
        sorted.sort_by(f64::total_cmp);
        for (got, want) in sorted.iter().zip([0.0, 1.0, 4.0]) {
            assert!((got - want).abs() < 1e-14, "{got} vs {want}");
        }
        for m in 0..3 {
            for i in 0..3 {
                let av: f64 = (0..3).map(|j| a[i][j] * vectors[j][m]).sum();
                assert!((av - values[m] * vectors[i][m]).abs() < 1e-14);
            }
        }
    }
}
