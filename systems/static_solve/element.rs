//! One particle's stiffness V B^T C B between the entries of its stencil, block by block:
//! what the direct solver assembles into K and the block preconditioner into its blocks.

use super::operator::Law;
use crate::base::dim::Dim;
use crate::base::sym::SymTensor;
use crate::store::world::World;
use crate::systems::dilatation::{isotropic, trace};

/// Calls `add(l, k, block)` for each pair of entries of particle `i`'s `support` (entry,
/// grad S) that `wanted(l, k)` (positions in `support`) accepts, `block[b]` the force on
/// entry l per unit motion of entry k along axis b under `law`: for each entry k and axis
/// b, the stress of the unit strain of e_b (x) grad S_k and its force V sigma . grad S_l.
/// With the group's `mean` gradients the strain's in-plane trace is the group's and the
/// force carries the mean pressure (B-bar).
pub(super) fn particle_stiffness<D: Dim>(
    world: &World<D>,
    law: Law<D>,
    i: usize,
    support: &[(usize, D::Vec)],
    mean: Option<&[D::Vec]>,
    wanted: impl Fn(usize, usize) -> bool,
    mut add: impl FnMut(usize, usize, &[D::Vec; 3]),
) {
    let p = &world.particles;
    let m = &world.materials[p.material[i] as usize];
    let (plane, volume) = (world.settings.plane, p.volume[i]);
    let per_axis = 1.0 / D::D as f64;
    // stress[k * D + b]: the stress of the unit gradient e_b (x) grad S_k.
    let mut stress = vec![D::Sym::default(); D::D * support.len()];
    for (k, &(_, g)) in support.iter().enumerate() {
        for b in 0..D::D {
            let mut e = D::zero();
            e[b] = 1.0;
            let mut l = D::outer(e, g);
            if let Some(mean) = mean {
                l = l + isotropic::<D>((mean[k][b] - g[b]) * per_axis);
            }
            stress[k * D::D + b] = law.stress(m, plane, i, &l);
        }
    }
    let mut block = [D::zero(); 3];
    for (lk, &(l, gl)) in support.iter().enumerate() {
        for (k, &(kn, _)) in support.iter().enumerate() {
            if !wanted(lk, k) {
                continue;
            }
            for (b, f) in block.iter_mut().enumerate().take(D::D) {
                let s = &stress[k * D::D + b];
                *f = D::stress_dot(s, gl);
                if let Some(mean) = mean {
                    *f += (mean[lk] - gl) * (trace::<D>(&s.to_sym3()) * per_axis);
                }
                *f *= volume;
            }
            add(l, kn, &block);
        }
    }
}
