//! `static_solve`: one load step of a static scene (`[simulation] solver = "static"`): the
//! equilibrium K u = f_ext(t) of the particles' small-strain linear elastic stiffness on
//! the grid nodes, solved without assembling K by conjugate gradients with a Jacobi
//! preconditioner; then each particle takes the displacement, its gradient and the stress
//! they give. Particles are the quadrature points with their volumes and the scene's shape
//! functions, at their initial positions (small strain: the stiffness does not move).

use crate::base::dim::Dim;
use crate::base::error::Unstable;
use crate::base::sym::{Sym3, SymTensor};
use crate::physics::material::{Material, Plane};
use crate::record::solve_log::Solved;
use crate::store::disjoint::Disjoint;
use crate::store::world::{CHUNK, World};
use crate::systems::p2g::add_internal_force;
use crate::systems::stress::velocity_gradient;
use crate::systems::{bin, p2g};
use crate::with_shape;
use rayon::prelude::*;

/// The residual, relative to the external force, at which a load step has converged: far
/// below the discretisation's own error, and above what the iteration's round-off reaches
/// on the largest scenes.
pub const TOLERANCE: f64 = 1e-10;

/// Most iterations per load step, per unknown along the grid's longest axis: conjugate
/// gradients on a well-supported grid converge in a small multiple of it.
const ITERATIONS_PER_NODE: usize = 50;

/// Solves the load step ending at the next step's time and sets the particles to it: x =
/// x0 + u, v = 0, grad u and the stress it gives; adds the work of the loads over the step
/// (trapezoidal, exact for a linear response). Refuses a solve that does not converge.
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
    let free = free_dofs(world);
    let f_ext: Vec<D::Vec> = (world.grid.force.iter())
        .zip(&free)
        .map(|(&f, &k)| mask::<D>(f, k))
        .collect();
    let diag = diagonal(world, &free);
    let (u, solved) = conjugate_gradients(world, &f_ext, &diag, &free)?;
    reactions(world, &u);
    let work = load_work(world, &before, t_start, t_end, &u);
    world.work.external += work;
    set_particles(world, &u);
    Ok(solved)
}

/// Per node, 1 on the components that are unknowns: the node carries mass (a particle
/// reaches it) and no boundary prescribes it.
fn free_dofs<D: Dim>(world: &World<D>) -> Vec<D::Vec> {
    let tol = world.settings.mass_tol;
    let mut free: Vec<D::Vec> = (world.grid.mass.iter())
        .map(|&m| if m > tol { ones::<D>() } else { D::zero() })
        .collect();
    for bc in &world.bcs {
        let held = (0..D::D).filter(|&a| bc.axes[a]);
        for &n in &bc.nodes {
            held.clone().for_each(|a| free[n as usize][a] = 0.0);
        }
    }
    free
}

/// The vector of ones.
fn ones<D: Dim>() -> D::Vec {
    let mut k = D::zero();
    (0..D::D).for_each(|a| k[a] = 1.0);
    k
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

/// y = K x on the free components, particle by particle: grad x gathered at each particle,
/// the stress it gives, and that stress's nodal force, tile by tile in colour classes (the
/// same scatter, in the same order, for any thread count).
fn apply<D: Dim>(world: &World<D>, x: &[D::Vec], free: &[D::Vec], y: &mut [D::Vec]) {
    y.par_chunks_mut(CHUNK).for_each(|c| c.fill(D::zero()));
    let (shape, plane) = (world.settings.shape, world.settings.plane);
    let stride = &world.grid.geom.stride;
    let (p, materials, tiles) = (&world.particles, &world.materials, &world.tiles);
    let y_w = Disjoint::new(y);
    tiles.for_each_coloured(|t| {
        let mine = tiles.particles(t).iter().map(|&i| i as usize);
        for_each_free_particle!(D, shape, &tiles.stencils, None, mine, |i, st| {
            let rows = st.rows::<D>(stride);
            let l = velocity_gradient::<D, N>(&st, &rows, x);
            let s = elastic::<D>(&materials[p.material[i] as usize], plane, &l);
            // SAFETY: tiles of one colour class touch disjoint nodes (tiles.rs), and each
            // tile is handled by one thread. Given -V, the internal-force scatter adds
            // +V sigma . grad S: the rows of K x.
            unsafe { add_internal_force::<D, N>(&st, &rows, &s, -p.volume[i], &y_w) };
        })
    });
    y.par_chunks_mut(CHUNK)
        .zip(free.par_chunks(CHUNK))
        .for_each(|(y, k)| {
            for (y, &k) in y.iter_mut().zip(k) {
                *y = mask::<D>(*y, k);
            }
        });
}

/// The diagonal of K (its free components; 1 elsewhere, so the preconditioner leaves the
/// fixed ones alone): for node n and axis a, sum over particles of V e_a . (C : sym(e_a ⊗
/// grad S_n)) . grad S_n.
fn diagonal<D: Dim>(world: &World<D>, free: &[D::Vec]) -> Vec<D::Vec> {
    let mut d = vec![D::zero(); free.len()];
    let (shape, plane) = (world.settings.shape, world.settings.plane);
    let stride = &world.grid.geom.stride;
    let p = &world.particles;
    for i in 0..p.len() {
        let m = &world.materials[p.material[i] as usize];
        with_shape!(shape, S, N => {
            let st = crate::physics::shape::Stencil::<N>::cached::<D>(S, &world.tiles.stencils, i);
            st.for_each::<D>(stride, |n, _, grad| {
                for a in 0..D::D {
                    let mut e = D::zero();
                    e[a] = 1.0;
                    let s = elastic::<D>(m, plane, &D::outer(e, grad));
                    d[n][a] += p.volume[i] * D::stress_dot(&s, grad)[a];
                }
            });
        });
    }
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
/// (Hestenes & Stiefel 1952), to a residual of [`TOLERANCE`] times |f|.
fn conjugate_gradients<D: Dim>(
    world: &World<D>,
    f: &[D::Vec],
    diag: &[D::Vec],
    free: &[D::Vec],
) -> Result<(Vec<D::Vec>, Solved), Unstable> {
    let n = f.len();
    let mut u = vec![D::zero(); n];
    let norm_f = dot::<D>(f, f).sqrt();
    if norm_f == 0.0 {
        return Ok((u, Solved::default()));
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
    let mut z = precondition(&r);
    let mut dir = z.clone();
    let mut rz = dot::<D>(&r, &z);
    let mut q = vec![D::zero(); n];
    let cells = world.grid.geom.cells;
    let most = ITERATIONS_PER_NODE * (cells[0].max(cells[1]).max(cells[2]) + 1);
    for k in 1..=most {
        apply(world, &dir, free, &mut q);
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
        if residual <= TOLERANCE {
            return Ok((
                u,
                Solved {
                    iterations: k,
                    residual,
                },
            ));
        }
        z = precondition(&r);
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
/// force column still holds f_ext).
fn reactions<D: Dim>(world: &mut World<D>, u: &[D::Vec]) {
    if world.bcs.is_empty() {
        return;
    }
    let every = vec![ones::<D>(); u.len()];
    let mut ku = vec![D::zero(); u.len()];
    apply(world, u, &every, &mut ku);
    let force = &world.grid.force;
    for bc in &mut world.bcs {
        for (k, &n) in bc.nodes.iter().enumerate() {
            let r = ku[n as usize] - force[n as usize];
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

/// The work of the particle loads and gravity over the step, the force taken as the mean
/// of its values at the step's ends (exact for a linear response). The first step starts
/// from the unloaded body: its loads rise from zero, whatever their value at t = 0.
fn load_work<D: Dim>(
    world: &World<D>,
    before: &[D::Vec],
    t_start: f64,
    t_end: f64,
    u: &[D::Vec],
) -> f64 {
    let after = gather(world, u);
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

/// Each particle's displacement, interpolated from the nodes'.
fn gather<D: Dim>(world: &World<D>, u: &[D::Vec]) -> Vec<D::Vec> {
    let (shape, stride) = (world.settings.shape, &world.grid.geom.stride);
    (0..world.particles.len())
        .map(|i| {
            let mut up = D::zero();
            with_shape!(shape, S, N => {
                let st = crate::physics::shape::Stencil::<N>::cached::<D>(S, &world.tiles.stencils, i);
                st.for_each::<D>(stride, |n, w, _| up += u[n] * w);
            });
            up
        })
        .collect()
}

/// Each particle at the solution: x = x0 + u, at rest, with grad u (when kept) and the
/// stress C : sym(grad u).
fn set_particles<D: Dim>(world: &mut World<D>, u: &[D::Vec]) {
    let disp = gather(world, u);
    let (shape, plane) = (world.settings.shape, world.settings.plane);
    let stride = world.grid.geom.stride;
    let keep = !world.particles.grad_u.is_empty();
    for (i, &d) in disp.iter().enumerate() {
        let l: D::Mat;
        with_shape!(shape, S, N => {
            let st = crate::physics::shape::Stencil::<N>::cached::<D>(S, &world.tiles.stencils, i);
            l = velocity_gradient::<D, N>(&st, &st.rows::<D>(&stride), u);
        });
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
