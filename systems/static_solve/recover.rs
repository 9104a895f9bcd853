//! The grid entries' displacement at a load step's start, recovered from the particles'.
//! Each particle's displacement is the last answer interpolated from the entries it
//! reaches, and where particles outnumber those entries the interpolation loses nothing:
//! the entries are its least-squares inverse, the consistent-mass projection
//! (sum_p m_p S_ip S_jp) u_j = sum_p m_p S_ip d_p, solved by conjugate gradients from the
//! lumped projection (the mass-weighted mean). Sliding crack faces need it: their slip over
//! a step counts from there, and the mean smooths each field's displacement over its cell.

use super::gather;
use super::scatter::entry_sums;
use super::vectors::Sums;
use crate::base::dim::Dim;
use crate::store::world::World;

/// Residual, relative to the right-hand side, at which the recovery stops: far below what
/// a slip or a friction work needs, above round-off.
const TOLERANCE: f64 = 1e-12;

/// Most conjugate-gradient iterations: the consistent mass is within a small factor of the
/// lumped one that preconditions it, so a few tens suffice.
const MOST: usize = 200;

/// Each entry's displacement whose interpolation best fits the particles' `disp` in the
/// mass-weighted least-squares sense (zero on entries without mass).
pub(super) fn recovered<D: Dim>(world: &World<D>, disp: &[D::Vec]) -> Vec<D::Vec> {
    let (mass, m) = (&world.grid.mass, &world.particles.mass);
    let tol = world.settings.mass_tol;
    let sums = Sums::of(world);
    let lumped = |r: &[D::Vec]| -> Vec<D::Vec> {
        (r.iter().zip(mass))
            .map(|(&r, &me)| if me > tol { r * (1.0 / me) } else { D::zero() })
            .collect()
    };
    let apply = |x: &[D::Vec]| {
        let at = gather(world, x);
        entry_sums(world, |i, w, _| at[i] * (m[i] * w))
    };
    let b = entry_sums(world, |i, w, _| disp[i] * (m[i] * w));
    let stop = TOLERANCE * TOLERANCE * sums.dot::<D>(&b, &b);
    let mut x = lumped(&b);
    let mut r: Vec<D::Vec> = (b.iter().zip(apply(&x))).map(|(&b, a)| b - a).collect();
    let mut z = lumped(&r);
    let mut p = z.clone();
    let mut rz = sums.dot::<D>(&r, &z);
    for _ in 0..MOST {
        if sums.dot::<D>(&r, &r) <= stop {
            break;
        }
        let q = apply(&p);
        let alpha = rz / sums.dot::<D>(&p, &q);
        x.iter_mut().zip(&p).for_each(|(x, &p)| *x += p * alpha);
        r.iter_mut().zip(&q).for_each(|(r, &q)| *r -= q * alpha);
        z = lumped(&r);
        let next = sums.dot::<D>(&r, &z);
        let beta = next / rz;
        rz = next;
        p.iter_mut().zip(&z).for_each(|(p, &z)| *p = z + *p * beta);
    }
    x
}
