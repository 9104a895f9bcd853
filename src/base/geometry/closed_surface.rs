//! A closed triangulated surface, its triangles turned to agree with their neighbours, and
//! the exact test of whether a point lies inside it: a body read from a mesh file.
//!
//! The test casts a ray from the point along +x and counts the triangles it crosses
//! (ray parity). Each decision is an exact predicate (`robust`'s orient2d on the triangle's
//! projection onto the y-z plane, orient3d against its plane), and a ray through an edge
//! or vertex is decided by moving the point symbolically by (0, eps, eps^2) (simulation of
//! simplicity, Edelsbrunner & Muecke 1990), so it crosses exactly one of the triangles
//! that share that edge: a point is decided the same way every time, whatever the
//! triangles' order. A point on the surface (found first, exactly) counts as inside, as on
//! a box's faces.

use robust::{Coord, Coord3D, orient2d, orient3d};

/// Vertices and triangles as indices into them: a surface as files give it.
pub type TriangleList = (Vec<[f64; 3]>, Vec<[u32; 3]>);

/// What makes a triangle list unfit to bound a body.
#[derive(Clone, Debug, PartialEq)]
pub enum SurfaceDefect {
    /// No triangles.
    Empty,
    /// A vertex with a coordinate that is not finite.
    NotFinite {
        /// Its index.
        vertex: usize,
    },
    /// A triangle of zero area (a repeated vertex, or three in a line).
    Degenerate {
        /// Its index.
        triangle: usize,
    },
    /// An edge bounded by one triangle only: the surface has a hole there.
    Open {
        /// A triangle along the edge.
        triangle: usize,
        /// The edge's end points.
        edge: [[f64; 3]; 2],
    },
    /// An edge shared by more than two triangles: the surface is not a manifold.
    Inconsistent {
        /// A triangle along the edge.
        triangle: usize,
        /// The edge's end points.
        edge: [[f64; 3]; 2],
    },
    /// Triangles that cannot all be turned to agree with their neighbours.
    OneSided {
        /// The triangle where turning failed.
        triangle: usize,
    },
}

impl std::fmt::Display for SurfaceDefect {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let p = |x: &[f64; 3]| format!("({:.6e}, {:.6e}, {:.6e})", x[0], x[1], x[2]);
        match self {
            SurfaceDefect::Empty => write!(f, "the surface has no triangles"),
            SurfaceDefect::NotFinite { vertex } => {
                write!(f, "vertex {vertex} has a coordinate that is not finite")
            }
            SurfaceDefect::Degenerate { triangle } => {
                write!(f, "triangle {triangle} has zero area")
            }
            SurfaceDefect::Open { triangle, edge } => write!(
                f,
                "the surface is not closed: the edge {} - {} of triangle {triangle} borders \
                 no other triangle",
                p(&edge[0]),
                p(&edge[1])
            ),
            SurfaceDefect::Inconsistent { triangle, edge } => write!(
                f,
                "the edge {} - {} of triangle {triangle} is shared by more than two \
                 triangles: the surface is not a manifold",
                p(&edge[0]),
                p(&edge[1])
            ),
            SurfaceDefect::OneSided { triangle } => write!(
                f,
                "the surface is one-sided: turning triangle {triangle} to agree with one \
                 neighbour turns it against another"
            ),
        }
    }
}

/// A closed, consistently oriented surface, with its triangles binned by their y-z extent
/// for the ray test.
#[derive(Clone, Debug)]
pub struct ClosedSurface {
    vertices: Vec<[f64; 3]>,
    triangles: Vec<[u32; 3]>,
    lo: [f64; 3],
    hi: [f64; 3],
    /// Bins per axis (y, z), their size and, per bin, the triangles whose y-z box meets it.
    bins: [usize; 2],
    bin: [f64; 2],
    members: Vec<Vec<u32>>,
}

impl ClosedSurface {
    /// Checks `triangles` over `vertices`, turns those that disagree with their neighbours
    /// (the inside test does not depend on which way they face) and indexes them.
    pub fn new(vertices: Vec<[f64; 3]>, triangles: Vec<[u32; 3]>) -> Result<Self, SurfaceDefect> {
        if triangles.is_empty() {
            return Err(SurfaceDefect::Empty);
        }
        if let Some(v) = vertices
            .iter()
            .position(|v| v.iter().any(|c| !c.is_finite()))
        {
            return Err(SurfaceDefect::NotFinite { vertex: v });
        }
        let at = |i: u32| vertices[i as usize];
        for (t, tri) in triangles.iter().enumerate() {
            let [a, b, c] = tri.map(at);
            let (u, v) = (sub(b, a), sub(c, a));
            let n = [
                u[1] * v[2] - u[2] * v[1],
                u[2] * v[0] - u[0] * v[2],
                u[0] * v[1] - u[1] * v[0],
            ];
            if n == [0.0; 3] {
                return Err(SurfaceDefect::Degenerate { triangle: t });
            }
        }
        let triangles = orient(&vertices, &triangles)?;
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for v in &vertices {
            for a in 0..3 {
                lo[a] = lo[a].min(v[a]);
                hi[a] = hi[a].max(v[a]);
            }
        }
        // About one triangle per bin on a surface that wraps the box.
        let per_axis = ((triangles.len() as f64).sqrt().ceil() as usize).clamp(1, 4096);
        let bins = [per_axis, per_axis];
        let bin = [1, 2].map(|a| ((hi[a] - lo[a]) / per_axis as f64).max(f64::MIN_POSITIVE));
        let mut members = vec![Vec::new(); per_axis * per_axis];
        let cell = |x: f64, a: usize| -> usize {
            (((x - lo[a + 1]) / bin[a]).floor().max(0.0) as usize).min(bins[a] - 1)
        };
        for (t, tri) in triangles.iter().enumerate() {
            let ps = tri.map(at);
            let (y0, y1) = min_max(ps.map(|p| p[1]));
            let (z0, z1) = min_max(ps.map(|p| p[2]));
            for j in cell(y0, 0)..=cell(y1, 0) {
                for k in cell(z0, 1)..=cell(z1, 1) {
                    members[j * bins[1] + k].push(t as u32);
                }
            }
        }
        Ok(ClosedSurface {
            vertices,
            triangles,
            lo,
            hi,
            bins,
            bin,
            members,
        })
    }

    /// The bounding box (lower, upper corner), m.
    pub fn bounds(&self) -> ([f64; 3], [f64; 3]) {
        (self.lo, self.hi)
    }

    /// The enclosed volume (m^3): the sum of the signed tetrahedra from the origin, made
    /// positive whichever way the triangles face.
    pub fn volume(&self) -> f64 {
        let six: f64 = (self.triangles.iter())
            .map(|t| {
                let [a, b, c] = t.map(|i| self.vertices[i as usize]);
                a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                    + a[2] * (b[0] * c[1] - b[1] * c[0])
            })
            .sum();
        six.abs() / 6.0
    }

    /// Whether `p` lies inside the surface or on it.
    pub fn contains(&self, p: [f64; 3]) -> bool {
        if (0..3).any(|a| p[a] < self.lo[a] || p[a] > self.hi[a]) {
            return false;
        }
        let j = (((p[1] - self.lo[1]) / self.bin[0]) as usize).min(self.bins[0] - 1);
        let k = (((p[2] - self.lo[2]) / self.bin[1]) as usize).min(self.bins[1] - 1);
        let candidates = &self.members[j * self.bins[1] + k];
        let corners = |t: u32| self.triangles[t as usize].map(|i| self.vertices[i as usize]);
        if candidates.iter().any(|&t| on_triangle(corners(t), p)) {
            return true;
        }
        let mut inside = false;
        for &t in candidates {
            let [a, b, c] = corners(t);
            // The projection's orientation; 0 when the triangle is edge-on to the ray.
            let area = orient2d(yz(a), yz(b), yz(c));
            if area == 0.0 {
                continue;
            }
            let s = area.signum();
            let q = yz(p);
            if ![(a, b), (b, c), (c, a)]
                .iter()
                .all(|&(u, v)| side(u, v, q) == s)
            {
                continue;
            }
            // The ray meets the triangle's plane; where, against p, is the sign of orient3d
            // relative to the projection's orientation.
            let o = orient3d(xyz(a), xyz(b), xyz(c), xyz(p));
            if o.signum() == s {
                inside = !inside;
            }
        }
        inside
    }
}

/// The side of the edge u -> v on which the point q moved by (eps, eps^2) in the y-z plane
/// lies: the sign of orient2d, with a tie broken by the symbolic move (never 0 for an edge
/// of nonzero length).
fn side(u: [f64; 3], v: [f64; 3], q: Coord<f64>) -> f64 {
    let o = orient2d(yz(u), yz(v), q);
    if o != 0.0 {
        return o.signum();
    }
    // orient2d(u, v, q + (e, e^2)) = o + (v_y - u_y) e^2 - (v_z - u_z) e.
    if v[2] != u[2] {
        (u[2] - v[2]).signum()
    } else {
        (v[1] - u[1]).signum()
    }
}

/// Whether `p` lies on the triangle `t` (its edges and corners included): in its plane, and
/// inside it in the projection onto the coordinate plane where it has the largest area.
fn on_triangle(t: [[f64; 3]; 3], p: [f64; 3]) -> bool {
    let [a, b, c] = t;
    if orient3d(xyz(a), xyz(b), xyz(c), xyz(p)) != 0.0 {
        return false;
    }
    let plane = |i: usize, j: usize, x: [f64; 3]| Coord { x: x[i], y: x[j] };
    let (i, j) = [(1, 2), (2, 0), (0, 1)]
        .into_iter()
        .max_by(|&(i, j), &(k, l)| {
            let area = |i, j| orient2d(plane(i, j, a), plane(i, j, b), plane(i, j, c)).abs();
            area(i, j).total_cmp(&area(k, l))
        })
        .expect("three planes");
    let s = [(a, b), (b, c), (c, a)]
        .map(|(u, v)| orient2d(plane(i, j, u), plane(i, j, v), plane(i, j, p)));
    s.iter().all(|&x| x >= 0.0) || s.iter().all(|&x| x <= 0.0)
}

/// The triangles turned, where needed, to agree with their neighbours: every edge
/// traversed once each way. The first triangle of each connected piece keeps its turn. An
/// edge with one triangle leaves the surface open; one with more than two, or a piece that
/// cannot be turned to agree (one-sided), is refused.
fn orient(vertices: &[[f64; 3]], triangles: &[[u32; 3]]) -> Result<Vec<[u32; 3]>, SurfaceDefect> {
    // Every side as (lower vertex, higher vertex, triangle, slot), sorted so that the sides
    // of one edge are neighbours in the list.
    let mut sides: Vec<(u32, u32, u32, u8)> = Vec::with_capacity(3 * triangles.len());
    for (t, tri) in triangles.iter().enumerate() {
        for k in 0..3 {
            let (i, j) = (tri[k], tri[(k + 1) % 3]);
            sides.push((i.min(j), i.max(j), t as u32, k as u8));
        }
    }
    sides.sort_unstable();
    let edge = |i: u32, j: u32| [vertices[i as usize], vertices[j as usize]];
    // The triangle across each slot, and the first defect by triangle index.
    let mut across = vec![[0u32; 3]; triangles.len()];
    let mut bad: Option<(u32, SurfaceDefect)> = None;
    for group in sides.chunk_by(|a, b| (a.0, a.1) == (b.0, b.1)) {
        if let [(_, _, t1, k1), (_, _, t2, k2)] = group {
            across[*t1 as usize][*k1 as usize] = *t2;
            across[*t2 as usize][*k2 as usize] = *t1;
            continue;
        }
        let (i, j, t, _) = group[0];
        if bad.as_ref().is_none_or(|b| t < b.0) {
            let (triangle, edge) = (t as usize, edge(i, j));
            let defect = if group.len() == 1 {
                SurfaceDefect::Open { triangle, edge }
            } else {
                SurfaceDefect::Inconsistent { triangle, edge }
            };
            bad = Some((t, defect));
        }
    }
    if let Some((_, defect)) = bad {
        return Err(defect);
    }
    // Whether triangle tri runs its edge i -> j (rather than j -> i).
    let runs =
        |tri: &[u32; 3], i: u32, j: u32| (0..3).any(|k| tri[k] == i && tri[(k + 1) % 3] == j);
    let mut out = triangles.to_vec();
    let mut done = vec![false; triangles.len()];
    let mut stack = Vec::new();
    for first in 0..triangles.len() {
        if done[first] {
            continue;
        }
        done[first] = true;
        stack.push(first);
        while let Some(t) = stack.pop() {
            for k in 0..3 {
                let (a, b) = (triangles[t][k], triangles[t][(k + 1) % 3]);
                let (i, j) = if runs(&out[t], a, b) { (a, b) } else { (b, a) };
                let n = across[t][k] as usize;
                if done[n] {
                    if runs(&out[n], i, j) {
                        return Err(SurfaceDefect::OneSided { triangle: n });
                    }
                    continue;
                }
                if runs(&out[n], i, j) {
                    out[n].swap(1, 2);
                }
                done[n] = true;
                stack.push(n);
            }
        }
    }
    Ok(out)
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn min_max(v: [f64; 3]) -> (f64, f64) {
    (v[0].min(v[1]).min(v[2]), v[0].max(v[1]).max(v[2]))
}

fn yz(p: [f64; 3]) -> Coord<f64> {
    Coord { x: p[1], y: p[2] }
}

fn xyz(p: [f64; 3]) -> Coord3D<f64> {
    Coord3D {
        x: p[0],
        y: p[1],
        z: p[2],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The unit cube [0, 1]^3 as 12 outward triangles.
    fn cube() -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
        let v: Vec<[f64; 3]> = (0..8)
            .map(|i| [(i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64])
            .collect();
        let quads = [
            [0, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
        ];
        let t = quads
            .iter()
            .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
            .collect();
        (v, t)
    }

    /// Inside, outside and on the cube, including points whose rays run along its faces
    /// and through its edges and vertices: every one decided as the box would, with the
    /// triangles in either orientation, any order, or some turned against the rest.
    #[test]
    fn cube_decides_like_a_box() {
        let (v, t) = cube();
        let flipped: Vec<[u32; 3]> = t.iter().rev().map(|[a, b, c]| [*a, *c, *b]).collect();
        let mut mixed = t.clone();
        for k in [3, 4, 9] {
            mixed[k].swap(0, 1);
        }
        for tris in [t, flipped, mixed] {
            let s = ClosedSurface::new(v.clone(), tris).unwrap();
            assert!((s.volume() - 1.0).abs() < 1e-15);
            let vals = [-0.5, 0.0, 0.25, 0.5, 1.0, 1.5];
            for &x in &vals {
                for &y in &vals {
                    for &z in &vals {
                        let want = [x, y, z].iter().all(|c| (0.0..=1.0).contains(c));
                        assert_eq!(s.contains([x, y, z]), want, "({x}, {y}, {z})");
                    }
                }
            }
        }
    }

    /// A surface with a hole, one with an edge of three triangles (a fin inside the cube),
    /// a degenerate triangle and a NaN coordinate are refused, naming what is wrong.
    #[test]
    fn defects_are_named() {
        let (v, t) = cube();
        let open = ClosedSurface::new(v.clone(), t[1..].to_vec()).unwrap_err();
        assert!(matches!(open, SurfaceDefect::Open { .. }), "{open}");
        let mut fin = t.clone();
        fin.push([0, 1, 2]);
        fin.push([0, 2, 1]);
        let e = ClosedSurface::new(v.clone(), fin).unwrap_err();
        assert!(matches!(e, SurfaceDefect::Inconsistent { .. }), "{e}");
        let mut flat = t.clone();
        flat.push([0, 0, 1]);
        assert_eq!(
            ClosedSurface::new(v.clone(), flat).unwrap_err(),
            SurfaceDefect::Degenerate { triangle: 12 }
        );
        let mut nan = v.clone();
        nan[5][1] = f64::NAN;
        assert_eq!(
            ClosedSurface::new(nan, t).unwrap_err(),
            SurfaceDefect::NotFinite { vertex: 5 }
        );
        assert_eq!(
            ClosedSurface::new(v, Vec::new()).unwrap_err(),
            SurfaceDefect::Empty
        );
    }
}
