//! The first static load step of a scene (`systems::static_solve`: classification, the
//! loads, the linear solve to the scene's tolerance, the particles set to the answer). By
//! conjugate gradients (`/cg`) in particle-iterations per second: each iteration is one
//! pass over the particles (K applied without assembling it), so the time per iteration is
//! the load step's time over its iterations (printed); by the sparse direct solver
//! (`/direct`: pattern, symbolic analysis, assembly, factorization, solve) in particles
//! per second. Scenes: the shipped static cantilever
//! (`scenarios/cantilever_static_2d.toml`, 16,000 particles, no crack), the DCB
//! (`scenarios/dcb_2d.toml`, 9,600 particles, a crack: its fields are unknowns) and the
//! ENF (`scenarios/enf_2d.toml`, frictionless faces: an active set of solves) switched to
//! static, and the penny crack in a 30 mm cube (216,000 particles, 3D), by conjugate
//! gradients with Jacobi (`/cg`) and with the coarse grid (`/two_level`, the 3D default:
//! its set-up is in the load step's time).
//!
//! `cargo bench --bench static_solve`.

mod common;

use common::PENNY;
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use fissure::io::scenario::{Source, build};
use fissure::systems::{DimSystems, static_solve};
use std::time::{Duration, Instant};

/// The scenario at `scenarios/{name}.toml`, switched to static in one load step, solved by
/// the `linear` solver.
fn source(name: &str, linear: &str) -> Source {
    let path = format!("{}/scenarios/{name}.toml", env!("CARGO_MANIFEST_DIR"));
    let set = [
        "simulation.solver=\"static\"".to_string(),
        "simulation.load_steps=1".to_string(),
        format!("simulation.linear=\"{linear}\""),
    ];
    Source::load(std::path::Path::new(&path), &set).expect("the scenario loads")
}

fn bench<D: DimSystems>(c: &mut Criterion, label: &str, src: &Source) {
    let world = build::<D>(src).expect("the scenario builds").world;
    let solved = static_solve::run(&mut world.clone(), &mut Default::default())
        .expect("the load step solves");
    let iterations = solved.iterations.max(1);
    println!(
        "{label}: {} particles, {} iterations and {} factorizations in {} solves",
        world.particles.len(),
        solved.iterations,
        solved.factorizations,
        solved.contact_rounds
    );
    let mut g = c.benchmark_group("static_solve");
    g.sample_size(10)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(5))
        .throughput(Throughput::Elements(
            (world.particles.len() * iterations) as u64,
        ));
    // Each sample solves the first load step from the built scene (a fresh copy, not
    // timed). As in the launcher, the solves run inside the thread pool: each conjugate-
    // gradient iteration makes several parallel passes, and a hand-over from this thread
    // for each would cost a worker's wake-up (it made the cantilever twice as slow).
    let pool = rayon::ThreadPoolBuilder::new()
        .build()
        .expect("thread pool");
    g.bench_function(label, |b| {
        b.iter_custom(|iters| {
            let mut spent = Duration::ZERO;
            for _ in 0..iters {
                let mut fresh = world.clone();
                spent += pool.install(|| {
                    let t0 = Instant::now();
                    static_solve::run(&mut fresh, &mut Default::default())
                        .expect("the load step solves");
                    t0.elapsed()
                });
            }
            spent
        })
    });
    g.finish();
}

fn static_solve(c: &mut Criterion) {
    use fissure::base::dim::{D2, D3};
    for linear in ["cg", "direct"] {
        bench::<D2>(
            c,
            &format!("cantilever/{linear}"),
            &source("cantilever_static_2d", linear),
        );
        bench::<D2>(c, &format!("dcb/{linear}"), &source("dcb_2d", linear));
        bench::<D2>(c, &format!("enf/{linear}"), &source("enf_2d", linear));
    }
    for linear in ["cg", "two_level"] {
        let set = [
            "simulation.solver=\"static\"".to_string(),
            "simulation.load_steps=1".to_string(),
            format!("simulation.linear=\"{linear}\""),
        ];
        let penny = Source::parse("penny.toml", PENNY, &set).expect("the penny scene parses");
        bench::<D3>(c, &format!("penny-216k/{linear}"), &penny);
    }
}

criterion_group!(benches, static_solve);
criterion_main!(benches);
