//! The cost of plasticity: the stress update (`stress`) and a full step of the same block,
//! elastic, J2 below yield (the trial check only) and J2 yielding at every particle, in
//! plane strain, plane stress (whose return iterates) and 3D.
//!
//! `RAYON_NUM_THREADS=1 cargo bench --bench plasticity`. The block is the kernel benches'
//! (2D 256 x 256 cells, 3D 40 x 40 x 40, linear shape functions). For `yielding`, every
//! particle starts on the yield surface in uniaxial tension along x and the block is
//! stretched along x at 10 /s about its middle, so each update returns every particle to
//! the surface. Each timed step starts from a copy of the block one step in (the copy is
//! not timed), before the free surfaces' unloading reaches into it.

mod common;

use common::scene_text;
use criterion::{BatchSize, Criterion, Throughput, criterion_group, criterion_main};
use fissure::base::dim::{D2, D3, Dim};
use fissure::base::sym::{Sym3, SymTensor};
use fissure::io::scenario::{Source, build};
use fissure::pipeline::schedule::Schedule;
use fissure::store::world::World;
use fissure::systems::DimSystems;
use fissure::systems::stress;
use std::time::Duration;

/// Yield stress of the plastic variants (Pa); E = 200 GPa.
const YIELD: f64 = 250e6;

/// The block as elastic, plastic below yield or plastic and yielding.
#[derive(Clone, Copy)]
enum Variant {
    Elastic,
    BelowYield,
    Yielding,
}

fn world<D: Dim>(label: &str, n: usize, plane: &str, variant: Variant) -> World<D> {
    let mut text = scene_text(D::D, n, "linear", "usavg");
    if D::D == 2 {
        text = text.replace(
            "dimension = 2",
            &format!("dimension = 2\nplane = \"{plane}\""),
        );
    }
    if !matches!(variant, Variant::Elastic) {
        text = text.replace(
            "rho = 7800.0",
            &format!("rho = 7800.0\nmodel = \"j2\"\nsigma_y = {YIELD:e}\nn = 10"),
        );
    }
    let src = Source::parse(label, &text, &[]).expect("bench scene parses");
    let mut w = build::<D>(&src).expect("bench scene builds").world;
    if let Variant::Yielding = variant {
        let p = &mut w.particles;
        let middle = 0.5e-3 * n as f64;
        for i in 0..p.len() {
            let x = D::to_xyz(p.x[i]);
            p.v[i] = D::unit_x() * (10.0 * (x[0] - middle));
            p.stress[i] = D::Sym::from_sym3(Sym3 {
                xx: YIELD,
                ..Sym3::default()
            });
        }
    }
    w
}

fn bench<D: DimSystems>(c: &mut Criterion, label: &str, n: usize, plane: &str) {
    let mut g = c.benchmark_group(label);
    g.sample_size(10)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(3));
    for (name, variant) in [
        ("elastic", Variant::Elastic),
        ("j2-below-yield", Variant::BelowYield),
        ("j2-yielding", Variant::Yielding),
    ] {
        let mut w = world::<D>(label, n, plane, variant);
        let mut schedule = Schedule::for_world(&w, None);
        schedule.step(&mut w).expect("stable");
        g.throughput(Throughput::Elements(w.particles.len() as u64));
        g.bench_function(format!("{name}/stress"), |b| {
            b.iter(|| stress::run(&mut w, 0.5))
        });
        // Each timed step starts from the same state, one step in: free surfaces unload
        // the block within tens of steps, and then "yielding" would no longer be.
        let mut start = world::<D>(label, n, plane, variant);
        schedule.step(&mut start).expect("stable");
        g.bench_function(format!("{name}/step"), |b| {
            b.iter_batched_ref(
                || start.clone(),
                |w| schedule.step(w).expect("stable"),
                BatchSize::LargeInput,
            )
        });
    }
    g.finish();
}

fn plasticity(c: &mut Criterion) {
    bench::<D2>(c, "plastic-2d-strain", 256, "strain");
    bench::<D2>(c, "plastic-2d-stress", 256, "stress");
    bench::<D3>(c, "plastic-3d", 40, "strain");
}

criterion_group!(benches, plasticity);
criterion_main!(benches);
