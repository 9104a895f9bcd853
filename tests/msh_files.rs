//! Bodies from Gmsh MSH 4.1 files, ASCII and binary: the boundary of a volume mesh of
//! hexahedra or tetrahedra, and a surface mesh whose triangles face different ways, all
//! fill exactly the box they bound; a surface that passes through itself and malformed
//! files are refused by name.

mod common;
use common::mesh::{Block, folder, msh, positions, scene};
use fissure::base::dim::D3;
use fissure::io::scenario::{Source, build};

/// The 20 x 30 x 40 mm block's corners, corner i at bit k of i set -> upper on axis k.
fn corners(split_x: bool) -> Vec<[f64; 3]> {
    let b = [0.02, 0.03, 0.04];
    let mut out = Vec::new();
    // With `split_x`, a middle layer at x = 10 mm (tags 9..12: y, then z, upper at bits 0
    // and 1) for two hexahedra.
    for i in 0..8 {
        out.push([0, 1, 2].map(|k| if (i >> k) & 1 == 1 { b[k] } else { 0.0 }));
    }
    if split_x {
        for i in 0..4 {
            out.push([0.01, [0.0, 0.03][i & 1], [0.0, 0.04][i >> 1]]);
        }
    }
    out
}

/// The box the block fills once moved by the translation the tests use.
fn the_box() -> Vec<[u64; 3]> {
    positions(&scene(
        "box = { min = [0.0103, 0.0201, 0.0307], max = [0.0303, 0.0501, 0.0707] }",
    ))
}

fn body(file: &std::path::Path) -> String {
    scene(&format!(
        "mesh = {{ file = \"{}\", translate = [0.0103, 0.0201, 0.0307] }}",
        file.display()
    ))
}

/// Two hexahedra side by side (their shared face dropped), ASCII and binary; six
/// tetrahedra around the main diagonal, some listed inside out (turned); the box's faces
/// as triangles in two surface entities, the second listed the other way round, with
/// sparse node tags and boundary lines that are skipped: each is the box bit for bit.
#[test]
fn blocks_from_msh_files_are_the_box() {
    let dir = folder("msh");
    let want = the_box();
    // Node tags 1..: corners 1..8, middle layer 9..12. Gmsh hexahedron order: the x-y
    // square at low z counterclockwise, then the one above.
    let hex = |c: [u64; 4], d: [u64; 4]| vec![c[0], c[1], c[2], c[3], d[0], d[1], d[2], d[3]];
    let hexes = Block {
        dim: 3,
        kind: 5,
        elements: vec![
            hex([1, 9, 10, 3], [5, 11, 12, 7]),
            hex([9, 2, 4, 10], [11, 6, 8, 12]),
        ],
    };
    let tags: Vec<u64> = (1..=12).collect();
    for binary in [false, true] {
        let file = dir.join(format!("hex{binary}.msh"));
        std::fs::write(
            &file,
            msh(&tags, &corners(true), std::slice::from_ref(&hexes), binary),
        )
        .unwrap();
        assert_eq!(positions(&body(&file)), want, "hexahedra, binary {binary}");
    }
    let file = dir.join("tet.msh");
    std::fs::write(&file, msh(&tags[..8], &corners(false), &[tets(0)], false)).unwrap();
    assert_eq!(positions(&body(&file)), want, "tetrahedra");
    // Faces as quads of corner tags (tags 10 * (i + 1)), split in two; the second entity's
    // triangles turned the other way.
    let quads = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    let tag = |i: usize| 10 * (i as u64 + 1);
    let tris = |q: &[usize; 4], flip: bool| {
        let t = [[q[0], q[1], q[2]], [q[0], q[2], q[3]]];
        t.map(|t| {
            let t = if flip { [t[0], t[2], t[1]] } else { t };
            t.iter().map(|&i| tag(i)).collect::<Vec<u64>>()
        })
    };
    let blocks = [
        Block {
            dim: 2,
            kind: 2,
            elements: quads[..3].iter().flat_map(|q| tris(q, false)).collect(),
        },
        Block {
            dim: 2,
            kind: 2,
            elements: quads[3..].iter().flat_map(|q| tris(q, true)).collect(),
        },
        Block {
            dim: 1,
            kind: 1,
            elements: vec![vec![tag(0), tag(1)]],
        },
    ];
    let sparse: Vec<u64> = (0..8).map(tag).collect();
    let file = dir.join("surface.msh");
    std::fs::write(&file, msh(&sparse, &corners(false), &blocks, false)).unwrap();
    assert_eq!(positions(&body(&file)), want, "surface");
    std::fs::remove_dir_all(dir).ok();
}

/// The block as six tetrahedra around its main diagonal (corner tags 1..=8 from
/// [`corners`], plus `shift`), some listed inside out.
fn tets(shift: u64) -> Block {
    Block {
        dim: 3,
        kind: 4,
        elements: [
            [1, 2, 4],
            [1, 4, 3],
            [1, 3, 7],
            [1, 7, 5],
            [1, 5, 6],
            [1, 6, 2],
        ]
        .iter()
        .map(|t| vec![t[0] + shift, t[1] + shift, t[2] + shift, 8 + shift])
        .collect(),
    }
}

/// Node tags 1..=n.
fn tags_of(n: u64) -> Vec<u64> {
    (1..=n).collect()
}

/// The build error of a scene whose body is read from `file`.
fn refused(file: &std::path::Path) -> String {
    let text = body(file);
    match Source::parse("bad.toml", &text, &[]) {
        Ok(src) => build::<D3>(&src)
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default(),
        Err(e) => e.to_string(),
    }
}

/// A closed surface passing through itself (two boxes that overlap, as one mesh), MSH
/// version 2.2, an element type that is not read (28-node triangles), an element on a missing node, a file
/// cut short and a node section that declares no nodes: each refused, naming the file
/// and what is wrong.
#[test]
fn bad_msh_files_are_named() {
    let dir = folder("msh-bad");
    let tri28 = Block {
        dim: 2,
        kind: 42,
        elements: vec![(0..28).map(|k| 1 + k % 8).collect()],
    };
    let high = dir.join("tri28.msh");
    std::fs::write(&high, msh(&tags_of(8), &corners(false), &[tri28], false)).unwrap();
    let e = refused(&high);
    assert!(e.contains("tri28.msh") && e.contains("type Tri28"), "{e}");
    let mut nodes = corners(false);
    nodes.extend(corners(false).iter().map(|p| p.map(|c| c + 0.005)));
    let tags = tags_of(16);
    let two = dir.join("two.msh");
    let blocks = [tets(0), tets(8)];
    std::fs::write(&two, msh(&tags, &nodes, &blocks, false)).unwrap();
    let e = refused(&two);
    assert!(
        e.contains("body[0].mesh.file") && e.contains("two.msh") && e.contains("meets itself"),
        "{e}"
    );
    let one = msh(&tags[..8], &corners(false), &[tets(0)], false);
    let text = String::from_utf8(one.clone()).unwrap();
    let cases = [
        (
            "old.msh",
            text.replace("4.1 0 8", "2.2 0 8"),
            "only 4.1 is read",
        ),
        (
            "missing.msh",
            text.replace("6 1 6 2 8", "6 1 6 2 99"),
            "node 99 is not in $Nodes",
        ),
        (
            "cut.msh",
            text[..text.len() - 40].to_string(),
            "not a readable MSH 4.1 file",
        ),
        (
            "empty.msh",
            text.replace("$Nodes\n1 8 1 8", "$Nodes\n1 0 1 8"),
            "at least 1",
        ),
    ];
    for (name, content, says) in cases {
        let file = dir.join(name);
        std::fs::write(&file, content).unwrap();
        let e = refused(&file);
        assert!(e.contains(name) && e.contains(says), "{name}: {e}");
    }
    std::fs::remove_dir_all(dir).ok();
}
