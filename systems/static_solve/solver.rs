//! The linear solver of one set of unknowns: the sparse direct factorization or conjugate
//! gradients (with Jacobi, or Jacobi and the coarse grid), as `[simulation] linear`, the
//! scene's dimension and the ranks choose, on the unknowns' [`Frame`] (with the direct
//! solver's pattern and symbolic analysis, or the coarse grid's factor, made once here).

use super::Kept;
use super::blocks::Blocks;
use super::cg::conjugate_gradients;
use super::coarse::Coarse;
use super::direct::Direct;
use super::frame::Frame;
use super::operator::Law;
use super::unknowns::Unknowns;
use crate::base::dim::Dim;
use crate::base::error::Unstable;
use crate::record::solve_log::Solved;
use crate::store::world::{LinearSolver, World};
use std::sync::Arc;

/// Particles from which a 2D scene solved by Newton iterations takes the coarse grid under
/// "auto": the direct solver factorizes the tangent at every iteration, the coarse grid
/// once a run, and from about 10^4 particles the conjugate gradients cost less than the
/// factorizations (docs/static-solver.md, "Linear solves").
const NEWTON_TWO_LEVEL_PARTICLES: usize = 10_000;

/// The largest Poisson's ratio at which "auto" takes the coarse grid for Newton iterations:
/// conjugate gradients slow as the bulk stiffness outgrows the shear (on the plastic
/// cylinder they break even with the factorizations at nu = 0.4 and take 45 times as long
/// at 0.4999).
const NEWTON_TWO_LEVEL_NU: f64 = 0.35;

/// Whether a 2D scene's Newton iterations (a J2 material) are solved faster by conjugate
/// gradients with the coarse grid than by a factorization per iteration.
fn newton_pays_for_two_level<D: Dim>(world: &World<D>) -> bool {
    let p = &world.particles;
    !p.hardened.is_empty()
        && p.len() >= NEWTON_TWO_LEVEL_PARTICLES
        && (world.materials.iter()).all(|m| m.poisson <= NEWTON_TWO_LEVEL_NU)
}

/// The solves on one set of unknowns.
pub(super) struct Solver<D: Dim> {
    /// What they share.
    pub frame: Frame<D>,
    /// The sparse direct solver, when the scene's dimension and `linear` call for it.
    direct: Option<Direct<D>>,
    /// Whether "auto" chose the direct solver and its factor was too large.
    too_large: bool,
}

impl<D: Dim> Solver<D> {
    /// The solver of the unknowns `dofs` (`kept`: the last load step's direct analysis and
    /// coarse grid, reused when they fit these unknowns, else replaced by this one's).
    /// Refuses a direct solve (`linear = "direct"`) whose factor would not fit in memory;
    /// under "auto" such a scene goes to conjugate gradients.
    pub fn new(world: &World<D>, dofs: &Unknowns<D>, kept: &mut Kept) -> Result<Self, Unstable> {
        let failed = |what: String| Unstable {
            step: world.step + 1,
            time: (world.step + 1) as f64 * world.settings.dt,
            what,
        };
        let split = world.domain.is_split();
        let auto_two_level = D::D == 3 || split || newton_pays_for_two_level(world);
        let coarse = match world.settings.linear {
            LinearSolver::TwoLevel => true,
            LinearSolver::Auto => auto_two_level,
            _ => false,
        };
        let coarse = match (coarse, &kept.coarse) {
            (false, _) => None,
            (true, Some(c)) if c.fits(world, dofs) => Some(c.clone()),
            (true, last) => {
                let last = last.as_deref();
                let c = Coarse::new(world, dofs, last).map_err(failed)?;
                if last.is_none_or(|l| !c.shares_factor(l)) {
                    kept.coarse_factorizations += 1;
                }
                let c = Arc::new(c);
                kept.coarse = Some(c.clone());
                Some(c)
            }
        };
        let mut frame = Frame::new(world, dofs, coarse);
        let (direct, too_large) = match world.settings.linear {
            LinearSolver::Cg | LinearSolver::TwoLevel => (None, false),
            LinearSolver::Auto if auto_two_level => (None, false),
            LinearSolver::Auto => {
                match Direct::new(world, dofs, &frame.modes, &mut kept.analysis) {
                    Ok(d) => (Some(d), false),
                    Err(_) => (None, true),
                }
            }
            LinearSolver::Direct => {
                let direct =
                    Direct::new(world, dofs, &frame.modes, &mut kept.analysis).map_err(failed)?;
                (Some(direct), false)
            }
        };
        if direct.is_none() {
            frame.blocks = Blocks::new(world, dofs, &frame.ghost);
        }
        Ok(Solver {
            frame,
            direct,
            too_large,
        })
    }

    /// Solves K u = f on the free components (K the stiffness of `law`, plus the ghost's,
    /// clear of the free rigid motions) to a residual of `tolerance` times |f|: by the
    /// direct solver when there is one, else by conjugate gradients from `start` (or
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
        let frame = &self.frame;
        let Some(direct) = &self.direct else {
            let (u, mut solved) =
                conjugate_gradients(world, law, frame, dofs, f, start, tolerance)?;
            solved.too_large = self.too_large;
            return Ok((u, solved));
        };
        let (u, mut solved) = direct.solve(world, law, frame, dofs, f, tolerance)?;
        if solved.residual <= tolerance {
            return Ok((u, solved));
        }
        // A K nearly singular (entries only the ghost stiffness holds) leaves round-off in
        // the factor that refinement does not remove: conjugate gradients finish from the
        // direct answer, or say why they cannot.
        let (u, cg) = conjugate_gradients(world, law, frame, dofs, f, Some(u), tolerance)?;
        solved.iterations += cg.iterations;
        solved.residual = cg.residual;
        Ok((u, solved))
    }
}
