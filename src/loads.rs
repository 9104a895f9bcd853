//! External particle forces and prescribed grid velocities.

use crate::dim::Dim;
use crate::timefn::TimeFn;

/// A force spread equally over a fixed set of particles, scaled by a time function.
#[derive(Clone, Debug)]
pub struct Load<D: Dim> {
    /// Loaded particles.
    pub particles: Vec<u32>,
    /// Force on each particle at full load (N).
    pub force: D::Vec,
    /// Time multiplier.
    pub time: TimeFn,
}

/// Prescribed velocity components on a fixed set of grid nodes (fixed supports, symmetry
/// planes, moving grips).
#[derive(Clone, Debug)]
pub struct VelocityBc<D: Dim> {
    /// Constrained nodes.
    pub nodes: Vec<u32>,
    /// Which components are prescribed.
    pub axes: [bool; 3],
    /// Prescribed velocity at full scale (m/s).
    pub velocity: D::Vec,
    /// Time multiplier on `velocity`.
    pub time: TimeFn,
}

impl<D: Dim> VelocityBc<D> {
    /// Prescribed velocity component `a` at time `t`.
    #[inline(always)]
    pub fn value(&self, a: usize, t: f64) -> f64 {
        self.velocity[a] * self.time.at(t)
    }
}
