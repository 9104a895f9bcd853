//! Per-system microbenchmarks and one full step, in particle throughput.
//!
//! `cargo bench --bench systems` (all cores) or `RAYON_NUM_THREADS=1 cargo bench --bench
//! systems` (one thread). USAVG unless the label says otherwise. Scenes: a block filling
//! the grid at 2 particles per cell per axis, 2D 256 x 256 cells (262,144 particles), 3D
//! 40 x 40 x 40 cells (512,000 particles); the `-16k` and `-27k` scenes (2D 64 x 64, 3D
//! 15 x 15 x 15 cells) fit in the caches, as the validation scenarios do.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use fissure::dim::{D2, D3, Dim};
use fissure::scenario::{Source, build};
use fissure::schedule::Schedule;
use fissure::systems::{bin, g2p, grid_update, p2g, stress, stress_bin, stress_force};
use std::time::Duration;

fn scene_text(dim: usize, n: usize, shape: &str, update: &str) -> String {
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

fn bench_scene<D: Dim>(c: &mut Criterion, label: &str, n: usize, shape: &str, update: &str) {
    let text = scene_text(D::D, n, shape, update);
    let src = Source::parse(label, &text, &[]).expect("bench scene parses");
    let mut world = build::<D>(&src).expect("bench scene builds").world;
    let mut schedule = Schedule::for_world(&world);
    schedule.step(&mut world).expect("stable");
    let mut g = c.benchmark_group(label);
    g.sample_size(10)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(3))
        .throughput(Throughput::Elements(world.particles.len() as u64));
    g.bench_function("bin", |b| {
        b.iter(|| {
            world.tiles.fresh = false;
            bin::run(&mut world).expect("in grid")
        })
    });
    g.bench_function("p2g", |b| b.iter(|| p2g::run(&mut world, true)));
    g.bench_function("grid_update", |b| b.iter(|| grid_update::run(&mut world)));
    g.bench_function("g2p", |b| b.iter(|| g2p::run(&mut world)));
    g.bench_function("g2p_remap", |b| b.iter(|| g2p::run_with_remap(&mut world)));
    bin::run(&mut world).expect("in grid");
    g.bench_function("stress", |b| b.iter(|| stress::run(&mut world, 1.0)));
    g.bench_function("stress_bin", |b| {
        b.iter(|| stress_bin::run(&mut world, 1.0).expect("in grid"))
    });
    g.bench_function("stress_force", |b| {
        b.iter(|| stress_force::run(&mut world, 1.0))
    });
    // As the launcher does, the step runs inside the pool, so its parallel loops are not
    // each handed over from an outside thread.
    let pool = rayon::ThreadPoolBuilder::new()
        .build()
        .expect("thread pool");
    g.bench_function("step", |b| {
        b.iter(|| pool.install(|| schedule.step(&mut world).expect("stable")))
    });
    g.finish();
}

fn systems(c: &mut Criterion) {
    bench_scene::<D2>(c, "2d-linear", 256, "linear", "usavg");
    bench_scene::<D2>(c, "2d-linear-16k", 64, "linear", "usavg");
    bench_scene::<D2>(c, "2d-linear-usl", 256, "linear", "usl");
    bench_scene::<D2>(c, "2d-ugimp", 256, "ugimp", "usavg");
    bench_scene::<D3>(c, "3d-ugimp", 40, "ugimp", "usavg");
    bench_scene::<D3>(c, "3d-ugimp-27k", 15, "ugimp", "usavg");
    bench_scene::<D3>(c, "3d-bspline", 40, "bspline", "usavg");
}

criterion_group!(benches, systems);
criterion_main!(benches);
