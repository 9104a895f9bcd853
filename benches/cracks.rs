//! Crack systems on the DCB scene (`scenarios/dcb_2d.toml`, 9,600 particles, a 50 mm crack
//! with 104 segments): `classify` per step, as a full pass and reusing its record (only
//! the particles with no clearance redone), and the J-integral at the tip per output step;
//! and frictionless `contact` per step (its two passes: on the scattered momenta, which
//! also sums the nodal displacements, then on the updated velocities) on the ENF scene
//! (`scenarios/enf_2d.toml`, the same beam with its arms sliding). In 3D: `classify` and J
//! and K along the front (60 vertices, a tube of 4 cells) on a 30 mm cube of 216,000
//! particles with a 5 mm penny crack under tension.
//!
//! `cargo bench --bench cracks`.

mod common;

use common::PENNY;
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use fissure::base::dim::{D2, D3};
use fissure::io::scenario::{Source, build};
use fissure::pipeline::schedule::Schedule;
use fissure::systems::{classify, contact, fracture, fracture_front};
use std::time::Duration;

fn cracks(c: &mut Criterion) {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/scenarios/dcb_2d.toml");
    let src = Source::load(std::path::Path::new(path), &[]).expect("the DCB scenario loads");
    let scene = build::<D2>(&src).expect("the DCB scenario builds");
    let plan = scene.fracture.clone().expect("the DCB measures J");
    let mut world = scene.world;
    let mut schedule = Schedule::for_world(&world, None);
    for _ in 0..50 {
        schedule.step(&mut world).expect("stable");
    }
    let mut g = c.benchmark_group("cracks-dcb");
    g.sample_size(20)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(3));
    g.throughput(Throughput::Elements(world.particles.len() as u64));
    let every_step = |world: &mut fissure::store::world::World<D2>, on: bool| {
        world
            .cracks
            .as_mut()
            .expect("the DCB has a crack")
            .scratch
            .classified
            .every_step = on;
    };
    every_step(&mut world, true);
    g.bench_function("classify_full", |b| {
        b.iter(|| classify::run(&mut world).expect("room for every crack"))
    });
    every_step(&mut world, false);
    g.bench_function("classify_reuse", |b| {
        b.iter(|| classify::run(&mut world).expect("room for every crack"))
    });
    g.throughput(Throughput::Elements(1));
    g.bench_function("j_integral", |b| {
        b.iter(|| fracture::measure(&world, &plan))
    });
    g.finish();

    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/scenarios/enf_2d.toml");
    let src = Source::load(std::path::Path::new(path), &[]).expect("the ENF scenario loads");
    let mut world = build::<D2>(&src).expect("the ENF scenario builds").world;
    let mut schedule = Schedule::for_world(&world, None);
    for _ in 0..200 {
        schedule.step(&mut world).expect("stable");
    }
    let mut g = c.benchmark_group("cracks-enf");
    g.sample_size(20)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(3));
    g.throughput(Throughput::Elements(world.particles.len() as u64));
    g.bench_function("contact", |b| {
        b.iter(|| {
            contact::run(&mut world, false);
            contact::run(&mut world, true)
        })
    });
    g.finish();
}

fn cracks_3d(c: &mut Criterion) {
    let src = Source::parse("penny.toml", PENNY, &[]).expect("the penny scene parses");
    let scene = build::<D3>(&src).expect("the penny scene builds");
    let plan = scene.fracture.clone().expect("the penny measures J");
    let mut world = scene.world;
    let mut schedule = Schedule::for_world(&world, None);
    for _ in 0..20 {
        schedule.step(&mut world).expect("stable");
    }
    let mut g = c.benchmark_group("cracks-penny-3d");
    g.sample_size(10)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(5));
    g.throughput(Throughput::Elements(world.particles.len() as u64));
    let every_step = |world: &mut fissure::store::world::World<D3>, on: bool| {
        let c = world.cracks.as_mut().expect("the penny scene has a crack");
        c.scratch.classified.every_step = on;
    };
    every_step(&mut world, true);
    g.bench_function("classify_full", |b| {
        b.iter(|| classify::run(&mut world).expect("room for every crack"))
    });
    every_step(&mut world, false);
    g.bench_function("classify_reuse", |b| {
        b.iter(|| classify::run(&mut world).expect("room for every crack"))
    });
    let vertices = world
        .cracks
        .as_ref()
        .map_or(0, |c| c.topology.fronts()[0].vertices.len());
    g.throughput(Throughput::Elements(vertices as u64));
    g.bench_function("front_j_k", |b| {
        b.iter(|| fracture_front::measure(&world, &plan))
    });
    g.finish();
}

criterion_group!(benches, cracks, cracks_3d);
criterion_main!(benches);
