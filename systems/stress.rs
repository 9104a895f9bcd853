//! `stress`: small-strain constitutive update, d(eps) = sym(grad v) dt, with grad v gathered
//! from the grid velocities p/m, in parallel over particle chunks (the particles near a
//! crack afterwards, from their fields' entries).

use crate::base::dim::Dim;
use crate::base::sym::{Sym3, SymTensor};
use crate::physics::material::{Material, Plane};
use crate::physics::plastic::Hardened;
use crate::physics::shape::{Rows, Stencil};
use crate::store::disjoint::Disjoint;
use crate::store::particles::Particles;
use crate::store::world::{CHUNK, World};
use crate::systems::mirror;
use crate::with_shape;
use rayon::prelude::*;

/// Gathers grad v = sum (p_i/m_i) ⊗ grad S and updates the stress over `fraction` of the
/// step (and grad v, grad u when J-integrals need them), in parallel over particle chunks.
/// The grid's velocity column is overwritten with p/m first (grid_update rewrites it with
/// end-of-step velocities afterwards).
pub fn run<D: Dim>(world: &mut World<D>, fraction: f64) {
    node_velocities(world);
    let dt = world.settings.dt * fraction;
    let (shape, plane) = (world.settings.shape, world.settings.plane);
    let grid = &world.grid;
    let materials = &world.materials;
    let stencils = &world.tiles.stencils;
    let fields = world.cracks.as_ref().map(|c| &c.scratch.fields);
    let n = world.particles.len();
    let (columns, material) = StressColumns::of(&mut world.particles);
    let stride = &grid.geom.stride;
    (0..n.div_ceil(CHUNK)).into_par_iter().for_each(|c| {
        let chunk = c * CHUNK..((c + 1) * CHUNK).min(n);
        for_each_free_particle!(D, shape, stencils, fields, chunk, |i, st| {
            let l = velocity_gradient::<D, N>(&st, &st.rows::<D>(stride), &grid.velocity);
            let m = &materials[material[i] as usize];
            // SAFETY: the chunks partition the particles and each chunk is one task.
            unsafe { columns.update(i, l, dt, plane, m) };
        })
    });
    update_coded(world, dt);
}

/// The update of the particles near a crack: grad v over each stencil node's entry for the
/// particle's side (Guo & Nairn 3D (2006) Eq. 20), sequentially in particle order.
pub(crate) fn update_coded<D: Dim>(world: &mut World<D>, dt: f64) {
    let Some(c) = world.cracks.as_ref() else {
        return;
    };
    let (shape, plane) = (world.settings.shape, world.settings.plane);
    let (grid, f) = (&world.grid, &c.scratch.fields);
    let (columns, material) = StressColumns::of(&mut world.particles);
    for &i in &f.coded {
        let i = i as usize;
        let targets = f.targets_of(i).expect("coded particle");
        let mut l = D::mat_zero();
        with_shape!(shape, S, N => {
            let st = Stencil::<N>::cached::<D>(S, &world.tiles.stencils, i);
            st.for_each_target::<D>(&grid.geom.stride, targets, |n, _, g| {
                l = l + D::outer(grid.velocity[n], g);
            });
        });
        let m = &world.materials[material[i] as usize];
        // SAFETY: one thread runs this loop.
        unsafe { columns.update(i, l, dt, plane, m) };
    }
}

/// The particle columns a stress update writes, borrowed for writes from the threads of a
/// parallel pass: the stress; grad v and grad u when J-integrals keep them; the plastic
/// strain and hardening state when a material is plastic.
pub(crate) struct StressColumns<'a, D: Dim> {
    stress: Disjoint<'a, D::Sym>,
    grad_v: Disjoint<'a, D::Mat>,
    grad_u: Disjoint<'a, D::Mat>,
    plastic_strain: Disjoint<'a, D::Sym>,
    hardened: Disjoint<'a, Hardened>,
    keep: bool,
    plastic: bool,
}

impl<'a, D: Dim> StressColumns<'a, D> {
    /// Borrows the columns (grad v and grad u are empty unless J-integrals keep them, the
    /// plastic ones unless a material is plastic).
    pub(crate) fn new(
        stress: &'a mut [D::Sym],
        grad_v: &'a mut [D::Mat],
        grad_u: &'a mut [D::Mat],
        plastic_strain: &'a mut [D::Sym],
        hardened: &'a mut [Hardened],
    ) -> Self {
        StressColumns {
            keep: !grad_u.is_empty(),
            plastic: !hardened.is_empty(),
            stress: Disjoint::new(stress),
            grad_v: Disjoint::new(grad_v),
            grad_u: Disjoint::new(grad_u),
            plastic_strain: Disjoint::new(plastic_strain),
            hardened: Disjoint::new(hardened),
        }
    }

    /// Borrows the stress-update columns of `p`, with its material column beside them.
    pub(crate) fn of(p: &'a mut Particles<D>) -> (Self, &'a [u16]) {
        let Particles {
            stress,
            grad_v,
            grad_u,
            plastic_strain,
            hardened,
            material,
            ..
        } = p;
        let columns = Self::new(stress, grad_v, grad_u, plastic_strain, hardened);
        (columns, material)
    }

    /// Particle `i`'s update from its velocity gradient `l` over `dt`: grad v and grad u
    /// when they are kept, then the stress (with the return map for a plastic material).
    /// Returns the new stress.
    ///
    /// # Safety
    /// No other thread may access particle `i`'s entries during the call.
    #[inline(always)]
    pub(crate) unsafe fn update(
        &self,
        i: usize,
        l: D::Mat,
        dt: f64,
        plane: Plane,
        m: &Material,
    ) -> D::Sym {
        // SAFETY: the caller's guarantee, passed on.
        unsafe {
            if self.keep {
                self.grad_v.set(i, l);
                self.grad_u.set(i, self.grad_u.get(i) + l * dt);
            }
            // Read before de and copied (not read straight into sigma): the other order
            // measured 12 % slower on the elastic stress bench (the generated loop).
            let start = self.stress.get(i).to_sym3();
            let de = D::sym_part(&l) * dt;
            let mut sigma = start;
            m.update(plane, de, &mut sigma);
            // A plastic particle whose elastic trial stays inside the yield surface keeps
            // its plastic state untouched (the common case, and no extra traffic).
            if let Some(j2) = m.j2.as_ref().filter(|_| self.plastic) {
                let h = self.hardened.get(i);
                if j2.yields(&sigma, &h) {
                    self.return_plastic(i, plane, m, &mut sigma, h);
                }
            }
            let s = D::Sym::from_sym3(sigma);
            self.stress.set(i, s);
            s
        }
    }

    /// The plastic correction of particle `i`'s elastic trial `sigma` (outside the yield
    /// surface of its state `h`; see [`Material::correct_plastic`]). Kept out of line so
    /// that the elastic loop around it compiles as it would without plasticity.
    ///
    /// # Safety
    /// As [`Self::update`].
    #[inline(never)]
    unsafe fn return_plastic(
        &self,
        i: usize,
        plane: Plane,
        m: &Material,
        sigma: &mut Sym3,
        mut h: Hardened,
    ) {
        // SAFETY: the caller's guarantee, passed on.
        unsafe {
            let mut ep = self.plastic_strain.get(i).to_sym3();
            m.correct_plastic(plane, sigma, &mut ep, &mut h);
            self.plastic_strain.set(i, D::Sym::from_sym3(ep));
            self.hardened.set(i, h);
        }
    }
}

/// grad v of one particle away from cracks: sum over its stencil of v_i ⊗ grad S_i, row by
/// row (sum_rows (sum_i v_i dw_i) ⊗ q x̂ + (sum_i v_i w_i) ⊗ g_yz).
#[inline(always)]
pub(crate) fn velocity_gradient<D: Dim, const N: usize>(
    st: &Stencil<N>,
    rows: &Rows,
    velocity: &[D::Vec],
) -> D::Mat {
    let mut l = D::mat_zero();
    for r in 0..rows.len {
        let row = rows.first[r];
        let (mut vd, mut vw) = (D::zero(), D::zero());
        // One bounds check per row: the slice has N nodes.
        for (a, &v) in velocity[row..row + N].iter().enumerate() {
            vd += v * st.dw[0][a];
            vw += v * st.w[0][a];
        }
        l = D::add_row(l, vd, rows.q[r], vw, rows.gy[r], rows.gz[r]);
    }
    l
}

/// Sets the grid velocity column to p/m (zero on nodes lighter than the mass tolerance;
/// image nodes their sources', reflected).
pub(crate) fn node_velocities<D: Dim>(world: &mut World<D>) {
    let tol = world.settings.mass_tol;
    let g = &mut world.grid;
    let (mass, momentum) = (&g.mass, &g.momentum);
    for span in world.domain.spans(g.velocity.len(), g.geom.node_count()) {
        let first = span.start;
        g.velocity[span]
            .par_chunks_mut(CHUNK)
            .enumerate()
            .for_each(|(c, vel)| {
                for (k, v) in vel.iter_mut().enumerate() {
                    let n = first + c * CHUNK + k;
                    *v = if mass[n] > tol {
                        momentum[n] * (1.0 / mass[n])
                    } else {
                        D::zero()
                    };
                }
            });
    }
    if !g.mirrors.is_empty() {
        mirror::reflect_velocity(g, false);
    }
}
