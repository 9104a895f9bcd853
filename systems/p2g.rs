//! `p2g`: particle-to-grid scatter of mass, momentum and forces (Guo & Nairn 2D (2004)
//! Eqs. 3-6, single velocity field), tile by tile in colour classes.

use crate::crack::Fields;
use crate::dim::Dim;
use crate::grid::{Grid, GridGeom};
use crate::particles::Particles;
use crate::shape::{ShapeKind, Stencil, StencilCache};
use crate::with_nodes;
use crate::world::World;
use rayon::prelude::*;
use std::marker::PhantomData;

/// Write access to the grid's scatter columns shared by the tiles of one colour class.
struct NodeWriter<'a, D: Dim> {
    mass: *mut f64,
    momentum: *mut D::Vec,
    force: *mut D::Vec,
    len: usize,
    _borrow: PhantomData<&'a mut Grid<D>>,
}

// SAFETY: the writer only hands out element writes through `add`, whose contract requires
// that no two threads touch the same node at once; the pointed-to columns are exclusively
// borrowed for the writer's lifetime.
unsafe impl<D: Dim> Sync for NodeWriter<'_, D> {}
// SAFETY: as for Sync; the raw pointers refer to heap columns that outlive the writer.
unsafe impl<D: Dim> Send for NodeWriter<'_, D> {}

impl<'a, D: Dim> NodeWriter<'a, D> {
    fn new(mass: &'a mut [f64], momentum: &'a mut [D::Vec], force: &'a mut [D::Vec]) -> Self {
        assert!(mass.len() == momentum.len() && mass.len() == force.len());
        NodeWriter {
            len: mass.len(),
            mass: mass.as_mut_ptr(),
            momentum: momentum.as_mut_ptr(),
            force: force.as_mut_ptr(),
            _borrow: PhantomData,
        }
    }

    /// Adds a force to node `n`.
    ///
    /// # Safety
    /// No other thread may access node `n` during the call.
    #[inline(always)]
    unsafe fn add_force(&self, n: usize, f: D::Vec) {
        assert!(n < self.len);
        // SAFETY: n is in bounds (checked above) and the caller guarantees exclusive access
        // to node n.
        unsafe { *self.force.add(n) += f };
    }

    /// Adds mass to node `n`.
    ///
    /// # Safety
    /// No other thread may access node `n` during the call.
    #[inline(always)]
    unsafe fn add_mass(&self, n: usize, m: f64) {
        assert!(n < self.len);
        // SAFETY: n is in bounds (checked above) and the caller guarantees exclusive access
        // to node n.
        unsafe { *self.mass.add(n) += m };
    }

    /// Adds momentum to node `n`.
    ///
    /// # Safety
    /// No other thread may access node `n` during the call.
    #[inline(always)]
    unsafe fn add_momentum(&self, n: usize, p: D::Vec) {
        assert!(n < self.len);
        // SAFETY: n is in bounds (checked above) and the caller guarantees exclusive access
        // to node n.
        unsafe { *self.momentum.add(n) += p };
    }
}

/// Scatters mass and momentum (and, when `internal`, the internal force -V sigma . grad S)
/// to a zeroed grid, then adds the external particle loads.
pub fn run<D: Dim>(world: &mut World<D>, internal: bool) {
    world.grid.force.par_iter_mut().for_each(|f| *f = D::zero());
    if internal {
        scatter::<D, true, true, true>(world);
    } else {
        scatter::<D, true, true, false>(world);
    }
    scatter_loads(world);
}

/// Re-scatters the updated particle momenta with the start-of-step shape functions, so
/// that the final stress update reads grid velocities that are mass-weighted averages of
/// particle velocities (the modified USL of Sulsky, Zhou & Schreyer 1995). Without it,
/// nodes with a tiny share of mass get huge velocities and linear shape functions go
/// unstable. The nodal masses are those of `p2g` (same particles, same weights).
pub fn remap<D: Dim>(world: &mut World<D>) {
    scatter::<D, false, true, false>(world);
}

/// Scatters the internal force -V sigma . grad S alone (USF and USAVG, after the first
/// stress update).
pub fn internal_force<D: Dim>(world: &mut World<D>) {
    scatter::<D, false, false, true>(world);
}

/// One scatter pass over the tiles, colour class by colour class (Guo & Nairn 2D (2004)
/// Eqs. 3 and 6, single velocity field): mass when `MASS`, momentum when `MOMENTUM` (each
/// zeroed first), the internal force -V sigma . grad S when `FORCE`. Compile-time flags
/// keep the hot loop free of branches.
fn scatter<D: Dim, const MASS: bool, const MOMENTUM: bool, const FORCE: bool>(
    world: &mut World<D>,
) {
    let Grid {
        geom,
        mass,
        momentum,
        force,
        ..
    } = &mut world.grid;
    if MASS {
        mass.par_iter_mut().for_each(|m| *m = 0.0);
    }
    if MOMENTUM {
        momentum.par_iter_mut().for_each(|m| *m = D::zero());
    }
    let writer = NodeWriter::<D>::new(mass, momentum, force);
    let p = &world.particles;
    let shape = world.settings.shape;
    let geom = &*geom;
    let fields = world.cracks.as_ref().map(|c| &c.fields);
    world.tiles.for_each_coloured(|t| {
        with_nodes!(shape, N => for &i in world.tiles.particles(t) {
            let i = i as usize;
            // Particles near a crack are scattered field by field afterwards.
            if fields.is_some_and(|f| f.slot[i] != u32::MAX) {
                continue;
            }
            let st = Stencil::<N>::cached::<D>(&world.tiles.stencils, i);
            let (m, mv) = (p.mass[i], p.v[i] * p.mass[i]);
            // Internal force split as in `Stencil::for_each_row`.
            let (s, vol) = (p.stress[i], -p.volume[i]);
            let sx = D::stress_dot(&s, D::unit_x()) * vol;
            st.for_each_row::<D>(&geom.stride, |row, q, gyz| {
                let (mq, mvq, sxq) = (m * q, mv * q, sx * q);
                let syz = D::stress_dot(&s, gyz) * vol;
                for a in 0..N {
                    let (w, dw) = (st.w[0][a], st.dw[0][a]);
                    // SAFETY: tiles of one colour class touch disjoint nodes (tiles.rs), and
                    // each tile is handled by one thread.
                    unsafe {
                        if MASS {
                            writer.add_mass(row + a, mq * w);
                        }
                        if MOMENTUM {
                            writer.add_momentum(row + a, mvq * w);
                        }
                        if FORCE {
                            writer.add_force(row + a, sxq * dw + syz * w);
                        }
                    }
                }
            });
        })
    });
    if let Some(f) = fields {
        let stencils = &world.tiles.stencils;
        let columns = (&mut mass[..], &mut momentum[..], &mut force[..]);
        scatter_coded::<D, MASS, MOMENTUM, FORCE>(f, p, shape, stencils, columns, geom);
    }
}

/// The scatter of the particles near a crack, each pair into its field's grid entry
/// (Guo & Nairn 2D (2004) Eqs. 3 and 6), sequentially in particle order.
fn scatter_coded<D: Dim, const MASS: bool, const MOMENTUM: bool, const FORCE: bool>(
    fields: &Fields,
    p: &Particles<D>,
    shape: ShapeKind,
    stencils: &StencilCache,
    (mass, momentum, force): (&mut [f64], &mut [D::Vec], &mut [D::Vec]),
    geom: &GridGeom<D>,
) {
    for &i in &fields.coded {
        let i = i as usize;
        let targets = fields.targets_of(i).expect("coded particle");
        let (m, mv, s, vol) = (p.mass[i], p.v[i] * p.mass[i], p.stress[i], p.volume[i]);
        with_nodes!(shape, N => {
            let st = Stencil::<N>::cached::<D>(stencils, i);
            st.for_each_target::<D>(&geom.stride, targets, |n, w, g| {
                if MASS {
                    mass[n] += m * w;
                }
                if MOMENTUM {
                    momentum[n] += mv * w;
                }
                if FORCE {
                    force[n] -= D::stress_dot(&s, g) * vol;
                }
            });
        });
    }
}

/// Adds external particle forces to the grid (sequential, in load order) and books the
/// first half of their work over the step.
fn scatter_loads<D: Dim>(world: &mut World<D>) {
    let (t, dt) = (world.time, world.settings.dt);
    let p = &world.particles;
    let geom = &world.grid.geom;
    let shape = world.settings.shape;
    let mut work = 0.0;
    for load in &world.loads {
        let scale = load.time.at(t);
        for (&i, &f) in load.particles.iter().zip(&load.forces) {
            let (i, f) = (i as usize, f * scale);
            let targets = world.cracks.as_ref().and_then(|c| c.fields.targets_of(i));
            with_nodes!(shape, N => {
                let st = Stencil::<N>::cached::<D>(&world.tiles.stencils, i);
                match targets {
                    Some(t) => st.for_each_target::<D>(&geom.stride, t, |n, w, _| {
                        world.grid.force[n] += f * w
                    }),
                    None => st.for_each::<D>(&geom.stride, |n, w, _| world.grid.force[n] += f * w),
                }
            });
            work += 0.5 * dt * D::dot(f, p.v[i]);
        }
    }
    world.work.external += work;
}
