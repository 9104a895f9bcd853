//! Snapshot write and read speed for one million 3D particles (uGIMP, so every particle
//! column is present), against copying the same file on the same disk.
//!
//! `cargo bench --bench snapshot`. All three include an fsync: the snapshot writer syncs
//! before its rename, so the copy is synced too for a like-for-like comparison.

mod common;

use criterion::{Criterion, SamplingMode, Throughput, criterion_group, criterion_main};
use fissure::base::dim::D3;
use fissure::io::scenario::build;
use fissure::io::snapshot::Reader;
use fissure::io::snapshot::state::write;
use fissure::record::state::RunState;
use std::fs::File;
use std::time::Duration;

fn snapshot(c: &mut Criterion) {
    // 50 x 50 x 50 cells at 2 particles per cell per axis: 1,000,000 particles.
    let src = common::block_source("snapshot_bench", 3, 50, "ugimp", "usavg");
    let world = build::<D3>(&src).expect("bench scene builds").world;
    assert_eq!(world.particles.len(), 1_000_000);
    let state = RunState::start(&world, 0, 1, 1.0, 1.0, None);
    let dir = std::env::temp_dir().join(format!("fissure-snapshot-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("scratch folder");
    let path = dir.join("bench.fsnap");
    let copy = dir.join("copy.fsnap");
    write(&path, &src, &world, &state).expect("snapshot writes");
    let bytes = std::fs::metadata(&path).expect("snapshot exists").len();

    let mut g = c.benchmark_group("snapshot-3d-1M");
    g.sample_size(10)
        .sampling_mode(SamplingMode::Flat)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(10))
        .throughput(Throughput::Bytes(bytes));
    g.bench_function("write", |b| {
        b.iter(|| write(&path, &src, &world, &state).expect("snapshot writes"))
    });
    g.bench_function("read", |b| {
        b.iter(|| {
            let mut r = Reader::open(&path).expect("snapshot opens");
            assert!(r.verify().expect("columns read").iter().all(|c| c.1));
        })
    });
    g.bench_function("copy", |b| {
        b.iter(|| {
            std::fs::copy(&path, &copy).expect("copy");
            File::open(&copy).and_then(|f| f.sync_all()).expect("sync");
        })
    });
    g.finish();
    std::fs::remove_dir_all(dir).ok();
}

criterion_group!(benches, snapshot);
criterion_main!(benches);
