//! Crack elements: a segment of two vertices in 2D, a triangle of three in 3D, with the
//! exact predicates classification, contact and the crack checks ask of them. Each
//! element type fixes its vector type, so code written for one shape of element does not
//! compile for the other.

use super::{Aabb, Point, point_segment, point_segment_sq, point_triangle, segment_segment};
use glam::{DVec2, DVec3};
use std::fmt::Debug;

/// A crack element: a fixed number of vertex indices into a vertex list, and the
/// geometric predicates on the element those vertices span.
pub trait Element: Copy + Debug + PartialEq + Send + Sync + 'static {
    /// The vertices' vector type.
    type Vec: Point;
    /// Vertices per element.
    const VERTICES: usize;
    /// Boundary features per element: end points of a segment, edges of a triangle.
    const FEATURES: usize;
    /// Whether a line through a feature shared by two elements crosses exactly one of them
    /// under [`Element::crossing`]'s tie rule (2D vertices: the orientation tie rule; 3D
    /// edges: the perturbation of `edge_side`), so that `classify` may treat the feature
    /// as interior.
    const SHARED_FEATURE_SAFE: bool;

    /// The element's vertex indices.
    fn vertices(&self) -> &[u32];
    /// The element of these vertices (exactly [`Element::VERTICES`] of them).
    fn from_vertices(v: &[u32]) -> Self;
    /// Vertex indices of boundary feature `k` (a segment's end point twice, a triangle's
    /// edge from vertex k to k + 1).
    fn feature(&self, k: usize) -> [u32; 2];

    /// Whether the line from `p` to `q` crosses the element of vertices `v` (2D: the
    /// segment `e[0]`-`e[1]`; 3D: the triangle `e[0]`, `e[1]`, `e[2]`): +1 if `p` is above
    /// it (left of the segment's direction; on the side of the triangle's counterclockwise
    /// normal), -1 if below, 0 if there is no crossing. Exact orientation predicates
    /// (Shewchuk's, from `robust`); a point exactly on the crack line or plane counts as
    /// above, so a line through a vertex shared by two segments crosses exactly one of them.
    fn crossing(&self, p: Self::Vec, q: Self::Vec, v: &[Self::Vec]) -> i8 {
        self.crossing_from(p, self.side(p, v), q, v)
    }
    /// [`Element::crossing`] given `sp`, the [`Element::side`] of `p` (a particle tested
    /// against every node of its stencil computes it once).
    fn crossing_from(&self, p: Self::Vec, sp: i8, q: Self::Vec, v: &[Self::Vec]) -> i8;
    /// Side of the element's line (2D) or plane (3D) that `x` lies on: +1 above or on it,
    /// -1 below; the first test of [`Element::crossing`].
    fn side(&self, x: Self::Vec, v: &[Self::Vec]) -> i8;
    /// Squared distance from `x` to the element (m^2).
    fn distance_sq(&self, x: Self::Vec, v: &[Self::Vec]) -> f64;
    /// Distance from `x` to the element (m).
    fn distance(&self, x: Self::Vec, v: &[Self::Vec]) -> f64 {
        self.distance_sq(x, v).sqrt()
    }
    /// Distance from `x` to the element's line (2D) or plane (3D) (m).
    fn plane_distance(&self, x: Self::Vec, v: &[Self::Vec]) -> f64;
    /// Unit normal, pointing above the element (left of a segment's direction; along a
    /// counterclockwise triangle's normal).
    fn normal(&self, v: &[Self::Vec]) -> Self::Vec;
    /// Distance from feature `k` of the element to the segment `p`-`q` (m).
    fn feature_distance(&self, p: Self::Vec, q: Self::Vec, v: &[Self::Vec], k: usize) -> f64;
    /// The element's axis-aligned box.
    fn bounds(&self, v: &[Self::Vec]) -> Aabb<Self::Vec> {
        let [first, rest @ ..] = self.vertices() else {
            unreachable!("an element has vertices")
        };
        (rest.iter()).fold(Aabb::at(v[*first as usize]), |b, &k| {
            b.union(&Aabb::at(v[k as usize]))
        })
    }
}

/// A 2D crack element: the segment from vertex 0 to vertex 1.
pub type Segment = [u32; 2];

/// A 3D crack element: the triangle of vertices 0, 1, 2, counterclockwise seen from above.
pub type Triangle = [u32; 3];

/// +1 for a non-negative orientation, -1 otherwise (the tie rule of [`Element::crossing`]).
#[inline(always)]
fn sign(o: f64) -> i8 {
    if o >= 0.0 { 1 } else { -1 }
}

fn coord2(u: DVec2) -> robust::Coord<f64> {
    robust::Coord { x: u.x, y: u.y }
}

fn coord3(u: DVec3) -> robust::Coord3D<f64> {
    robust::Coord3D {
        x: u.x,
        y: u.y,
        z: u.z,
    }
}

impl Element for Segment {
    type Vec = DVec2;
    const VERTICES: usize = 2;
    const FEATURES: usize = 2;
    const SHARED_FEATURE_SAFE: bool = true;

    fn vertices(&self) -> &[u32] {
        self
    }
    fn from_vertices(v: &[u32]) -> Self {
        [v[0], v[1]]
    }
    fn feature(&self, k: usize) -> [u32; 2] {
        [self[k], self[k]]
    }
    fn side(&self, x: DVec2, v: &[DVec2]) -> i8 {
        sign(robust::orient2d(
            coord2(v[self[0] as usize]),
            coord2(v[self[1] as usize]),
            coord2(x),
        ))
    }
    fn crossing_from(&self, p: DVec2, sp: i8, q: DVec2, v: &[DVec2]) -> i8 {
        let (a, b) = (v[self[0] as usize], v[self[1] as usize]);
        if sp == self.side(q, v) {
            return 0;
        }
        let sa = sign(robust::orient2d(coord2(p), coord2(q), coord2(a)));
        if sa == sign(robust::orient2d(coord2(p), coord2(q), coord2(b))) {
            return 0;
        }
        sp
    }
    fn distance_sq(&self, x: DVec2, v: &[DVec2]) -> f64 {
        point_segment_sq(x, v[self[0] as usize], v[self[1] as usize])
    }
    fn plane_distance(&self, x: DVec2, v: &[DVec2]) -> f64 {
        let (a, b) = (v[self[0] as usize], v[self[1] as usize]);
        let t = b - a;
        let len = t.length();
        if len > 0.0 {
            t.perp_dot(x - a).abs() / len
        } else {
            (x - a).length()
        }
    }
    fn normal(&self, v: &[DVec2]) -> DVec2 {
        let ab = v[self[1] as usize] - v[self[0] as usize];
        let len = ab.dot(ab).sqrt();
        DVec2::new(-ab[1] / len, ab[0] / len)
    }
    fn feature_distance(&self, p: DVec2, q: DVec2, v: &[DVec2], k: usize) -> f64 {
        point_segment(v[self[k] as usize], p, q)
    }
}

impl Element for Triangle {
    type Vec = DVec3;
    const VERTICES: usize = 3;
    const FEATURES: usize = 3;
    const SHARED_FEATURE_SAFE: bool = true;

    fn vertices(&self) -> &[u32] {
        self
    }
    fn from_vertices(v: &[u32]) -> Self {
        [v[0], v[1], v[2]]
    }
    fn feature(&self, k: usize) -> [u32; 2] {
        [self[k], self[(k + 1) % 3]]
    }
    fn side(&self, x: DVec3, v: &[DVec3]) -> i8 {
        let [a, b, t] = self.map(|k| coord3(v[k as usize]));
        // robust::orient3d is positive below the plane of a counterclockwise triangle.
        sign(-robust::orient3d(a, b, t, coord3(x)))
    }
    fn crossing_from(&self, p: DVec3, sp: i8, q: DVec3, v: &[DVec3]) -> i8 {
        if sp == self.side(q, v) {
            return 0;
        }
        let [va, vb, vt] = self.map(|k| v[k as usize]);
        let s1 = edge_side(p, q, va, vb);
        let s2 = edge_side(p, q, vb, vt);
        let s3 = edge_side(p, q, vt, va);
        if s1 == s2 && s2 == s3 { sp } else { 0 }
    }
    fn distance_sq(&self, x: DVec3, v: &[DVec3]) -> f64 {
        self.distance(x, v).powi(2)
    }
    fn distance(&self, x: DVec3, v: &[DVec3]) -> f64 {
        let [a, b, c] = self.map(|k| v[k as usize]);
        point_triangle(x, a, b, c)
    }
    fn plane_distance(&self, x: DVec3, v: &[DVec3]) -> f64 {
        let [a, b, c] = self.map(|k| v[k as usize]);
        let n = (b - a).cross(c - a);
        let len = n.length();
        if len > 0.0 {
            n.dot(x - a).abs() / len
        } else {
            point_triangle(x, a, b, c)
        }
    }
    fn normal(&self, v: &[DVec3]) -> DVec3 {
        let [a, b, c] = self.map(|k| v[k as usize]);
        (b - a).cross(c - a).normalize()
    }
    fn feature_distance(&self, p: DVec3, q: DVec3, v: &[DVec3], k: usize) -> f64 {
        let [a, b] = self.feature(k).map(|i| v[i as usize]);
        segment_segment(p, q, a, b)
    }
}

/// Directions along which `edge_side` moves a line that meets an edge exactly.
pub const NUDGE: [DVec3; 2] = [
    DVec3::new(0.571_428_57, 0.301_953_12, 0.763_143_73),
    DVec3::new(-0.212_121_21, 0.927_835_05, 0.306_651_63),
];

/// Which side of the line from `p` to `q` the directed edge `a` -> `b` passes (the sign of
/// robust::orient3d(p, q, a, b), as +1 or -1). Where the line meets the edge exactly the
/// line is taken as moved a vanishing distance along a fixed direction (simulation of
/// simplicity): the sign is that of the first-order change, d . ((q - p) x (a - b)), which
/// flips exactly with the edge's direction. So a line through an edge shared by two
/// triangles (met in opposite directions) crosses exactly one of them, and a line through
/// a vertex crosses the one triangle of its fan the moved line passes through.
fn edge_side(p: DVec3, q: DVec3, a: DVec3, b: DVec3) -> i8 {
    let o = robust::orient3d(coord3(p), coord3(q), coord3(a), coord3(b));
    if o != 0.0 {
        return sign(o);
    }
    let axis = (q - p).cross(a - b);
    NUDGE
        .iter()
        .map(|d| d.dot(axis))
        .find(|&k| k != 0.0)
        .map_or(1, sign)
}
