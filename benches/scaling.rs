//! Two-thread speed-up of a full step, measured so that a shared machine's slow phases
//! cancel out: blocks of steps on one thread and on two threads alternate, and the
//! speed-up is the median over rounds of each round's ratio. Each round also times an
//! arithmetic-only loop (enough independent multiply-add chains to keep the floating-point
//! units busy, no memory traffic) on one and two threads: its ratio is the machine's own
//! ceiling in the same window (below 2 when the host steals time or lowers the clock with
//! both cores busy).
//!
//! `cargo bench --bench scaling` (all scenes of `benches/systems.rs`), or
//! `cargo bench --bench scaling -- 3d` (scenes whose label contains `3d`).

mod common;

use common::{SCENES, block};
use fissure::base::dim::{D2, D3};
use fissure::pipeline::schedule::Schedule;
use fissure::systems::DimSystems;
use rayon::prelude::*;
use rayon::{ThreadPool, ThreadPoolBuilder};
use std::hint::black_box;
use std::time::Instant;

/// Rounds per scene (each: one block per thread count, for the scene and the ceiling).
const ROUNDS: usize = 11;
/// Target wall time of a one-thread block of steps (s).
const BLOCK_SECONDS: f64 = 0.3;
/// Multiply-add iterations per chain in one share of the ceiling loop.
const SPIN: u64 = 1_500_000;

/// One share of the ceiling loop: 32 independent multiply-add chains.
fn spin(seed: f64) -> f64 {
    let mut x: [f64; 32] = std::array::from_fn(|k| seed + k as f64 * 1e-3);
    for _ in 0..SPIN {
        for v in &mut x {
            *v = *v * 1.000_000_1 + 1e-9;
        }
    }
    black_box(x.iter().sum())
}

/// Seconds for two shares of the ceiling loop in `pool` (one after the other on one thread,
/// side by side on two).
fn ceiling(pool: &ThreadPool) -> f64 {
    let t0 = Instant::now();
    pool.install(|| {
        let s: f64 = (0..2).into_par_iter().map(|k| spin(k as f64)).sum();
        black_box(s);
    });
    t0.elapsed().as_secs_f64()
}

/// Median of `v` (sorted in place).
fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// Measures one scene and prints its row.
fn scene<D: DimSystems>(label: &str, n: usize, shape: &str, update: &str, pools: &[ThreadPool; 2]) {
    let mut world = block::<D>(label, n, shape, update);
    let mut schedule = Schedule::for_world(&world, None);
    let particles = world.particles.len() as f64;
    let mut block_of = |pool: &ThreadPool, steps: usize| {
        let t0 = Instant::now();
        pool.install(|| {
            for _ in 0..steps {
                schedule.step(&mut world).expect("stable");
            }
        });
        t0.elapsed().as_secs_f64()
    };
    block_of(&pools[1], 3);
    let per_step = block_of(&pools[0], 3) / 3.0;
    let steps = ((BLOCK_SECONDS / per_step).round() as usize).max(1);
    let (mut speed, mut ratio, mut ceil, mut rel) = ([vec![], vec![]], vec![], vec![], vec![]);
    for round in 0..ROUNDS {
        // Alternate which thread count goes first, so a drifting machine favours neither.
        let order = if round % 2 == 0 { [0, 1] } else { [1, 0] };
        let mut t = [0.0; 2];
        let mut c = [0.0; 2];
        for k in order {
            t[k] = block_of(&pools[k], steps);
            c[k] = ceiling(&pools[k]);
        }
        for k in 0..2 {
            speed[k].push(particles * steps as f64 / t[k] / 1e6);
        }
        ratio.push(t[0] / t[1]);
        ceil.push(c[0] / c[1]);
        rel.push((t[0] / t[1]) / (c[0] / c[1]));
    }
    let (lo, hi) = (
        ratio.iter().copied().fold(f64::INFINITY, f64::min),
        ratio.iter().copied().fold(0.0, f64::max),
    );
    println!(
        "{label:14} {:>9.2} {:>9.2} {:>9.2} {:>5.2}-{:<5.2} {:>9.2} {:>9.2}",
        median(&mut speed[0]),
        median(&mut speed[1]),
        median(&mut ratio),
        lo,
        hi,
        median(&mut ceil),
        median(&mut rel),
    );
}

fn main() {
    let filters: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with("--"))
        .collect();
    let chosen: Vec<_> = SCENES
        .into_iter()
        .filter(|s| filters.is_empty() || filters.iter().any(|f| s.0.contains(f.as_str())))
        .collect();
    if chosen.is_empty() {
        let labels: Vec<_> = SCENES.iter().map(|s| s.0).collect();
        eprintln!(
            "no scene label contains any of {filters:?}; the scenes are {}",
            labels.join(", ")
        );
        std::process::exit(2);
    }
    let pool = |n| {
        ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .expect("thread pool")
    };
    let pools = [pool(1), pool(2)];
    println!(
        "{ROUNDS} alternating rounds per scene; medians; M particle-steps/s; speed-up = one-thread \
         block time / two-thread block time (min-max over rounds); ceiling = the same ratio for \
         an arithmetic-only loop in the same rounds; of ceiling = speed-up / ceiling, per round"
    );
    println!(
        "{:14} {:>9} {:>9} {:>9} {:>11} {:>9} {:>9}",
        "scene", "1 thread", "2 threads", "speed-up", "range", "ceiling", "of ceil."
    );
    for (label, dim, n, shape, update) in chosen {
        if dim == 2 {
            scene::<D2>(label, n, shape, update, &pools);
        } else {
            scene::<D3>(label, n, shape, update, &pools);
        }
    }
}
