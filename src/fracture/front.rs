//! The local frame at each vertex of a 3D crack front (Guo & Nairn 3D (2006) Eqs. 24-31):
//! x2 normal to the crack surface (towards its top face), x3 along the front, and
//! x1 = x2 x x3 in the surface, pointing away from the crack: the direction it would extend
//! in.

use crate::base::dim::D3;
use crate::store::crack::{Cracks, Front};
use glam::{DMat3, DVec3};
use std::collections::HashMap;

/// One front vertex with its frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrontFrame {
    /// The vertex's index in the crack store.
    pub vertex: u32,
    /// Its position (m).
    pub x: DVec3,
    /// The local axes x1 (extension), x2 (surface normal) and x3 (along the front), unit and
    /// right-handed: the rows of the rotation into front axes (Eq. 31).
    pub e: [DVec3; 3],
}

impl FrontFrame {
    /// Components of the global vector `v` in front axes (Eq. 28).
    pub fn local(&self, v: DVec3) -> DVec3 {
        to_local(&self.e, v)
    }

    /// The global tensor `m` in front axes (Eqs. 29-30).
    pub fn local_tensor(&self, m: &DMat3) -> DMat3 {
        tensor_to_local(&self.e, m)
    }
}

/// Components of the global vector `v` along the unit axes `e`.
pub fn to_local(e: &[DVec3; 3], v: DVec3) -> DVec3 {
    DVec3::new(e[0].dot(v), e[1].dot(v), e[2].dot(v))
}

/// The global tensor `m` in the unit axes `e`: entry (a, b) is e_a . (m e_b).
pub fn tensor_to_local(e: &[DVec3; 3], m: &DMat3) -> DMat3 {
    let column = |b: DVec3| to_local(e, *m * b);
    DMat3::from_cols(column(e[0]), column(e[1]), column(e[2]))
}

/// The frames at the vertices of a front, in its order, and whether the front is closed.
#[derive(Clone, Debug)]
pub struct FrontLine {
    /// One frame per front vertex.
    pub frames: Vec<FrontFrame>,
    /// Whether the last vertex joins the first.
    pub closed: bool,
}

/// The frames at the vertices of `front`, in its order. The normal at a vertex is the
/// area-weighted mean of its crack's triangles around it, the front direction the chord
/// between its neighbours along the front (one-sided at the ends of an open front; a front
/// is closed when its two ends share a triangle edge). A vertex whose frame is degenerate
/// (no triangle, or the front folding back on itself) gets NaN axes.
pub fn front_line(cracks: &Cracks<D3>, front: &Front) -> FrontLine {
    let topo = &cracks.topology;
    let x = &cracks.geometry.x;
    let fv = &front.vertices;
    let ordinal: HashMap<u32, usize> = fv.iter().enumerate().map(|(k, &v)| (v, k)).collect();
    // Per front vertex: the summed area normals and the summed centroids of its triangles.
    let mut normal = vec![DVec3::ZERO; fv.len()];
    let mut centroid = vec![(DVec3::ZERO, 0.0); fv.len()];
    for (e, &c) in topo.elems().iter().zip(topo.elem_crack()) {
        if c != front.crack {
            continue;
        }
        let [a, b, d] = e.map(|k| x[k as usize]);
        let area_normal = 0.5 * (b - a).cross(d - a);
        for k in e {
            if let Some(&o) = ordinal.get(k) {
                normal[o] += area_normal;
                centroid[o].0 += (a + b + d) / 3.0;
                centroid[o].1 += 1.0;
            }
        }
    }
    let closed = topo.is_closed(front);
    let n = fv.len();
    let frames = (0..n)
        .map(|k| {
            let at = |o: usize| x[fv[o] as usize];
            let (prev, next) = match (k, closed) {
                (0, true) => (at(n - 1), at(1 % n)),
                (_, true) if k == n - 1 => (at(k - 1), at(0)),
                (0, false) => (at(0), at(1.min(n - 1))),
                (_, false) if k == n - 1 => (at(k - 1), at(k)),
                _ => (at(k - 1), at(k + 1)),
            };
            let t = (next - prev).normalize();
            let e2 = (normal[k] - normal[k].dot(t) * t).normalize();
            let mut e1 = t.cross(e2);
            let behind = centroid[k].0 / centroid[k].1;
            if e1.dot(at(k) - behind) < 0.0 {
                e1 = -e1;
            }
            FrontFrame {
                vertex: fv[k],
                x: at(k),
                e: [e1, e2, e1.cross(e2)],
            }
        })
        .collect();
    FrontLine { frames, closed }
}
