//! The benchmark scenes shared by the benches: a steel block filling a regular grid of 1 mm
//! cells at 2 particles per cell per axis, moving at 1 mm/s; a cube with a penny crack.
#![allow(dead_code)]

use fissure::base::dim::Dim;
use fissure::io::scenario::{Source, build};
use fissure::store::world::World;

/// Scenario text of an `n`-cells-per-axis block in `dim` dimensions with the given shape
/// function and update order.
pub fn scene_text(dim: usize, n: usize, shape: &str, update: &str) -> String {
    let h = 1e-3;
    let v = |x: f64| vec![format!("{x}"); dim].join(", ");
    let len = n as f64 * h;
    format!(
        r#"
[simulation]
dimension = {dim}
shape = "{shape}"
update = "{update}"
duration = 1.0
[grid]
min = [{lo}]
max = [{hi}]
cell = [{cell}]
[[material]]
name = "steel"
E = 200e9
nu = 0.3
rho = 7800.0
[[body]]
material = "steel"
box = {{ min = [{bmin}], max = [{bmax}] }}
velocity = [{vel}]
"#,
        lo = v(-2.0 * h),
        hi = v(len + 2.0 * h),
        cell = v(h),
        bmin = v(0.0),
        bmax = v(len),
        vel = v(1e-3),
    )
}

/// The parsed scenario of [`scene_text`]'s block, named `label` in errors.
pub fn block_source(label: &str, dim: usize, n: usize, shape: &str, update: &str) -> Source {
    let text = scene_text(dim, n, shape, update);
    Source::parse(label, &text, &[]).expect("bench scene parses")
}

/// The built world of [`scene_text`]'s block, named `label` in errors.
pub fn block<D: Dim>(label: &str, n: usize, shape: &str, update: &str) -> World<D> {
    let src = block_source(label, D::D, n, shape, update);
    build::<D>(&src).expect("bench scene builds").world
}

/// The scenes of the kernel benches: label, dimension, cells per axis, shape, update.
pub const SCENES: [(&str, usize, usize, &str, &str); 7] = [
    ("2d-linear", 2, 256, "linear", "usavg"),
    ("2d-linear-16k", 2, 64, "linear", "usavg"),
    ("2d-linear-usl", 2, 256, "linear", "usl"),
    ("2d-ugimp", 2, 256, "ugimp", "usavg"),
    ("3d-ugimp", 3, 40, "ugimp", "usavg"),
    ("3d-ugimp-27k", 3, 15, "ugimp", "usavg"),
    ("3d-bspline", 3, 40, "bspline", "usavg"),
];

/// The penny-crack cube of the 3D benches: a 5 mm penny crack in a 30 mm steel cube under
/// 50 MPa, 1 mm cells, 216,000 particles.
pub const PENNY: &str = r#"
[simulation]
dimension = 3
shape = "ugimp"
update = "usavg"
duration = 1.0e-4
[grid]
min = [-0.002, -0.002, -0.002]
max = [0.032, 0.032, 0.032]
cell = [0.001, 0.001, 0.001]
[[material]]
name = "steel"
E = 200e9
nu = 0.3
rho = 8000.0
[[body]]
material = "steel"
box = { min = [0.0, 0.0, 0.0], max = [0.03, 0.03, 0.03] }
[[crack]]
name = "penny"
penny = { center = [0.015, 0.015, 0.015], normal = [0.0, 1.0, 0.0], radius = 0.005 }
[[load]]
region = { min = [0.0, 0.0295, 0.0], max = [0.03, 0.03, 0.03] }
force = [0.0, 45000.0, 0.0]
[[load]]
region = { min = [0.0, 0.0, 0.0], max = [0.03, 0.0005, 0.03] }
force = [0.0, -45000.0, 0.0]
[fracture]
domain = 4
"#;
