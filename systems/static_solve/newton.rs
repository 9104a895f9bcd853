//! A static load step of a scene with J2 plastic materials: Newton-Raphson on the grid
//! entries' displacement increment. Each iterate gives every particle its stress from the
//! state the last load step committed, by the return map (backward Euler: the same update
//! the explicit solver makes, in one increment), and each linear solve uses the return's
//! algorithmic tangent (Simo & Taylor 1985; in plane stress by central differences of the
//! projected return, Miehe 1996), which keeps the iteration quadratic. The
//! particles' state changes only when the step converges.

use super::Kept;
use super::frame::Frame;
use super::operator::{Law, mask, stiffness};
use super::solver::Solver;
use super::unknowns::Unknowns;
use super::vectors::Sums;
use super::{Linear, equilibrium, gradient, rigid};
use crate::base::dim::Dim;
use crate::base::error::Unstable;
use crate::base::sym::SymTensor;
use crate::physics::material::Plane;
use crate::physics::plastic::{Hardened, Tangent};
use crate::record::solve_log::Solved;
use crate::store::world::World;
use rayon::prelude::*;

/// Most Newton iterations in a load step: with the consistent tangent a step that
/// converges at all does so in a handful; one that has not by then is past a limit load
/// or needs smaller steps.
const NEWTON_ITERATIONS: usize = 30;

/// Most halvings of a Newton correction that raises the residual (a backtracking line
/// search): a return map that switches many particles between elastic and plastic at once
/// can overshoot; a correction that helps at none of these lengths is not a descent.
const HALVINGS: usize = 6;

/// The loosest and tightest relative tolerance of a Newton iteration's linear solve
/// (inexact Newton, Eisenstat & Walker 1996): loose while the residual is far above the
/// goal (an exact solve of a wrong tangent buys nothing), tight enough near it that the
/// next residual is the tangent's, not the solver's.
const LINEAR_TOLERANCE: (f64, f64) = (1e-2, 1e-1);

/// The particles' state at a trial increment: each one's stress, plastic strain and
/// hardening from its committed state by the return map, and the return's tangent (None
/// where the particle stays elastic).
pub(super) struct Returned<D: Dim> {
    /// Stress (Pa).
    pub stress: Vec<D::Sym>,
    /// Plastic strain.
    pub plastic: Vec<D::Sym>,
    /// Hardening state.
    pub hardened: Vec<Hardened>,
    /// Algorithmic tangent of the return.
    pub tangents: Vec<Option<Tangent>>,
}

/// A converged plastic load step.
pub(super) struct Step<D: Dim> {
    /// Every grid entry's displacement increment over the step.
    pub du: Vec<D::Vec>,
    /// The particles' state at it.
    pub returned: Returned<D>,
    /// What the solves took.
    pub solved: Solved,
}

/// Solves the load step on the unknowns `dofs`: the loads now in the grid's force column
/// and the sliding crack faces' `friction` (per entry), the moving supports' displacement
/// increment `held` over the step.
pub(super) fn solve<D: Dim>(
    world: &World<D>,
    kept: &mut Kept,
    dofs: &Unknowns<D>,
    held: Option<&[D::Vec]>,
    friction: Option<&[D::Vec]>,
    t_end: f64,
) -> Result<Step<D>, Unstable> {
    let mut external = world.grid.force.clone();
    if let Some(friction) = friction {
        external
            .iter_mut()
            .zip(friction)
            .for_each(|(f, &t)| *f += t);
    }
    let solver = Solver::new(world, dofs, kept)?;
    let frame = &solver.frame;
    let entries = world.grid.mass.len();
    // The first correction: the continuum tangent of the committed state (which a resumed
    // run finds the same) on the load less the committed stresses' force, with the
    // supports' increment.
    let mut f_int = vec![D::zero(); entries];
    let none = vec![D::zero(); entries];
    let committed = Law::Given(&world.particles.stress);
    stiffness(world, committed, &none, dofs, &mut f_int);
    let unbalanced = (external.iter().zip(&f_int))
        .map(|(&f, &q)| f - q)
        .collect();
    let tolerance = world.settings.tolerance;
    let tangents = continuum(world);
    let first = Linear {
        law: Law::Tangent(&tangents),
        tolerance: LINEAR_TOLERANCE.0,
    };
    let (mut du, mut solved) = equilibrium(world, dofs, &solver, first, unbalanced, held, None)?;
    let load = Load::new(world, dofs, &external, held);
    let mut now = residual(world, dofs, frame, &load, &du);
    let mut history = vec![now.relative()];
    for newton in 1..=NEWTON_ITERATIONS {
        if now.relative() <= tolerance {
            solved.newton = newton;
            solved.residual = now.relative();
            return Ok(Step {
                du,
                returned: now.returned,
                solved,
            });
        }
        let eta = (0.1 * tolerance / now.relative()).clamp(LINEAR_TOLERANCE.0, LINEAR_TOLERANCE.1);
        let law = Law::Tangent(&now.returned.tangents);
        let (mut delta, linear) = solver.solve(world, law, dofs, &now.r, None, eta)?;
        solved.iterations += linear.iterations;
        solved.factorizations += linear.factorizations;
        dofs.expand(&mut delta);
        let mut length = 1.0;
        let next = loop {
            let trial: Vec<D::Vec> = (du.iter().zip(&delta))
                .map(|(&u, &d)| u + d * length)
                .collect();
            let then = residual(world, dofs, frame, &load, &trial);
            if then.norm < now.norm || length < 0.5f64.powi(HALVINGS as i32) {
                du = trial;
                break then;
            }
            length *= 0.5;
        };
        if next.norm >= now.norm {
            history.push(next.relative());
            return Err(diverged(world, t_end, &history, friction.is_some()));
        }
        now = next;
        history.push(now.relative());
    }
    Err(diverged(world, t_end, &history, friction.is_some()))
}

/// The error of a load step whose Newton iteration did not converge, with its residuals
/// and, where crack faces rub (`rubbing`), the other cause seen on such scenes.
fn diverged<D: Dim>(world: &World<D>, t_end: f64, history: &[f64], rubbing: bool) -> Unstable {
    let list: Vec<String> = history.iter().map(|r| format!("{r:.2e}")).collect();
    let faces = if rubbing {
        "; or the Coulomb faces' friction forces hold it up (seen on 3D cracks oblique to \
         the grid: frictionless faces or solver = \"explicit\" may answer)"
    } else {
        ""
    };
    Unstable {
        step: world.step + 1,
        time: t_end,
        what: format!(
            "the plastic load step did not converge in {} Newton iterations (relative \
             residuals {}): past a limit load, or too large a load step (give more \
             `load_steps`){faces}",
            history.len() - 1,
            list.join(", ")
        ),
    }
}

/// The step's external force, folded onto the unknowns, and the squared force a residual is
/// measured against at least.
struct Load<D: Dim> {
    force: Vec<D::Vec>,
    norm2: f64,
}

/// The least force a residual is measured against, as a fraction of the force the
/// supports' increment would exert on the body held still (elastic K u_c): where the body
/// carries next to no load (a piece the supports move rigidly) the residual is round-off,
/// and against round-off it would never converge. Any loaded scene's force is far above it.
const DRIVE_FLOOR: f64 = 1e-3;

impl<D: Dim> Load<D> {
    /// The `external` force per entry, on `dofs`, with the supports' increment `held`.
    fn new(
        world: &World<D>,
        dofs: &Unknowns<D>,
        external: &[D::Vec],
        held: Option<&[D::Vec]>,
    ) -> Self {
        let sums = Sums::of(world);
        let mut force = external.to_vec();
        dofs.fold(&mut force);
        let drive2 = held.map_or(0.0, |u_c| {
            let mut k_c = vec![D::zero(); u_c.len()];
            stiffness(world, Law::Elastic, u_c, dofs, &mut k_c);
            sums.dot::<D>(&k_c, &k_c)
        });
        let norm2 = sums
            .dot::<D>(&force, &force)
            .max(DRIVE_FLOOR * DRIVE_FLOOR * drive2);
        Load { force, norm2 }
    }
}

/// The out-of-balance force at an increment, with the state it came from.
struct Residual<D: Dim> {
    /// f_ext - f_int on the free components, rigid motions taken out.
    r: Vec<D::Vec>,
    /// |r|.
    norm: f64,
    /// The force it is measured against: the larger of |f_ext| and |f_int| (which holds
    /// the supports' reactions, and so measures a scene driven by moving supports).
    scale: f64,
    /// The particles' state at the increment.
    returned: Returned<D>,
}

impl<D: Dim> Residual<D> {
    /// |r| over the scale (0 for a scene with no force at all).
    fn relative(&self) -> f64 {
        if self.scale > 0.0 {
            self.norm / self.scale
        } else {
            0.0
        }
    }
}

/// The residual at the increment `du` (every entry's).
fn residual<D: Dim>(
    world: &World<D>,
    dofs: &Unknowns<D>,
    frame: &Frame<D>,
    load: &Load<D>,
    du: &[D::Vec],
) -> Residual<D> {
    let sums = Sums::of(world);
    let returned = return_map(world, dofs, du);
    let mut f_int = vec![D::zero(); du.len()];
    stiffness(world, Law::Given(&returned.stress), du, dofs, &mut f_int);
    let scale = load.norm2.max(sums.dot::<D>(&f_int, &f_int)).sqrt();
    let mut r: Vec<D::Vec> = (load.force.iter().zip(&f_int).zip(&dofs.free))
        .map(|((&f, &q), &k)| mask::<D>(f - q, k))
        .collect();
    dofs.project(&mut r);
    rigid::deflate::<D>(sums, &mut r, &frame.modes);
    let norm = sums.dot::<D>(&r, &r).sqrt();
    Residual {
        r,
        norm,
        scale,
        returned,
    }
}

/// Each particle's continuum tangent at its committed state (None: elastic).
fn continuum<D: Dim>(world: &World<D>) -> Vec<Option<Tangent>> {
    let p = &world.particles;
    // In plane stress the first correction is elastic: the line search and the iterations'
    // tangents (of the projected return) take it from there.
    let plane_stress = world.settings.plane == Plane::Stress;
    (0..p.len())
        .into_par_iter()
        .map(|i| {
            let m = &world.materials[p.material[i] as usize];
            (m.j2.as_ref().filter(|_| !plane_stress))
                .and_then(|j2| j2.continuum_tangent(&p.stress[i].to_sym3(), &p.hardened[i]))
        })
        .collect()
}

/// Every particle's state at the increment `du`: the committed stress plus the elastic
/// increment of sym(grad du) (its dilatation its group's mean, with `dofs`' groups),
/// returned to the yield surface of the committed hardening.
fn return_map<D: Dim>(world: &World<D>, dofs: &Unknowns<D>, du: &[D::Vec]) -> Returned<D> {
    let p = &world.particles;
    let plane = world.settings.plane;
    let grouped = dofs
        .groups
        .as_ref()
        .map(|g| g.gradients(world, |i| gradient(world, i, du)));
    let states: Vec<_> = (0..p.len())
        .into_par_iter()
        .map(|i| {
            let m = &world.materials[p.material[i] as usize];
            let l = grouped
                .as_ref()
                .map_or_else(|| gradient(world, i, du), |g| g[i]);
            let mut s = p.stress[i].to_sym3();
            let mut plastic = p.plastic_strain[i].to_sym3();
            let mut h = p.hardened[i];
            let de = D::sym_part(&l);
            let tangent = if m.j2.is_some() {
                m.update_plastic_tangent(plane, de, &mut s, &mut plastic, &mut h)
            } else {
                m.update(plane, de, &mut s);
                None
            };
            (D::Sym::from_sym3(s), D::Sym::from_sym3(plastic), h, tangent)
        })
        .collect();
    let mut out = Returned {
        stress: Vec::with_capacity(states.len()),
        plastic: Vec::with_capacity(states.len()),
        hardened: Vec::with_capacity(states.len()),
        tangents: Vec::with_capacity(states.len()),
    };
    for (s, e, h, t) in states {
        out.stress.push(s);
        out.plastic.push(e);
        out.hardened.push(h);
        out.tangents.push(t);
    }
    out
}

/// Commits the converged step to the particles: their new stress, plastic strain and
/// hardening, grad u advanced by grad du (when kept), x = x0 + `disp`, at rest.
pub(super) fn commit<D: Dim>(world: &mut World<D>, step: Step<D>, disp: &[D::Vec]) {
    let keep = !world.particles.grad_u.is_empty();
    if keep {
        let grads: Vec<D::Mat> = (0..disp.len())
            .into_par_iter()
            .map(|i| gradient(world, i, &step.du))
            .collect();
        let p = &mut world.particles;
        p.grad_u
            .iter_mut()
            .zip(grads)
            .for_each(|(g, l)| *g = *g + l);
    }
    let p = &mut world.particles;
    let r = step.returned;
    p.stress = r.stress;
    p.plastic_strain = r.plastic;
    p.hardened = r.hardened;
    for (i, &d) in disp.iter().enumerate() {
        p.x[i] = p.x0[i] + d;
        p.v[i] = D::zero();
    }
    world.tiles.fresh = false;
}
