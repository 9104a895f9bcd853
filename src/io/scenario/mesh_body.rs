//! Surfaces read from files: `body.mesh`, a body bounded by the closed surface in an STL
//! file (read with `stl_io`), an OBJ file (`tobj`) or a Gmsh MSH file (`mshio`, see
//! [`super::msh`]), and `crack.mesh_file`, a crack surface from any of them; each placed by
//! its scale, rotation and offset, with the file and the triangle named in every error.

use super::schema::{MeshBodySpec, RotateSpec};
use super::source::Source;
use crate::base::dim::D3;
use crate::base::error::ScenarioError;
use crate::base::geometry::{ClosedSurface, Element, Triangle, TriangleList};
use crate::physics::bodies::Solid;
use glam::{DMat3, DVec3};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

type R<T> = Result<T, ScenarioError>;

/// Largest mesh file read (bytes): 1 GiB, some 20 million binary triangles.
const MAX_BYTES: u64 = 1 << 30;

/// How close (a fraction of the surface's size) two triangles sharing no vertex may come
/// before the surface is taken to meet itself.
const SELF_MEET: f64 = 1e-9;

/// The solid bounded by the surface `spec` names (checked closed and oriented one way).
pub(super) fn solid(src: &Source, key: &str, spec: &MeshBodySpec) -> R<Solid> {
    let place = placement(src, key, spec.scale, spec.rotate.as_ref(), &spec.translate)?;
    let (path, refuse) = file(src, key, &spec.file)?;
    let (unique, triangles) = read(&path).map_err(&refuse)?;
    let points: Vec<DVec3> = unique.into_iter().map(place).collect();
    let vertices = points.iter().map(|v| v.to_array()).collect();
    let surface =
        ClosedSurface::new(vertices, triangles.clone()).map_err(|d| refuse(d.to_string()))?;
    let elems: Vec<Triangle> = triangles
        .iter()
        .map(|t| Triangle::from_vertices(t))
        .collect();
    let (lo, hi) = surface.bounds();
    let tol = SELF_MEET * DVec3::from(hi).distance(DVec3::from(lo));
    if let Some((a, b)) = super::crack_meet::self_meets::<D3>(&points, &elems, tol) {
        return Err(refuse(format!(
            "the surface meets itself: triangles {a} and {b}, which share no vertex, cross \
             or touch"
        )));
    }
    Ok(Solid::Mesh(Arc::new(surface)))
}

/// The triangles of the STL or OBJ file at `path` (by its extension), every coordinate
/// finite, corners at one place one vertex.
pub(super) fn read(path: &Path) -> Result<TriangleList, String> {
    let (positions, triangles) = match extension(path).as_str() {
        "stl" => read_stl(path),
        "obj" => read_obj(path),
        "msh" => super::msh::read_msh(path),
        _ => Err(
            "not an .stl, .obj or .msh file: surfaces are read from STL (ASCII or \
                  binary), OBJ and Gmsh MSH 4.1 files"
                .into(),
        ),
    }?;
    finite(&positions, &triangles)?;
    Ok(merge(&positions, &triangles))
}

/// Corners at the same place are one vertex (-0.0 and 0.0 too), numbered in order of
/// first use.
fn merge(positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> TriangleList {
    let (mut unique, mut index) = (Vec::new(), HashMap::new());
    let triangles = (triangles.iter())
        .map(|tri| {
            tri.map(|i| {
                let v = positions[i as usize];
                *index
                    .entry(v.map(|c| (c + 0.0).to_bits()))
                    .or_insert_with(|| {
                        unique.push(v);
                        (unique.len() - 1) as u32
                    })
            })
        })
        .collect();
    (unique, triangles)
}

/// x = R (scale x_file) + translate, from the keys under `key`.
pub(super) fn placement(
    src: &Source,
    key: &str,
    scale: Option<f64>,
    rotate: Option<&RotateSpec>,
    translate: &Option<Vec<f64>>,
) -> R<impl Fn([f64; 3]) -> DVec3 + use<>> {
    let scale = scale.unwrap_or(1.0);
    if !(scale.is_finite() && scale > 0.0) {
        return Err(src.error(&format!("{key}.scale"), "give a finite factor > 0"));
    }
    let translate = match translate {
        None => DVec3::ZERO,
        Some(t) if t.len() == 3 && t.iter().all(|c| c.is_finite()) => DVec3::new(t[0], t[1], t[2]),
        Some(_) => {
            return Err(src.error(&format!("{key}.translate"), "give [x, y, z] in m, finite"));
        }
    };
    let rotation = match rotate {
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
    Ok(move |v: [f64; 3]| rotation * DVec3::from_array(v.map(|c| c * scale)) + translate)
}

/// The path of `name` (relative to the scenario file's folder), checked to be a regular
/// file of at most [`MAX_BYTES`], and how to refuse it, naming the key and the file.
pub(super) fn file<'a>(
    src: &'a Source,
    key: &str,
    name: &str,
) -> R<(PathBuf, impl Fn(String) -> ScenarioError + use<'a>)> {
    let given = Path::new(name);
    let path = match Path::new(&src.file).parent() {
        Some(dir) if given.is_relative() => dir.join(given),
        _ => given.to_path_buf(),
    };
    let shown = path.display().to_string();
    let file_key = format!("{key}.file");
    let refuse = move |message: String| src.error(&file_key, format!("{shown}: {message}"));
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
    Ok((path, refuse))
}

fn extension(path: &Path) -> String {
    (path.extension().and_then(|e| e.to_str()))
        .unwrap_or("")
        .to_ascii_lowercase()
}

/// Refuses a triangle with a corner that is not finite, naming it.
fn finite(positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> Result<(), String> {
    let bad = |i: &u32| positions[*i as usize].iter().any(|c| !c.is_finite());
    match triangles.iter().position(|t| t.iter().any(bad)) {
        Some(t) => Err(format!("triangle {t}: a coordinate is not finite")),
        None => Ok(()),
    }
}

/// The triangles of an STL file (ASCII or binary), three corners each in file order.
fn read_stl(path: &Path) -> Result<TriangleList, String> {
    let mut file = std::fs::File::open(path).map_err(|e| format!("cannot open it: {e}"))?;
    let reader = stl_io::create_stl_reader(&mut file)
        .map_err(|e| format!("not a readable STL file: {e}"))?;
    let (mut positions, mut triangles) = (Vec::new(), Vec::new());
    for (t, tri) in reader.enumerate() {
        let tri = tri.map_err(|e| format!("triangle {t}: {e}"))?;
        let first = positions.len() as u32;
        positions.extend(tri.vertices.map(|v| v.0.map(f64::from)));
        triangles.push([first, first + 1, first + 2]);
    }
    Ok((positions, triangles))
}

/// The vertices of an OBJ file in its order, all its objects together, and its faces split
/// into triangles (`tobj`; materials, points and lines are ignored).
fn read_obj(path: &Path) -> Result<TriangleList, String> {
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
    let (mut positions, mut triangles) = (Vec::new(), Vec::new());
    for m in &models {
        let first = positions.len() as u32;
        let count = (m.mesh.positions.len() / 3) as u32;
        positions.extend(m.mesh.positions.chunks_exact(3).map(|c| [c[0], c[1], c[2]]));
        for (k, f) in m.mesh.indices.chunks_exact(3).enumerate() {
            if f.iter().any(|&i| i >= count) {
                return Err(format!(
                    "object `{}`, face {k}: a vertex index past the end",
                    m.name
                ));
            }
            triangles.push([f[0] + first, f[1] + first, f[2] + first]);
        }
    }
    Ok((positions, triangles))
}
