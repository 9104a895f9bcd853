//! Products with the stiffness K of a static scene, matrix-free: particle by particle, the
//! stress a displacement gradient gives under a [`Law`], scattered as nodal forces.

use super::faces::add_spring_forces;
use super::scatter::{entry_sums, near_crack_sums};
use super::unknowns::Unknowns;
use super::{each_entry, fields, gradient};
use crate::base::dim::Dim;
use crate::base::sym::{Sym3, SymTensor};
use crate::physics::material::{Material, Plane};
use crate::physics::plastic::Tangent;
use crate::store::disjoint::Disjoint;
use crate::store::world::{CHUNK, World};
use crate::systems::p2g::add_internal_force;
use crate::systems::stress::velocity_gradient;
use rayon::prelude::*;
use std::borrow::Cow;

/// Which stress a particle's displacement gradient gives, in a product with K.
#[derive(Clone, Copy)]
pub(super) enum Law<'a, D: Dim> {
    /// The material's elastic C : sym(grad u).
    Elastic,
    /// Each particle's algorithmic tangent from its last return map (None: elastic) :
    /// sym(grad u): the Newton iteration's K.
    Tangent(&'a [Option<Tangent>]),
    /// The given stresses, whatever the displacement: the internal force they make.
    Given(&'a [D::Sym]),
}

impl<D: Dim> Law<'_, D> {
    /// Particle `i`'s stress from its displacement gradient `l`.
    #[inline(always)]
    pub fn stress(&self, m: &Material, plane: Plane, i: usize, l: &D::Mat) -> D::Sym {
        match self {
            Law::Elastic => elastic::<D>(m, plane, l),
            Law::Tangent(t) => match &t[i] {
                Some(t) => D::Sym::from_sym3(t.apply(m.lambda, m.mu, &D::sym_part(l))),
                None => elastic::<D>(m, plane, l),
            },
            Law::Given(s) => s[i],
        }
    }
}

/// `v` with the components `keep` has at 0 cleared.
#[inline(always)]
pub(super) fn mask<D: Dim>(v: D::Vec, keep: D::Vec) -> D::Vec {
    let mut out = v;
    for a in 0..D::D {
        out[a] *= keep[a];
    }
    out
}

/// The stress C : sym(l) of material `m`.
#[inline(always)]
pub(super) fn elastic<D: Dim>(m: &Material, plane: Plane, l: &D::Mat) -> D::Sym {
    let mut s = Sym3::default();
    m.update(plane, D::sym_part(l), &mut s);
    D::Sym::from_sym3(s)
}

/// y = K x, particle by particle: grad x gathered at each particle (tied entries taking
/// the value of the entry they move with), the stress it gives under `law`, and that stress's nodal
/// force, tile by tile in colour classes (the same scatter, in the same order, for any
/// thread count), the sliding faces' friction tangents added (`dofs.springs`), tied
/// entries' forces folded into their partners'. With mean-dilatation
/// groups the stresses come first, from the group-mean strains, and scatter with their
/// groups' mean pressure ([`Groups`](crate::systems::dilatation::Groups)).
pub(super) fn stiffness<D: Dim>(
    world: &World<D>,
    law: Law<D>,
    x: &[D::Vec],
    dofs: &Unknowns<D>,
    y: &mut [D::Vec],
) {
    entry_stiffness(world, law, x, dofs, y);
    dofs.fold(y);
}

/// [`stiffness`] on every grid entry before tied entries and images are folded into their
/// partners and sources: each entry's own share of K x (a symmetry plane's reaction needs
/// the images').
pub(super) fn entry_stiffness<D: Dim>(
    world: &World<D>,
    law: Law<D>,
    x: &[D::Vec],
    dofs: &Unknowns<D>,
    y: &mut [D::Vec],
) {
    let expanded;
    let x = if dofs.ties.is_empty() && dofs.normal_ties.is_empty() && dofs.images.is_empty() {
        x
    } else {
        let mut e = x.to_vec();
        dofs.expand(&mut e);
        expanded = e;
        &expanded[..]
    };
    let grouped;
    let law = match &dofs.groups {
        Some(groups) => {
            let p = &world.particles;
            let stresses: Vec<D::Sym> = match law {
                Law::Given(s) => s.to_vec(),
                _ => {
                    let plane = world.settings.plane;
                    (groups
                        .gradients(world, |i| gradient(world, i, x))
                        .par_iter()
                        .enumerate())
                    .map(|(i, l)| law.stress(&world.materials[p.material[i] as usize], plane, i, l))
                    .collect()
                }
            };
            grouped = groups.effective(world, &stresses);
            Law::Given(&grouped)
        }
        None => law,
    };
    y.par_chunks_mut(CHUNK).for_each(|c| c.fill(D::zero()));
    let (shape, plane) = (world.settings.shape, world.settings.plane);
    let stride = &world.grid.geom.stride;
    let (p, materials, tiles) = (&world.particles, &world.materials, &world.tiles);
    let (fields, domain) = (fields(world), &world.domain);
    let y_w = Disjoint::new(y);
    tiles.for_each_coloured_then(
        |t| {
            let mine = tiles.particles(t).iter().map(|&i| i as usize);
            for_each_free_particle!(D, shape, &tiles.stencils, fields, mine, |i, st| {
                let rows = st.rows::<D>(stride);
                let l = velocity_gradient::<D, N>(&st, &rows, x);
                let s = law.stress(&materials[p.material[i] as usize], plane, i, &l);
                // SAFETY: tiles of one colour class touch disjoint nodes (tiles.rs), and
                // each tile is handled by one thread. Given -V, the internal-force scatter
                // adds +V sigma . grad S: the rows of K x.
                unsafe { add_internal_force::<D, N>(&st, &rows, &s, -p.volume[i], &y_w) };
            })
        },
        domain.waits(),
        |classes, run| domain.settle_pass(classes, &[&y_w], run),
    );
    // The particles near a crack, on their sides' entries, in particle order.
    near_crack_sums(world, y, |i, emit| {
        let l = gradient(world, i, x);
        let s = law.stress(&materials[p.material[i] as usize], plane, i, &l);
        each_entry(world, i, |n, _, g| {
            emit(n, D::stress_dot(&s, g) * p.volume[i])
        });
    });
    add_spring_forces::<D>(&dofs.springs, x, y);
}

/// y = K x on the free components ([`stiffness`]), with `ghost`'s stiffness (per
/// component) times x added when given.
pub(super) fn apply<D: Dim>(
    world: &World<D>,
    law: Law<D>,
    x: &[D::Vec],
    dofs: &Unknowns<D>,
    ghost: Option<&[D::Vec]>,
    y: &mut [D::Vec],
) {
    stiffness(world, law, x, dofs, y);
    y.par_chunks_mut(CHUNK)
        .zip(dofs.free.par_chunks(CHUNK))
        .zip(x.par_chunks(CHUNK))
        .enumerate()
        .for_each(|(c, ((y, k), x))| {
            for (j, (y, &k)) in y.iter_mut().zip(k).enumerate() {
                *y = mask::<D>(*y, k);
                if let Some(g) = ghost {
                    let g = g[c * CHUNK + j];
                    for a in 0..D::D {
                        y[a] += g[a] * x[j][a] * k[a];
                    }
                }
            }
        });
    dofs.project(y);
}

/// The diagonal of K (its free components; 1 elsewhere, so the preconditioner leaves the
/// fixed ones alone): for node n and axis a, sum over particles of V e_a . (C : sym(e_a ⊗
/// grad S_n)) . grad S_n. A tied entry adds its own to its partner's (along the normal
/// for a sliding pair: [`Unknowns::fold_diagonal`]): a particle reaches one entry of a
/// node, so the two share no particle and K has no term between them.
pub(super) fn diagonal<D: Dim>(world: &World<D>, dofs: &Unknowns<D>) -> Vec<D::Vec> {
    let free = &dofs.free;
    let plane = world.settings.plane;
    let p = &world.particles;
    let mut d = entry_sums(world, |i, _, grad| {
        let m = &world.materials[p.material[i] as usize];
        let mut d = D::zero();
        for a in 0..D::D {
            let mut e = D::zero();
            e[a] = 1.0;
            let s = elastic::<D>(m, plane, &D::outer(e, grad));
            d[a] = p.volume[i] * D::stress_dot(&s, grad)[a];
        }
        d
    });
    dofs.fold_diagonal(&mut d);
    for (d, &k) in d.iter_mut().zip(free) {
        for a in 0..D::D {
            if k[a] == 0.0 || d[a] <= 0.0 {
                d[a] = 1.0;
            }
        }
    }
    d
}

/// `diag` (the frame's, without the friction tangents) with the diagonal of `dofs`'
/// springs added on the free components: k (1 - n_a^2 - d_a^2) on both entries of each.
pub(super) fn with_springs<'a, D: Dim>(
    diag: &'a [D::Vec],
    dofs: &Unknowns<D>,
) -> Cow<'a, [D::Vec]> {
    if dofs.springs.is_empty() {
        return Cow::Borrowed(diag);
    }
    let mut d = diag.to_vec();
    for s in &dofs.springs {
        for e in [s.above, s.below] {
            let (d, free) = (&mut d[e], dofs.free[e]);
            for a in (0..D::D).filter(|&a| free[a] != 0.0) {
                d[a] += s.k * (1.0 - s.normal[a] * s.normal[a] - s.along[a] * s.along[a]);
            }
        }
    }
    Cow::Owned(d)
}
