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
pub mod fracture;
pub mod fracture_front;
pub mod g2p;
pub mod grid_update;
pub mod grow;
pub mod grow_front;
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
use crate::store::crack::Fields;
use crate::store::world::World;

/// Whether particle `i` sees no crack (`fields`, the crack store's per-particle fields, when
/// the scene has cracks): the particle systems handle it in their common loop, the coded
/// ones field by field afterwards.
#[inline(always)]
pub(crate) fn is_free(fields: Option<&Fields>, i: usize) -> bool {
    !fields.is_some_and(|f| f.is_coded(i))
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
