//! What a static scene (`solver = "static"`) may hold so far: linear elastic bodies held
//! still by their boundaries, under loads and gravity, with open cracks. Crack-face
//! contact, growth, plasticity and prescribed displacements are refused by name until the
//! static solver takes them.

use super::check::R;
use super::source::Source;
use crate::physics::material::Material;
use crate::store::world::Solver;

/// Refuses what the static solver does not take yet, naming the key.
pub(super) fn check(src: &Source, materials: &[Material], used: &[bool]) -> R<()> {
    let sc = &src.scenario;
    if sc.simulation.solver != Solver::Static {
        return Ok(());
    }
    for (c, crack) in sc.cracks.iter().enumerate() {
        if crack.contact.as_ref().is_some_and(|k| k.law != "none") {
            return Err(src.error(
                &format!("crack[{c}].contact"),
                "the static solver does not take crack-face contact yet (faces that close \
                 need contact constraints): give law = \"none\" for open cracks, or run \
                 this scene with solver = \"explicit\"",
            ));
        }
        if crack.growth.is_some() {
            return Err(src.error(
                &format!("crack[{c}].growth"),
                "the static solver does not grow cracks yet: run this scene with solver = \
                 \"explicit\"",
            ));
        }
    }
    if let Some(k) = (0..materials.len()).find(|&k| used[k] && materials[k].j2.is_some()) {
        return Err(src.error(
            &format!("material[{k}]"),
            "the static solver does not take J2 plasticity yet (it needs Newton iterations): \
             run this scene with solver = \"explicit\"",
        ));
    }
    for (i, bc) in sc.boundaries.iter().enumerate() {
        if bc
            .velocity
            .as_ref()
            .is_some_and(|v| v.iter().any(|&c| c != 0.0))
        {
            return Err(src.error(
                &format!("boundary[{i}].velocity"),
                "a static scene's boundaries hold their nodes still: prescribed \
                 displacements are not taken yet",
            ));
        }
    }
    Ok(())
}
