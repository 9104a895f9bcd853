//! The systems, one file each, listed in pipeline order (the order `Schedule::for_world`
//! runs them in; `bin` and `stress_bin` also open and close the step). Each is a plain
//! function over the World.

/// The loop the particle systems run over a list of particles (`usize` indices): for each
/// [free](is_free) particle, `$body` with `$i` its index and `$st` its cached stencil of `N`
/// nodes per axis in dimension `$d`. `N` is a constant in `$body` (bound by `with_shape!`
/// outside the loop), so stencil loops unroll and no particle matches on the shape.
/// `stress_bin` alone runs its particles inside the binning pass, with the same test.
macro_rules! for_each_free_particle {
    ($d:ty, $shape:expr, $stencils:expr, $fields:expr, $particles:expr, |$i:ident, $st:ident| $body:block) => {
        $crate::with_shape!($shape, S, N => for $i in $particles {
            if !$crate::systems::is_free($fields, $i) {
                continue;
            }
            let $st = $crate::physics::shape::Stencil::<N>::cached::<$d>(S, $stencils, $i);
            $body
        })
    };
}

pub mod bin;
pub mod classify;
pub mod contact;
pub mod crack_advect;
pub mod dilatation;
pub mod fracture;
pub mod fracture_front;
pub mod g2p;
pub mod grid_update;
pub mod grow;
pub mod grow_front;
pub mod mean_stress;
pub mod mirror;
pub mod p2g;
pub mod scatter_coded;
pub mod static_solve;
pub mod stress;
pub mod stress_bin;
pub mod stress_force;

use crate::base::dim::{D2, D3, Dim};
use crate::base::error::Unstable;
use crate::fracture::plan::{FracturePlan, Measured};
use crate::physics::growth::GrowthRow;
use crate::physics::shape::{ShapeKind, Stencil};
use crate::store::crack::Fields;
use crate::store::world::World;
use crate::with_shape;

/// Whether particle `i` sees no crack (`fields`, the crack store's per-particle fields, when
/// the scene has cracks): the particle systems handle it in their common loop, the coded
/// ones field by field afterwards.
#[inline(always)]
pub(crate) fn is_free(fields: Option<&Fields>, i: usize) -> bool {
    !fields.is_some_and(|f| f.is_coded(i))
}

/// Calls `f(entry, weight, grad S)` for each node of particle `i`'s stencil, on the entry
/// of the particle's side where a crack splits the node.
pub(crate) fn each_entry<D: Dim>(
    world: &World<D>,
    i: usize,
    mut f: impl FnMut(usize, f64, D::Vec),
) {
    let shape: ShapeKind = world.settings.shape;
    let stride = &world.grid.geom.stride;
    let targets = world
        .cracks
        .as_ref()
        .and_then(|c| c.scratch.fields.targets_of(i));
    with_shape!(shape, S, N => {
        let st = Stencil::<N>::cached::<D>(S, &world.tiles.stencils, i);
        match targets {
            Some(t) => st.for_each_target::<D>(stride, t, &mut f),
            None => st.for_each::<D>(stride, &mut f),
        }
    });
}

/// The gradient at particle `i` of a field given on the grid entries (`u`: displacements
/// in a static solve, velocities in an explicit step).
pub(crate) fn entry_gradient<D: Dim>(world: &World<D>, i: usize, u: &[D::Vec]) -> D::Mat {
    let mut l = D::mat_zero();
    each_entry(world, i, |n, _, g| l = l + D::outer(u[n], g));
    l
}

/// The systems whose algorithm differs by dimension: J and K at crack tips in 2D and at
/// every front vertex in 3D, and the growth of tips or fronts. Each returns what it
/// measured, for the step to report.
pub trait DimSystems: Dim {
    /// J and K at every crack front of the world as the plan says.
    fn fracture(world: &World<Self>, plan: &FracturePlan) -> Measured;
    /// Advances the growing crack tips (2D) or fronts (3D) after a step: a row per growth.
    fn grow(
        world: &mut World<Self>,
        plan: Option<&FracturePlan>,
    ) -> Result<Vec<GrowthRow>, Unstable>;
}

impl DimSystems for D2 {
    fn fracture(world: &World<D2>, plan: &FracturePlan) -> Measured {
        fracture::measure(world, plan)
    }
    fn grow(
        world: &mut World<D2>,
        plan: Option<&FracturePlan>,
    ) -> Result<Vec<GrowthRow>, Unstable> {
        grow::run(world, plan)
    }
}

impl DimSystems for D3 {
    fn fracture(world: &World<D3>, plan: &FracturePlan) -> Measured {
        fracture_front::measure(world, plan)
    }
    fn grow(
        world: &mut World<D3>,
        plan: Option<&FracturePlan>,
    ) -> Result<Vec<GrowthRow>, Unstable> {
        grow_front::run(world, plan)
    }
}
