//! The same scenario gives bitwise-identical results for any thread count.

mod common;
use common::final_world;
use fissure::dim::{D2, D3, Dim};
use fissure::world::World;

/// Every bit of the particle state that the next step depends on.
fn bits<D: Dim>(w: &World<D>) -> Vec<u64> {
    let p = &w.particles;
    let mut out = Vec::new();
    for i in 0..p.len() {
        let (x, v, u) = (D::to_xyz(p.x[i]), D::to_xyz(p.v[i]), D::to_xyz(p.u[i]));
        out.extend(x.iter().chain(&v).chain(&u).map(|c| c.to_bits()));
        out.extend(p.stress[i].to_array().iter().map(|c| c.to_bits()));
    }
    out.push(w.work.external.to_bits());
    out.push(w.work.damping.to_bits());
    out
}

fn scene(dim: usize, shape: &str, update: &str) -> String {
    let v = |a: f64, b: f64| common::v(dim, a, b);
    format!(
        r#"
[simulation]
dimension = {dim}
shape = "{shape}"
update = "{update}"
duration = 1e-5
damping = 1000.0
gravity = {g}
[grid]
min = {gmin}
max = {gmax}
cell = {cell}
[[material]]
name = "m"
E = 70e9
nu = 0.33
rho = 2700.0
[[body]]
material = "m"
box = {{ min = {bmin}, max = {bmax} }}
velocity = {vel}
[[body]]
material = "m"
{disc}
[[boundary]]
region = {{ min = {gmin}, max = {fix} }}
[[load]]
region = {{ min = {lmin}, max = {bmax} }}
force = {force}
time = {{ kind = "ramp", rise = 5e-6 }}
"#,
        g = v(0.0, -9.81),
        gmin = v(0.0, 0.0),
        gmax = v(0.064, if dim == 2 { 0.032 } else { 0.016 }),
        cell = v(0.001, 0.001),
        bmin = v(0.002, 0.002),
        bmax = v(0.04, 0.012),
        vel = v(3.0, -1.0),
        disc = if dim == 2 {
            "disc = { center = [0.05, 0.022], radius = 0.006 }"
        } else {
            "sphere = { center = [0.05, 0.008, 0.008], radius = 0.005 }"
        },
        fix = v(0.003, if dim == 2 { 0.032 } else { 0.016 }),
        lmin = v(0.038, 0.002),
        force = v(2e4, 5e3),
    )
}

fn same_bits_for_thread_counts<D: Dim>(text: &str) {
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
    same_bits_for_thread_counts::<D2>(&scene(2, "ugimp", "usavg"));
    same_bits_for_thread_counts::<D2>(&scene(2, "linear", "usl"));
}

#[test]
fn bitwise_identical_across_thread_counts_3d() {
    same_bits_for_thread_counts::<D3>(&scene(3, "bspline", "usf"));
}
