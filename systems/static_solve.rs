//! `static_solve`: one load step of a static scene (`[simulation] solver = "static"`): the
//! equilibrium K u = f_ext(t) of the particles' small-strain linear elastic stiffness on
//! the grid entries (a node's own, and one per crack field where the classification gives
//! the node more than one: Guo & Nairn 2D (2004) Eqs. 3 and 6 with the stress from the
//! strain), solved without assembling K by conjugate gradients with a Jacobi
//! preconditioner; then each particle takes the displacement, its gradient and the stress
//! they give. Particles are the quadrature points with their volumes and the scene's shape
//! functions, at their initial positions (small strain: neither the stiffness nor the
//! cracks move), each particle near a crack on its own side's entries.

use crate::base::dim::Dim;
use crate::base::error::Unstable;
use crate::base::sym::{Sym3, SymTensor};
use crate::physics::material::{Material, Plane};
use crate::physics::shape::{ShapeKind, Stencil};
use crate::record::solve_log::Solved;
use crate::store::crack::Fields;
use crate::store::disjoint::Disjoint;
use crate::store::world::{CHUNK, World};
use crate::systems::p2g::add_internal_force;
use crate::systems::stress::velocity_gradient;
use crate::systems::{bin, classify, crack_advect, p2g};
use crate::with_shape;
use rayon::prelude::*;

mod faces;
mod rigid;
mod supports;
mod unknowns;

use unknowns::Unknowns;

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

/// An entry is light, and takes the ghost stiffness, below this fraction of the heaviest
/// entry's mass. The sliver nodes of the turned DCB lie below it; a box's edge and corner
/// nodes (a half and a quarter) above. At 3 % the turned DCB's K moved in the fourth digit.
const LIGHT: f64 = 0.1;

/// Most iterations per load step, per unknown along the grid's longest axis: conjugate
/// gradients on a well-supported grid converge in a small multiple of it.
const ITERATIONS_PER_NODE: usize = 50;

/// Solves the load step ending at the next step's time and sets the particles to it: x =
/// x0 + u, v = 0, grad u and the stress it gives; adds the work of the loads and the moving
/// supports over the step (trapezoidal, exact for a linear response). Refuses a solve that
/// does not converge.
pub fn run<D: Dim>(world: &mut World<D>) -> Result<Solved, Unstable> {
    let t_end = (world.step + 1) as f64 * world.settings.dt;
    let before: Vec<D::Vec> = (world.particles.x.iter())
        .zip(&world.particles.x0)
        .map(|(&x, &x0)| x - x0)
        .collect();
    // The stiffness lives on the initial positions.
    let p = &mut world.particles;
    p.x.copy_from_slice(&p.x0);
    world.tiles.fresh = false;
    bin::run(world)?;
    classify::run(world)?;
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
    let held = supports::prescribed(world, t_end);
    let start_forces = supports::start_forces(world, t_start);
    let Solution { u, dofs, solved } = with_contact(world, held.as_deref(), t_end)?;
    reactions(world, &dofs, &u);
    let after = gather(world, &u);
    move_cracks(world, &before, &after);
    let work = load_work(world, &before, &after, t_start, t_end)
        + supports::work(world, &start_forces, t_start, t_end);
    world.work.external += work;
    set_particles(world, &u, &after);
    Ok(solved)
}

/// A load step's answer.
struct Solution<D: Dim> {
    /// Every grid entry's displacement.
    u: Vec<D::Vec>,
    /// The unknowns of the last solve.
    dofs: Unknowns<D>,
    /// What the solves took, all together.
    solved: Solved,
}

/// The load step's equilibrium with its crack faces' contact settled: solves until the
/// active set of closed face pairs changes no more (one solve without such faces).
fn with_contact<D: Dim>(
    world: &World<D>,
    held: Option<&[D::Vec]>,
    t_end: f64,
) -> Result<Solution<D>, Unstable> {
    let pairs = faces::pairs(world);
    let mut closed = vec![false; pairs.len()];
    let mut iterations = 0;
    let mut rounds = 0;
    let mut last: Option<Vec<D::Vec>> = None;
    let (u, dofs, mut solved) = loop {
        let dofs = Unknowns::new(world, &pairs, &closed);
        let (u, solved) = equilibrium(world, &dofs, held, last.as_deref(), t_end)?;
        iterations += solved.iterations;
        rounds += 1;
        if pairs.is_empty() {
            break (u, dofs, solved);
        }
        let changes = faces_round(world, &pairs, &mut closed, &u);
        if changes.closed + changes.opened == 0 {
            break (u, dofs, solved);
        }
        last = Some(u);
        if rounds >= CONTACT_ROUNDS {
            return Err(Unstable {
                step: world.step + 1,
                time: t_end,
                what: format!(
                    "the crack faces' contact did not settle in {rounds} solves (the last \
                     closed {} pairs and opened {})",
                    changes.closed, changes.opened
                ),
            });
        }
    };
    solved.iterations = iterations;
    solved.contact_rounds = rounds;
    solved.closed_faces = closed.iter().filter(|&&c| c).count();
    Ok(Solution { u, dofs, solved })
}

/// Most solves a load step's contact active set may take: each round closes the pairs
/// that overlap and opens those that pull, and a few rounds settle a face.
const CONTACT_ROUNDS: usize = 50;

/// Equilibrium with the unknowns `dofs`: K u_f = f - K u_c on the free components (u_c
/// the moving supports' displacement `held`), the rigid motions K leaves free taken out,
/// from `guess` (every entry's displacement) or from zero; returns every entry's
/// displacement u_f + u_c (tied entries given their partners').
fn equilibrium<D: Dim>(
    world: &World<D>,
    dofs: &Unknowns<D>,
    held: Option<&[D::Vec]>,
    guess: Option<&[D::Vec]>,
    t_end: f64,
) -> Result<(Vec<D::Vec>, Solved), Unstable> {
    let free = &dofs.free;
    let diag = diagonal(world, dofs);
    let largest = (diag.iter().zip(free))
        .flat_map(|(d, k)| (0..D::D).filter(|&a| k[a] != 0.0).map(|a| d[a]))
        .fold(0.0, f64::max);
    let mut f_ext = world.grid.force.clone();
    if let Some(u_c) = held {
        let mut k_c = vec![D::zero(); u_c.len()];
        stiffness(world, u_c, dofs, &mut k_c);
        f_ext.iter_mut().zip(&k_c).for_each(|(f, &k)| *f -= k);
    }
    dofs.fold(&mut f_ext);
    for (f, &k) in f_ext.iter_mut().zip(free) {
        *f = mask::<D>(*f, k);
    }
    dofs.project(&mut f_ext);
    let ghost = ghost_stiffness(world, &diag);
    let modes = rigid::free_motions(world, dofs, &ghost, largest);
    let norm = dot::<D>(&f_ext, &f_ext).sqrt();
    rigid::deflate::<D>(&mut f_ext, &modes);
    let imbalance = if norm > 0.0 {
        1.0 - dot::<D>(&f_ext, &f_ext).sqrt() / norm
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
        rigid::deflate::<D>(&mut s, &modes);
        s
    });
    let (mut u, mut solved) =
        conjugate_gradients(world, &f_ext, &ghost, &diag, dofs, &modes, start)?;
    dofs.expand(&mut u);
    leans_on_ghost(world, &u, &ghost, dofs, &f_ext, t_end)?;
    if let Some(u_c) = held {
        u.iter_mut().zip(u_c).for_each(|(u, &c)| *u += c);
    }
    solved.free_motions = modes.len();
    solved.imbalance = imbalance;
    Ok((u, solved))
}

/// One active-set round on the crack-face `pairs` at the solution `u`: the overlap along
/// each pair's normal, and the force its constraint carries (K u - f_ext on the field
/// above). Tolerances: 1e-9 of the largest displacement, 1e-8 of the largest nodal force.
fn faces_round<D: Dim>(
    world: &World<D>,
    pairs: &[faces::Pair<D::Vec>],
    closed: &mut [bool],
    u: &[D::Vec],
) -> faces::Changes {
    let loose = Unknowns::new(world, &[], &[]);
    let mut r = vec![D::zero(); u.len()];
    stiffness(world, u, &loose, &mut r);
    let largest = |v: &[D::Vec]| {
        (v.iter())
            .map(|x| D::dot(*x, *x).sqrt())
            .fold(0.0, f64::max)
    };
    let force_tol = 1e-8 * largest(&r);
    r.iter_mut()
        .zip(&world.grid.force)
        .for_each(|(r, &f)| *r -= f);
    faces::update::<D>(pairs, closed, u, &r, 1e-9 * largest(u), force_tol)
}

/// `v` with the components `keep` has at 0 cleared.
#[inline(always)]
fn mask<D: Dim>(v: D::Vec, keep: D::Vec) -> D::Vec {
    let mut out = v;
    for a in 0..D::D {
        out[a] *= keep[a];
    }
    out
}

/// The stress C : sym(l) of material `m`.
#[inline(always)]
fn elastic<D: Dim>(m: &Material, plane: Plane, l: &D::Mat) -> D::Sym {
    let mut s = Sym3::default();
    m.update(plane, D::sym_part(l), &mut s);
    D::Sym::from_sym3(s)
}

/// y = K x, particle by particle: grad x gathered at each particle (tied entries taking
/// the value of the entry they move with), the stress it gives, and that stress's nodal
/// force, tile by tile in colour classes (the same scatter, in the same order, for any
/// thread count), tied entries' forces folded into their partners'.
fn stiffness<D: Dim>(world: &World<D>, x: &[D::Vec], dofs: &Unknowns<D>, y: &mut [D::Vec]) {
    let expanded;
    let x = if dofs.ties.is_empty() && dofs.normal_ties.is_empty() {
        x
    } else {
        let mut e = x.to_vec();
        dofs.expand(&mut e);
        expanded = e;
        &expanded[..]
    };
    y.par_chunks_mut(CHUNK).for_each(|c| c.fill(D::zero()));
    let (shape, plane) = (world.settings.shape, world.settings.plane);
    let stride = &world.grid.geom.stride;
    let (p, materials, tiles) = (&world.particles, &world.materials, &world.tiles);
    let fields = fields(world);
    let y_w = Disjoint::new(y);
    tiles.for_each_coloured(|t| {
        let mine = tiles.particles(t).iter().map(|&i| i as usize);
        for_each_free_particle!(D, shape, &tiles.stencils, fields, mine, |i, st| {
            let rows = st.rows::<D>(stride);
            let l = velocity_gradient::<D, N>(&st, &rows, x);
            let s = elastic::<D>(&materials[p.material[i] as usize], plane, &l);
            // SAFETY: tiles of one colour class touch disjoint nodes (tiles.rs), and each
            // tile is handled by one thread. Given -V, the internal-force scatter adds
            // +V sigma . grad S: the rows of K x.
            unsafe { add_internal_force::<D, N>(&st, &rows, &s, -p.volume[i], &y_w) };
        })
    });
    // The particles near a crack, on their sides' entries, in particle order.
    for &i in fields.map_or(&[][..], |f| &f.coded[..]) {
        let i = i as usize;
        let l = gradient(world, i, x);
        let s = elastic::<D>(&materials[p.material[i] as usize], plane, &l);
        each_entry(world, i, |n, _, g| {
            y[n] += D::stress_dot(&s, g) * p.volume[i]
        });
    }
    dofs.fold(y);
}

/// y = K x on the free components ([`stiffness`]), with `ghost`'s stiffness (per
/// component) times x added when given.
fn apply<D: Dim>(
    world: &World<D>,
    x: &[D::Vec],
    dofs: &Unknowns<D>,
    ghost: Option<&[D::Vec]>,
    y: &mut [D::Vec],
) {
    stiffness(world, x, dofs, y);
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
/// grad S_n)) . grad S_n. A tied entry adds its own to its partner's: a particle reaches
/// one entry of a node, so the two share no particle and K has no term between them.
fn diagonal<D: Dim>(world: &World<D>, dofs: &Unknowns<D>) -> Vec<D::Vec> {
    let free = &dofs.free;
    let mut d = vec![D::zero(); free.len()];
    let plane = world.settings.plane;
    let p = &world.particles;
    for i in 0..p.len() {
        let m = &world.materials[p.material[i] as usize];
        each_entry(world, i, |n, _, grad| {
            for a in 0..D::D {
                let mut e = D::zero();
                e[a] = 1.0;
                let s = elastic::<D>(m, plane, &D::outer(e, grad));
                d[n][a] += p.volume[i] * D::stress_dot(&s, grad)[a];
            }
        });
    }
    dofs.fold(&mut d);
    for (d, &k) in d.iter_mut().zip(free) {
        for a in 0..D::D {
            if k[a] == 0.0 || d[a] <= 0.0 {
                d[a] = 1.0;
            }
        }
    }
    d
}

/// The sum of a * b over all components, in fixed chunks (the same bits for any thread
/// count).
fn dot<D: Dim>(a: &[D::Vec], b: &[D::Vec]) -> f64 {
    let parts: Vec<f64> = a
        .par_chunks(CHUNK)
        .zip(b.par_chunks(CHUNK))
        .map(|(a, b)| a.iter().zip(b).map(|(&x, &y)| D::dot(x, y)).sum())
        .collect();
    parts.iter().sum()
}

/// Solves K u = f on the free components from u = 0 by preconditioned conjugate gradients
/// (Hestenes & Stiefel 1952), to a residual of the scene's tolerance times |f|.
fn conjugate_gradients<D: Dim>(
    world: &World<D>,
    f: &[D::Vec],
    ghost: &[D::Vec],
    diag: &[D::Vec],
    dofs: &Unknowns<D>,
    modes: &[Vec<D::Vec>],
    start: Option<Vec<D::Vec>>,
) -> Result<(Vec<D::Vec>, Solved), Unstable> {
    let n = f.len();
    let norm_f = dot::<D>(f, f).sqrt();
    if norm_f == 0.0 {
        return Ok((vec![D::zero(); n], Solved::default()));
    }
    let precondition = |r: &[D::Vec]| -> Vec<D::Vec> {
        r.par_iter()
            .zip(diag.par_iter())
            .map(|(&r, &d)| {
                let mut z = r;
                for a in 0..D::D {
                    z[a] /= d[a];
                }
                z
            })
            .collect()
    };
    let mut r = f.to_vec();
    let mut u = match start {
        Some(u) => {
            let mut q = vec![D::zero(); n];
            apply(world, &u, dofs, Some(ghost), &mut q);
            r.iter_mut().zip(&q).for_each(|(r, &q)| *r -= q);
            u
        }
        None => vec![D::zero(); n],
    };
    let residual = dot::<D>(&r, &r).sqrt() / norm_f;
    if residual <= world.settings.tolerance {
        let solved = Solved {
            residual,
            ..Solved::default()
        };
        return Ok((u, solved));
    }
    let mut z = precondition(&r);
    dofs.project(&mut z);
    rigid::deflate::<D>(&mut z, modes);
    let mut dir = z.clone();
    let mut rz = dot::<D>(&r, &z);
    let mut q = vec![D::zero(); n];
    let cells = world.grid.geom.cells;
    let most = ITERATIONS_PER_NODE * (cells[0].max(cells[1]).max(cells[2]) + 1);
    for k in 1..=most {
        apply(world, &dir, dofs, Some(ghost), &mut q);
        let pq = dot::<D>(&dir, &q);
        // A direction of no stiffness (or NaN): K is singular on what the loads start.
        if pq.is_nan() || pq <= 0.0 {
            return Err(not_converged(world, k, dot::<D>(&r, &r).sqrt() / norm_f));
        }
        let alpha = rz / pq;
        u.par_iter_mut()
            .zip(r.par_iter_mut())
            .zip(dir.par_iter().zip(q.par_iter()))
            .for_each(|((u, r), (&p, &q))| {
                *u += p * alpha;
                *r -= q * alpha;
            });
        let residual = dot::<D>(&r, &r).sqrt() / norm_f;
        if residual <= world.settings.tolerance {
            return Ok((
                u,
                Solved {
                    iterations: k,
                    residual,
                    ..Solved::default()
                },
            ));
        }
        z = precondition(&r);
        dofs.project(&mut z);
        rigid::deflate::<D>(&mut z, modes);
        let rz_next = dot::<D>(&r, &z);
        let beta = rz_next / rz;
        rz = rz_next;
        dir.par_iter_mut()
            .zip(z.par_iter())
            .for_each(|(p, &z)| *p = z + *p * beta);
    }
    Err(not_converged(world, most, dot::<D>(&r, &r).sqrt() / norm_f))
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

/// Each support's reaction on the body, K u - f_ext on its held components (the grid's
/// force column still holds f_ext; a node's entries are summed, so a tied entry's force
/// counts once, wherever it sits).
fn reactions<D: Dim>(world: &mut World<D>, dofs: &Unknowns<D>, u: &[D::Vec]) {
    if world.bcs.is_empty() {
        return;
    }
    let mut ku = vec![D::zero(); u.len()];
    stiffness(world, u, dofs, &mut ku);
    let force = &world.grid.force;
    let fields = world.cracks.as_ref().map(|c| &c.scratch.fields);
    for bc in &mut world.bcs {
        for (k, &n) in bc.nodes.iter().enumerate() {
            let r = (entries(n, fields)).fold(D::zero(), |r, e| r + ku[e] - force[e]);
            let mut held = D::zero();
            for a in 0..D::D {
                if bc.axes[a] {
                    held[a] = r[a];
                }
            }
            bc.reaction[k] = held;
        }
    }
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
    let mut work = 0.0;
    for load in &world.loads {
        let start = if first { 0.0 } else { load.time.at(t_start) };
        let mean = 0.5 * (start + load.time.at(t_end));
        for (&i, &f) in load.particles.iter().zip(&load.forces) {
            work += D::dot(f * mean, step(i as usize));
        }
    }
    let g = world.settings.gravity * if first { 0.5 } else { 1.0 };
    work + (0..p.len())
        .map(|i| p.mass[i] * D::dot(g, step(i)))
        .sum::<f64>()
}

/// Moves the cracks' vertices and surfaces over the step as the explicit solver would
/// (`crack_advect`), with each entry's mass-weighted particle displacement in place of
/// its velocity: each surface follows its side's fields, which gives the crack opening.
fn move_cracks<D: Dim>(world: &mut World<D>, before: &[D::Vec], after: &[D::Vec]) {
    if world.cracks.is_none() {
        return;
    }
    let mut moved = vec![D::zero(); world.grid.mass.len()];
    let mass = &world.particles.mass;
    for (i, (&b, &a)) in before.iter().zip(after).enumerate() {
        let d = (a - b) * mass[i];
        each_entry(world, i, |n, w, _| moved[n] += d * w);
    }
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
/// entries' `u`), at rest, with grad u (when kept) and the stress C : sym(grad u).
fn set_particles<D: Dim>(world: &mut World<D>, u: &[D::Vec], disp: &[D::Vec]) {
    let plane = world.settings.plane;
    let keep = !world.particles.grad_u.is_empty();
    for (i, &d) in disp.iter().enumerate() {
        let l = gradient(world, i, u);
        let p = &mut world.particles;
        let m = &world.materials[p.material[i] as usize];
        p.stress[i] = elastic::<D>(m, plane, &l);
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
    let held: f64 = (u.iter().zip(ghost).zip(&dofs.free))
        .map(|((u, g), k)| (0..D::D).map(|a| g[a] * k[a] * u[a] * u[a]).sum::<f64>())
        .sum();
    let total = dot::<D>(f, u);
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
/// sides' entries and the nodes they share) and on the light ones (below [`LIGHT`] of the
/// heaviest), zero elsewhere.
fn ghost_stiffness<D: Dim>(world: &World<D>, diag: &[D::Vec]) -> Vec<D::Vec> {
    let mut ghost = vec![D::zero(); diag.len()];
    for &i in fields(world).map_or(&[][..], |f| &f.coded[..]) {
        each_entry(world, i as usize, |n, _, _| ghost[n] = diag[n] * GHOST);
    }
    let mass = &world.grid.mass;
    let full = mass.iter().copied().fold(0.0, f64::max);
    for (e, &m) in mass.iter().enumerate() {
        if m < LIGHT * full {
            ghost[e] = diag[e] * GHOST;
        }
    }
    ghost
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

/// Calls `f(entry, weight, grad S)` for each node of particle `i`'s stencil, on the entry
/// of the particle's side where a crack splits the node.
fn each_entry<D: Dim>(world: &World<D>, i: usize, mut f: impl FnMut(usize, f64, D::Vec)) {
    let shape: ShapeKind = world.settings.shape;
    let stride = &world.grid.geom.stride;
    let targets = fields(world).and_then(|c| c.targets_of(i));
    with_shape!(shape, S, N => {
        let st = Stencil::<N>::cached::<D>(S, &world.tiles.stencils, i);
        match targets {
            Some(t) => st.for_each_target::<D>(stride, t, &mut f),
            None => st.for_each::<D>(stride, &mut f),
        }
    });
}

/// grad u at particle `i` from the entries' displacements `u`.
fn gradient<D: Dim>(world: &World<D>, i: usize, u: &[D::Vec]) -> D::Mat {
    let mut l = D::mat_zero();
    each_entry(world, i, |n, _, g| l = l + D::outer(u[n], g));
    l
}
