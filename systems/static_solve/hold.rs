//! Load steps that change nothing: the loads and the moving supports' displacements the
//! same at both ends of the step (a ramp's hold, the output times after it) and the cracks
//! as the last solve left them. Their equilibrium is the last step's, which the particles
//! already hold, so such a step solves nothing. Every part of the test is in a snapshot
//! (the time functions in the scene; with the cracks, their topology's version at the last
//! solve), so a resumed run skips the same steps.

use super::supports;
use crate::base::dim::Dim;
use crate::store::world::World;

/// Whether the load step from `t_start` to `t_end` would solve what the last one solved:
/// not the first step (which starts from the unloaded body), every load's time factor and
/// every moving support's displacement the same at both ends (gravity does not vary), and
/// no crack grown since the last solve.
pub(super) fn unchanged<D: Dim>(world: &World<D>, t_start: f64, t_end: f64) -> bool {
    world.step > 0
        && (world.loads.iter()).all(|l| l.time.at(t_start) == l.time.at(t_end))
        && (world.bcs.iter())
            .filter(|bc| supports::moves(bc))
            .all(|bc| bc.time.integral(t_start) == bc.time.integral(t_end))
        && (world.cracks.as_ref()).is_none_or(|c| c.solved == Some(c.topology.version()))
}
