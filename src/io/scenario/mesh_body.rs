//! `body.mesh`: a body bounded by the closed surface in an STL file, read with `stl_io`,
//! placed by its scale and offset, and checked (closed, consistently oriented, nothing
//! degenerate) with the file and the triangle named in every error.

use super::schema::MeshBodySpec;
use super::source::Source;
use crate::base::error::ScenarioError;
use crate::base::geometry::ClosedSurface;
use crate::physics::bodies::Solid;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Largest mesh file read (bytes): 1 GiB, some 20 million binary triangles.
const MAX_BYTES: u64 = 1 << 30;

/// The solid bounded by the surface `spec` names.
pub(super) fn solid(src: &Source, key: &str, spec: &MeshBodySpec) -> Result<Solid, ScenarioError> {
    let scale = spec.scale.unwrap_or(1.0);
    if !(scale.is_finite() && scale > 0.0) {
        return Err(src.error(&format!("{key}.scale"), "give a finite factor > 0"));
    }
    let translate = match &spec.translate {
        None => [0.0; 3],
        Some(t) if t.len() == 3 && t.iter().all(|c| c.is_finite()) => [t[0], t[1], t[2]],
        Some(_) => {
            return Err(src.error(&format!("{key}.translate"), "give [x, y, z] in m, finite"));
        }
    };
    let path = resolve(src, &spec.file);
    let name = path.display().to_string();
    let refuse = |message: String| src.error(&format!("{key}.file"), format!("{name}: {message}"));
    if path
        .extension()
        .is_none_or(|e| !e.eq_ignore_ascii_case("stl"))
    {
        return Err(refuse(
            "not an .stl file: bodies are read from STL (ASCII or binary) so far".into(),
        ));
    }
    let meta = std::fs::metadata(&path).map_err(|e| refuse(format!("cannot read it: {e}")))?;
    if !meta.is_file() {
        return Err(refuse("not a regular file".into()));
    }
    if meta.len() > MAX_BYTES {
        return Err(refuse(format!(
            "{} bytes, over the {MAX_BYTES}-byte limit for a mesh file",
            meta.len()
        )));
    }
    let mut file =
        std::fs::File::open(&path).map_err(|e| refuse(format!("cannot open it: {e}")))?;
    let reader = stl_io::create_stl_reader(&mut file)
        .map_err(|e| refuse(format!("not a readable STL file: {e}")))?;
    let (mut vertices, mut triangles) = (Vec::new(), Vec::new());
    let mut index: HashMap<[u32; 3], u32> = HashMap::new();
    for (t, tri) in reader.enumerate() {
        let tri = tri.map_err(|e| refuse(format!("triangle {t}: {e}")))?;
        if tri
            .vertices
            .iter()
            .any(|v| v.0.iter().any(|c| !c.is_finite()))
        {
            return Err(refuse(format!("triangle {t}: a coordinate is not finite")));
        }
        let corners = tri.vertices.map(|v| {
            // -0.0 and 0.0 are one coordinate.
            let key = v.0.map(|c| (c + 0.0).to_bits());
            *index.entry(key).or_insert_with(|| {
                vertices.push(std::array::from_fn(|a| {
                    f64::from(v.0[a]) * scale + translate[a]
                }));
                (vertices.len() - 1) as u32
            })
        });
        triangles.push(corners);
    }
    let surface = ClosedSurface::new(vertices, triangles).map_err(|d| refuse(d.to_string()))?;
    Ok(Solid::Mesh(Arc::new(surface)))
}

/// `file` taken relative to the scenario file's folder (as given when absolute).
fn resolve(src: &Source, file: &str) -> PathBuf {
    let given = Path::new(file);
    match Path::new(&src.file).parent() {
        Some(dir) if given.is_relative() => dir.join(given),
        _ => given.to_path_buf(),
    }
}
