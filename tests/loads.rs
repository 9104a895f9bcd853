//! Traction loads from a stress field: the Williams near-tip tractions on the outer boundary
//! of a square around a traction-free crack are self-equilibrated, and each particle's force
//! is the closed-form traction times the face it carries.

use fissure::dim::D2;
use fissure::near_tip;
use fissure::scenario::{Source, build};

/// A 10 mm square at 0.5 mm cells, 2 particles per cell per axis, the four faces loaded by
/// the Williams field of a tip at its centre.
fn square() -> String {
    let mut s = String::from(
        r#"name = "williams_faces"
[simulation]
dimension = 2
duration = 1e-6
[grid]
min = [-0.006, -0.006]
max = [0.006, 0.006]
cell = [0.0005, 0.0005]
[[material]]
name = "steel"
E = 200e9
nu = 0.3
rho = 7800.0
[[body]]
material = "steel"
box = { min = [-0.005, -0.005], max = [0.005, 0.005] }
"#,
    );
    for (lo, hi, n) in [
        ("[0.0048, -0.005]", "[0.005, 0.005]", "[1.0, 0.0]"),
        ("[-0.005, -0.005]", "[-0.0048, 0.005]", "[-1.0, 0.0]"),
        ("[-0.005, 0.0048]", "[0.005, 0.005]", "[0.0, 1.0]"),
        ("[-0.005, -0.005]", "[0.005, -0.0048]", "[0.0, -1.0]"),
    ] {
        s += &format!(
            "[[load]]\nregion = {{ min = {lo}, max = {hi} }}\nnormal = {n}\n\
             williams = {{ KI = 1.0e6, KII = 0.5e6, tip = [0.0, 0.0], direction = 0.0 }}\n"
        );
    }
    s
}

#[test]
fn williams_tractions_are_self_equilibrated() {
    let src = Source::parse("williams.toml", &square(), &[]).unwrap();
    let world = build::<D2>(&src).unwrap().world;
    let (mut sum, mut size) = ([0.0; 2], 0.0);
    for load in &world.loads {
        for f in &load.forces {
            sum[0] += f.x;
            sum[1] += f.y;
            size += f.length();
        }
    }
    // The field is in equilibrium with free crack faces, so the boundary tractions sum to
    // zero; the midpoint rule over 0.25 mm faces leaves an O(h^2) residue.
    assert!(
        sum[0].abs() < 1e-3 * size && sum[1].abs() < 1e-3 * size,
        "net force {sum:?} of total {size}"
    );
}

#[test]
fn williams_force_is_traction_times_face() {
    let src = Source::parse("williams.toml", &square(), &[]).unwrap();
    let world = build::<D2>(&src).unwrap().world;
    let load = &world.loads[0];
    let p = &world.particles;
    for (&i, f) in load.particles.iter().zip(&load.forces) {
        let x = p.x[i as usize];
        // The face point is half a particle spacing (0.125 mm) outside the particle centre.
        let (fx, fy) = (x.x + 0.000125, x.y);
        let [sxx, _, sxy] = near_tip::stress(1.0e6, 0.5e6, fx.hypot(fy), fy.atan2(fx));
        let area = 0.00025; // face length times the unit thickness of plane strain
        assert!(
            (f.x - sxx * area).abs() < 1e-12 * sxx.abs().max(1.0),
            "{f} vs {sxx}"
        );
        assert!(
            (f.y - sxy * area).abs() < 1e-12 * sxy.abs().max(1.0),
            "{f} vs {sxy}"
        );
    }
}
