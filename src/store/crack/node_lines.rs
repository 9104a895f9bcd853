//! Cracks that lie on a line of grid nodes (2D) or a plane of them (3D). The nodes on such
//! a crack sit on neither of its sides, so J and K read less accurately there and the
//! particles' classification cannot be reused from step to step. Measured: the DCB reads
//! K_I 1.2 % low on a node row against 0.3 % half a cell off, in 60 % more time; a penny
//! crack on a node plane reads K_I 0.1 to 6.4 % high depending on its radius, against a
//! steady 1.9 to 2.8 % half a cell off (docs/validation.md).

use super::Cracks;
use crate::base::dim::Dim;
use crate::base::geometry::Element;
use crate::store::grid::GridGeom;
use std::collections::BTreeMap;

/// A crack found lying on a node line or plane.
#[derive(Clone, Debug, PartialEq)]
pub struct NodeLine {
    /// The crack's index.
    pub crack: usize,
    /// The grid axis the line or plane is normal to (0 = x).
    pub axis: usize,
    /// Its coordinate on that axis (m).
    pub at: f64,
    /// The share of the crack's elements on it.
    pub share: f64,
}

/// Share of a crack's elements on one node line or plane from which it is reported.
const REPORTED_SHARE: f64 = 0.25;

/// The cracks with at least a quarter of their elements on one node line (2D) or plane
/// (3D) normal to a grid axis (every vertex within a millionth of a cell of it), each with
/// the line that holds most of them.
pub fn on_node_lines<D: Dim>(cracks: &Cracks<D>, geom: &GridGeom<D>) -> Vec<NodeLine> {
    let topo = &cracks.topology;
    let x = &cracks.geometry.x;
    let mut on: BTreeMap<(u16, usize, i64), usize> = BTreeMap::new();
    let mut elements = vec![0usize; topo.cracks().len()];
    for (e, &c) in topo.elems().iter().zip(topo.elem_crack()) {
        elements[c as usize] += 1;
        for a in 0..D::D {
            let mut lines = (e.vertices().iter()).map(|&v| node_line(geom, x[v as usize], a));
            if let Some(Some(k)) = lines.next()
                && lines.all(|l| l == Some(k))
            {
                *on.entry((c, a, k)).or_default() += 1;
            }
        }
    }
    // Per crack, the line holding most of its elements (the first such in axis order).
    let mut best: BTreeMap<u16, (usize, usize, i64)> = BTreeMap::new();
    for ((c, a, k), n) in on {
        if best.get(&c).is_none_or(|b| n > b.0) {
            best.insert(c, (n, a, k));
        }
    }
    (best.into_iter())
        .map(|(c, (n, a, k))| NodeLine {
            crack: c as usize,
            axis: a,
            at: geom.origin[a] + k as f64 * geom.h[a],
            share: n as f64 / elements[c as usize] as f64,
        })
        .filter(|l| l.share >= REPORTED_SHARE)
        .collect()
}

/// The node line or plane normal to axis `a` that `p` lies on (within a millionth of a
/// cell), by its node index.
fn node_line<D: Dim>(geom: &GridGeom<D>, p: D::Vec, a: usize) -> Option<i64> {
    let s = (p[a] - geom.origin[a]) * geom.inv_h[a];
    ((s - s.round()).abs() <= 1e-6).then_some(s.round() as i64)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::base::dim::D2;
    use crate::store::crack::Contact;
    use glam::DVec2;

    /// A straight crack of ten segments along y = `y` in a grid of 1 mm cells from -2 mm.
    fn line(y: f64) -> Cracks<D2> {
        let mut c = Cracks::<D2>::default();
        let open = Contact::OPEN;
        let segments: Vec<[u32; 2]> = (0..10).map(|k| [k, k + 1]).collect();
        c.topology
            .add_crack("c".into(), open, None, 11, &segments, &[]);
        c.geometry.x = (0..11).map(|k| DVec2::new(1e-3 * k as f64, y)).collect();
        c
    }

    #[test]
    fn a_crack_on_a_node_row_is_found_and_one_between_rows_is_not() {
        let geom = GridGeom::<D2>::new(DVec2::splat(-2e-3), DVec2::splat(1e-3), [20, 20, 1]);
        let on = on_node_lines(&line(3e-3), &geom);
        assert_eq!(on.len(), 1);
        assert_eq!((on[0].crack, on[0].axis, on[0].share), (0, 1, 1.0));
        assert!((on[0].at - 3e-3).abs() < 1e-15);
        assert!(on_node_lines(&line(3.5e-3), &geom).is_empty());
        // A millionth of a cell off still counts; a thousandth does not.
        assert_eq!(on_node_lines(&line(3e-3 + 1e-10), &geom).len(), 1);
        assert!(on_node_lines(&line(3e-3 + 1e-6), &geom).is_empty());
    }
}
