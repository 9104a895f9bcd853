//! The cost of a body read from a mesh file: indexing a closed surface and deciding, for
//! every point of a particle lattice, whether it lies inside (`ClosedSurface::contains`).
//!
//! `cargo bench --bench geometry`. The surface is a sphere of radius 30 mm as an
//! icosahedron split 6 times (81,920 triangles); the lattice is 100^3 = 10^6 points over
//! its bounding box (the inside takes about half of them).

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use fissure::base::geometry::ClosedSurface;
use std::collections::HashMap;
use std::hint::black_box;
use std::time::Duration;

/// Vertices and triangles of the split icosahedron on a sphere of radius `r`.
fn icosphere(r: f64, levels: usize) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let g = (1.0 + 5f64.sqrt()) / 2.0;
    let mut v: Vec<[f64; 3]> = vec![
        [-1.0, g, 0.0],
        [1.0, g, 0.0],
        [-1.0, -g, 0.0],
        [1.0, -g, 0.0],
        [0.0, -1.0, g],
        [0.0, 1.0, g],
        [0.0, -1.0, -g],
        [0.0, 1.0, -g],
        [g, 0.0, -1.0],
        [g, 0.0, 1.0],
        [-g, 0.0, -1.0],
        [-g, 0.0, 1.0],
    ];
    let unit = |p: [f64; 3]| {
        let n = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
        p.map(|x| x / n)
    };
    v = v.into_iter().map(unit).collect();
    let mut t: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..levels {
        let mut mids: HashMap<(u32, u32), u32> = HashMap::new();
        let mut mid = |a: u32, b: u32, v: &mut Vec<[f64; 3]>| {
            *mids.entry((a.min(b), a.max(b))).or_insert_with(|| {
                let (p, q) = (v[a as usize], v[b as usize]);
                v.push(unit([p[0] + q[0], p[1] + q[1], p[2] + q[2]]));
                (v.len() - 1) as u32
            })
        };
        t = t
            .iter()
            .flat_map(|&[a, b, c]| {
                let (ab, bc, ca) = (mid(a, b, &mut v), mid(b, c, &mut v), mid(c, a, &mut v));
                [[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]
            })
            .collect();
    }
    (v.into_iter().map(|p| p.map(|x| r * x)).collect(), t)
}

fn bench(c: &mut Criterion) {
    let (v, t) = icosphere(0.03, 6);
    let mut group = c.benchmark_group("closed_surface");
    group
        .measurement_time(Duration::from_secs(20))
        .sample_size(10);
    group.bench_function("index_81920_triangles", |b| {
        b.iter(|| ClosedSurface::new(black_box(v.clone()), black_box(t.clone())).unwrap())
    });
    let surface = ClosedSurface::new(v, t).unwrap();
    let n = 100;
    group.throughput(Throughput::Elements((n * n * n) as u64));
    group.bench_function("contains_1e6_points", |b| {
        b.iter(|| {
            let step = 0.06 / n as f64;
            let mut inside = 0usize;
            for i in 0..n {
                for j in 0..n {
                    for k in 0..n {
                        let p = [i, j, k].map(|a| -0.03 + (a as f64 + 0.5) * step);
                        inside += usize::from(surface.contains(black_box(p)));
                    }
                }
            }
            inside
        })
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
