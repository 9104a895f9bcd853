//! The schedule holds only the systems a scene needs, in pipeline order.

mod common;
use common::source;
use fissure::base::dim::D2;
use fissure::io::scenario::build;
use fissure::pipeline::schedule::Schedule;
use fissure::store::world::World;
use fissure::systems::bin;

fn names(extra: &str, update: &str) -> Vec<&'static str> {
    let text = common::block_2d(1e-5, 0.004, 0.016, extra).replace(
        "dimension = 2",
        &format!("dimension = 2\nupdate = \"{update}\""),
    );
    let world = build::<D2>(&source(&text)).unwrap().world;
    Schedule::for_world(&world, None)
        .systems
        .iter()
        .map(|s| s.name())
        .collect()
}

#[test]
fn usf_without_boundaries_has_no_remap_and_no_grid_bc() {
    assert_eq!(
        names("", "usf"),
        ["bin", "p2g", "stress_force", "grid_update", "g2p"]
    );
}

#[test]
fn usl_remaps_before_its_stress_update_which_bins_the_next_step() {
    assert_eq!(
        names("", "usl"),
        ["bin", "p2g", "grid_update", "g2p_remap", "stress_bin"]
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
            "stress_force",
            "grid_update",
            "g2p_remap",
            "grid_bc",
            "stress_bin"
        ]
    );
}

/// The closing stress update fused with the binning (`stress_bin`) gives the bits of the two
/// systems run apart, and leaves the bins and stencils a fresh binning builds.
#[test]
fn fused_stress_bin_matches_stress_then_bin() {
    for (shape, update) in [("ugimp", "usavg"), ("linear", "usl")] {
        let text = common::mixed_scene(2, shape, update);
        let (fused, mut apart) = common::fused_and_unfused::<D2>(&text, 30);
        assert!(fused.tiles.fresh && !apart.tiles.fresh);
        bin::run(&mut apart).unwrap();
        let bits = |w: &World<D2>| {
            format!(
                "{:?} {:?} {:?} {:?} {:?}",
                w.particles.stress,
                w.particles.x,
                w.tiles.order,
                w.tiles.stencils.first,
                w.tiles.stencils.params
            )
        };
        assert!(bits(&fused) == bits(&apart), "{shape} {update}");
    }
}

/// The cell's mean dilatation swaps the fused stress updates for `mean_stress` (the opening
/// one scatters the forces too; no binning: the next step's `bin` does it) and USL's
/// internal forces for `mean_force`, after the momenta.
#[test]
fn cell_mean_dilatation_updates_and_scatters_apart() {
    let mean = |update| {
        let text = common::block_2d(1e-5, 0.004, 0.016, "").replace(
            "dimension = 2",
            &format!("dimension = 2\nupdate = \"{update}\"\ndilatation = \"cell_mean\""),
        );
        let world = build::<D2>(&source(&text)).unwrap().world;
        let names: Vec<_> = (Schedule::for_world(&world, None).systems.iter())
            .map(|s| s.name())
            .collect();
        names
    };
    assert_eq!(
        mean("usf"),
        ["bin", "p2g", "mean_stress", "grid_update", "g2p"]
    );
    assert_eq!(
        mean("usl"),
        [
            "bin",
            "p2g",
            "mean_force",
            "grid_update",
            "g2p_remap",
            "mean_stress"
        ]
    );
    assert_eq!(
        mean("usavg"),
        [
            "bin",
            "p2g",
            "mean_stress",
            "grid_update",
            "g2p_remap",
            "mean_stress"
        ]
    );
}
