//! Body geometries fill the right volume: total particle volume against the closed form.

mod common;
use common::source;
use fissure::base::dim::{D2, D3};
use fissure::io::scenario::build;

fn scene(dim: usize, cell: f64, body: &str) -> String {
    let v = |x: f64| vec![format!("{x:e}"); dim].join(", ");
    format!(
        r#"
[simulation]
dimension = {dim}
duration = 1e-6
[grid]
min = [{lo}]
max = [{hi}]
cell = [{cell}]
[[material]]
name = "m"
E = 1e9
nu = 0.3
rho = 1000.0
[[body]]
material = "m"
ppc = 2
{body}
"#,
        lo = v(0.0),
        hi = v(0.1),
        cell = v(cell),
    )
}

/// A 2D triangle (legs 60 and 40 mm, unit thickness): area 1.2e-3 m^2.
#[test]
fn polygon_area() {
    let text = scene(
        2,
        0.001,
        "polygon = { points = [[0.02, 0.02], [0.08, 0.02], [0.02, 0.06]] }",
    );
    let w = build::<D2>(&source(&text)).unwrap().world;
    let vol: f64 = w.particles.volume.iter().sum();
    assert!((vol - 1.2e-3).abs() / 1.2e-3 < 0.01, "triangle area {vol}");
}

/// A 3D cylinder r = 20 mm, L = 50 mm along z: pi r^2 L.
#[test]
fn cylinder_volume() {
    let text = scene(
        3,
        0.002,
        "cylinder = { center = [0.05, 0.05, 0.02], axis = \"z\", radius = 0.02, length = 0.05 }",
    );
    let w = build::<D3>(&source(&text)).unwrap().world;
    let vol: f64 = w.particles.volume.iter().sum();
    let want = std::f64::consts::PI * 0.02f64.powi(2) * 0.05;
    assert!(
        (vol - want).abs() / want < 0.01,
        "cylinder volume {vol} vs {want}"
    );
    let mass: f64 = w.particles.mass.iter().sum();
    assert!((mass - 1000.0 * vol).abs() < 1e-12 * mass);
}

/// A tube (r = 20 mm, bore 12 mm, L = 20 mm along z) clipped to the half y >= its axis:
/// pi (r^2 - r_i^2) L / 2 within 1 % (0.5 mm particle spacing, 16 across the wall), and
/// nothing below the clipping plane.
#[test]
fn clipped_tube_volume() {
    let text = scene(
        3,
        0.001,
        "cylinder = { center = [0.025, 0.025, 0.015], axis = \"z\", radius = 0.02, \
         inner_radius = 0.012, length = 0.02 }\n\
         clip = { point = [0.0, 0.025, 0.0], normal = [0.0, 1.0, 0.0] }",
    )
    .replace("max = [1e-1, 1e-1, 1e-1]", "max = [5e-2, 5e-2, 5e-2]");
    let w = build::<D3>(&source(&text)).unwrap().world;
    let vol: f64 = w.particles.volume.iter().sum();
    let want = 0.5 * std::f64::consts::PI * (0.02f64.powi(2) - 0.012f64.powi(2)) * 0.02;
    assert!(
        (vol - want).abs() / want < 0.01,
        "half-tube volume {vol} vs {want}"
    );
    assert!(w.particles.x.iter().all(|x| x.y > 0.025));
}

/// A sphere r = 30 mm: 4/3 pi r^3; an extruded square polygon: side^2 * depth.
#[test]
fn sphere_and_extruded_polygon_volumes() {
    let sphere = scene(
        3,
        0.002,
        "sphere = { center = [0.05, 0.05, 0.05], radius = 0.03 }",
    );
    let w = build::<D3>(&source(&sphere)).unwrap().world;
    let vol: f64 = w.particles.volume.iter().sum();
    let want = 4.0 / 3.0 * std::f64::consts::PI * 0.03f64.powi(3);
    assert!(
        (vol - want).abs() / want < 0.01,
        "sphere volume {vol} vs {want}"
    );

    let prism = scene(
        3,
        0.002,
        "polygon = { points = [[0.02, 0.02], [0.06, 0.02], [0.06, 0.06], [0.02, 0.06]], z = [0.01, 0.03] }",
    );
    let w = build::<D3>(&source(&prism)).unwrap().world;
    let vol: f64 = w.particles.volume.iter().sum();
    assert!((vol - 3.2e-5).abs() / 3.2e-5 < 1e-9, "prism volume {vol}");
}

/// A 60 x 60 mm plate with two holes (r = 8 and 5 mm): area 3.6e-3 - pi (r1^2 + r2^2)
/// within 1 % (0.5 mm particle spacing); a hollow sphere (6 and 15 mm) in 3D:
/// 4/3 pi (r^3 - r_i^3) within 1 % (0.5 mm spacing; at 1 mm it reads 1.4 % high).
#[test]
fn holes_and_hollow_spheres() {
    let text = scene(
        2,
        0.001,
        "box = { min = [0.02, 0.02], max = [0.08, 0.08] }\n\
         holes = [{ center = [0.04, 0.045], radius = 0.008 }, \
         { center = [0.065, 0.035], radius = 0.005 }]",
    );
    let w = build::<D2>(&source(&text)).unwrap().world;
    let vol: f64 = w.particles.volume.iter().sum();
    let want = 3.6e-3 - std::f64::consts::PI * (0.008f64.powi(2) + 0.005f64.powi(2));
    assert!(
        (vol - want).abs() / want < 0.01,
        "plate area {vol} vs {want}"
    );
    let text = scene(
        3,
        0.001,
        "sphere = { center = [0.025, 0.025, 0.025], radius = 0.015, inner_radius = 0.006 }",
    )
    .replace("max = [1e-1, 1e-1, 1e-1]", "max = [5e-2, 5e-2, 5e-2]");
    let w = build::<D3>(&source(&text)).unwrap().world;
    let vol: f64 = w.particles.volume.iter().sum();
    let want = 4.0 / 3.0 * std::f64::consts::PI * (0.015f64.powi(3) - 0.006f64.powi(3));
    assert!(
        (vol - want).abs() / want < 0.01,
        "shell volume {vol} vs {want}"
    );
}

/// Where bodies overlap, the first listed keeps the points: two overlapping 40 x 40 mm
/// squares fill their union (2,800 mm^2) once; a 10 mm disc of a second material listed
/// before a plate is an inclusion, the plate around it filling the rest (the plate's area
/// in all, pi 10^2 mm^2 of it the disc's material, to the lattice's 1 %).
#[test]
fn overlapping_bodies_fill_their_union_once() {
    let text = scene(
        2,
        0.001,
        "box = { min = [0.01, 0.01], max = [0.05, 0.05] }\n[[body]]\nmaterial = \"m\"\n\
         box = { min = [0.03, 0.03], max = [0.07, 0.07] }",
    );
    let w = build::<D2>(&source(&text)).unwrap().world;
    let vol: f64 = w.particles.volume.iter().sum();
    assert!((vol - 2.8e-3).abs() < 1e-12, "union area {vol}");
    let inclusion = "[[material]]\nname = \"hard\"\nE = 2e11\nnu = 0.3\nrho = 8000.0\n[[body]]\n\
                     material = \"hard\"\ndisc = { center = [0.05, 0.05], radius = 0.01 }\n";
    let text = scene(2, 0.001, "box = { min = [0.02, 0.02], max = [0.08, 0.08] }")
        .replace("[[body]]", &format!("{inclusion}[[body]]"));
    let w = build::<D2>(&source(&text)).unwrap().world;
    let p = &w.particles;
    let of = |m: u16| -> f64 {
        (0..p.len())
            .filter(|&i| p.material[i] == m)
            .map(|i| p.volume[i])
            .sum()
    };
    let disc = std::f64::consts::PI * 1e-4;
    let hard = w.materials.iter().position(|m| m.name == "hard").unwrap() as u16;
    assert!(
        (of(hard) - disc).abs() / disc < 0.01,
        "disc {} vs {disc}",
        of(hard)
    );
    let all: f64 = p.volume.iter().sum();
    assert!((all - 3.6e-3).abs() < 1e-12, "plate {all}");
}
