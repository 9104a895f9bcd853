//! Body geometries and filling them with particles.

use crate::base::geometry::{ClosedSurface, Outline};

/// A body's shape, in padded 3-component coordinates (z = 0 in 2D).
#[derive(Clone, Debug)]
pub enum Solid {
    /// Axis-aligned box.
    Box {
        /// Lower corner (m).
        min: [f64; 3],
        /// Upper corner (m).
        max: [f64; 3],
    },
    /// Disc (2D, ignores z) or sphere (3D), hollow (a ring, a spherical shell) when
    /// `inner` > 0.
    Round {
        /// Centre (m).
        center: [f64; 3],
        /// Radius (m).
        radius: f64,
        /// Radius of the hole (m), 0 for a full disc or sphere.
        inner: f64,
        /// Whether z counts (sphere).
        sphere: bool,
    },
    /// Circular cylinder along a coordinate axis, hollow (a tube) when `inner` > 0.
    Cylinder {
        /// Centre of the base (m).
        center: [f64; 3],
        /// Axis index (0, 1, 2).
        axis: usize,
        /// Radius (m).
        radius: f64,
        /// Radius of the bore (m), 0 for a solid cylinder.
        inner: f64,
        /// Length (m).
        length: f64,
    },
    /// The inside of a closed triangulated surface (3D).
    Mesh(std::sync::Arc<ClosedSurface>),
    /// The region closed outlines bound in x-y (2D: a flat mesh's boundary, holes included).
    Outline(std::sync::Arc<Outline>),
    /// Polygon in x-y, extruded over `z` in 3D.
    Polygon {
        /// Vertices (m).
        points: Vec<[f64; 2]>,
        /// Extrusion range (3D) or None (2D).
        z: Option<[f64; 2]>,
    },
}

impl Solid {
    /// Whether a point lies inside.
    pub fn contains(&self, x: [f64; 3]) -> bool {
        match self {
            Solid::Box { min, max } => (0..3).all(|a| x[a] >= min[a] && x[a] <= max[a]),
            Solid::Round {
                center,
                radius,
                inner,
                sphere,
            } => {
                let n = if *sphere { 3 } else { 2 };
                let r2: f64 = (0..n).map(|a| (x[a] - center[a]).powi(2)).sum();
                r2 <= radius * radius && r2 >= inner * inner
            }
            Solid::Cylinder {
                center,
                axis,
                radius,
                inner,
                length,
            } => {
                let along = x[*axis] - center[*axis];
                let r2: f64 = (0..3)
                    .filter(|a| a != axis)
                    .map(|a| (x[a] - center[a]).powi(2))
                    .sum();
                (0.0..=*length).contains(&along) && r2 <= radius * radius && r2 >= inner * inner
            }
            Solid::Mesh(surface) => surface.contains(x),
            Solid::Outline(outline) => outline.contains([x[0], x[1]]),
            Solid::Polygon { points, z } => {
                if let Some([z0, z1]) = z
                    && !(x[2] >= *z0 && x[2] <= *z1)
                {
                    return false;
                }
                point_in_polygon(points, [x[0], x[1]])
            }
        }
    }

    /// Bounding box (lower, upper), m.
    pub fn bounds(&self) -> ([f64; 3], [f64; 3]) {
        match self {
            Solid::Box { min, max } => (*min, *max),
            Solid::Round {
                center,
                radius,
                sphere,
                ..
            } => {
                let mut lo = *center;
                let mut hi = *center;
                for a in 0..if *sphere { 3 } else { 2 } {
                    lo[a] -= radius;
                    hi[a] += radius;
                }
                (lo, hi)
            }
            Solid::Cylinder {
                center,
                axis,
                radius,
                length,
                ..
            } => {
                let mut lo = *center;
                let mut hi = *center;
                for a in 0..3 {
                    if a == *axis {
                        hi[a] += length;
                    } else {
                        lo[a] -= radius;
                        hi[a] += radius;
                    }
                }
                (lo, hi)
            }
            Solid::Mesh(surface) => surface.bounds(),
            Solid::Outline(outline) => {
                let (lo, hi) = outline.bounds();
                ([lo[0], lo[1], 0.0], [hi[0], hi[1], 0.0])
            }
            Solid::Polygon { points, z } => {
                let mut lo = [f64::INFINITY, f64::INFINITY, 0.0];
                let mut hi = [f64::NEG_INFINITY, f64::NEG_INFINITY, 0.0];
                for p in points {
                    for a in 0..2 {
                        lo[a] = lo[a].min(p[a]);
                        hi[a] = hi[a].max(p[a]);
                    }
                }
                if let Some([z0, z1]) = z {
                    lo[2] = *z0;
                    hi[2] = *z1;
                }
                (lo, hi)
            }
        }
    }
}

/// Even-odd rule point-in-polygon test.
fn point_in_polygon(points: &[[f64; 2]], p: [f64; 2]) -> bool {
    let mut inside = false;
    let mut j = points.len() - 1;
    for i in 0..points.len() {
        let (a, b) = (points[i], points[j]);
        if (a[1] > p[1]) != (b[1] > p[1]) {
            let x = a[0] + (p[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
            if p[0] < x {
                inside = !inside;
            }
        }
        j = i;
    }
    inside
}

/// Hands `visit` the particle positions filling `geom` in lattice order: `ppc` per cell per
/// axis at sub-cell centres of the grid cells (origin, h, cells per axis; `dims` axes
/// used), none of them stored.
pub fn fill(
    geom: &Solid,
    dims: usize,
    origin: [f64; 3],
    h: [f64; 3],
    cells: [usize; 3],
    ppc: usize,
    mut visit: impl FnMut([f64; 3]),
) {
    let range = covered(geom, dims, origin, h, |a| (0.0, cells[a] as f64));
    lattice(range, dims, origin, h, ppc, |x| {
        if geom.contains(x) {
            visit(x);
        }
        false
    });
}

/// The first point of the particle lattice in `geom` that `keep` accepts in the layer of
/// cells just outside the grid (index -1 or `cells` on some axis), where the grid would
/// cut the body; None when the body stays inside.
pub fn first_outside(
    geom: &Solid,
    dims: usize,
    origin: [f64; 3],
    h: [f64; 3],
    cells: [usize; 3],
    ppc: usize,
    keep: impl Fn([f64; 3]) -> bool,
) -> Option<[f64; 3]> {
    let range = covered(geom, dims, origin, h, |a| (-1.0, cells[a] as f64 + 1.0));
    // The layer's slabs, one per axis and side that the body's box reaches.
    let mut found = None;
    for a in 0..dims {
        for edge in [-1, cells[a] as i64] {
            if !(range[a].0..range[a].1).contains(&edge) {
                continue;
            }
            let mut slab = range;
            slab[a] = (edge, edge + 1);
            lattice(slab, dims, origin, h, ppc, |x| {
                if geom.contains(x) && keep(x) {
                    found = Some(x);
                }
                found.is_some()
            });
            if found.is_some() {
                return found;
            }
        }
    }
    None
}

/// The cells `geom`'s box covers, as a cell index range per axis (end exclusive), kept
/// within `limit(axis)` (lowest index, end) on each of the `dims` axes used.
fn covered(
    geom: &Solid,
    dims: usize,
    origin: [f64; 3],
    h: [f64; 3],
    limit: impl Fn(usize) -> (f64, f64),
) -> [(i64, i64); 3] {
    let (lo, hi) = geom.bounds();
    let mut range = [(0i64, 1i64); 3];
    for a in 0..dims {
        let (from, to) = limit(a);
        let first = ((lo[a] - origin[a]) / h[a]).floor().clamp(from, to) as i64;
        let last = ((hi[a] - origin[a]) / h[a]).ceil().clamp(from, to) as i64;
        range[a] = (first.min(last), last);
    }
    range
}

/// Visits the sub-cell centres (`ppc` per cell per axis) of the cells in `range` (cell
/// indices per axis, end exclusive, negative for cells before the grid's origin) in
/// order; stops when `visit` returns true.
fn lattice(
    range: [(i64, i64); 3],
    dims: usize,
    origin: [f64; 3],
    h: [f64; 3],
    ppc: usize,
    mut visit: impl FnMut([f64; 3]) -> bool,
) {
    let sub = |a: usize| if a < dims { ppc } else { 1 };
    for k in range[2].0..range[2].1 {
        for j in range[1].0..range[1].1 {
            for i in range[0].0..range[0].1 {
                let cell = [i, j, k];
                for sk in 0..sub(2) {
                    for sj in 0..sub(1) {
                        for si in 0..sub(0) {
                            let s = [si, sj, sk];
                            let mut x = [0.0; 3];
                            for a in 0..dims {
                                x[a] = origin[a]
                                    + (cell[a] as f64 + (s[a] as f64 + 0.5) / ppc as f64) * h[a];
                            }
                            if visit(x) {
                                return;
                            }
                        }
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A filled disc's or ring's particle count times the particle area approaches
    /// pi (r^2 - r_i^2).
    #[test]
    fn disc_fill_area_converges() {
        for inner in [0.0, 0.1] {
            let g = Solid::Round {
                center: [0.5, 0.5, 0.0],
                radius: 0.3,
                inner,
                sphere: false,
            };
            let mut n = 0;
            fill(&g, 2, [0.0; 3], [0.01, 0.01, 1.0], [100, 100, 1], 2, |_| {
                n += 1
            });
            let area = n as f64 * 0.005 * 0.005;
            let exact = std::f64::consts::PI * (0.09 - inner * inner);
            assert!((area - exact).abs() / exact < 2e-3, "{area} vs {exact}");
        }
    }

    #[test]
    fn polygon_contains_and_excludes() {
        let tri = Solid::Polygon {
            points: vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]],
            z: None,
        };
        assert!(tri.contains([0.2, 0.2, 0.0]));
        assert!(!tri.contains([0.6, 0.6, 0.0]));
    }
}
