//! Bodies read from STL and OBJ files: they fill what their surface encloses, the same points as
//! the built-in geometry where the two coincide, and bad files are refused by name.

mod common;
use common::mesh::{Block, folder, msh, positions, scene, write_stl};
use common::source;
use fissure::base::dim::D3;
use fissure::base::geometry::ClosedSurface;
use fissure::io::scenario::{Source, build};

/// The surface of a sphere of radius `r` about `c`: an icosahedron whose faces are split
/// `levels` times, vertices pushed onto the sphere, faces outward.
fn icosphere(c: [f64; 3], r: f64, levels: usize) -> Vec<[[f32; 3]; 3]> {
    let g = (1.0 + 5f64.sqrt()) / 2.0;
    let v = [
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
    let faces = [
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
    let unit = |p: [f64; 3]| {
        let n = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
        p.map(|x| x / n)
    };
    let mut tris: Vec<[[f64; 3]; 3]> = faces.iter().map(|f| f.map(|i| unit(v[i]))).collect();
    for _ in 0..levels {
        let mid = |a: [f64; 3], b: [f64; 3]| unit([0, 1, 2].map(|k| a[k] + b[k]));
        tris = tris
            .iter()
            .flat_map(|&[a, b, cc]| {
                let (ab, bc, ca) = (mid(a, b), mid(b, cc), mid(cc, a));
                [[a, ab, ca], [ab, b, bc], [ca, bc, cc], [ab, bc, ca]]
            })
            .collect();
    }
    tris.iter()
        .map(|t| t.map(|p| [0, 1, 2].map(|k| (c[k] + r * p[k]) as f32)))
        .collect()
}

/// An icosphere of radius 30 mm (1,280 triangles, written in mm and read with
/// scale = 1e-3): the particles fill the polyhedron's volume within 1 % (2 mm cells, as
/// the built-in sphere's test), and every one of them is also a particle of the built-in
/// sphere of the same radius, which holds the inscribed polyhedron.
#[test]
fn icosphere_fills_its_polyhedron_inside_the_sphere() {
    let dir = folder("sphere");
    let file = dir.join("ball.stl");
    let tris = icosphere([0.0; 3], 30.0, 3);
    write_stl(&file, &tris);
    let text = scene(&format!(
        "mesh = {{ file = \"{}\", scale = 1e-3, translate = [0.05, 0.05, 0.05] }}",
        file.display()
    ));
    let w = build::<D3>(&source(&text)).unwrap().world;
    let vol: f64 = w.particles.volume.iter().sum();
    let (v, t) = indexed(&tris, 1e-3, [0.05; 3]);
    let want = ClosedSurface::new(v, t).unwrap().volume();
    assert!((vol - want).abs() / want < 0.01, "{vol} vs {want}");
    let sphere = positions(&scene(
        "sphere = { center = [0.05, 0.05, 0.05], radius = 0.03 }",
    ));
    let mesh = positions(&text);
    assert!(mesh.len() < sphere.len());
    assert!(mesh.iter().all(|p| sphere.binary_search(p).is_ok()));
    std::fs::remove_dir_all(dir).ok();
}

/// The triangles as an indexed list (vertices merged), scaled and moved.
fn indexed(tris: &[[[f32; 3]; 3]], scale: f64, shift: [f64; 3]) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let mut vertices: Vec<[f32; 3]> = Vec::new();
    let t = tris
        .iter()
        .map(|tri| {
            tri.map(|p| match vertices.iter().position(|q| *q == p) {
                Some(i) => i as u32,
                None => {
                    vertices.push(p);
                    (vertices.len() - 1) as u32
                }
            })
        })
        .collect();
    let v = vertices
        .iter()
        .map(|p| [0, 1, 2].map(|k| f64::from(p[k]) * scale + shift[k]))
        .collect();
    (v, t)
}

/// A 20 x 30 x 40 mm block written as 12 triangles, placed by `translate` in a scenario
/// that names the file relative to its own folder: exactly the particles of the same box
/// given as `box`.
#[test]
fn block_from_a_file_is_the_box() {
    let dir = folder("block");
    let (a, b) = ([0.0f32; 3], [0.02f32, 0.03, 0.04]);
    let corner = |i: usize| [0, 1, 2].map(|k| if (i >> k) & 1 == 1 { b[k] } else { a[k] });
    let quads = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    let tris: Vec<[[f32; 3]; 3]> = quads
        .iter()
        .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
        .map(|t: [usize; 3]| t.map(corner))
        .collect();
    write_stl(&dir.join("block.stl"), &tris);
    let file = dir.join("block.toml");
    std::fs::write(
        &file,
        scene("mesh = { file = \"block.stl\", translate = [0.0103, 0.0201, 0.0307] }"),
    )
    .unwrap();
    let mesh = build::<D3>(&Source::load(&file, &[]).unwrap())
        .unwrap()
        .world;
    let boxed = build::<D3>(&source(&scene(
        "box = { min = [0.0103, 0.0201, 0.0307], max = [0.0303, 0.0501, 0.0707] }",
    )))
    .unwrap()
    .world;
    assert_eq!(mesh.particles.x, boxed.particles.x);
    std::fs::remove_dir_all(dir).ok();
}

/// The same block written as an OBJ file with quadrilateral faces, drawn 30 wide in x and
/// 20 in y and turned 90 degrees about z (x -> y, y -> -x): the particles of the box it
/// then occupies.
#[test]
fn turned_block_from_an_obj_file_is_the_box() {
    let dir = folder("obj");
    let file = dir.join("block.obj");
    let mut text = String::from("o block\n");
    for i in 0..8 {
        let c = [0.03, 0.02, 0.04];
        let p = [0, 1, 2].map(|k| if (i >> k) & 1 == 1 { c[k] } else { 0.0 });
        text += &format!("v {} {} {}\n", p[0], p[1], p[2]);
    }
    for q in [
        [1, 3, 4, 2],
        [5, 6, 8, 7],
        [1, 2, 6, 5],
        [3, 7, 8, 4],
        [1, 5, 7, 3],
        [2, 4, 8, 6],
    ] {
        text += &format!("f {} {} {} {}\n", q[0], q[1], q[2], q[3]);
    }
    std::fs::write(&file, text).unwrap();
    let mesh = positions(&scene(&format!(
        "mesh = {{ file = \"{}\", rotate = {{ axis = [0.0, 0.0, 2.0], angle = 90.0 }}, \
         translate = [0.0403, 0.0201, 0.0307] }}",
        file.display()
    )));
    let boxed = positions(&scene(
        "box = { min = [0.0203, 0.0201, 0.0307], max = [0.0403, 0.0501, 0.0707] }",
    ));
    assert_eq!(mesh, boxed);
    std::fs::remove_dir_all(dir).ok();
}

/// A surface with a hole, a file neither STL nor OBJ, an OBJ file with no faces, a
/// truncated binary STL file, a missing file
/// and a closed surface as a 2D body (whose mesh must be flat) are refused, naming the key,
/// the file and what is wrong.
#[test]
fn bad_mesh_files_are_named() {
    let dir = folder("bad");
    let err = |body: String| match Source::parse("bad.toml", &scene(&body), &[]) {
        Ok(src) => build::<D3>(&src)
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default(),
        Err(e) => e.to_string(),
    };
    let mut tris = icosphere([0.0; 3], 30.0, 1);
    tris.remove(17);
    let open = dir.join("open.stl");
    write_stl(&open, &tris);
    let e = err(format!("mesh = {{ file = \"{}\" }}", open.display()));
    assert!(
        e.contains("body[0].mesh.file") && e.contains("open.stl") && e.contains("not closed"),
        "{e}"
    );
    let step = dir.join("part.step");
    std::fs::write(&step, "ISO-10303-21;\n").unwrap();
    let e = err(format!("mesh = {{ file = \"{}\" }}", step.display()));
    assert!(
        e.contains("part.step") && e.contains("not an .stl, .obj or .msh file"),
        "{e}"
    );
    let points = dir.join("points.obj");
    std::fs::write(&points, "v 0 0 0\nv 1 0 0\n").unwrap();
    let e = err(format!("mesh = {{ file = \"{}\" }}", points.display()));
    assert!(
        e.contains("points.obj") && e.contains("no triangles"),
        "{e}"
    );
    let whole = dir.join("whole.stl");
    write_stl(&whole, &icosphere([0.0; 3], 30.0, 1));
    let bytes = std::fs::read(&whole).unwrap();
    let cut = dir.join("cut.stl");
    std::fs::write(&cut, &bytes[..bytes.len() - 30]).unwrap();
    let e = err(format!("mesh = {{ file = \"{}\" }}", cut.display()));
    assert!(e.contains("cut.stl") && e.contains("triangle 79"), "{e}");
    let e = err(format!(
        "mesh = {{ file = \"{}\" }}",
        dir.join("none.stl").display()
    ));
    assert!(
        e.contains("none.stl") && e.contains("cannot read it"),
        "{e}"
    );
    let e = err(format!(
        "mesh = {{ file = \"{}\", scale = -1.0 }}",
        whole.display()
    ));
    assert!(e.contains("body[0].mesh.scale"), "{e}");
    let flat = scene(&format!("mesh = {{ file = \"{}\" }}", whole.display()))
        .replace("dimension = 3", "dimension = 2")
        .replace("[0.0, 0.0, 0.0]", "[0.0, 0.0]")
        .replace("[0.1, 0.1, 0.1]", "[0.1, 0.1]")
        .replace("[0.002, 0.002, 0.002]", "[0.002, 0.002]");
    let e = match Source::parse("flat.toml", &flat, &[]) {
        Ok(src) => build::<fissure::base::dim::D2>(&src)
            .err()
            .unwrap()
            .to_string(),
        Err(e) => e.to_string(),
    };
    assert!(e.contains("one plane z = const"), "{e}");
    std::fs::remove_dir_all(dir).ok();
}

/// An edge crack through a 12 mm block (y = 6.5 mm, from outside the x = 0 face to
/// x = 5 mm, through the thickness in z), its front along x = 5 mm: as vertex and triangle
/// lists in the scenario and as an OBJ file. `crack` is the `[[crack]]` geometry line.
fn edge_crack_block(crack: &str) -> String {
    format!(
        r#"name = "edge_crack"
[simulation]
dimension = 3
shape = "ugimp"
duration = 4.0e-6
damping = 6.0e5
[grid]
min = [-0.002, -0.002, -0.002]
max = [0.014, 0.014, 0.014]
cell = [0.001, 0.001, 0.001]
[[material]]
name = "steel"
E = 200e9
nu = 0.3
rho = 8000.0
[[body]]
material = "steel"
box = {{ min = [0.0, 0.0, 0.0], max = [0.012, 0.012, 0.012] }}
[[crack]]
name = "edge"
{crack}
[[load]]
region = {{ min = [0.0, 0.0115, 0.0], max = [0.012, 0.012, 0.012] }}
force = [0.0, 2.0e4, 0.0]
time = {{ kind = "ramp", rise = 2.0e-6 }}
[[load]]
region = {{ min = [0.0, 0.0, 0.0], max = [0.012, 0.0005, 0.012] }}
force = [0.0, -2.0e4, 0.0]
time = {{ kind = "ramp", rise = 2.0e-6 }}
[fracture]
domain = 2
[output]
history_interval = 1.0e-6
"#
    )
}

/// The edge crack's vertices (a 3 x 8 grid over x in [-1, 5] mm, z in [-1, 13] mm),
/// triangles (0-based) and front (the x = 5 mm column, in z order).
fn edge_crack_mesh() -> (Vec<[f64; 3]>, Vec<[usize; 3]>, Vec<usize>) {
    let (xs, zs) = (
        [-0.001, 0.002, 0.005],
        (0..8).map(|k| -0.001 + 0.002 * k as f64),
    );
    let zs: Vec<f64> = zs.collect();
    let at = |i: usize, k: usize| k * 3 + i;
    let v = (0..zs.len())
        .flat_map(|k| xs.map(|x| [x, 0.0065, zs[k]]))
        .collect();
    let mut t = Vec::new();
    for k in 0..zs.len() - 1 {
        for i in 0..2 {
            t.push([at(i, k), at(i, k + 1), at(i + 1, k + 1)]);
            t.push([at(i, k), at(i + 1, k + 1), at(i + 1, k)]);
        }
    }
    (v, t, (0..zs.len()).map(|k| at(2, k)).collect())
}

/// A crack surface read from an OBJ file (`mesh_file`, the front given by its vertices'
/// positions, or found as the boundary inside the block) or a binary MSH file runs bit for bit as the same mesh
/// written into the scenario: the same J and K at every front vertex and step, the same
/// energies. The inline vertices are numbered
/// in order of first use by the triangles, as a file's are once read.
#[test]
fn crack_from_an_obj_file_is_the_inline_mesh() {
    let dir = folder("crack");
    let (v, t, front) = edge_crack_mesh();
    let mut order: Vec<usize> = Vec::new();
    for i in t.iter().flatten() {
        if !order.contains(i) {
            order.push(*i);
        }
    }
    let renumber = |i: usize| order.iter().position(|&j| j == i).unwrap();
    let point = |p: &[f64; 3]| format!("[{:e}, {:e}, {:e}]", p[0], p[1], p[2]);
    let join = |items: Vec<String>| items.join(", ");
    let inline = format!(
        "mesh = {{ vertices = [{}], triangles = [{}], front = [{}] }}",
        join(order.iter().map(|&i| point(&v[i])).collect()),
        join(
            t.iter()
                .map(|tri| format!(
                    "[{}]",
                    join(tri.iter().map(|&i| renumber(i).to_string()).collect())
                ))
                .collect()
        ),
        join(front.iter().map(|&i| renumber(i).to_string()).collect())
    );
    let mut obj = String::new();
    for p in &v {
        obj += &format!("v {:e} {:e} {:e}\n", p[0], p[1], p[2]);
    }
    for tri in &t {
        obj += &format!("f {} {} {}\n", tri[0] + 1, tri[1] + 1, tri[2] + 1);
    }
    let file = dir.join("edge.obj");
    std::fs::write(&file, obj).unwrap();
    let from_file = format!(
        "mesh_file = {{ file = \"{}\", front = [{}] }}",
        file.display(),
        join(front.iter().map(|&i| point(&v[i])).collect())
    );
    let a = common::history(&edge_crack_block(&inline));
    let b = common::history(&edge_crack_block(&from_file));
    assert!(
        a.fracture.iter().any(|r| r.j[0] > 0.0),
        "the front measures J"
    );
    assert_eq!(format!("{:?}", a.fracture), format!("{:?}", b.fracture));
    assert_eq!(format!("{:?}", a.rows), format!("{:?}", b.rows));
    // Without `front`, the boundary edges inside the block: the same front.
    let found = format!("mesh_file = {{ file = \"{}\" }}", file.display());
    let c = common::history(&edge_crack_block(&found));
    assert_eq!(format!("{:?}", a.fracture), format!("{:?}", c.fracture));
    // The same triangles in a Gmsh MSH file.
    let tags: Vec<u64> = (1..=v.len() as u64).collect();
    let tris = Block {
        dim: 2,
        kind: 2,
        elements: t
            .iter()
            .map(|tri| tri.iter().map(|&i| i as u64 + 1).collect())
            .collect(),
    };
    let msh_file = dir.join("edge.msh");
    std::fs::write(&msh_file, msh(&tags, &v, &[tris], true)).unwrap();
    let found = format!("mesh_file = {{ file = \"{}\" }}", msh_file.display());
    let d = common::history(&edge_crack_block(&found));
    assert_eq!(format!("{:?}", a.fracture), format!("{:?}", d.fracture));
    let wrong = format!(
        "mesh_file = {{ file = \"{}\", front = [[0.005, 0.0065, 0.0]] }}",
        file.display()
    );
    let e = match Source::parse("bad.toml", &edge_crack_block(&wrong), &[]) {
        Ok(src) => build::<D3>(&src).err().unwrap().to_string(),
        Err(e) => e.to_string(),
    };
    assert!(
        e.contains("crack[0].mesh_file.front[0]") && e.contains("no vertex"),
        "{e}"
    );
    // The crack surface's own checks name the file: a front vertex off the boundary.
    let inner = format!(
        "mesh_file = {{ file = \"{}\", front = [[0.002, 0.0065, 0.001]] }}",
        file.display()
    );
    let e = match Source::parse("bad.toml", &edge_crack_block(&inner), &[]) {
        Ok(src) => build::<D3>(&src).err().unwrap().to_string(),
        Err(e) => e.to_string(),
    };
    assert!(
        e.contains("crack[0].mesh_file") && e.contains("edge.obj") && e.contains("boundary"),
        "{e}"
    );
    std::fs::remove_dir_all(dir).ok();
}

/// The shipped tube's surface crack (scenarios/long/cylinder_surface_3d.toml), its inline
/// mesh written to an OBJ file and read back without its front, on 6 mm cells for a few
/// steps: the front found inside the tube is the one the scenario lists, and the fracture
/// history is the same bit for bit.
#[test]
fn tube_crack_from_an_obj_file_runs_as_the_inline_mesh() {
    let dir = folder("tube");
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenarios/long/cylinder_surface_3d.toml"
    );
    let text = std::fs::read_to_string(path)
        .unwrap()
        .replace(
            "cell = [0.003, 0.003, 0.003]",
            "cell = [0.006, 0.006, 0.006]",
        )
        .replace(
            "min = [-0.249, -0.009, -0.009]",
            "min = [-0.252, -0.012, -0.012]",
        )
        .replace("max = [0.249, 0.249, 0.249]", "max = [0.252, 0.252, 0.252]")
        .replace("duration = 5.0e-4", "duration = 1.2e-5")
        .replace("history_interval = 2.5e-5", "history_interval = 4.0e-6");
    // Its expects judge the long run: dropped.
    let text = format!(
        "{}{}",
        &text[..text.find("[[expect]]").unwrap()],
        &text[text.find("[[crack]]").unwrap()..]
    );
    let doc: toml::Table = toml::from_str(&text).unwrap();
    let mesh = &doc["crack"].as_array().unwrap()[0]["mesh"];
    let num = |v: &toml::Value| {
        v.as_float()
            .unwrap_or_else(|| v.as_integer().unwrap() as f64)
    };
    let list = |k: &str| mesh[k].as_array().unwrap().clone();
    let mut obj = String::new();
    for v in list("vertices") {
        let p: Vec<f64> = v.as_array().unwrap().iter().map(num).collect();
        obj += &format!("v {:e} {:e} {:e}\n", p[0], p[1], p[2]);
    }
    for t in list("triangles") {
        let t: Vec<i64> = t
            .as_array()
            .unwrap()
            .iter()
            .map(|i| i.as_integer().unwrap())
            .collect();
        obj += &format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    std::fs::write(dir.join("crack.obj"), obj).unwrap();
    // The [crack.mesh] table ends the file.
    let start = text.find("[crack.mesh]").unwrap();
    let from_file = format!(
        "{}mesh_file = {{ file = \"{}\" }}\n",
        &text[..start],
        dir.join("crack.obj").display()
    );
    let a = common::history(&text);
    let b = common::history(&from_file);
    assert!(
        a.fracture.iter().any(|r| r.j[0] > 0.0),
        "the front measures J"
    );
    assert_eq!(format!("{:?}", a.fracture), format!("{:?}", b.fracture));
    std::fs::remove_dir_all(dir).ok();
}
