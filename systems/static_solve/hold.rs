//! Load steps that change nothing: the loads and the moving supports' displacements the
//! same at both ends of the step (a ramp's hold, the output times after it) and the cracks
//! as the last solve left them. Their equilibrium is the last step's, which the particles
//! already hold, so such a step solves nothing. Every part of the test is in a snapshot
//! (the time functions in the scene; with the cracks, their topology's version at the last
//! solve), so a resumed run skips the same steps.

use super::supports;
use crate::base::dim::Dim;
use crate::store::world::World;

/// Load factors and support displacements that differ by less than this fraction of their
/// size are the same. A step ends at k duration / load_steps, rounded, so a time function's
/// breakpoint is met within a few roundings (7e-5 / 7 ends the first step at
/// 0.9999999999999998 of a 10 us ramp); a solve, stopped at 1e-12 of the load at the
/// finest, resolves nothing so small.
const SAME: f64 = 1e-14;

/// Whether the load step from `t_start` to `t_end` would solve what the last one solved:
/// not the first step (which starts from the unloaded body), every load's time factor and
/// every moving support's displacement the same at both ends (to [`SAME`]; gravity does
/// not vary), and no crack grown since the last solve.
pub(super) fn unchanged<D: Dim>(world: &World<D>, t_start: f64, t_end: f64) -> bool {
    world.step > 0
        && (world.loads.iter()).all(|l| same(l.time.at(t_start), l.time.at(t_end)))
        && (world.bcs.iter())
            .filter(|bc| supports::moves(bc))
            .all(|bc| same(bc.time.integral(t_start), bc.time.integral(t_end)))
        && (world.cracks.as_ref()).is_none_or(|c| c.solved == Some(c.topology.version()))
}

/// Whether `a` and `b` are the same to [`SAME`] of the larger.
fn same(a: f64, b: f64) -> bool {
    (a - b).abs() <= SAME * a.abs().max(b.abs())
}
