//! Preconditioned conjugate gradients (Hestenes & Stiefel 1952) on a static scene's K,
//! matrix-free, with exact sums over the entries so that every thread count and every split
//! across ranks gives the same bits.

use super::frame::Frame;
use super::operator::{Law, apply, with_springs};
use super::rigid;
use super::unknowns::Unknowns;
use super::vectors::{DotPair, Sums};
use crate::base::dim::Dim;
use crate::base::error::Unstable;
use crate::record::solve_log::Solved;
use crate::store::world::World;
use rayon::prelude::*;

/// Most iterations per load step, per unknown along the grid's longest axis: conjugate
/// gradients on a well-supported grid converge in a small multiple of it.
const ITERATIONS_PER_NODE: usize = 50;

/// Solves K u = f on the free components (K the stiffness of `law`, plus the ghost's) from
/// `start` or from u = 0 by preconditioned conjugate gradients (Hestenes & Stiefel 1952),
/// to a residual of `tolerance` times |f|.
pub(super) fn conjugate_gradients<D: Dim>(
    world: &World<D>,
    law: Law<D>,
    frame: &Frame<D>,
    dofs: &Unknowns<D>,
    f: &[D::Vec],
    start: Option<Vec<D::Vec>>,
    tolerance: f64,
) -> Result<(Vec<D::Vec>, Solved), Unstable> {
    let Frame {
        diag,
        ghost,
        modes,
        coarse,
        blocks,
    } = frame;
    let diag = &with_springs(diag, dofs)[..];
    let n = f.len();
    let sums = Sums::of(world);
    let norm_f = sums.dot::<D>(f, f).sqrt();
    if norm_f == 0.0 {
        return Ok((vec![D::zero(); n], Solved::default()));
    }
    let precondition = |r: &[D::Vec]| -> Vec<D::Vec> {
        let mut z: Vec<D::Vec> = r
            .par_iter()
            .zip(diag.par_iter())
            .map(|(&r, &d)| {
                let mut z = r;
                for a in 0..D::D {
                    z[a] /= d[a];
                }
                z
            })
            .collect();
        if let Some(b) = blocks {
            b.solve(r, &mut z);
        }
        if let Some(c) = coarse {
            c.correct::<D>(sums, r, &mut z);
        }
        z
    };
    let mut r = f.to_vec();
    let mut u = match start {
        Some(u) => {
            let mut q = vec![D::zero(); n];
            apply(world, law, &u, dofs, Some(ghost), &mut q);
            r.iter_mut().zip(&q).for_each(|(r, &q)| *r -= q);
            u
        }
        None => vec![D::zero(); n],
    };
    // The residual's norm, and the preconditioned residual z with r . z, in one exchange.
    let step = |r: &[D::Vec]| -> (f64, Vec<D::Vec>, f64) {
        let mut z = precondition(r);
        dofs.project(&mut z);
        let (rr, along, rz) = residual_sums::<D>(sums, r, &z, modes);
        rigid::remove::<D>(&mut z, modes, &along);
        (rr.sqrt() / norm_f, z, rz)
    };
    let (residual, z, mut rz) = step(&r);
    if residual <= tolerance {
        let solved = Solved {
            residual,
            ..Solved::default()
        };
        return Ok((u, solved));
    }
    let mut dir = z;
    let mut q = vec![D::zero(); n];
    let cells = world.grid.geom.cells;
    let most = ITERATIONS_PER_NODE * (cells[0].max(cells[1]).max(cells[2]) + 1);
    for k in 1..=most {
        apply(world, law, &dir, dofs, Some(ghost), &mut q);
        let pq = sums.dot::<D>(&dir, &q);
        // A direction of no stiffness (or NaN): K is singular on what the loads start.
        if pq.is_nan() || pq <= 0.0 {
            return Err(not_converged(
                world,
                k,
                sums.dot::<D>(&r, &r).sqrt() / norm_f,
            ));
        }
        let alpha = rz / pq;
        u.par_iter_mut()
            .zip(r.par_iter_mut())
            .zip(dir.par_iter().zip(q.par_iter()))
            .for_each(|((u, r), (&p, &q))| {
                *u += p * alpha;
                *r -= q * alpha;
            });
        let (residual, z, rz_next) = step(&r);
        if residual <= tolerance {
            return Ok((
                u,
                Solved {
                    iterations: k,
                    residual,
                    ..Solved::default()
                },
            ));
        }
        let beta = rz_next / rz;
        rz = rz_next;
        dir.par_iter_mut()
            .zip(z.par_iter())
            .for_each(|(p, &z)| *p = z + *p * beta);
    }
    Err(not_converged(
        world,
        most,
        sums.dot::<D>(&r, &r).sqrt() / norm_f,
    ))
}

/// r . r, the projections of `z` on the orthonormal `modes`, and r . z' for z' the
/// deflated z (r . z less each projection times r's own along that mode), from one
/// exchange between ranks: a conjugate-gradient iteration's sums but one.
fn residual_sums<D: Dim>(
    sums: Sums,
    r: &[D::Vec],
    z: &[D::Vec],
    modes: &[Vec<D::Vec>],
) -> (f64, Vec<f64>, f64) {
    let mut pairs: Vec<DotPair<D>> = vec![(r, r), (r, z)];
    for m in modes {
        pairs.push((z, m));
        pairs.push((r, m));
    }
    let d = sums.dots::<D>(&pairs);
    let per_mode = d[2..].chunks_exact(2);
    let along: Vec<f64> = per_mode.clone().map(|m| m[0]).collect();
    let rz = per_mode.fold(d[1], |rz, m| rz - m[0] * m[1]);
    (d[0], along, rz)
}

fn not_converged<D: Dim>(world: &World<D>, iterations: usize, residual: f64) -> Unstable {
    Unstable {
        step: world.step + 1,
        time: (world.step + 1) as f64 * world.settings.dt,
        what: format!(
            "the static solve did not converge: relative residual {residual:.3e} after \
             {iterations} conjugate-gradient iterations (is the body held against every rigid \
             motion the loads would start?)"
        ),
    }
}
