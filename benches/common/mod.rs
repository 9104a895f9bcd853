//! The benchmark scene shared by the benches: a steel block filling a regular grid of 1 mm
//! cells at 2 particles per cell per axis, moving at 1 mm/s.
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
