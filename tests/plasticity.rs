//! J2 plasticity in whole runs: the plastic state is deterministic across thread counts,
//! the energy balance with the plastic work closes, and an elastic scene carries no plastic
//! columns.

mod common;
use common::{final_world, history, mixed_scene, plastic};
use fissure::base::dim::{D2, D3, Dim};
use fissure::base::sym::SymTensor;
use fissure::record::history::energy_balance;
use fissure::store::world::World;
use fissure::systems::DimSystems;

/// Every bit of the stress and plastic state.
fn bits<D: Dim>(w: &World<D>) -> Vec<u64> {
    let p = &w.particles;
    let mut out = Vec::new();
    for i in 0..p.len() {
        out.extend(D::to_xyz(p.x[i]).map(f64::to_bits));
        out.extend(p.stress[i].to_sym3().to_array().map(f64::to_bits));
        out.extend(p.plastic_strain[i].to_sym3().to_array().map(f64::to_bits));
        let h = p.hardened[i];
        out.extend([h.equivalent, h.flow_stress, h.work].map(f64::to_bits));
    }
    out
}

/// The fraction of particles that have yielded.
fn yielded<D: Dim>(w: &World<D>) -> f64 {
    let p = &w.particles;
    p.hardened.iter().filter(|h| h.equivalent > 0.0).count() as f64 / p.len() as f64
}

fn same_bits_for_thread_counts<D: DimSystems>(text: &str) {
    let one = final_world::<D>(text, 1);
    let y = yielded(&one);
    assert!(
        y > 0.05 && y < 0.95,
        "{}D: {y} of the particles yielded",
        D::D
    );
    let one = bits(&one);
    for threads in [2, 3] {
        assert!(
            one == bits(&final_world::<D>(text, threads)),
            "{}D plastic results differ between 1 and {threads} threads",
            D::D
        );
    }
}

/// The mixed scene (an impact on a clamp, a load, damping) with yield at 20 MPa: part of
/// the body yields, and every bit matches for 1, 2 and 3 threads, in plane strain, plane
/// stress (whose return iterates) and 3D.
#[test]
fn plastic_results_are_bitwise_identical_across_thread_counts() {
    let text = plastic(&mixed_scene(2, "ugimp", "usavg"), 2e7, "n = 5");
    same_bits_for_thread_counts::<D2>(&text);
    let stress = text.replace("dimension = 2", "dimension = 2\nplane = \"stress\"");
    same_bits_for_thread_counts::<D2>(&stress);
    let text = plastic(&mixed_scene(3, "linear", "usf"), 2e7, "H = 5e9");
    same_bits_for_thread_counts::<D3>(&text);
}

/// Without damping, the kinetic energy of the impact goes into elastic energy and plastic
/// work: K + W + W_p - W_ext stays at its start to the accuracy of the elastic scene's own
/// balance (the explicit step's O(dt) error), while W_p is a sizeable share of the energy.
#[test]
fn energy_balance_with_plastic_work_closes() {
    let elastic = mixed_scene(2, "ugimp", "usavg").replace("damping = 1000.0", "damping = 0.0");
    let h = history(&plastic(&elastic, 2e7, "H = 2e9"));
    let last = h.rows.last().unwrap().energies;
    let share = last.plastic_work / last.internal();
    assert!(
        share > 0.05,
        "plastic work is {share} of the energy: too little to test"
    );
    let drift = energy_balance(&h).unwrap();
    let reference = energy_balance(&history(&elastic)).unwrap();
    assert!(
        drift < 2.0 * reference.max(1e-4),
        "balance drift {drift:e} (elastic scene: {reference:e})"
    );
}

/// A scene without plastic materials keeps no plastic columns and reports no plastic work.
#[test]
fn elastic_scene_has_no_plastic_state() {
    let w = final_world::<D2>(&mixed_scene(2, "linear", "usl"), 1);
    assert!(w.particles.hardened.is_empty() && w.particles.plastic_strain.is_empty());
    assert_eq!(w.energies().plastic_work, 0.0);
}

/// The edge-cracked plate of the growth tests, its crack held still.
fn edge_plate() -> String {
    common::edge_plate("", 1.5e-5).replace("[crack.growth]\n\n", "")
}

/// K comes from J only while the contour runs through elastic material: a plate whose
/// remote stress (100 MPa) is twice the yield stress reports J but no K; one whose yield
/// stress is never reached gives bitwise the elastic run's J and K.
#[test]
fn k_is_reported_only_while_the_contour_is_elastic() {
    let last = |text: &str| *history(text).fracture.last().expect("a tip row");
    let elastic = last(&edge_plate());
    assert!(elastic.k[0] > 0.0 && elastic.j[0] > 0.0);
    let unyielded = last(&plastic(&edge_plate(), 1e10, "H = 0"));
    assert_eq!(
        unyielded.values().map(f64::to_bits),
        elastic.values().map(f64::to_bits)
    );
    let yielded = last(&plastic(&edge_plate(), 5e7, "H = 0"));
    assert!(
        yielded.j[0].is_finite() && yielded.j[0] > 0.0,
        "J {:?}",
        yielded.j
    );
    assert!(yielded.k[0].is_nan() && yielded.k_interaction[0].is_nan());
    // The launcher says why a K expect then has no value.
    let dir = std::env::temp_dir().join(format!("fissure-k-plastic-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("yielded.toml");
    let expect = "[[expect]]\nquantity = \"KI\"\ncrack = \"edge\"\nreference = 1e6\n\
                  tolerance = 0.1\nsource = \"any\"\n";
    std::fs::write(&file, plastic(&edge_plate(), 5e7, "H = 0") + expect).unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_fissure"))
        .args(["run", file.to_str().unwrap(), "--out"])
        .arg(dir.join("out"))
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(1), "{stdout}");
    assert!(stdout.contains("a K expect has no value"), "{stdout}");
    std::fs::remove_dir_all(dir).ok();
}

/// A 14 mm cube (E = 1 GPa) with a centred penny crack of radius 3 mm normal to y, pulled
/// by 2 MPa on its y faces for 15 us, J and K on tubes of 3 cells every 5 us.
fn penny_cube() -> String {
    r#"[simulation]
dimension = 3
duration = 1.5e-5
[grid]
min = [-0.002, -0.002, -0.002]
max = [0.016, 0.016, 0.016]
cell = [0.001, 0.001, 0.001]
[[material]]
name = "m"
E = 1e9
nu = 0.3
rho = 1000.0
[[body]]
material = "m"
box = { min = [0.0, 0.0, 0.0], max = [0.014, 0.014, 0.014] }
[[crack]]
name = "p"
penny = { center = [0.007, 0.007, 0.007], normal = [0.0, 1.0, 0.0], radius = 0.003 }
[[load]]
region = { min = [0.0, 0.0135, 0.0], max = [0.014, 0.014, 0.014] }
force = [0.0, 392.0, 0.0]
time = { kind = "ramp", rise = 2.0e-6 }
[[load]]
region = { min = [0.0, 0.0, 0.0], max = [0.014, 0.0005, 0.014] }
force = [0.0, -392.0, 0.0]
time = { kind = "ramp", rise = 2.0e-6 }
[fracture]
domain = 3
[output]
history_interval = 5.0e-6
"#
    .to_string()
}

/// In 3D too, K along the front comes from J only while the tube's surface is elastic: a
/// yield stress of half the load withholds K at every vertex (J stays); one never reached
/// gives bitwise the elastic run's J and K.
#[test]
fn front_k_is_reported_only_while_the_tube_is_elastic() {
    let last_rows = |text: &str| {
        let h = history(text);
        let last = h.fracture.last().expect("front rows").step;
        (h.fracture.into_iter())
            .filter(|t| t.step == last)
            .collect::<Vec<_>>()
    };
    let elastic = last_rows(&penny_cube());
    assert!(elastic.iter().all(|t| t.k[0] > 0.0), "the penny opens");
    let unyielded = last_rows(&plastic(&penny_cube(), 1e8, "H = 0"));
    let bits = |rows: &[fissure::fracture::plan::TipResult]| {
        (rows.iter())
            .flat_map(|t| t.values().map(f64::to_bits))
            .collect::<Vec<_>>()
    };
    assert_eq!(bits(&unyielded), bits(&elastic));
    let yielded = last_rows(&plastic(&penny_cube(), 1e6, "H = 0"));
    for t in &yielded {
        assert!(
            t.j[0].is_finite() && t.k.iter().all(|k| k.is_nan()),
            "{t:?}"
        );
    }
}
