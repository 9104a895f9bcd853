//! Per-system microbenchmarks and one full step, in particle throughput.
//!
//! `cargo bench --bench systems` (all cores) or `RAYON_NUM_THREADS=1 cargo bench --bench
//! systems` (one thread). USAVG unless the label says otherwise. Scenes: a block filling
//! the grid at 2 particles per cell per axis, 2D 256 x 256 cells (262,144 particles), 3D
//! 40 x 40 x 40 cells (512,000 particles); the `-16k` and `-27k` scenes (2D 64 x 64, 3D
//! 15 x 15 x 15 cells) fit in the caches, as the validation scenarios do.

mod common;

use common::{SCENES, block};
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use fissure::base::dim::{D2, D3};
use fissure::pipeline::schedule::Schedule;
use fissure::systems::DimSystems;
use fissure::systems::{bin, g2p, grid_update, p2g, stress, stress_bin, stress_force};
use std::time::{Duration, Instant};

fn bench_scene<D: DimSystems>(c: &mut Criterion, label: &str, n: usize, shape: &str, update: &str) {
    let mut world = block::<D>(label, n, shape, update);
    let mut schedule = Schedule::for_world(&world, None);
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
    // As in the launcher, the steps run inside the pool: a sample's steps are one hand-over
    // from this thread, not one each (which on small scenes costs a worker's wake-up per
    // step).
    let pool = rayon::ThreadPoolBuilder::new()
        .build()
        .expect("thread pool");
    g.bench_function("step", |b| {
        b.iter_custom(|iters| {
            pool.install(|| {
                let t0 = Instant::now();
                for _ in 0..iters {
                    schedule.step(&mut world).expect("stable");
                }
                t0.elapsed()
            })
        })
    });
    g.finish();
}

fn systems(c: &mut Criterion) {
    for (label, dim, n, shape, update) in SCENES {
        if dim == 2 {
            bench_scene::<D2>(c, label, n, shape, update);
        } else {
            bench_scene::<D3>(c, label, n, shape, update);
        }
    }
}

criterion_group!(benches, systems);
criterion_main!(benches);
