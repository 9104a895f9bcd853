//! VTK XML output for ParaView: particle and crack `.vtu` files (appended raw binary) and
//! `.pvd` collections indexing them by time.

use crate::base::dim::Dim;
use crate::base::geometry::Element;
use crate::base::sym::SymTensor;
use crate::fracture::plan::TipResult;
use crate::store::crack::Cracks;
use crate::store::particles::Particles;
use std::io::Write;
use std::path::Path;

/// One appended data array: its XML attributes and little-endian bytes.
struct Array {
    attrs: String,
    bytes: Vec<u8>,
}

fn f64s(values: impl Iterator<Item = f64>) -> Vec<u8> {
    values.flat_map(f64::to_le_bytes).collect()
}

/// The particle arrays' attributes (all but plastic strain), in the order written.
const PARTICLE_ARRAYS: [&str; 5] = [
    r#"type="Float64" Name="velocity" NumberOfComponents="3""#,
    r#"type="Float64" Name="displacement" NumberOfComponents="3""#,
    r#"type="Float64" Name="stress" NumberOfComponents="6""#,
    r#"type="Float64" Name="mass" NumberOfComponents="1""#,
    r#"type="Int32" Name="material" NumberOfComponents="1""#,
];
/// The equivalent plastic strain's attributes (plastic scenes only).
const PLASTIC_ARRAY: &str = r#"type="Float64" Name="plastic_strain" NumberOfComponents="1""#;
/// The particles' point attributes.
const POINTS: &str = r#"type="Float64" Name="Points" NumberOfComponents="3""#;
/// What ParaView shows first.
const ACTIVE: &str = r#"Vectors="velocity" Tensors="stress""#;

/// Writes the particles as vertex cells to `path` with velocity, displacement, stress
/// (ParaView's symmetric-tensor order xx, yy, zz, xy, yz, xz), mass and material, and in a
/// plastic scene the equivalent plastic strain.
pub fn write_particles<D: Dim>(path: &Path, p: &Particles<D>) -> std::io::Result<()> {
    let n = p.len();
    let vec3 = |c: &[D::Vec]| f64s(c.iter().flat_map(|v| D::to_xyz(*v)));
    let bytes = [
        vec3(&p.v),
        f64s((0..n).flat_map(|i| D::to_xyz(p.displacement(i)))),
        f64s(
            p.stress
                .iter()
                .map(|s| s.to_sym3())
                .flat_map(|s| [s.xx, s.yy, s.zz, s.xy, s.yz, s.xz]),
        ),
        f64s(p.mass.iter().copied()),
        (p.material.iter())
            .flat_map(|&m| (m as i32).to_le_bytes())
            .collect(),
    ];
    let mut point_data: Vec<Array> = (PARTICLE_ARRAYS.iter().zip(bytes))
        .map(|(a, bytes)| Array {
            attrs: (*a).into(),
            bytes,
        })
        .collect();
    if !p.hardened.is_empty() {
        point_data.push(Array {
            attrs: PLASTIC_ARRAY.into(),
            bytes: f64s(p.hardened.iter().map(|h| h.equivalent)),
        });
    }
    let points = Array {
        attrs: POINTS.into(),
        bytes: vec3(&p.x),
    };
    let cells = [
        (0..n as i64).flat_map(i64::to_le_bytes).collect(),
        (1..=n as i64).flat_map(i64::to_le_bytes).collect(),
        vec![1u8; n],
    ];
    write_unstructured(path, (n, n), ACTIVE, &point_data, points, cells)
}

/// Writes the cracks of `c` as line cells (2D) or triangle cells (3D): the crack-plane
/// vertices joined by the crack elements, with the opening (top minus bottom surface, m),
/// the crack index and K (Pa sqrt(m)) of `tips`, the latest measurement, at the tip and
/// front vertices (NaN elsewhere).
pub fn write_cracks<D: Dim>(path: &Path, c: &Cracks<D>, tips: &[TipResult]) -> std::io::Result<()> {
    let n = c.geometry.x.len();
    let topo = &c.topology;
    // K at the tip (2D) and front (3D) vertices from the latest measurement, NaN elsewhere.
    let mut k = vec![[f64::NAN; 3]; n];
    let mut ordinal = vec![0u32; topo.cracks().len()];
    for f in topo.fronts() {
        for &v in &f.vertices {
            let tip = if D::D == 2 {
                f.end
            } else {
                ordinal[f.crack as usize]
            };
            ordinal[f.crack as usize] += 1;
            if let Some(t) = tips
                .iter()
                .find(|t| (t.crack, t.tip) == (u32::from(f.crack), tip))
            {
                k[v as usize] = t.k;
            }
        }
    }
    let m = topo.elems().len();
    let per = <D::Elem as Element>::VERTICES;
    // VTK_LINE and VTK_TRIANGLE.
    let kind = if per == 2 { 3u8 } else { 5u8 };
    let opening = f64s((0..n).flat_map(|k| D::to_xyz(c.geometry.top[k] - c.geometry.bottom[k])));
    let mut crack = vec![0i32; n];
    for (k, cr) in topo.cracks().iter().enumerate() {
        for &v in &cr.vertices {
            crack[v as usize] = k as i32;
        }
    }
    let point_data = vec![
        Array {
            attrs: r#"type="Float64" Name="opening" NumberOfComponents="3""#.into(),
            bytes: opening,
        },
        Array {
            attrs: r#"type="Int32" Name="crack" NumberOfComponents="1""#.into(),
            bytes: crack.iter().flat_map(|k| k.to_le_bytes()).collect(),
        },
        Array {
            attrs: r#"type="Float64" Name="K" NumberOfComponents="3""#.into(),
            bytes: f64s(k.into_iter().flatten()),
        },
    ];
    let points = Array {
        attrs: r#"type="Float64" Name="Points" NumberOfComponents="3""#.into(),
        bytes: f64s(c.geometry.x.iter().flat_map(|v| D::to_xyz(*v))),
    };
    let cells = [
        topo.elems()
            .iter()
            .flat_map(|e| e.vertices().iter().map(|&v| v as i64))
            .flat_map(i64::to_le_bytes)
            .collect(),
        (1..=m as i64)
            .flat_map(|k| (per as i64 * k).to_le_bytes())
            .collect(),
        vec![kind; m],
    ];
    write_unstructured(
        path,
        (n, m),
        r#"Vectors="opening""#,
        &point_data,
        points,
        cells,
    )
}

/// Writes an unstructured grid of `counts` = (points, cells) with appended raw arrays:
/// point data, the points, and the cells' connectivity (Int64), offsets (Int64) and
/// types (UInt8).
fn write_unstructured(
    path: &Path,
    (points_n, cells_n): (usize, usize),
    active: &str,
    point_data: &[Array],
    points: Array,
    [connectivity, offsets, types]: [Vec<u8>; 3],
) -> std::io::Result<()> {
    let cells = [
        Array {
            attrs: r#"type="Int64" Name="connectivity""#.into(),
            bytes: connectivity,
        },
        Array {
            attrs: r#"type="Int64" Name="offsets""#.into(),
            bytes: offsets,
        },
        Array {
            attrs: r#"type="UInt8" Name="types""#.into(),
            bytes: types,
        },
    ];
    let mut offset = 0usize;
    let mut tag = |a: &Array| {
        let s = format!(
            r#"<DataArray {} format="appended" offset="{offset}"/>"#,
            a.attrs
        );
        offset += 8 + a.bytes.len();
        s
    };
    let mut xml = String::new();
    xml.push_str("<?xml version=\"1.0\"?>\n");
    xml.push_str("<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n");
    xml.push_str("<UnstructuredGrid>\n");
    xml.push_str(&format!(
        "<Piece NumberOfPoints=\"{points_n}\" NumberOfCells=\"{cells_n}\">\n<PointData {active}>\n"
    ));
    for a in point_data {
        xml.push_str(&tag(a));
        xml.push('\n');
    }
    xml.push_str("</PointData>\n<Points>\n");
    xml.push_str(&tag(&points));
    xml.push_str("\n</Points>\n<Cells>\n");
    for a in &cells {
        xml.push_str(&tag(a));
        xml.push('\n');
    }
    xml.push_str("</Cells>\n</Piece>\n</UnstructuredGrid>\n<AppendedData encoding=\"raw\">\n_");
    let mut f = std::io::BufWriter::new(std::fs::File::create(path)?);
    f.write_all(xml.as_bytes())?;
    for a in point_data.iter().chain([&points]).chain(&cells) {
        f.write_all(&(a.bytes.len() as u64).to_le_bytes())?;
        f.write_all(&a.bytes)?;
    }
    f.write_all(b"\n</AppendedData>\n</VTKFile>\n")?;
    f.flush()
}

/// Writes a `.pvtu` file joining the particle pieces `pieces` (one `.vtu` per MPI rank, as
/// [`write_particles`] writes them; `plastic` when they carry the plastic strain).
pub fn write_particle_pieces(path: &Path, pieces: &[String], plastic: bool) -> std::io::Result<()> {
    let mut s = String::from(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"PUnstructuredGrid\" version=\"1.0\" \
         byte_order=\"LittleEndian\" header_type=\"UInt64\">\n<PUnstructuredGrid GhostLevel=\"0\">\n",
    );
    s.push_str(&format!("<PPointData {ACTIVE}>\n"));
    let plastic = plastic.then_some(PLASTIC_ARRAY);
    for a in PARTICLE_ARRAYS.iter().chain(plastic.as_ref()) {
        s.push_str(&format!("<PDataArray {a}/>\n"));
    }
    s.push_str(&format!(
        "</PPointData>\n<PPoints>\n<PDataArray {POINTS}/>\n</PPoints>\n"
    ));
    s.push_str("<PCells>\n<PDataArray type=\"Int64\" Name=\"connectivity\"/>\n");
    s.push_str("<PDataArray type=\"Int64\" Name=\"offsets\"/>\n");
    s.push_str("<PDataArray type=\"UInt8\" Name=\"types\"/>\n</PCells>\n");
    for p in pieces {
        s.push_str(&format!("<Piece Source=\"{p}\"/>\n"));
    }
    s.push_str("</PUnstructuredGrid>\n</VTKFile>\n");
    std::fs::write(path, s)
}

/// Writes a `.pvd` collection of `(time, file name)` frames.
pub fn write_collection(path: &Path, frames: &[(f64, String)]) -> std::io::Result<()> {
    let mut s = String::from(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n<Collection>\n",
    );
    for (t, file) in frames {
        s.push_str(&format!(
            "<DataSet timestep=\"{t:.9e}\" group=\"\" part=\"0\" file=\"{file}\"/>\n"
        ));
    }
    s.push_str("</Collection>\n</VTKFile>\n");
    std::fs::write(path, s)
}
