//! What a static scene (`solver = "static"`) may hold so far: linear elastic bodies held
//! by their boundaries (still, or moved by a prescribed velocity's displacement), under
//! loads and gravity, with open cracks or faces in frictionless contact, growing or not,
//! elastic or J2 plastic, and faces under Coulomb friction. The `stick` law is refused by
//! name until the static solver takes it.

use super::check::R;
use super::source::Source;
use crate::store::world::Solver;

/// The convergence tolerances a static scene may ask for: below the lower, round-off
/// keeps the iteration from converging; above the upper, the answer is not a solution.
const TOLERANCE_RANGE: (f64, f64) = (1e-12, 1e-2);

/// Refuses what the static solver does not take yet, naming the key.
pub(super) fn check(src: &Source) -> R<()> {
    let sc = &src.scenario;
    if let Some(t) = sc.simulation.tolerance {
        if sc.simulation.solver != Solver::Static {
            return Err(src.error(
                "simulation.tolerance",
                "a convergence tolerance belongs to a static scene (solver = \"static\")",
            ));
        }
        if !(TOLERANCE_RANGE.0..=TOLERANCE_RANGE.1).contains(&t) {
            return Err(src.error(
                "simulation.tolerance",
                format!(
                    "give a residual between {:e} (round-off stops conjugate gradients near \
                     1e-10) and {:e} of the load",
                    TOLERANCE_RANGE.0, TOLERANCE_RANGE.1
                ),
            ));
        }
    }
    if sc.simulation.solver != Solver::Static {
        if sc.simulation.linear.is_some() {
            return Err(src.error(
                "simulation.linear",
                "a linear solver belongs to a static scene (solver = \"static\")",
            ));
        }
        return Ok(());
    }
    for (c, crack) in sc.cracks.iter().enumerate() {
        if crack.contact.as_ref().is_some_and(|k| k.law == "stick") {
            return Err(src.error(
                &format!("crack[{c}].contact.law"),
                "the static solver takes frictionless faces and Coulomb friction (`friction`), \
                 not `stick` yet (faces that stick whatever the force: give a large friction \
                 coefficient, or run this scene with solver = \"explicit\")",
            ));
        }
    }
    Ok(())
}

/// The keys of a static scene that apply to explicit runs only, as given (none in an
/// explicit scene): the launcher and summary.json name them, so that a scene switched
/// between the solvers by one key never drops one silently.
pub fn ignored(src: &Source) -> Vec<String> {
    let sc = &src.scenario;
    let sim = &sc.simulation;
    if sim.solver != Solver::Static {
        return Vec::new();
    }
    let mut keys = Vec::new();
    let given = [
        ("simulation.cfl", sim.cfl.is_some()),
        ("simulation.dt", sim.dt.is_some()),
        ("simulation.damping", sim.damping != 0.0),
    ];
    keys.extend((given.iter()).filter(|g| g.1).map(|g| g.0.to_string()));
    for (b, body) in sc.bodies.iter().enumerate() {
        if body.velocity.is_some() {
            keys.push(format!("body[{b}].velocity"));
        }
        if body.angular_velocity.is_some() {
            keys.push(format!("body[{b}].angular_velocity"));
        }
    }
    keys
}
