//! What every linear solve on one set of unknowns shares: K's diagonal (the Jacobi
//! preconditioner, from the elastic K), the blocks of weakly supported entries and the
//! coarse grid where there are any, the ghost stiffness and the free rigid motions.

use super::blocks::Blocks;
use super::coarse::Coarse;
use super::ghost_stiffness;
use super::operator::diagonal;
use super::rigid;
use super::unknowns::Unknowns;
use super::vectors::Sums;
use crate::base::dim::Dim;
use crate::store::world::World;
use std::sync::Arc;

/// The shared state of the solves on one set of unknowns.
pub(super) struct Frame<D: Dim> {
    /// K's diagonal on the free components (1 elsewhere).
    pub diag: Vec<D::Vec>,
    /// The ghost stiffness per component ([`super::ghost_stiffness`]).
    pub ghost: Vec<D::Vec>,
    /// An orthonormal basis of the rigid motions K leaves free.
    pub modes: Vec<Vec<D::Vec>>,
    /// The coarse grid under the Jacobi preconditioner, where the solver has one.
    pub coarse: Option<Arc<Coarse>>,
    /// Block Jacobi on the weakly supported entries, where an iterative solve has any.
    pub blocks: Option<Blocks<D>>,
}

impl<D: Dim> Frame<D> {
    /// The frame of the unknowns `dofs`, with the `coarse` grid given.
    pub fn new(world: &World<D>, dofs: &Unknowns<D>, coarse: Option<Arc<Coarse>>) -> Self {
        let diag = diagonal(world, dofs);
        let largest = (diag.iter().zip(&dofs.free))
            .flat_map(|(d, k)| (0..D::D).filter(|&a| k[a] != 0.0).map(|a| d[a]))
            .fold(0.0, f64::max);
        let largest = Sums::of(world).max(largest);
        let ghost = ghost_stiffness(world, &diag);
        let modes = rigid::free_motions(world, dofs, &ghost, largest);
        Frame {
            diag,
            ghost,
            modes,
            coarse,
            blocks: None,
        }
    }
}
