//! `static_solve`: one load step of a static scene (`[simulation] solver = "static"`): the
//! equilibrium K u = f_ext(t) of the particles' small-strain linear elastic stiffness on
//! the grid entries (a node's own, and one per crack field where the classification gives
//! the node more than one: Guo & Nairn 2D (2004) Eqs. 3 and 6 with the stress from the
//! strain), solved by a sparse Cholesky factorization of the assembled K (direct.rs) or
//! matrix-free by conjugate gradients with a Jacobi preconditioner (cg.rs), as
//! `[simulation] linear` and the scene's dimension choose (solver.rs); then each particle
//! takes the displacement, its gradient and the stress they give. A scene with J2 plastic
//! materials takes Newton iterations instead (newton.rs).
//! Particles are the quadrature points with their volumes and the scene's shape functions,
//! at their initial positions (small strain: neither the stiffness nor the cracks move),
//! each particle near a crack on its own side's entries.

use crate::base::dim::Dim;
use crate::base::error::Unstable;
use crate::base::exact_sum::ExactSum;
use crate::ranks::ABSENT;
use crate::record::solve_log::Solved;
use crate::store::crack::Fields;
use crate::store::world::World;
use crate::systems::{
    bin, classify, crack_advect, each_entry, entry_gradient as gradient, mirror, p2g,
};
use std::mem::discriminant;
use std::sync::Arc;

mod blocks;
mod cg;
mod cholesky;
mod coarse;
mod direct;
mod element;
mod faces;
mod frame;
mod hold;
mod newton;
mod operator;
mod recover;
mod rigid;
mod scatter;
mod solver;
mod supports;
mod unknowns;
mod vectors;

use coarse::Coarse;
use direct::Analysis;
use faces::Face;
use operator::{Law, elastic, entry_stiffness, mask, stiffness};
use scatter::entry_sums;
use solver::Solver;
use unknowns::{Unknowns, ones};
use vectors::Sums;

/// Most of the load (as a fraction of its norm) a body free to move may leave unbalanced:
/// the discrete imbalance of balanced tractions is far below it; a load that would
/// accelerate the body as a whole is far above it.
const IMBALANCE: f64 = 1e-3;

/// The ghost stiffness: each unknown's own diagonal stiffness times this, added to K on the
/// entries with little support: the nodes a body's edge cuts obliquely (a sliver of a cell,
/// a particle's corner) and a crack's fields, which split nodes among the few particles on
/// each side. There K leaves local motions that cost almost no strain energy, and on them
/// conjugate gradients lose the round-off battle and diverge (the DCB turned 30 degrees to
/// the grid did). A stiffness this small makes K positive definite again (the ghost-penalty
/// idea of Burman 2010, in its simplest, diagonal form) and leaves the answer as it was:
/// that DCB's K_I reads the same five digits with 1e-10, 1e-11 and 1e-12, on these entries
/// or on all.
const GHOST: f64 = 1e-11;

/// The ghost stiffness, as [`GHOST`], of the entries next to a crack that one particle alone
/// reaches ([`scatter::lone_entries`]): their zero-energy modes are not loaded, yet held at
/// 1e-11 the solver's round-off moved them by 0.1 m on a frictionless penny cutting the grid
/// obliquely (the body's displacements 5 um) and its ghost share passed [`GHOST_SHARE`].
const LONE_GHOST: f64 = 1e-8;

/// An entry is light, and takes the ghost stiffness, below this fraction of the heaviest
/// entry's mass. The sliver nodes of the turned DCB lie below it; a box's edge and corner
/// nodes (a half and a quarter) above. At 3 % the turned DCB's K moved in the fourth digit.
const LIGHT: f64 = 0.1;

/// What a static scene keeps from one load step to the next: the direct solver's symbolic
/// analysis, reused while K's pattern holds, and the coarse grid of `"two_level"`, reused
/// while the supports and the crack fields under the particles hold.
#[derive(Clone, Debug, Default)]
pub struct Kept {
    analysis: Option<Analysis>,
    coarse: Option<Arc<Coarse>>,
    /// The coarse grid's stiffnesses factorized so far.
    coarse_factorizations: u64,
}

impl Kept {
    /// The coarse grid's stiffnesses factorized since this was made (a run resumed from a
    /// snapshot makes its first afresh).
    pub fn coarse_factorizations(&self) -> u64 {
        self.coarse_factorizations
    }
}

/// Solves the load step ending at the next step's time and sets the particles to it: x =
/// x0 + u, v = 0, grad u and the stress it gives; adds the work of the loads and the moving
/// supports over the step (trapezoidal, exact for a linear response). Refuses a solve that
/// does not converge. `kept` carries the solvers' set-up from step to step ([`Kept`]).
pub fn run<D: Dim>(world: &mut World<D>, kept: &mut Kept) -> Result<Solved, Unstable> {
    let t_end = end_time(world);
    let before: Vec<D::Vec> = (world.particles.x.iter())
        .zip(&world.particles.x0)
        .map(|(&x, &x0)| x - x0)
        .collect();
    // The stiffness lives on the initial positions.
    let p = &mut world.particles;
    let x = std::mem::replace(&mut p.x, p.x0.clone());
    world.tiles.fresh = false;
    bin::run(world)?;
    classify_undeformed(world)?;
    // Mass (which nodes the particles support) and the loads at the step's end.
    let t_start = world.time;
    world.time = t_end;
    p2g::run(world, false);
    world.time = t_start;
    let g = world.settings.gravity;
    let grid = &mut world.grid;
    for (f, &m) in grid.force.iter_mut().zip(&grid.mass) {
        *f += g * m;
    }
    if hold::unchanged(world, t_start, t_end) {
        world.particles.x.copy_from_slice(&x);
        supports::reactions_at_rest(world, t_end);
        // No solve: a row with no contact round (`Solved::kept`).
        return Ok(Solved::default());
    }
    if let Some(c) = &mut world.cracks {
        c.solved = Some(c.topology.version());
    }
    let held = supports::prescribed(world, t_end);
    let start_forces = supports::start_forces(world, t_start);
    if !world.particles.hardened.is_empty() {
        let ends = (t_start, t_end);
        return plastic_step(world, kept, held, &start_forces, &before, ends);
    }
    // Conjugate gradients start from the last load step's answer, carried by the
    // particles: a step whose load and cracks changed little needs fewer iterations.
    let guess = (world.step > 0).then(|| entry_displacements(world, &before));
    let Solution {
        u,
        dofs,
        solved,
        friction,
    } = with_contact(world, kept, held.as_deref(), guess, (&before, t_end))?;
    reactions(world, &dofs, Law::Elastic, &u);
    let after = gather(world, &u);
    move_cracks(world, &before, &after);
    let work = load_work(world, &before, &after, t_start, t_end)
        + supports::work(world, &start_forces, t_start, t_end);
    world.work.external += work;
    world.work.friction += friction;
    set_particles(world, &dofs, &u, &after);
    Ok(solved)
}

/// The load step of a scene with plastic materials ([`newton`]), its crack faces' contact
/// settled by the same active set as a linear step's: the supports move by their increment
/// over the step, from `held` (their displacement at the step's end).
fn plastic_step<D: Dim>(
    world: &mut World<D>,
    kept: &mut Kept,
    held: Option<Vec<D::Vec>>,
    start_forces: &[Vec<D::Vec>],
    before: &[D::Vec],
    (t_start, t_end): (f64, f64),
) -> Result<Solved, Unstable> {
    let increment = held.map(|mut end| {
        let start = supports::prescribed(world, t_start).unwrap_or_default();
        end.iter_mut().zip(&start).for_each(|(e, &s)| *e -= s);
        end
    });
    let pairs = faces::pairs(world);
    let any_pairs = world.domain.any(!pairs.is_empty());
    let mut faces = vec![Face::Open; pairs.len()];
    let mut opened = vec![0; pairs.len()];
    let rubbing = world.domain.any(pairs.iter().any(|p| p.friction.is_some()));
    // The entries' displacement at the step's start, which the faces' overlap adds to:
    // where faces rub, the one the particles carry (their slip counts from there).
    let start = if !any_pairs {
        Vec::new()
    } else if rubbing && world.step > 0 {
        recover::recovered(world, before)
    } else {
        entry_displacements(world, before)
    };
    let (mut iterations, mut factorizations, mut newton) = (0, 0, 0);
    let mut rounds = 0;
    let (dofs, mut step) = loop {
        let dofs = Unknowns::new(world, &pairs, &faces);
        let friction = rubbing.then(|| {
            let mut f = vec![D::zero(); world.grid.mass.len()];
            faces::add_friction::<D>(&pairs, &faces, &mut f);
            f
        });
        let (held, friction) = (increment.as_deref(), friction.as_deref());
        let step = newton::solve(world, kept, &dofs, held, friction, t_end)?;
        iterations += step.solved.iterations;
        factorizations += step.solved.factorizations;
        newton += step.solved.newton;
        rounds += 1;
        if !any_pairs {
            break (dofs, step);
        }
        let u: Vec<D::Vec> = (start.iter().zip(&step.du)).map(|(&a, &d)| a + d).collect();
        let zero = vec![D::zero(); u.len()];
        let law = Law::Given(&step.returned.stress);
        let changes = faces_round(
            world,
            &pairs,
            (&mut faces, &mut opened),
            (&u, &start),
            (law, &zero),
        );
        if changes.none() {
            break (dofs, step);
        }
        if rounds >= CONTACT_ROUNDS {
            return Err(unsettled(world, t_end, rounds, changes));
        }
    };
    step.solved.iterations = iterations;
    step.solved.factorizations = factorizations;
    step.solved.newton = newton;
    step.solved.contact_rounds = rounds;
    step.solved.closed_faces = closed_count(world, &pairs, &faces);
    if rubbing {
        let u: Vec<D::Vec> = (start.iter().zip(&step.du)).map(|(&a, &d)| a + d).collect();
        world.work.friction += friction_work(world, &pairs, &faces, (&u, &start));
    }
    reactions(world, &dofs, Law::Given(&step.returned.stress), &step.du);
    let after: Vec<D::Vec> = (before.iter().zip(gather(world, &step.du)))
        .map(|(&b, d)| b + d)
        .collect();
    move_cracks(world, before, &after);
    let work = load_work(world, before, &after, t_start, t_end)
        + supports::work(world, start_forces, t_start, t_end);
    world.work.external += work;
    let solved = step.solved;
    newton::commit(world, step, &after);
    Ok(solved)
}

/// Classifies the particles, at their initial places, against the cracks where they lie in
/// the undeformed body (their places before the first load step, moved by growth only):
/// K is the undeformed body's, and the cracks moved with the solutions, a fraction of a
/// cell in a slender beam, would split other particle-node pairs from step to step.
fn classify_undeformed<D: Dim>(world: &mut World<D>) -> Result<(), Unstable> {
    let Some(c) = world.cracks.as_mut() else {
        return Ok(());
    };
    let g = &mut c.geometry;
    if g.x0.len() != g.x.len() {
        g.x0 = g.x.clone();
    }
    let deformed = std::mem::replace(&mut g.x, g.x0.clone());
    let classified = classify::run(world);
    if let Some(c) = world.cracks.as_mut() {
        c.geometry.x = deformed;
    }
    classified
}

/// Each entry's mass-weighted displacement from the particles' `disp` (as the explicit
/// contact measures it, Guo & Nairn 3D (2006) Eq. 68); zero on an entry without mass.
fn entry_displacements<D: Dim>(world: &World<D>, disp: &[D::Vec]) -> Vec<D::Vec> {
    let mass = &world.grid.mass;
    let p = &world.particles;
    let sums = entry_sums(world, |i, w, _| disp[i] * (p.mass[i] * w));
    (sums.into_iter().zip(mass))
        .map(|(s, &m)| if m > 0.0 { s * (1.0 / m) } else { D::zero() })
        .collect()
}

/// The error of a load step whose crack-face contact did not settle: what its last round
/// changed, and, when only friction moved, what to try.
fn unsettled(world: &World<impl Dim>, t_end: f64, rounds: usize, last: faces::Changes) -> Unstable {
    let friction = if last.slid == 0 {
        String::new()
    } else if last.closed + last.opened == 0 {
        format!(
            ", and changed only the friction of {} sliding or stuck pairs: Coulomb friction's \
             fixed point was not reached; a smaller `friction`, frictionless faces or \
             solver = \"explicit\" may answer",
            last.slid
        )
    } else {
        format!(", and changed the friction of {} more", last.slid)
    };
    Unstable {
        step: world.step + 1,
        time: t_end,
        what: format!(
            "the crack faces' contact did not settle in {rounds} solves (the last closed {} \
             pairs and opened {}{friction})",
            last.closed, last.opened
        ),
    }
}

/// A load step's answer.
struct Solution<D: Dim> {
    /// Every grid entry's displacement.
    u: Vec<D::Vec>,
    /// The unknowns of the last solve.
    dofs: Unknowns<D>,
    /// What the solves took, all together.
    solved: Solved,
    /// The energy the sliding faces dissipated over the step (J).
    friction: f64,
}

/// The load step's equilibrium with its crack faces' contact settled: solves until the
/// active set of closed face pairs changes no more (one solve without such faces); the
/// first conjugate-gradient solve starts from `guess` (every entry's displacement).
fn with_contact<D: Dim>(
    world: &World<D>,
    kept: &mut Kept,
    held: Option<&[D::Vec]>,
    guess: Option<Vec<D::Vec>>,
    (before, t_end): (&[D::Vec], f64),
) -> Result<Solution<D>, Unstable> {
    let pairs = faces::pairs(world);
    let any_pairs = world.domain.any(!pairs.is_empty());
    let rubbing = world.domain.any(pairs.iter().any(|p| p.friction.is_some()));
    // A face's slip is over the step: from the entries' displacement at its start.
    let start = if rubbing && world.step > 0 {
        recover::recovered(world, before)
    } else {
        Vec::new()
    };
    let mut faces = vec![Face::Open; pairs.len()];
    let mut opened = vec![0; pairs.len()];
    let (mut iterations, mut factorizations) = (0, 0);
    let mut rounds = 0;
    let mut last = guess;
    // The unknowns and their solver, kept over the rounds that move only friction forces
    // (every rank alike: a new solver takes collectives).
    let kinds = |faces: &[Face<D::Vec>]| -> Vec<_> { faces.iter().map(discriminant).collect() };
    let mut built: Option<(Vec<_>, Unknowns<D>, Solver<D>)> = None;
    let (u, mut solved) = loop {
        let now = kinds(&faces);
        if world.domain.any(built.as_ref().is_none_or(|b| b.0 != now)) {
            let dofs = Unknowns::new(world, &pairs, &faces);
            let solver = Solver::new(world, &dofs, kept)?;
            built = Some((now, dofs, solver));
        }
        let Some((_, dofs, solver)) = built.as_mut() else {
            unreachable!("the unknowns are built before the first round")
        };
        dofs.set_springs(&pairs, &faces);
        let (dofs, solver) = (&*dofs, &*solver);
        let mut load = world.grid.force.clone();
        faces::add_friction::<D>(&pairs, &faces, &mut load);
        // The friction tangents act on the slip over the step, from the step's start.
        if !start.is_empty() {
            faces::add_spring_forces::<D>(&dofs.springs, &start, &mut load);
        }
        let tied = |s: usize, m: usize| dofs.ties.binary_search(&(s, m)).is_ok();
        let kept_slip = faces::kept_slip::<D>(&pairs, &faces, &start, tied);
        // Every rank alike, with or without stuck pairs of its own: K d is a collective.
        let kept_slip = match world.domain.any(kept_slip.is_some()) {
            true => Some(kept_slip.unwrap_or_else(|| vec![D::zero(); start.len()])),
            false => None,
        };
        if let Some(d) = &kept_slip {
            let mut kd = vec![D::zero(); d.len()];
            stiffness(
                world,
                Law::Elastic,
                d,
                &Unknowns::new(world, &[], &[]),
                &mut kd,
            );
            load.iter_mut().zip(&kd).for_each(|(f, &k)| *f -= k);
        }
        let linear = Linear::elastic(world);
        let (mut u, solved) =
            equilibrium(world, dofs, solver, linear, load, held, last.as_deref())?;
        if let Some(d) = &kept_slip {
            u.iter_mut().zip(d).for_each(|(u, &d)| *u += d);
        }
        iterations += solved.iterations;
        factorizations += solved.factorizations;
        rounds += 1;
        if !any_pairs {
            break (u, solved);
        }
        let changes = faces_round(
            world,
            &pairs,
            (&mut faces, &mut opened),
            (&u, &start),
            (Law::Elastic, &u),
        );
        if changes.none() {
            break (u, solved);
        }
        last = Some(u);
        if rounds >= CONTACT_ROUNDS {
            return Err(unsettled(world, t_end, rounds, changes));
        }
    };
    let Some((_, dofs, _)) = built else {
        unreachable!("a round was solved")
    };
    solved.iterations = iterations;
    solved.factorizations = factorizations;
    solved.contact_rounds = rounds;
    solved.closed_faces = closed_count(world, &pairs, &faces);
    let friction = if rubbing {
        friction_work(world, &pairs, &faces, (&u, &start))
    } else {
        0.0
    };
    Ok(Solution {
        u,
        dofs,
        solved,
        friction,
    })
}

/// How a linear solve is made: the stiffness, and the residual (relative to the load) at
/// which it stops.
#[derive(Clone, Copy)]
struct Linear<'a, D: Dim> {
    law: Law<'a, D>,
    tolerance: f64,
}

impl<D: Dim> Linear<'_, D> {
    /// The elastic K to the scene's tolerance: a linear scene's load step.
    fn elastic(world: &World<D>) -> Self {
        Linear {
            law: Law::Elastic,
            tolerance: world.settings.tolerance,
        }
    }
}

/// The time at the end of the load step being solved.
fn end_time<D: Dim>(world: &World<D>) -> f64 {
    (world.step + 1) as f64 * world.settings.dt
}

/// Most solves a load step's contact active set may take: each round closes the pairs
/// that overlap and opens those that pull, and a few rounds settle a face.
const CONTACT_ROUNDS: usize = 50;

/// Equilibrium with the unknowns `dofs` (and their `solver`) under `linear`'s K: K u_f =
/// load - K u_c on the free components (`load` per grid entry, u_c the moving supports'
/// displacement `held`), the rigid motions K leaves free taken out, from `guess` (every
/// entry's displacement) or from zero; returns every entry's displacement u_f + u_c (tied
/// entries given their partners'). Refuses a load that would move a free body as a whole.
fn equilibrium<D: Dim>(
    world: &World<D>,
    dofs: &Unknowns<D>,
    solver: &Solver<D>,
    linear: Linear<D>,
    mut load: Vec<D::Vec>,
    held: Option<&[D::Vec]>,
    guess: Option<&[D::Vec]>,
) -> Result<(Vec<D::Vec>, Solved), Unstable> {
    let t_end = end_time(world);
    let sums = Sums::of(world);
    let free = &dofs.free;
    if let Some(u_c) = held {
        let mut k_c = vec![D::zero(); u_c.len()];
        stiffness(world, linear.law, u_c, dofs, &mut k_c);
        load.iter_mut().zip(&k_c).for_each(|(f, &k)| *f -= k);
    }
    dofs.fold(&mut load);
    for (f, &k) in load.iter_mut().zip(free) {
        *f = mask::<D>(*f, k);
    }
    dofs.project(&mut load);
    let modes = &solver.frame.modes;
    let norm = sums.dot::<D>(&load, &load).sqrt();
    rigid::deflate::<D>(sums, &mut load, modes);
    let imbalance = if norm > 0.0 {
        1.0 - sums.dot::<D>(&load, &load).sqrt() / norm
    } else {
        0.0
    };
    if imbalance > IMBALANCE {
        return Err(Unstable {
            step: world.step + 1,
            time: t_end,
            what: format!(
                "no static equilibrium: {:.3} % of the load would move the body as a whole \
                 ({} rigid motions are free: hold the body, or balance its loads)",
                100.0 * imbalance,
                modes.len()
            ),
        });
    }
    // A start from the last round's answer (contact), in this round's unknowns.
    let start = guess.map(|g| {
        let mut s: Vec<D::Vec> = (g.iter().enumerate())
            .map(|(e, &x)| mask::<D>(x - held.map_or(D::zero(), |h| h[e]), free[e]))
            .collect();
        dofs.project(&mut s);
        rigid::deflate::<D>(sums, &mut s, modes);
        s
    });
    let (mut u, mut solved) =
        solver.solve(world, linear.law, dofs, &load, start, linear.tolerance)?;
    dofs.expand(&mut u);
    leans_on_ghost(world, &u, &solver.frame.ghost, dofs, &load, t_end)?;
    if let Some(u_c) = held {
        u.iter_mut().zip(u_c).for_each(|(u, &c)| *u += c);
    }
    solved.free_motions = modes.len();
    solved.imbalance = imbalance;
    Ok((u, solved))
}

/// One active-set round on the crack-face `pairs` at the solution `u` (every entry's
/// displacement): the overlap along each pair's normal, and the force its constraint
/// carries (f_int - f_ext on the field above, f_int the product of `law` with its
/// displacement: K u, or the internal force of given stresses at zero). Tolerances: 1e-9
/// of the largest displacement, 1e-8 of the largest nodal force.
fn faces_round<D: Dim>(
    world: &World<D>,
    pairs: &[faces::Pair<D::Vec>],
    (faces, opened): (&mut [Face<D::Vec>], &mut [u8]),
    (u, start): (&[D::Vec], &[D::Vec]),
    (law, at): (Law<D>, &[D::Vec]),
) -> faces::Changes {
    let loose = Unknowns::new(world, &[], &[]);
    let mut r = vec![D::zero(); u.len()];
    stiffness(world, law, at, &loose, &mut r);
    let largest = |v: &[D::Vec]| {
        (v.iter())
            .map(|x| D::dot(*x, *x).sqrt())
            .fold(0.0, f64::max)
    };
    let sums = Sums::of(world);
    let force_tol = 1e-8 * sums.max(largest(&r));
    r.iter_mut()
        .zip(&world.grid.force)
        .for_each(|(r, &f)| *r -= f);
    let gap_tol = 1e-9 * sums.max(largest(u));
    let most_turn = faces::turn_cap(world);
    // Split across ranks, a pair on a shared node changes alike on each: its owner counts it.
    let counted = |p: &faces::Pair<D::Vec>| sums.owns(p.own);
    let tols = (gap_tol, force_tol, most_turn);
    let mine = faces::update::<D>(pairs, (faces, opened), (u, start), &r, tols, counted);
    faces::Changes {
        closed: sums.count(mine.closed),
        opened: sums.count(mine.opened),
        slid: sums.count(mine.slid),
    }
}

/// How many of the face `pairs` are closed, over all ranks.
fn closed_count<D: Dim>(
    world: &World<D>,
    pairs: &[faces::Pair<D::Vec>],
    faces: &[Face<D::Vec>],
) -> usize {
    let sums = Sums::of(world);
    let mine = (pairs.iter().zip(faces)).filter(|(p, f)| f.closed() && sums.owns(p.own));
    sums.count(mine.count())
}

/// Each support's reaction on the body, f_int - f_ext on its held components (f_int the
/// product of `law` with `u`: K u, or the internal force of the given stresses; the grid's
/// force column still holds f_ext; a node's entries are summed, so a tied entry's force
/// counts once, wherever it sits), and on a B-spline symmetry plane its images' part
/// ([`mirror::credit_reactions`]).
fn reactions<D: Dim>(world: &mut World<D>, dofs: &Unknowns<D>, law: Law<D>, u: &[D::Vec]) {
    if world.bcs.is_empty() {
        return;
    }
    let mut ku = vec![D::zero(); u.len()];
    entry_stiffness(world, law, u, dofs, &mut ku);
    let g = world.settings.gravity;
    let m = &world.grid.mirrors;
    // Each image's own K u - f, before the fold takes it to its source.
    let images: Vec<D::Vec> = (m.images.iter().zip(&m.shares))
        .map(|(im, s)| ku[im.node as usize] - (s.force + g * s.mass))
        .collect();
    dofs.fold(&mut ku);
    let force = &world.grid.force;
    let fields = world.cracks.as_ref().map(|c| &c.scratch.fields);
    supports::set_reactions(&mut world.bcs, |n| {
        (entries(n, fields)).fold(D::zero(), |r, e| r + ku[e] - force[e])
    });
    mirror::credit_reactions(&world.grid.mirrors, &mut world.bcs, |k| images[k]);
}

/// The work of the particle loads and gravity over the step (particle displacements
/// `before` and `after` it), the force taken as the mean of its values at the step's ends
/// (exact for a linear response). The first step starts
/// from the unloaded body: its loads rise from zero, whatever their value at t = 0.
fn load_work<D: Dim>(
    world: &World<D>,
    before: &[D::Vec],
    after: &[D::Vec],
    t_start: f64,
    t_end: f64,
) -> f64 {
    let p = &world.particles;
    let step = |i: usize| after[i] - before[i];
    let first = world.step == 0;
    let mut work = ExactSum::new();
    for load in &world.loads {
        let start = if first { 0.0 } else { load.time.at(t_start) };
        let mean = 0.5 * (start + load.time.at(t_end));
        for (&i, &f) in load.particles.iter().zip(&load.forces) {
            if i != ABSENT {
                work.add(D::dot(f * mean, step(i as usize)));
            }
        }
    }
    let g = world.settings.gravity * if first { 0.5 } else { 1.0 };
    (0..p.len()).for_each(|i| work.add(p.mass[i] * D::dot(g, step(i))));
    world.domain.sum(std::slice::from_mut(&mut work));
    work.value()
}

/// The energy the sliding face `pairs` dissipate over the step (J): each one's friction
/// force against its slip, the force the mean of its values at the step's ends (exact for a
/// response linear over the step, as `load_work`). At the start the force is the one the
/// face then carried: the tangential part of f_int - f_ext on its field above, from the
/// particles' stresses and the loads at that time (none before the first step). `u` and
/// `start` are the entries' displacements at the step's end and start.
fn friction_work<D: Dim>(
    world: &World<D>,
    pairs: &[faces::Pair<D::Vec>],
    faces: &[Face<D::Vec>],
    (u, start): (&[D::Vec], &[D::Vec]),
) -> f64 {
    let carried = if world.step == 0 {
        Vec::new()
    } else {
        let loose = Unknowns::new(world, &[], &[]);
        let mut r = vec![D::zero(); u.len()];
        let zero = vec![D::zero(); u.len()];
        stiffness(
            world,
            Law::Given(&world.particles.stress),
            &zero,
            &loose,
            &mut r,
        );
        let loads = p2g::load_forces(world, world.time);
        let g = world.settings.gravity;
        for ((r, &f), &m) in r.iter_mut().zip(&loads).zip(&world.grid.mass) {
            *r -= f + g * m;
        }
        r
    };
    let along = |v: D::Vec, n: D::Vec| v - n * D::dot(v, n);
    let moved = |e: usize| u[e] - start.get(e).copied().unwrap_or(D::zero());
    let mut dissipated = vec![0.0; u.len()];
    for (p, face) in pairs.iter().zip(faces) {
        if let Face::Sliding { force, .. } = *face {
            let (a, b) = p.above_below();
            let slip = along(moved(a) - moved(b), p.normal);
            let before = carried.get(a).map_or(D::zero(), |&r| along(r, p.normal));
            dissipated[a] += -0.5 * D::dot(force + before, slip);
        }
    }
    Sums::of(world).total(dissipated.len(), |e| dissipated[e])
}

/// Moves the cracks' vertices and surfaces over the step as the explicit solver would
/// (`crack_advect`), with each entry's mass-weighted particle displacement in place of
/// its velocity: each surface follows its side's fields, which gives the crack opening.
fn move_cracks<D: Dim>(world: &mut World<D>, before: &[D::Vec], after: &[D::Vec]) {
    if world.cracks.is_none() {
        return;
    }
    let mass = &world.particles.mass;
    let moved = entry_sums(world, |i, w, _| (after[i] - before[i]) * (mass[i] * w));
    crack_advect::displace(world, &moved);
}

/// Each particle's displacement, interpolated from the nodes'.
fn gather<D: Dim>(world: &World<D>, u: &[D::Vec]) -> Vec<D::Vec> {
    (0..world.particles.len())
        .map(|i| {
            let mut up = D::zero();
            each_entry(world, i, |n, w, _| up += u[n] * w);
            up
        })
        .collect()
}

/// Each particle at the solution: x = x0 + its displacement `disp` (interpolated from the
/// entries' `u`), at rest, with grad u (when kept) and the stress C : sym(grad u) (its
/// dilatation its group's mean, with `dofs`' groups).
fn set_particles<D: Dim>(world: &mut World<D>, dofs: &Unknowns<D>, u: &[D::Vec], disp: &[D::Vec]) {
    let plane = world.settings.plane;
    let keep = !world.particles.grad_u.is_empty();
    let grouped = dofs
        .groups
        .as_ref()
        .map(|g| g.gradients(world, |i| gradient(world, i, u)));
    for (i, &d) in disp.iter().enumerate() {
        let l = gradient(world, i, u);
        let p = &mut world.particles;
        let m = &world.materials[p.material[i] as usize];
        p.stress[i] = elastic::<D>(m, plane, grouped.as_ref().map_or(&l, |g| &g[i]));
        if keep {
            p.grad_u[i] = l;
        }
        p.x[i] = p.x0[i] + d;
        p.v[i] = D::zero();
    }
    world.tiles.fresh = false;
}

/// Most of the strain energy the ghost stiffness may hold: on a sound scene it holds about
/// [`GHOST`] of it.
const GHOST_SHARE: f64 = 1e-6;

/// Refuses a solution that the ghost stiffness, not the body, holds up: a load on
/// particles whose nodes nothing else holds (a mechanism), which would move them without
/// bound. Names the particle that moved most.
fn leans_on_ghost<D: Dim>(
    world: &World<D>,
    u: &[D::Vec],
    ghost: &[D::Vec],
    dofs: &Unknowns<D>,
    f: &[D::Vec],
    t_end: f64,
) -> Result<(), Unstable> {
    let sums = Sums::of(world);
    let held = sums.total(u.len(), |e| {
        (0..D::D)
            .map(|a| ghost[e][a] * dofs.free[e][a] * u[e][a] * u[e][a])
            .sum()
    });
    let total = sums.dot::<D>(f, u);
    if held <= GHOST_SHARE * total.abs() {
        return Ok(());
    }
    let moved = gather(world, u);
    let worst = (0..moved.len())
        .max_by(|&a, &b| D::dot(moved[a], moved[a]).total_cmp(&D::dot(moved[b], moved[b])))
        .unwrap_or(0);
    let at = D::to_xyz(world.particles.x0[worst]);
    Err(Unstable {
        step: world.step + 1,
        time: t_end,
        what: format!(
            "the static solve leans on its ghost stiffness ({:.2e} of the work): particle \
             {worst} at ({:.4e}, {:.4e}, {:.4e}) m sits on nodes that nothing but the ghost \
             holds (a body cut obliquely through cells, loaded at such an edge); run this \
             scene with solver = \"explicit\"",
            held / total.abs().max(f64::MIN_POSITIVE),
            at[0],
            at[1],
            at[2]
        ),
    })
}

/// [`GHOST`] times K's diagonal on the entries that particles next to a crack reach (their
/// sides' entries and the nodes they share; [`LONE_GHOST`] on those one particle alone
/// reaches) and on the light ones (below [`LIGHT`] of the heaviest), zero elsewhere.
fn ghost_stiffness<D: Dim>(world: &World<D>, diag: &[D::Vec]) -> Vec<D::Vec> {
    // Split across ranks, a shared node is marked where any rank's particles reach it.
    let mut near = vec![D::zero(); diag.len()];
    scatter::near_crack_sums(world, &mut near, |i, mark| {
        each_entry(world, i, |n, _, _| mark(n, ones::<D>()))
    });
    let mass = &world.grid.mass;
    let full = Sums::of(world).max(mass.iter().copied().fold(0.0, f64::max));
    let lone = match world.cracks {
        Some(_) => scatter::lone_entries(world),
        None => Vec::new(),
    };
    (0..diag.len())
        .map(|e| match (near[e] != D::zero(), mass[e] < LIGHT * full) {
            (true, _) if lone[e] => diag[e] * LONE_GHOST,
            (true, _) | (_, true) => diag[e] * GHOST,
            (false, false) => D::zero(),
        })
        .collect()
}

/// The node of grid entry `e` (a crack field's row belongs to a node).
fn entry_node<D: Dim>(world: &World<D>, e: usize) -> usize {
    match fields(world) {
        Some(f) if e >= f.nodes => f.node[e - f.nodes] as usize,
        _ => e,
    }
}

/// The crack fields of the scene's classification (None without cracks).
fn fields<D: Dim>(world: &World<D>) -> Option<&Fields> {
    world.cracks.as_ref().map(|c| &c.scratch.fields)
}

/// Node `n`'s grid entries: its own and its crack fields' rows.
fn entries(n: u32, fields: Option<&Fields>) -> impl Iterator<Item = usize> {
    let extra = fields.map_or(0..0, |f| f.rows_of(n));
    std::iter::once(n as usize).chain(extra)
}
