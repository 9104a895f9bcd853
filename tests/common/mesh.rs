//! Helpers for the tests of bodies and cracks read from mesh files: a scratch folder, a
//! one-body 3D scene, its particle positions, and Gmsh MSH 4.1 files written by hand.

use super::source;
use fissure::base::dim::D3;
use fissure::io::scenario::build;
use std::path::{Path, PathBuf};

/// A fresh folder for one test's files.
pub fn folder(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("fissure-mesh-{name}-{}", std::process::id()));
    std::fs::remove_dir_all(&dir).ok();
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A 3D scene in a 100 mm cube of 2 mm cells with one body, `body` its geometry.
pub fn scene(body: &str) -> String {
    format!(
        r#"
[simulation]
dimension = 3
duration = 1e-6
[grid]
min = [0.0, 0.0, 0.0]
max = [0.1, 0.1, 0.1]
cell = [0.002, 0.002, 0.002]
[[material]]
name = "m"
E = 1e9
nu = 0.3
rho = 1000.0
[[body]]
material = "m"
ppc = 2
{body}
"#
    )
}

/// The particle positions of the scene, as bits, sorted.
pub fn positions(text: &str) -> Vec<[u64; 3]> {
    let w = build::<D3>(&source(text)).unwrap().world;
    let mut out: Vec<[u64; 3]> = (w.particles.x.iter())
        .map(|x| x.to_array().map(f64::to_bits))
        .collect();
    out.sort_unstable();
    out
}

/// One block of elements of a Gmsh type (2 triangle, 3 quadrangle, 4 tetrahedron,
/// 5 hexahedron, ...), their node tags.
pub struct Block {
    pub dim: i32,
    pub kind: i32,
    pub elements: Vec<Vec<u64>>,
}

/// An MSH 4.1 file, ASCII or binary (little-endian), of one node block (`tags` and
/// their positions) and the element `blocks`, elements numbered from 1.
pub fn msh(tags: &[u64], nodes: &[[f64; 3]], blocks: &[Block], binary: bool) -> Vec<u8> {
    let count: usize = blocks.iter().map(|b| b.elements.len()).sum();
    let (lo, hi) = (tags.iter().min().unwrap(), tags.iter().max().unwrap());
    let mut out = format!("$MeshFormat\n4.1 {} 8\n", u8::from(binary)).into_bytes();
    if binary {
        out.extend(1i32.to_le_bytes());
        out.push(b'\n');
    }
    out.extend(b"$EndMeshFormat\n$Nodes\n");
    let size = |out: &mut Vec<u8>, v: u64| {
        if binary {
            out.extend(v.to_le_bytes());
        } else {
            out.extend(format!("{v} ").as_bytes());
        }
    };
    let int = |out: &mut Vec<u8>, v: i32| {
        if binary {
            out.extend(v.to_le_bytes());
        } else {
            out.extend(format!("{v} ").as_bytes());
        }
    };
    let newline = |out: &mut Vec<u8>| {
        if !binary {
            out.push(b'\n');
        }
    };
    for v in [1, tags.len() as u64, *lo, *hi] {
        size(&mut out, v);
    }
    newline(&mut out);
    for v in [3, 1, 0] {
        int(&mut out, v);
    }
    size(&mut out, tags.len() as u64);
    newline(&mut out);
    for &t in tags {
        size(&mut out, t);
        newline(&mut out);
    }
    for p in nodes {
        for c in p {
            if binary {
                out.extend(c.to_le_bytes());
            } else {
                out.extend(format!("{c:e} ").as_bytes());
            }
        }
        newline(&mut out);
    }
    if binary {
        out.push(b'\n');
    }
    out.extend(b"$EndNodes\n$Elements\n");
    for v in [blocks.len() as u64, count as u64, 1, count as u64] {
        size(&mut out, v);
    }
    newline(&mut out);
    let mut tag = 0;
    for (k, b) in blocks.iter().enumerate() {
        for v in [b.dim, k as i32 + 1, b.kind] {
            int(&mut out, v);
        }
        size(&mut out, b.elements.len() as u64);
        newline(&mut out);
        for e in &b.elements {
            tag += 1;
            size(&mut out, tag);
            for &n in e {
                size(&mut out, n);
            }
            newline(&mut out);
        }
    }
    if binary {
        out.push(b'\n');
    }
    out.extend(b"$EndElements\n");
    out
}

/// Writes `triangles` as a binary STL file.
pub fn write_stl(path: &Path, triangles: &[[[f32; 3]; 3]]) {
    let tris: Vec<stl_io::Triangle> = triangles
        .iter()
        .map(|t| stl_io::Triangle {
            normal: stl_io::Normal::new([0.0; 3]),
            vertices: t.map(stl_io::Vertex::new),
        })
        .collect();
    let mut f = std::fs::File::create(path).unwrap();
    stl_io::write_stl(&mut f, tris.iter()).unwrap();
}
