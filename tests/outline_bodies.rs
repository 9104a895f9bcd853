//! 2D bodies read from flat mesh files (`body.mesh` in 2D): the region the triangles
//! cover, holes included, fills with exactly the particles of the same region given
//! inline or counted on the particle lattice; meshes that are not a flat face are refused
//! with the file and what is wrong.

mod common;

use common::mesh::folder;
use common::source;
use fissure::base::dim::D2;
use fissure::io::scenario::{Source, build};
use std::path::Path;

/// A 2D scene in a 100 mm square of 1 mm cells with one body (2 particles a cell per axis,
/// 0.5 mm apart, at 0.25 mm + k 0.5 mm), `body` its geometry.
fn scene(body: &str) -> String {
    format!(
        r#"
[simulation]
dimension = 2
duration = 1e-6
[grid]
min = [0.0, 0.0]
max = [0.1, 0.1]
cell = [0.001, 0.001]
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

/// The particle positions of scenario text, or its error's text.
fn positions(text: &str, file: &Path) -> Result<Vec<[f64; 2]>, String> {
    std::fs::write(file, text).unwrap();
    let src = Source::load(file, &[]).map_err(|e| e.to_string())?;
    let world = build::<D2>(&src).map_err(|e| e.to_string())?.world;
    Ok(world.particles.x.iter().map(|x| x.to_array()).collect())
}

/// An OBJ file of `v x y z` lines and `f` lines (1-based corners).
fn write_obj(path: &Path, vertices: &[[f64; 3]], faces: &[Vec<usize>]) {
    let mut text = String::new();
    for v in vertices {
        text += &format!("v {} {} {}\n", v[0], v[1], v[2]);
    }
    for f in faces {
        let corners: Vec<String> = f.iter().map(|i| (i + 1).to_string()).collect();
        text += &format!("f {}\n", corners.join(" "));
    }
    std::fs::write(path, text).unwrap();
}

/// A 40 mm square with a 10 mm square hole, drawn in mm as eight quadrangles round the
/// hole (vertex k of the outer loop at index k, of the hole at 4 + k, in `z` = 0 or 5 mm),
/// their windings mixed.
fn framed_square(z: f64) -> (Vec<[f64; 3]>, Vec<Vec<usize>>) {
    let outer = [[0.0, 0.0], [40.0, 0.0], [40.0, 40.0], [0.0, 40.0]];
    let inner = [[15.0, 15.0], [25.0, 15.0], [25.0, 25.0], [15.0, 25.0]];
    let vertices = (outer.iter().chain(&inner))
        .map(|p| [p[0], p[1], z])
        .collect();
    let faces = (0..4)
        .map(|k| {
            let n = (k + 1) % 4;
            if k % 2 == 0 {
                vec![k, n, 4 + n, 4 + k]
            } else {
                vec![4 + k, 4 + n, n, k]
            }
        })
        .collect();
    (vertices, faces)
}

/// The framed square, read in mm (scale 1e-3) and moved by (10, 20) mm: every particle of
/// the 80 x 80 lattice points of the outer square but the 20 x 20 of the hole, 6,000, and
/// none of the hole's.
#[test]
fn a_flat_mesh_with_a_hole_fills_the_frame() {
    let dir = folder("frame");
    let (vertices, faces) = framed_square(0.0);
    write_obj(&dir.join("frame.obj"), &vertices, &faces);
    let body = "mesh = { file = \"frame.obj\", scale = 1e-3, translate = [0.01, 0.02] }";
    let x = positions(&scene(body), &dir.join("frame.toml")).unwrap();
    assert_eq!(x.len(), 80 * 80 - 20 * 20);
    let in_hole = |p: &[f64; 2]| (0.025..0.035).contains(&p[0]) && (0.035..0.045).contains(&p[1]);
    let in_square = |p: &[f64; 2]| (0.01..0.05).contains(&p[0]) && (0.02..0.06).contains(&p[1]);
    assert!(x.iter().all(|p| in_square(p) && !in_hole(p)));
    std::fs::remove_dir_all(dir).ok();
}

/// An L-shaped plate as a binary STL of four triangles drawn in the x-z plane (y = 0),
/// turned 90 degrees about x into the x-y plane: bit for bit the particles of the same L
/// given as an inline polygon.
#[test]
fn a_flat_stl_turned_into_the_plane_is_the_polygon() {
    let dir = folder("ell");
    let l = [
        [0.0, 0.0],
        [0.03, 0.0],
        [0.03, 0.01],
        [0.01, 0.01],
        [0.01, 0.02],
        [0.0, 0.02],
    ];
    // In the x-z plane: (x, 0, z) turns about x by +90 degrees to (x, -z, 0): draw z = -y.
    let at = |k: usize| [l[k][0] as f32, 0.0, -l[k][1] as f32];
    let tris: Vec<[[f32; 3]; 3]> = [[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 5]]
        .iter()
        .map(|t: &[usize; 3]| t.map(at))
        .collect();
    common::mesh::write_stl(&dir.join("ell.stl"), &tris);
    let turned = "mesh = { file = \"ell.stl\", rotate = { axis = [1.0, 0.0, 0.0], angle = 90.0 }, \
                  translate = [0.0203, 0.0101] }";
    let mesh = positions(&scene(turned), &dir.join("ell.toml")).unwrap();
    let points: Vec<String> = (l.iter())
        .map(|p| format!("[{:e}, {:e}]", p[0] + 0.0203, p[1] + 0.0101))
        .collect();
    let inline = format!("polygon = {{ points = [{}] }}", points.join(", "));
    let built = build::<D2>(&source(&scene(&inline))).unwrap().world;
    let polygon: Vec<[f64; 2]> = built.particles.x.iter().map(|x| x.to_array()).collect();
    assert!(!mesh.is_empty());
    assert_eq!(mesh, polygon);
    std::fs::remove_dir_all(dir).ok();
}

/// Meshes that are not one flat face are refused at `body[0].mesh.file`, naming the file
/// and the fault: a face out of the plane, triangles folded over their shared edge, three
/// triangles on one edge, a triangle without area, and two loops that cross; a 2D
/// `translate` of three numbers at its key.
#[test]
fn meshes_that_are_not_a_flat_face_are_refused() {
    let dir = folder("bad_faces");
    let refused = |name: &str, vertices: &[[f64; 3]], faces: &[Vec<usize>]| {
        write_obj(&dir.join(name), vertices, faces);
        let body = format!("mesh = {{ file = \"{name}\", scale = 1e-3 }}");
        positions(&scene(&body), &dir.join("bad.toml")).unwrap_err()
    };
    let (mut tilted, faces) = framed_square(0.0);
    tilted[2][2] = 1.0;
    let e = refused("tilted.obj", &tilted, &faces);
    assert!(
        e.contains("body[0].mesh.file") && e.contains("tilted.obj"),
        "{e}"
    );
    assert!(e.contains("one plane z = const"), "{e}");
    let square = [
        [0.0, 0.0, 0.0],
        [10.0, 0.0, 0.0],
        [10.0, 10.0, 0.0],
        [0.0, 10.0, 0.0],
    ];
    let e = refused("folded.obj", &square, &[vec![0, 1, 2], vec![0, 1, 3]]);
    assert!(e.contains("fold over their shared edge"), "{e}");
    let fan = [
        [0.0, 0.0, 0.0],
        [10.0, 0.0, 0.0],
        [5.0, 5.0, 0.0],
        [5.0, -5.0, 0.0],
        [5.0, 9.0, 0.0],
    ];
    let e = refused(
        "fan.obj",
        &fan,
        &[vec![0, 1, 2], vec![1, 0, 3], vec![0, 1, 4]],
    );
    assert!(e.contains("three or more triangles"), "{e}");
    let line = [[0.0, 0.0, 0.0], [10.0, 0.0, 0.0], [20.0, 0.0, 0.0]];
    let e = refused("line.obj", &line, &[vec![0, 1, 2]]);
    assert!(e.contains("no area"), "{e}");
    let bars = [
        [0.0, 4.0, 0.0],
        [20.0, 4.0, 0.0],
        [20.0, 6.0, 0.0],
        [0.0, 6.0, 0.0],
        [9.0, 0.0, 0.0],
        [11.0, 0.0, 0.0],
        [11.0, 20.0, 0.0],
        [9.0, 20.0, 0.0],
    ];
    let e = refused("cross.obj", &bars, &[vec![0, 1, 2, 3], vec![4, 5, 6, 7]]);
    assert!(e.contains("meets itself"), "{e}");
    let (vertices, faces) = framed_square(0.0);
    write_obj(&dir.join("frame.obj"), &vertices, &faces);
    let body = "mesh = { file = \"frame.obj\", translate = [0.0, 0.0, 0.0] }";
    let e = positions(&scene(body), &dir.join("bad.toml")).unwrap_err();
    assert!(e.contains("body[0].mesh.translate"), "{e}");
    std::fs::remove_dir_all(dir).ok();
}
