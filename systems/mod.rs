//! The systems, one file each, listed in pipeline order (the order `Schedule::for_world`
//! runs them in; `bin` and `stress_bin` also open and close the step). Each is a plain
//! function over the World.

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
pub mod p2g;
pub mod stress;
pub mod stress_bin;
pub mod stress_force;

use crate::base::dim::{D2, D3, Dim};
use crate::base::error::Unstable;
use crate::fracture::plan::{FracturePlan, Measured};
use crate::physics::growth::GrowthRow;
use crate::store::world::World;

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
