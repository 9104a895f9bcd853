//! Crack tips (2D) and front edges (3D) that lie on a line from a particle to a node of its
//! stencil. Whether such a line crosses the crack, and so which velocity field the pair
//! joins, is then decided by round-off, and it flips as the crack moves by round-off: the
//! edge-shear crack ending at a cell centre, where the lines from the quarter-point
//! particles to the cell's corner nodes meet, read J 1.5 % above the same crack ended
//! 0.05 mm either side in a damped run (docs/fracture.md).

use super::Cracks;
use crate::base::dim::Dim;
use crate::base::geometry::{point_segment, segment_segment};
use crate::physics::shape::ShapeKind;
use crate::store::grid::GridGeom;
use glam::DVec3;
use rayon::prelude::*;

/// A line within this fraction of the grid's smallest cell spacing of a tip lies on it: far
/// below any placement a scene would mean, far above round-off.
const ON: f64 = 1e-7;

/// Per crack (by index), how many lines from particles `x` (half-widths `half`) to the
/// nodes of their `shape` stencils pass through its tips or front edges, for the cracks
/// with any.
pub fn tips_on_lines<D: Dim>(
    cracks: &Cracks<D>,
    x: &[D::Vec],
    half: &[D::Vec],
    geom: &GridGeom<D>,
    shape: ShapeKind,
) -> Vec<(usize, usize)> {
    let topo = &cracks.topology;
    let at = |v: u32| DVec3::from(D::to_xyz(cracks.geometry.x[v as usize]));
    let (origin, h) = (D::to_xyz(geom.origin), D::to_xyz(geom.h));
    let tol = ON * geom.min_cell();
    // No stencil node lies farther from its particle than three cells on an axis.
    let reach = 3.0 * (0..D::D).map(|a| h[a]).fold(0.0, f64::max) * (D::D as f64).sqrt();
    let mut counts = vec![0usize; topo.cracks().len()];
    for front in topo.fronts() {
        let v = &front.vertices;
        // A 2D tip is a segment of zero length.
        let edges: Vec<(DVec3, DVec3)> = if D::D == 2 {
            vec![(at(v[0]), at(v[0]))]
        } else {
            let n = v.len();
            let count = if topo.is_closed(front) { n } else { n - 1 };
            (0..count).map(|k| (at(v[k]), at(v[(k + 1) % n]))).collect()
        };
        let lo = edges
            .iter()
            .fold(DVec3::INFINITY, |m, e| m.min(e.0).min(e.1))
            - reach;
        let hi = edges
            .iter()
            .fold(DVec3::NEG_INFINITY, |m, e| m.max(e.0).max(e.1))
            + reach;
        let lines: usize = (x.par_iter().zip(half))
            .map(|(&p, &l)| {
                let p = DVec3::from(D::to_xyz(p));
                if (0..D::D).any(|a| p[a] < lo[a] || p[a] > hi[a]) {
                    return 0;
                }
                let near: Vec<&(DVec3, DVec3)> = (edges.iter())
                    .filter(|(a, b)| point_segment(p, *a, *b) < reach)
                    .collect();
                if near.is_empty() {
                    return 0;
                }
                let l = D::to_xyz(l);
                // The stencil's first node and 1D weights per axis (a node of weight 0
                // takes nothing from the particle, so its line does not matter).
                let (mut first, mut w) = ([0usize; 3], [[1.0, 0.0, 0.0]; 3]);
                for a in 0..D::D {
                    let xi = (p[a] - origin[a]) / h[a];
                    (first[a], w[a], _) = shape.axis(xi, l[a] / h[a], 1.0 / h[a]);
                }
                let per = |a: usize| if a < D::D { shape.nodes() } else { 1 };
                let mut on = 0;
                for k in 0..per(2) {
                    for j in 0..per(1) {
                        for i in 0..per(0) {
                            if w[0][i] * w[1][j] * w[2][k] == 0.0 {
                                continue;
                            }
                            let index = [first[0] + i, first[1] + j, first[2] + k];
                            let mut node = DVec3::ZERO;
                            for a in 0..D::D {
                                node[a] = origin[a] + index[a] as f64 * h[a];
                            }
                            let hits = near
                                .iter()
                                .any(|(a, b)| segment_segment(p, node, *a, *b) < tol);
                            on += usize::from(hits);
                        }
                    }
                }
                on
            })
            .sum();
        counts[front.crack as usize] += lines;
    }
    (counts.into_iter().enumerate())
        .filter(|&(_, n)| n > 0)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::base::dim::{D2, D3};
    use crate::store::crack::Contact;
    use glam::{DVec2, DVec3};

    /// A 2D crack along y = 4.5 mm from x = 1 mm to a tip at `tip` (mm), and the grid of 1
    /// mm cells from the origin with two particles per cell per axis (at the quarter
    /// points, half-width a quarter cell).
    fn scene(tip: f64) -> (Cracks<D2>, Vec<DVec2>, Vec<DVec2>, GridGeom<D2>) {
        let mut c = Cracks::<D2>::default();
        c.topology.add_crack(
            "c".into(),
            Contact::OPEN,
            None,
            2,
            &[[0, 1]],
            &[(1, vec![1])],
        );
        c.geometry.x = vec![DVec2::new(1e-3, 4.5e-3), DVec2::new(tip * 1e-3, 4.5e-3)];
        let x: Vec<DVec2> = (0..20)
            .flat_map(|j| (0..20).map(move |i| DVec2::new(i as f64, j as f64) * 5e-4 + 2.5e-4))
            .collect();
        let half = vec![DVec2::splat(2.5e-4); x.len()];
        let geom = GridGeom::<D2>::new(DVec2::ZERO, DVec2::splat(1e-3), [10, 10, 1]);
        (c, x, half, geom)
    }

    /// A tip at the cell centre (5.5, 4.5) mm lies on the four diagonals from the cell's
    /// quarter-point particles to the corner nodes across the centre ((5.25, 4.25) to (6,
    /// 5), ...). A line through the centre from any other particle reaches a node only
    /// beyond the particle's uGIMP support (2 x 2 nodes of non-zero weight: those of the
    /// cell the particle's quarter-cell square lies in): 4 lines in all. 0.05 mm on, none.
    #[test]
    fn a_tip_at_a_cell_centre_lies_on_particle_node_lines() {
        let (c, x, half, geom) = scene(5.5);
        let found = tips_on_lines(&c, &x, &half, &geom, ShapeKind::Ugimp);
        assert_eq!(found, vec![(0, 4)]);
        let (c, x, half, geom) = scene(5.55);
        assert!(tips_on_lines(&c, &x, &half, &geom, ShapeKind::Ugimp).is_empty());
    }

    /// A 3D front edge from (5.5, 4.5, 0) to (5.5, 4.5, 10) mm through a lattice of quarter
    /// points: in each of the 20 layers of particles, the four around the edge see it on
    /// their x-y diagonal, each towards its two nodes in z of non-zero weight (the line
    /// meets the edge within its length): 20 x 4 x 2 = 160 lines. Moved 0.05 mm, none.
    #[test]
    fn a_front_edge_through_cell_centres_is_found() {
        let mut c = Cracks::<D3>::default();
        c.topology.add_crack(
            "c".into(),
            Contact::OPEN,
            None,
            3,
            &[[0, 1, 2]],
            &[(0, vec![1, 2])],
        );
        c.geometry.x = vec![
            DVec3::new(1e-3, 4.5e-3, 5e-3),
            DVec3::new(5.5e-3, 4.5e-3, 0.0),
            DVec3::new(5.5e-3, 4.5e-3, 1e-2),
        ];
        let x: Vec<DVec3> = (0..20)
            .flat_map(|k| {
                (0..20).flat_map(move |j| {
                    (0..20).map(move |i| DVec3::new(i as f64, j as f64, k as f64) * 5e-4 + 2.5e-4)
                })
            })
            .collect();
        let half = vec![DVec3::splat(2.5e-4); x.len()];
        let geom = GridGeom::<D3>::new(DVec3::ZERO, DVec3::splat(1e-3), [10, 10, 10]);
        let found = tips_on_lines(&c, &x, &half, &geom, ShapeKind::Ugimp);
        assert_eq!(found, vec![(0, 160)]);
        c.geometry.x[1].x += 5e-5;
        c.geometry.x[2].x += 5e-5;
        assert!(tips_on_lines(&c, &x, &half, &geom, ShapeKind::Ugimp).is_empty());
    }
}
