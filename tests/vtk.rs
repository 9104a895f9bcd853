//! The VTK XML files are well-formed and their appended-data offsets are right.

mod common;
use common::source;
use fissure::app::run::{RunOptions, run};

const SCENE: &str = r#"
[simulation]
dimension = 3
duration = 2e-6
[grid]
min = [0.0, 0.0, 0.0]
max = [0.01, 0.01, 0.01]
cell = [0.002, 0.002, 0.002]
[[material]]
name = "m"
E = 1e9
nu = 0.3
rho = 1000.0
[[body]]
material = "m"
box = { min = [0.002, 0.002, 0.002], max = [0.008, 0.008, 0.006] }
velocity = [1.0, 2.0, 3.0]
[output]
interval = 1e-6
"#;

#[test]
fn vtu_offsets_and_pvd_are_consistent() {
    offsets_and_pvd_are_consistent(SCENE, "elastic");
    // A plastic scene adds the equivalent plastic strain.
    let plastic = SCENE.replace(
        "rho = 1000.0",
        "rho = 1000.0\nmodel = \"j2\"\nsigma_y = 1e7",
    );
    offsets_and_pvd_are_consistent(&plastic, "plastic");
}

fn offsets_and_pvd_are_consistent(scene: &str, name: &str) {
    let dir = std::env::temp_dir().join(format!("fissure-vtk-{name}-{}", std::process::id()));
    let opts = RunOptions {
        out: Some(dir.clone()),
        ..RunOptions::default()
    };
    let out = run(&source(scene), &opts).unwrap();
    let n = out.summary.particles;
    // 6 x 6 x 4 mm at 2 mm cells and 2 particles per cell per axis.
    assert_eq!(n, 6 * 6 * 4);

    let pvd = std::fs::read_to_string(dir.join("particles.pvd")).unwrap();
    let doc = roxmltree::Document::parse(&pvd).expect("pvd is well-formed XML");
    let files: Vec<&str> = doc
        .descendants()
        .filter(|e| e.has_tag_name("DataSet"))
        .map(|e| e.attribute("file").unwrap())
        .collect();
    assert!(files.len() >= 3, "frames at t = 0, 1 and 2 us: {files:?}");

    let bytes = std::fs::read(dir.join(files[0])).unwrap();
    let marker = b"<AppendedData encoding=\"raw\">\n_";
    let at = bytes
        .windows(marker.len())
        .position(|w| w == marker)
        .expect("appended data marker");
    let header = std::str::from_utf8(&bytes[..at + marker.len() - 1]).unwrap();
    let xml = format!("{header}</AppendedData>\n</VTKFile>\n");
    let doc = roxmltree::Document::parse(&xml).expect("vtu header is well-formed XML");
    let data = &bytes[at + marker.len()..];
    let mut expected_offset = 0;
    let names: Vec<_> = (doc.descendants().filter(|e| e.has_tag_name("DataArray")))
        .filter_map(|e| e.attribute("Name"))
        .collect();
    assert_eq!(
        names.contains(&"plastic_strain"),
        name == "plastic",
        "{names:?}"
    );
    for array in doc.descendants().filter(|e| e.has_tag_name("DataArray")) {
        let offset: usize = array.attribute("offset").unwrap().parse().unwrap();
        assert_eq!(offset, expected_offset, "arrays are packed back to back");
        let comps: usize = array
            .attribute("NumberOfComponents")
            .map_or(1, |c| c.parse().unwrap());
        let size = match array.attribute("type").unwrap() {
            "Float64" | "Int64" => 8,
            "Int32" => 4,
            "UInt8" => 1,
            other => panic!("unexpected type {other}"),
        };
        let len = u64::from_le_bytes(data[offset..offset + 8].try_into().unwrap()) as usize;
        assert_eq!(len, n * comps * size, "{:?}", array.attribute("Name"));
        if array.attribute("Name") == Some("velocity") {
            let first: Vec<f64> = (0..3)
                .map(|k| {
                    f64::from_le_bytes(
                        data[offset + 8 + 8 * k..offset + 16 + 8 * k]
                            .try_into()
                            .unwrap(),
                    )
                })
                .collect();
            assert_eq!(
                first,
                [1.0, 2.0, 3.0],
                "velocities of a body in free flight"
            );
        }
        expected_offset = offset + 8 + len;
    }
    assert_eq!(&data[expected_offset..], b"\n</AppendedData>\n</VTKFile>\n");
    std::fs::remove_dir_all(dir).ok();
}

/// Crack files: the crack-plane vertices as points, the segments as line cells, K at the
/// tips (NaN without [fracture]), packed arrays, and a collection listing one file per
/// frame.
#[test]
fn crack_vtu_holds_the_segments() {
    let text = common::block_2d(
        2e-6,
        0.004,
        0.016,
        "[[crack]]\nline = { start = [0.003, 0.01], end = [0.01, 0.01], spacing = 1e-3 }\n\
         [output]\ninterval = 1e-6\n",
    );
    let dir = std::env::temp_dir().join(format!("fissure-vtk-crack-{}", std::process::id()));
    let opts = RunOptions {
        out: Some(dir.clone()),
        ..RunOptions::default()
    };
    run(&source(&text), &opts).unwrap();
    let pvd = std::fs::read_to_string(dir.join("cracks.pvd")).unwrap();
    let doc = roxmltree::Document::parse(&pvd).expect("pvd is well-formed XML");
    let files = doc
        .descendants()
        .filter(|e| e.has_tag_name("DataSet"))
        .count();
    assert!(files >= 3, "a crack file per frame");
    let bytes = std::fs::read(dir.join("cracks_00000.vtu")).unwrap();
    let marker = b"<AppendedData encoding=\"raw\">\n_";
    let at = bytes
        .windows(marker.len())
        .position(|w| w == marker)
        .unwrap();
    let header = std::str::from_utf8(&bytes[..at + marker.len() - 1]).unwrap();
    let xml = format!("{header}</AppendedData>\n</VTKFile>\n");
    let doc = roxmltree::Document::parse(&xml).expect("vtu header is well-formed XML");
    let piece = doc.descendants().find(|e| e.has_tag_name("Piece")).unwrap();
    // 7 mm at 1 mm spacing: 8 vertices, 7 segments.
    assert_eq!(piece.attribute("NumberOfPoints"), Some("8"));
    assert_eq!(piece.attribute("NumberOfCells"), Some("7"));
    let data = &bytes[at + marker.len()..];
    let mut next = 0;
    for array in doc.descendants().filter(|e| e.has_tag_name("DataArray")) {
        let offset: usize = array.attribute("offset").unwrap().parse().unwrap();
        assert_eq!(offset, next, "arrays are packed back to back");
        let len = u64::from_le_bytes(data[offset..offset + 8].try_into().unwrap()) as usize;
        let want = match array.attribute("Name").unwrap() {
            "opening" | "Points" | "K" => 8 * 3 * 8,
            "crack" => 8 * 4,
            "connectivity" => 7 * 2 * 8,
            "offsets" => 7 * 8,
            "types" => 7,
            other => panic!("unexpected array {other}"),
        };
        assert_eq!(len, want, "{:?}", array.attribute("Name"));
        next = offset + 8 + len;
    }
    assert_eq!(&data[next..], b"\n</AppendedData>\n</VTKFile>\n");
    std::fs::remove_dir_all(dir).ok();
}
