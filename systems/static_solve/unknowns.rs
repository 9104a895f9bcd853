//! The unknowns of a load step: the components of the grid entries that are free (a
//! particle reaches the entry, no boundary holds it), the crack fields that hold a sliver
//! of mass, tied to their node's heaviest entry, the closed crack faces that slide
//! (frictionless or against friction), tied along the crack's normal, and the stuck ones,
//! tied whole; with the sliding ones' friction tangents, which K carries, and the B-spline
//! symmetry planes' image nodes, each its source reflected.

use super::faces::{self, Face, Pair, Spring};
use super::{entries, fields};
use crate::base::dim::Dim;
use crate::store::mirror::Image;
use crate::store::world::{Dilatation, World};
use crate::systems::dilatation::Groups;
use crate::systems::mirror;

/// Which entry components are unknowns, and which entries move with another.
pub(super) struct Unknowns<D: Dim> {
    /// Per entry, 1 on the free components, 0 on the held ones and on tied entries.
    pub free: Vec<D::Vec>,
    /// (tied entry, the entry of the same node it moves with): slivers and the stuck
    /// faces' fields; no partner is tied itself.
    pub ties: Vec<(usize, usize)>,
    /// (tied entry, its partner, the unit normal along which they move together): closed
    /// pairs that slide. The tied entry's normal component is not an unknown.
    pub normal_ties: Vec<(usize, usize, D::Vec)>,
    /// The particles' mean-dilatation groups (`dilatation = "cell_mean"`), else None.
    pub groups: Option<Groups>,
    /// The sliding pairs' friction tangents (3D), part of K: [`faces::Spring`].
    pub springs: Vec<Spring<D::Vec>>,
    /// The B-spline symmetry planes' image nodes, each its source's value reflected.
    pub images: Vec<Image<D::Vec>>,
}

impl<D: Dim> Unknowns<D> {
    /// The free components and ties of the world's grid after `p2g`, with the face
    /// `pairs` in the states `faces`.
    pub fn new(world: &World<D>, pairs: &[Pair<D::Vec>], faces: &[Face<D::Vec>]) -> Self {
        let tol = world.settings.mass_tol;
        let mut free: Vec<D::Vec> = (world.grid.mass.iter())
            .map(|&m| if m > tol { ones::<D>() } else { D::zero() })
            .collect();
        for bc in &world.bcs {
            let held = (0..D::D).filter(|&a| bc.axes[a]);
            for &n in &bc.nodes {
                for e in entries(n, fields(world)) {
                    held.clone().for_each(|a| free[e][a] = 0.0);
                }
            }
        }
        let mut ties = slivers(world);
        let sliver = |e: usize| ties.binary_search_by_key(&e, |t| t.0).is_ok();
        let acting = (pairs.iter().zip(faces)).filter(|(p, _)| !sliver(p.row) && !sliver(p.own));
        let normal_ties = (acting.clone())
            .filter(|(_, f)| matches!(f, Face::Closed | Face::Sliding { .. }))
            .map(|(p, _)| (p.row, p.own, p.normal))
            .collect();
        let stuck: Vec<(usize, usize)> = (acting.filter(|(_, f)| **f == Face::Stuck))
            .map(|(p, _)| (p.row, p.own))
            .collect();
        // A sliver that moved with a stuck row moves with the row's partner.
        for t in ties.iter_mut() {
            if let Ok(k) = stuck.binary_search_by_key(&t.1, |s| s.0) {
                t.1 = stuck[k].1;
            }
        }
        ties.extend(stuck);
        ties.sort_unstable();
        for &(s, _) in &ties {
            free[s] = D::zero();
        }
        let groups =
            (world.settings.dilatation == Dilatation::CellMean).then(|| Groups::new(world));
        let mut dofs = Unknowns {
            free,
            ties,
            normal_ties,
            groups,
            springs: Vec::new(),
            images: world.grid.mirrors.images.clone(),
        };
        dofs.set_springs(pairs, faces);
        dofs
    }

    /// Takes the sliding pairs' friction tangents from `faces` (the same pairs in the same
    /// kinds of state as when these unknowns were made, only their forces moved).
    pub fn set_springs(&mut self, pairs: &[Pair<D::Vec>], faces: &[Face<D::Vec>]) {
        let tied = &self.normal_ties;
        let acting = |row: usize| tied.binary_search_by_key(&row, |t| t.0).is_ok();
        self.springs = faces::springs::<D>(pairs, faces, acting);
    }

    /// Gives each tied entry the value of the entry it moves with (along the normal for a
    /// frictionless pair): the faces' pairs first, so that a sliver whose heaviest entry is
    /// a pair's tied one takes that entry's whole value; each image node its source's,
    /// reflected.
    pub fn expand(&self, x: &mut [D::Vec]) {
        mirror::reflect_images::<D>(&self.images, x);
        for &(s, m, n) in &self.normal_ties {
            x[s] += n * D::dot(x[m] - x[s], n);
        }
        for &(s, m) in &self.ties {
            x[s] = x[m];
        }
    }

    /// Adds each tied entry's value (a force) to the entry it moves with, and clears it
    /// (its normal part, for a frictionless pair): the transpose of [`Self::expand`], in
    /// the reverse order.
    pub fn fold(&self, y: &mut [D::Vec]) {
        for &(s, m) in &self.ties {
            y[m] += y[s];
            y[s] = D::zero();
        }
        for &(s, m, n) in &self.normal_ties {
            let along = n * D::dot(y[s], n);
            y[m] += along;
            y[s] -= along;
        }
        mirror::fold_images::<D>(&self.images, y);
    }

    /// Folds a per-component diagonal of K into the diagonal on the unknowns: a tied
    /// entry's whole into its partner's (an image's into its source's); for a closed pair tied along its unit normal n,
    /// the partner gains n_a^2 (n . D_s n) on axis a and the tied entry keeps the diagonal
    /// of (I - n n^T) D_s (I - n n^T), D_s its diagonal. Unlike [`Self::fold`] (a force),
    /// neither goes negative on a normal oblique to the axes.
    pub fn fold_diagonal(&self, d: &mut [D::Vec]) {
        for im in &self.images {
            let v = std::mem::replace(&mut d[im.node as usize], D::zero());
            d[im.source as usize] += v;
        }
        for &(s, m) in &self.ties {
            d[m] += d[s];
            d[s] = D::zero();
        }
        for &(s, m, n) in &self.normal_ties {
            let ds = d[s];
            let normal: f64 = (0..D::D).map(|b| n[b] * n[b] * ds[b]).sum();
            for a in 0..D::D {
                d[m][a] += n[a] * n[a] * normal;
                d[s][a] = (0..D::D)
                    .map(|b| {
                        let p = (if a == b { 1.0 } else { 0.0 }) - n[a] * n[b];
                        p * p * ds[b]
                    })
                    .sum();
            }
        }
    }

    /// Clears the components that are not unknowns: the normal part of each frictionless
    /// pair's tied entry (the free mask clears the rest).
    pub fn project(&self, x: &mut [D::Vec]) {
        for &(s, _, n) in &self.normal_ties {
            x[s] -= n * D::dot(x[s], n);
        }
    }
}

/// A node's crack fields that hold a sliver of mass (above the grid's mass tolerance, at
/// most the scene's `sliver_mass`: a particle whose line to the node crosses the crack
/// while the node is at the edge of its support), each with the node's heaviest entry.
/// The explicit solver moves such fields with that entry (`grid_update`); here they are
/// the same unknown. Held on their own, by the few corners of particles that reach them,
/// they are near-mechanisms whose motions spoil the stresses next to the crack: the
/// inclined penny's K varied along the front by twice as much.
fn slivers<D: Dim>(world: &World<D>) -> Vec<(usize, usize)> {
    let Some(f) = fields(world) else {
        return Vec::new();
    };
    let (mass, tol, sliver) = (
        &world.grid.mass,
        world.settings.mass_tol,
        world.settings.sliver_mass,
    );
    let light = |e: usize| mass[e] > tol && mass[e] <= sliver;
    let mut ties = Vec::new();
    for (node, rows) in f.groups() {
        let group = || std::iter::once(node as usize).chain(rows.clone());
        if !group().any(light) {
            continue;
        }
        let heavy = group()
            .max_by(|&a, &b| mass[a].total_cmp(&mass[b]))
            .unwrap_or(node as usize);
        ties.extend(
            group()
                .filter(|&e| e != heavy && light(e))
                .map(|e| (e, heavy)),
        );
    }
    ties.sort_unstable();
    ties
}

/// The vector of ones.
pub(super) fn ones<D: Dim>() -> D::Vec {
    let mut k = D::zero();
    (0..D::D).for_each(|a| k[a] = 1.0);
    k
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::base::dim::D2;
    use glam::DVec2;

    /// A node with its own entry 0, a crack field 1 on a closed frictionless pair with it,
    /// and a sliver 2 whose heaviest entry is the pair's tied field: folding is the
    /// transpose of expanding on the unknowns (x . fold(y) = expand(x) . y), which keeps
    /// K symmetric for conjugate gradients.
    #[test]
    fn folding_is_the_transpose_of_expanding() {
        let n = DVec2::new(0.6, 0.8);
        let dofs = Unknowns::<D2> {
            free: vec![DVec2::ONE, DVec2::ONE, DVec2::ZERO],
            ties: vec![(2, 1)],
            normal_ties: vec![(1, 0, n)],
            groups: None,
            springs: Vec::new(),
            images: Vec::new(),
        };
        let mut x = vec![DVec2::new(1.0, -2.0), DVec2::new(3.0, 5.0), DVec2::ZERO];
        dofs.project(&mut x);
        let y = vec![
            DVec2::new(0.7, 1.1),
            DVec2::new(-1.3, 0.2),
            DVec2::new(2.9, -0.4),
        ];
        let mut expanded = x.clone();
        dofs.expand(&mut expanded);
        let mut folded = y.clone();
        dofs.fold(&mut folded);
        let dot = |a: &[DVec2], b: &[DVec2]| a.iter().zip(b).map(|(a, b)| a.dot(*b)).sum::<f64>();
        let (left, right) = (dot(&x, &folded), dot(&expanded, &y));
        assert!((left - right).abs() < 1e-14, "{left} vs {right}");
        assert!((expanded[2] - expanded[1]).length() == 0.0);
    }

    /// On an entry-diagonal K (each entry's stiffness per axis, no coupling) with a
    /// sliding pair along an oblique normal, the folded diagonal is the operator's own:
    /// e . fold(K expand(e)) for e the partner's axis and the tied entry's axis projected
    /// off the normal; equal stiffness on every axis, where folding it as a force would
    /// leave a zero.
    #[test]
    fn a_folded_diagonal_is_the_folded_operators() {
        let n = DVec2::new(1.0, 1.0).normalize();
        let dofs = Unknowns::<D2> {
            free: vec![DVec2::ONE, DVec2::ONE],
            ties: vec![],
            normal_ties: vec![(1, 0, n)],
            groups: None,
            springs: Vec::new(),
            images: Vec::new(),
        };
        let k = [DVec2::new(3.0, 5.0), DVec2::new(2.0, 2.0)];
        let operator = |x: &[DVec2]| {
            let mut e = x.to_vec();
            dofs.expand(&mut e);
            let mut y: Vec<DVec2> = e.iter().zip(&k).map(|(e, k)| *e * *k).collect();
            dofs.fold(&mut y);
            dofs.project(&mut y);
            y
        };
        let mut d = k.to_vec();
        dofs.fold_diagonal(&mut d);
        for entry in 0..2 {
            for axis in 0..2 {
                let mut x = vec![DVec2::ZERO; 2];
                x[entry][axis] = 1.0;
                dofs.project(&mut x);
                let y = operator(&x);
                let exact = x[0].dot(y[0]) + x[1].dot(y[1]);
                let folded = d[entry][axis];
                assert!(
                    (folded - exact).abs() < 1e-14,
                    "{entry} {axis}: {folded} vs {exact}"
                );
                assert!(folded > 0.0);
            }
        }
        let mut as_force = k.to_vec();
        dofs.fold(&mut as_force);
        assert!(as_force[1].min_element() <= 1e-15, "{:?}", as_force[1]);
    }
}
