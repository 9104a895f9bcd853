//! What every linear solve on one set of unknowns shares: K's diagonal, the ghost
//! stiffness, the free rigid motions, and the linear solver the scene's size calls for
//! (with the direct solver's pattern and symbolic analysis, made once here).

use super::cg::conjugate_gradients;
use super::direct::{Analysis, Direct};
use super::ghost_stiffness;
use super::operator::{Law, diagonal};
use super::rigid;
use super::unknowns::Unknowns;
use crate::base::dim::Dim;
use crate::base::error::Unstable;
use crate::record::solve_log::Solved;
use crate::store::world::{LinearSolver, World};

/// The shared state of the solves on one set of unknowns.
pub(super) struct Frame<D: Dim> {
    /// K's diagonal on the free components (1 elsewhere).
    pub diag: Vec<D::Vec>,
    /// The ghost stiffness per component ([`super::ghost_stiffness`]).
    pub ghost: Vec<D::Vec>,
    /// An orthonormal basis of the rigid motions K leaves free.
    pub modes: Vec<Vec<D::Vec>>,
    /// The sparse direct solver, when the scene's size and `linear` call for it.
    direct: Option<Direct<D>>,
}

impl<D: Dim> Frame<D> {
    /// The frame of the unknowns `dofs` (`kept`: the direct solver's last analysis, which
    /// takes this frame's). Refuses a direct solve (`linear = "direct"`) whose factor
    /// would not fit in memory.
    pub fn new(
        world: &World<D>,
        dofs: &Unknowns<D>,
        kept: &mut Option<Analysis>,
    ) -> Result<Self, Unstable> {
        let diag = diagonal(world, dofs);
        let largest = (diag.iter().zip(&dofs.free))
            .flat_map(|(d, k)| (0..D::D).filter(|&a| k[a] != 0.0).map(|a| d[a]))
            .fold(0.0, f64::max);
        let setting = world.settings.linear;
        let direct =
            setting == LinearSolver::Direct || (setting == LinearSolver::Auto && D::D == 2);
        let ghost = ghost_stiffness(world, &diag);
        let modes = rigid::free_motions(world, dofs, &ghost, largest);
        let direct = match setting {
            _ if !direct => None,
            LinearSolver::Direct => Some(Direct::new(world, dofs, &modes, kept).map_err(
                |what| Unstable {
                    step: world.step + 1,
                    time: (world.step + 1) as f64 * world.settings.dt,
                    what,
                },
            )?),
            _ => Direct::new(world, dofs, &modes, kept).ok(),
        };
        Ok(Frame {
            diag,
            ghost,
            modes,
            direct,
        })
    }

    /// Solves K u = f on the free components (K the stiffness of `law`, plus the ghost's,
    /// clear of the free rigid motions) to a residual of `tolerance` times |f|: by the
    /// direct solver when the frame has one, else by conjugate gradients from `start` (or
    /// zero).
    pub fn solve(
        &self,
        world: &World<D>,
        law: Law<D>,
        dofs: &Unknowns<D>,
        f: &[D::Vec],
        start: Option<Vec<D::Vec>>,
        tolerance: f64,
    ) -> Result<(Vec<D::Vec>, Solved), Unstable> {
        let Some(direct) = &self.direct else {
            return conjugate_gradients(world, law, self, dofs, f, start, tolerance);
        };
        let (u, mut solved) = direct.solve(world, law, self, dofs, f, tolerance)?;
        if solved.residual <= tolerance {
            return Ok((u, solved));
        }
        // A K nearly singular (entries only the ghost stiffness holds) leaves round-off in
        // the factor that refinement does not remove: conjugate gradients finish from the
        // direct answer, or say why they cannot.
        let (u, cg) = conjugate_gradients(world, law, self, dofs, f, Some(u), tolerance)?;
        solved.iterations += cg.iterations;
        solved.residual = cg.residual;
        Ok((u, solved))
    }
}
