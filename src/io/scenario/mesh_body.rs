//! `body.mesh`: a body bounded by the closed surface in an STL file (read with `stl_io`) or
//! an OBJ file (`tobj`), placed by its scale, rotation and offset, and checked (closed,
//! consistently oriented, nothing degenerate) with the file and the triangle named in
//! every error.

use super::schema::MeshBodySpec;
use super::source::Source;
use crate::base::error::ScenarioError;
use crate::base::geometry::ClosedSurface;
use crate::physics::bodies::Solid;
use glam::{DMat3, DVec3};
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
    let rotation = match &spec.rotate {
        None => DMat3::IDENTITY,
        Some(r) => {
            let axis = (r.axis.len() == 3 && r.axis.iter().all(|c| c.is_finite()))
                .then(|| DVec3::new(r.axis[0], r.axis[1], r.axis[2]))
                .filter(|a| a.length() > 0.0);
            match axis {
                Some(a) if r.angle.is_finite() => {
                    DMat3::from_axis_angle(a.normalize(), r.angle.to_radians())
                }
                _ => {
                    return Err(src.error(
                        &format!("{key}.rotate"),
                        "give { axis = [x, y, z] (not zero), angle = <degrees> }, finite",
                    ));
                }
            }
        }
    };
    let path = resolve(src, &spec.file);
    let name = path.display().to_string();
    let refuse = |message: String| src.error(&format!("{key}.file"), format!("{name}: {message}"));
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
    let ext = (path.extension().and_then(|e| e.to_str()))
        .unwrap_or("")
        .to_ascii_lowercase();
    let soup = match ext.as_str() {
        "stl" => read_stl(&path),
        "obj" => read_obj(&path),
        _ => Err(
            "not an .stl or .obj file: bodies are read from STL (ASCII or binary) and \
                  OBJ so far"
                .into(),
        ),
    }
    .map_err(refuse)?;
    if let Some(t) = soup
        .iter()
        .position(|t| t.iter().flatten().any(|c| !c.is_finite()))
    {
        return Err(refuse(format!("triangle {t}: a coordinate is not finite")));
    }
    // Corners at the same place in the file are one vertex (-0.0 and 0.0 too).
    let (mut vertices, mut index) = (Vec::new(), HashMap::new());
    let place = |v: [f32; 3]| {
        let x = rotation * DVec3::from_array(v.map(|c| f64::from(c) * scale));
        (x + DVec3::from_array(translate)).to_array()
    };
    let triangles = (soup.iter())
        .map(|tri| {
            tri.map(|v| {
                let key = v.map(|c| (c + 0.0).to_bits());
                *index.entry(key).or_insert_with(|| {
                    vertices.push(place(v));
                    (vertices.len() - 1) as u32
                })
            })
        })
        .collect();
    let surface = ClosedSurface::new(vertices, triangles).map_err(|d| refuse(d.to_string()))?;
    Ok(Solid::Mesh(Arc::new(surface)))
}

/// The triangles of an STL file (ASCII or binary), corner by corner.
fn read_stl(path: &Path) -> Result<Vec<[[f32; 3]; 3]>, String> {
    let mut file = std::fs::File::open(path).map_err(|e| format!("cannot open it: {e}"))?;
    let reader = stl_io::create_stl_reader(&mut file)
        .map_err(|e| format!("not a readable STL file: {e}"))?;
    (reader.enumerate())
        .map(|(t, tri)| {
            tri.map(|tri| tri.vertices.map(|v| v.0))
                .map_err(|e| format!("triangle {t}: {e}"))
        })
        .collect()
}

/// The faces of an OBJ file, split into triangles (`tobj`; materials, points and lines
/// are ignored), corner by corner, all its objects together.
fn read_obj(path: &Path) -> Result<Vec<[[f32; 3]; 3]>, String> {
    let file = std::fs::File::open(path).map_err(|e| format!("cannot open it: {e}"))?;
    let options = tobj::LoadOptions {
        triangulate: true,
        ignore_points: true,
        ignore_lines: true,
        ..Default::default()
    };
    let (models, _) = tobj::load_obj_buf(&mut std::io::BufReader::new(file), &options, |_| {
        Err(tobj::LoadError::OpenFileFailed)
    })
    .map_err(|e| format!("not a readable OBJ file: {e}"))?;
    let mut out = Vec::new();
    for m in &models {
        let p = &m.mesh.positions;
        let corner = |i: u32| -> Option<[f32; 3]> {
            let i = 3 * i as usize;
            p.get(i..i + 3).map(|c| [c[0], c[1], c[2]])
        };
        for (k, f) in m.mesh.indices.chunks(3).enumerate() {
            let tri = [f[0], f[1], f[2]].map(corner);
            match tri {
                [Some(a), Some(b), Some(c)] => out.push([a, b, c]),
                _ => {
                    return Err(format!(
                        "object `{}`, face {k}: a vertex index past the end",
                        m.name
                    ));
                }
            }
        }
    }
    Ok(out)
}

/// `file` taken relative to the scenario file's folder (as given when absolute).
fn resolve(src: &Source, file: &str) -> PathBuf {
    let given = Path::new(file);
    match Path::new(&src.file).parent() {
        Some(dir) if given.is_relative() => dir.join(given),
        _ => given.to_path_buf(),
    }
}
