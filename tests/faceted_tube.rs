//! A tube read from an STL file whose walls are 12-sided prisms: it fills exactly the
//! lattice points inside its faceted walls, and falls short of the built-in round tube
//! by what the faceting takes away.

mod common;
use common::mesh::{folder, positions, scene, write_stl};

/// Corner `j` of the `n`-gon of radius `r` (mm) about the tube's axis, as written (f32).
fn corner(r: f64, j: usize, n: usize) -> [f32; 2] {
    let t = 2.0 * std::f64::consts::PI * (j % n) as f64 / n as f64;
    [(r * t.cos()) as f32, (r * t.sin()) as f32]
}

/// A 12-sided tube, outer radius 40 mm, inner 25 mm, z from 10 to 90 mm, in mm about the
/// axis x = y = 0, read with scale 1e-3 and moved to x = y = 50 mm: its particles are the
/// points of the particle lattice inside the two 12-gons' prism (decided here by the
/// polygons' own edges), and their count over the built-in tube's is the faceted
/// annulus's area over the round one's, (12 / 2 pi) sin(2 pi / 12) = 0.9549, within 1 %
/// (the lattice's count of a ring of 15 mm wall at 1 mm spacing varies by less).
#[test]
fn faceted_tube_fills_its_prism() {
    let dir = folder("tube");
    let (n, big, small, z0, z1) = (12, 40.0, 25.0, 10.0f32, 90.0f32);
    let mut tris = Vec::new();
    for j in 0..n {
        let (o0, o1) = (corner(big, j, n), corner(big, j + 1, n));
        let (i0, i1) = (corner(small, j, n), corner(small, j + 1, n));
        let p = |c: [f32; 2], z: f32| [c[0], c[1], z];
        for (a, b) in [(o0, o1), (i1, i0)] {
            tris.push([p(a, z0), p(b, z0), p(b, z1)]);
            tris.push([p(a, z0), p(b, z1), p(a, z1)]);
        }
        for (z, flip) in [(z0, true), (z1, false)] {
            let quad = [p(i0, z), p(o0, z), p(o1, z), p(i1, z)];
            let (a, b) = ([quad[0], quad[1], quad[2]], [quad[0], quad[2], quad[3]]);
            for mut t in [a, b] {
                if flip {
                    t.swap(1, 2);
                }
                tris.push(t);
            }
        }
    }
    let file = dir.join("tube.stl");
    write_stl(&file, &tris);
    let mesh = positions(&scene(&format!(
        "mesh = {{ file = \"{}\", scale = 1e-3, translate = [0.05, 0.05, 0.0] }}",
        file.display()
    )));
    // The polygons as placed: x = f64(file) * 1e-3 + 0.05.
    let placed = |r: f64| -> Vec<[f64; 2]> {
        (0..n)
            .map(|j| corner(r, j, n).map(|c| f64::from(c) * 1e-3 + 0.05))
            .collect()
    };
    let (outer, inner) = (placed(big), placed(small));
    let inside = |poly: &[[f64; 2]], x: f64, y: f64| {
        (0..n).all(|j| {
            let (a, b) = (poly[j], poly[(j + 1) % n]);
            (b[0] - a[0]) * (y - a[1]) - (b[1] - a[1]) * (x - a[0]) > 0.0
        })
    };
    let lattice = positions(&scene(
        "box = { min = [0.009, 0.009, 0.009], max = [0.091, 0.091, 0.091] }",
    ));
    let (lo, hi) = (f64::from(z0) * 1e-3, f64::from(z1) * 1e-3);
    let want: Vec<[u64; 3]> = (lattice.into_iter())
        .filter(|p| {
            let [x, y, z] = p.map(f64::from_bits);
            (lo..=hi).contains(&z) && inside(&outer, x, y) && !inside(&inner, x, y)
        })
        .collect();
    assert_eq!(mesh, want);
    let round = positions(&scene(
        "cylinder = { center = [0.05, 0.05, 0.01], axis = \"z\", radius = 0.04, \
         inner_radius = 0.025, length = 0.08 }",
    ));
    let ratio = mesh.len() as f64 / round.len() as f64;
    let faceted =
        n as f64 / (2.0 * std::f64::consts::PI) * (2.0 * std::f64::consts::PI / n as f64).sin();
    assert!((ratio - faceted).abs() < 0.01, "{ratio} vs {faceted}");
    std::fs::remove_dir_all(dir).ok();
}
