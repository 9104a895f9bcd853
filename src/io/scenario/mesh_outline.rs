//! `body.mesh` in 2D: the region a flat triangle mesh covers (an STL, OBJ or Gmsh MSH
//! file of a face, triangles or quadrangles), bounded by the edges that only one triangle
//! has, holes included. Placed by its scale, rotation and offset; it must then lie in one
//! plane z = const. The file, and the triangles or edges at fault, are named in every
//! error.

use super::crack_meet::self_meets;
use super::mesh_body::{file, placement, read};
use super::schema::MeshBodySpec;
use super::source::Source;
use crate::base::dim::D2;
use crate::base::error::ScenarioError;
use crate::base::geometry::{Element, Outline, Segment};
use crate::physics::bodies::Solid;
use glam::{DVec2, DVec3};
use std::collections::HashMap;
use std::sync::Arc;

type R<T> = Result<T, ScenarioError>;

/// How far from one plane (a fraction of the mesh's size) a vertex may lie.
const FLAT: f64 = 1e-9;

/// How close (a fraction of the mesh's size) two boundary edges sharing no vertex may come
/// before the outline is taken to meet itself.
const SELF_MEET: f64 = 1e-9;

/// The 2D region the flat mesh `spec` names covers.
pub(super) fn outline(src: &Source, key: &str, spec: &MeshBodySpec) -> R<Solid> {
    let translate = match &spec.translate {
        None => None,
        Some(t) if t.len() == 2 => Some(vec![t[0], t[1], 0.0]),
        Some(_) => {
            return Err(src.error(&format!("{key}.translate"), "give [x, y] in m, finite"));
        }
    };
    let place = placement(src, key, spec.scale, spec.rotate.as_ref(), &translate)?;
    let (path, refuse) = file(src, key, &spec.file)?;
    let (unique, triangles) = read(&path).map_err(&refuse)?;
    let points: Vec<DVec3> = unique.into_iter().map(place).collect();
    let (lo, hi) = points
        .iter()
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &p| {
            (lo.min(p), hi.max(p))
        });
    let size = hi.distance(lo);
    if triangles.is_empty() || size == 0.0 {
        return Err(refuse("no triangle with an area: not a face".into()));
    }
    if hi.z - lo.z > FLAT * size {
        return Err(refuse(format!(
            "a 2D body's mesh must lie in one plane z = const (as placed, after any `rotate`): \
             its z spans {:e} to {:e} m",
            lo.z, hi.z
        )));
    }
    let flat: Vec<DVec2> = points.iter().map(|p| p.truncate()).collect();
    let edges = boundary(&flat, &triangles, size).map_err(&refuse)?;
    let segments: Vec<Segment> = edges.iter().map(|e| Segment::from_vertices(e)).collect();
    if let Some((a, b)) = self_meets::<D2>(&flat, &segments, SELF_MEET * size) {
        let [a, b] = [a, b].map(|k| edges[k].map(|v| flat[v as usize].to_array()));
        return Err(refuse(format!(
            "the outline meets itself: its edges {:?} to {:?} and {:?} to {:?} m, which share \
             no vertex, cross or touch",
            a[0], a[1], b[0], b[1]
        )));
    }
    let ends = |e: &[u32; 2]| e.map(|v| flat[v as usize].to_array());
    Ok(Solid::Outline(Arc::new(Outline::new(
        edges.iter().map(ends).collect(),
    ))))
}

/// The edges that one triangle alone has, as vertex pairs in order of first use. Refuses a
/// triangle without area, an edge three triangles share, and two triangles that fold over
/// their shared edge (both on one side of it).
fn boundary(points: &[DVec2], triangles: &[[u32; 3]], size: f64) -> Result<Vec<[u32; 2]>, String> {
    // Per undirected edge: the triangles that have it, and the direction the first of them
    // runs along it when turned counterclockwise.
    let mut seen: HashMap<[u32; 2], (u32, u32, bool)> = HashMap::new();
    let mut order: Vec<[u32; 2]> = Vec::new();
    for (t, tri) in triangles.iter().enumerate() {
        let [a, b, c] = tri.map(|v| points[v as usize]);
        let twice = (b - a).perp_dot(c - a);
        if twice.abs() <= f64::EPSILON * size * size {
            return Err(format!("triangle {t} has no area"));
        }
        let turned = if twice > 0.0 {
            *tri
        } else {
            [tri[0], tri[2], tri[1]]
        };
        for k in 0..3 {
            let (u, v) = (turned[k], turned[(k + 1) % 3]);
            let key = [u.min(v), u.max(v)];
            match seen.get_mut(&key) {
                None => {
                    seen.insert(key, (1, t as u32, u < v));
                    order.push(key);
                }
                Some((count, first, forward)) => {
                    let at = || key.map(|v| points[v as usize].to_array());
                    if *count == 2 {
                        return Err(format!(
                            "three or more triangles (the first {first}, the third {t}) share \
                             the edge from {:?} to {:?} m: not a face",
                            at()[0],
                            at()[1]
                        ));
                    }
                    if *forward == (u < v) {
                        return Err(format!(
                            "triangles {first} and {t} fold over their shared edge from {:?} to \
                             {:?} m (both lie on one side of it): the mesh overlaps itself",
                            at()[0],
                            at()[1]
                        ));
                    }
                    *count = 2;
                }
            }
        }
    }
    Ok(order.into_iter().filter(|e| seen[e].0 == 1).collect())
}
