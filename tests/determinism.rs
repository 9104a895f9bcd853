//! The same scenario gives bitwise-identical results for any thread count.

mod common;
use common::{final_world, mixed_scene};
use fissure::base::dim::{D2, D3, Dim};
use fissure::base::sym::SymTensor;
use fissure::store::world::World;
use fissure::systems::DimSystems;

/// Every bit of the particle state that the next step depends on.
fn bits<D: Dim>(w: &World<D>) -> Vec<u64> {
    let p = &w.particles;
    let mut out = Vec::new();
    for i in 0..p.len() {
        let (x, v) = (D::to_xyz(p.x[i]), D::to_xyz(p.v[i]));
        out.extend(x.iter().chain(&v).map(|c| c.to_bits()));
        out.extend(p.stress[i].to_sym3().to_array().iter().map(|c| c.to_bits()));
    }
    out.push(w.work.external.to_bits());
    out.push(w.work.damping.to_bits());
    out
}

fn same_bits_for_thread_counts<D: DimSystems>(text: &str) {
    let one = bits(&final_world::<D>(text, 1));
    for threads in [2, 3] {
        let many = bits(&final_world::<D>(text, threads));
        assert!(
            one == many,
            "{}D results differ between 1 and {threads} threads",
            D::D
        );
    }
}

#[test]
fn bitwise_identical_across_thread_counts_2d() {
    same_bits_for_thread_counts::<D2>(&mixed_scene(2, "ugimp", "usavg"));
    same_bits_for_thread_counts::<D2>(&mixed_scene(2, "linear", "usl"));
}

#[test]
fn bitwise_identical_across_thread_counts_3d() {
    same_bits_for_thread_counts::<D3>(&mixed_scene(3, "bspline", "usf"));
}

/// A 3D scene with an inclined penny crack with frictionless contact: classification,
/// crack fields, contact and crack advection are as deterministic as the rest.
#[test]
fn bitwise_identical_across_thread_counts_3d_with_a_crack() {
    let crack = "[[crack]]\npenny = { center = [0.02, 0.007, 0.007], normal = [1.0, 0.3, 0.2], \
                 radius = 0.003 }\ncontact = { law = \"frictionless\" }\n";
    let text = mixed_scene(3, "ugimp", "usavg").replace("duration = 1e-5", "duration = 2e-6");
    same_bits_for_thread_counts::<D3>(&(text + crack));
}

/// J and K along a 3D crack front are bitwise the same for any thread count.
#[test]
fn front_fracture_is_bitwise_identical_across_thread_counts() {
    let crack = "[[crack]]\npenny = { center = [0.02, 0.007, 0.007], normal = [1.0, 0.3, 0.2], \
                 radius = 0.003 }\n[fracture]\ndomain = 2\n";
    let text =
        mixed_scene(3, "ugimp", "usavg").replace("duration = 1e-5", "duration = 2e-6") + crack;
    let src = common::source(&text);
    let plan = fissure::io::scenario::build::<D3>(&src)
        .unwrap_or_else(|e| panic!("{e}"))
        .fracture
        .unwrap();
    let tips = |threads: usize| {
        let w = final_world::<D3>(&text, threads);
        let tips = fissure::systems::fracture_front::measure(&w, &plan).tips;
        assert!(tips.iter().any(|t| t.k[0].is_finite()), "no K measured");
        tips.iter()
            .flat_map(|t| t.values())
            .map(f64::to_bits)
            .collect::<Vec<u64>>()
    };
    let one = tips(1);
    for threads in [2, 3] {
        assert!(one == tips(threads), "front K differs at {threads} threads");
    }
}

/// The cell's mean dilatation (`dilatation = "cell_mean"`) sums each group's mean in one
/// order: a 2D scene with an edge crack (USAVG) and a 3D one (USF) are bitwise the same
/// for any thread count.
#[test]
fn cell_mean_dilatation_is_bitwise_identical_across_thread_counts() {
    let mean = |t: String| {
        t.replace(
            "damping = 1000.0",
            "damping = 1000.0\ndilatation = \"cell_mean\"",
        )
    };
    let crack = "[[crack]]\nline = { start = [0.02, 0.001], end = [0.02, 0.007] }\n";
    same_bits_for_thread_counts::<D2>(&(mean(mixed_scene(2, "ugimp", "usavg")) + crack));
    let short = mixed_scene(3, "bspline", "usf").replace("duration = 1e-5", "duration = 2e-6");
    same_bits_for_thread_counts::<D3>(&mean(short));
}
