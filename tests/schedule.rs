//! The schedule holds only the systems a scene needs, in pipeline order.

mod common;
use common::source;
use fissure::dim::D2;
use fissure::scenario::build;
use fissure::schedule::Schedule;

fn names(extra: &str, update: &str) -> Vec<&'static str> {
    let text = common::block_2d(1e-5, 0.004, 0.016, extra).replace(
        "dimension = 2",
        &format!("dimension = 2\nupdate = \"{update}\""),
    );
    let world = build::<D2>(&source(&text)).unwrap().world;
    Schedule::for_world(&world)
        .systems
        .iter()
        .map(|s| s.name())
        .collect()
}

#[test]
fn usf_without_boundaries_has_no_remap_and_no_grid_bc() {
    assert_eq!(
        names("", "usf"),
        [
            "bin",
            "p2g",
            "stress",
            "internal_force",
            "grid_update",
            "g2p"
        ]
    );
}

#[test]
fn usl_remaps_before_its_stress_update() {
    assert_eq!(
        names("", "usl"),
        ["bin", "p2g", "grid_update", "g2p_remap", "stress"]
    );
}

#[test]
fn boundaries_add_grid_bc_after_each_momentum_scatter() {
    let bc = "[[boundary]]\nplane = { axis = \"x\", at = 0.004 }";
    assert_eq!(
        names(bc, "usavg"),
        [
            "bin",
            "p2g",
            "grid_bc",
            "stress",
            "internal_force",
            "grid_update",
            "g2p_remap",
            "grid_bc",
            "stress"
        ]
    );
}
