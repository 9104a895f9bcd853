//! Whether a new crack meets one already in the store, or a surface meets itself. Cracks
//! must not cross or touch: each crack splits the velocity field on its own, so where two
//! meet a node's fields would be ambiguous.

use crate::base::dim::Dim;
use crate::base::geometry::{Aabb, Element, meeting_pairs};
use crate::store::crack::Cracks;

/// The edges of a crack element as vertex pairs: the segment itself in 2D, the three
/// edges of a triangle in 3D.
fn edges<D: Dim>(e: &D::Elem) -> Vec<[u32; 2]> {
    let v = e.vertices();
    if v.len() == 2 {
        vec![[v[0], v[1]]]
    } else {
        (0..v.len()).map(|k| [v[k], v[(k + 1) % v.len()]]).collect()
    }
}

/// Whether an edge of element `a` (vertices `va`) crosses element `b` (vertices `vb`), by
/// the exact predicates of [`Dim::crossing`] (an end on `b`'s line or plane counts).
fn edge_crosses<D: Dim>(va: &[D::Vec], a: &D::Elem, vb: &[D::Vec], b: D::Elem) -> bool {
    edges::<D>(a)
        .iter()
        .any(|&[p, q]| b.crossing(va[p as usize], va[q as usize], vb) != 0)
}

/// Whether element `a` (vertices `va`) touches element `b` (vertices `vb`) within `tol`
/// (m): a vertex of `a` on `b`, or an edge of `a` on a boundary feature of `b` (in 2D one
/// of `b`'s ends on `a`). It catches what the crossing predicates pass over: elements that
/// overlap on one line (2D) or plane (3D).
fn touches<D: Dim>(va: &[D::Vec], a: &D::Elem, vb: &[D::Vec], b: D::Elem, tol: f64) -> bool {
    let features = b.vertices().len();
    (a.vertices().iter()).any(|&p| b.distance(va[p as usize], vb) <= tol)
        || edges::<D>(a).iter().any(|&[p, q]| {
            (0..features).any(|k| b.feature_distance(va[p as usize], va[q as usize], vb, k) <= tol)
        })
}

/// An element of a crack in the store near a new crack: its box, its index within its
/// crack, and the element.
type Near<D> = (Aabb<<D as Dim>::Vec>, usize, <D as Dim>::Elem);

/// The first crack of `store` that the new crack of `points` and `elems` meets (crosses,
/// or comes within `tol` m of), with the indices of the two elements that meet (the new
/// crack's, then the other's within its crack), in index order.
pub(super) fn meets<D: Dim>(
    store: &Cracks<D>,
    points: &[D::Vec],
    elems: &[D::Elem],
    tol: f64,
) -> Option<(usize, usize, usize)> {
    let topo = &store.topology;
    let vx = &store.geometry.x;
    let mine: Vec<Aabb<D::Vec>> = elems.iter().map(|e| e.bounds(points)).collect();
    let reach = mine.iter().copied().reduce(|a, b| a.union(&b))?.grown(tol);
    // One pass over the store: the elements whose boxes reach the new crack's, by crack,
    // each with its index within its crack (a pass per crack made `check` of thousands of
    // cracks take minutes).
    let mut near: Vec<Vec<Near<D>>> = vec![Vec::new(); topo.cracks().len()];
    let mut count = vec![0usize; topo.cracks().len()];
    for (e, &k) in topo.elems().iter().zip(topo.elem_crack()) {
        let (k, b) = (k as usize, e.bounds(vx));
        if b.overlaps(&reach) {
            near[k].push((b, count[k], *e));
        }
        count[k] += 1;
    }
    for (c, theirs) in near.iter().enumerate() {
        if theirs.is_empty() {
            continue;
        }
        // The other crack's elements sorted by the low x of their boxes, so that only those
        // whose box can reach a new element's are tried.
        let widest = theirs
            .iter()
            .map(|(b, _, _)| b.hi[0] - b.lo[0])
            .fold(0.0, f64::max);
        let mut order: Vec<usize> = (0..theirs.len()).collect();
        order.sort_by(|&i, &j| theirs[i].0.lo[0].total_cmp(&theirs[j].0.lo[0]));
        let low: Vec<f64> = order.iter().map(|&i| theirs[i].0.lo[0]).collect();
        let mut found: Option<(usize, usize)> = None;
        for (ia, (ea, ba)) in elems.iter().zip(&mine).enumerate() {
            let from = low.partition_point(|&x| x < ba.lo[0] - widest);
            let to = low.partition_point(|&x| x <= ba.hi[0]);
            for &j in &order[from..to] {
                let (bb, ib, eb) = &theirs[j];
                if ba.overlaps(bb)
                    && (edge_crosses::<D>(points, ea, vx, *eb)
                        || edge_crosses::<D>(vx, eb, points, *ea)
                        || touches::<D>(points, ea, vx, *eb, tol)
                        || touches::<D>(vx, eb, points, *ea, tol))
                    && found.is_none_or(|f| (ia, *ib) < f)
                {
                    found = Some((ia, *ib));
                }
            }
            if found.is_some() {
                break;
            }
        }
        if let Some((ia, ib)) = found {
            return Some((c, ia, ib));
        }
    }
    None
}

/// The first pair of elements of one crack (`points`, `elems`) sharing no vertex that cross
/// or come within `tol` m of each other, in index order: a surface that passes through or
/// lies over itself. Only elements whose boxes meet are tried ([`meeting_pairs`]).
pub(super) fn self_meets<D: Dim>(
    points: &[D::Vec],
    elems: &[D::Elem],
    tol: f64,
) -> Option<(usize, usize)> {
    let boxes: Vec<Aabb<D::Vec>> = elems.iter().map(|e| e.bounds(points)).collect();
    let mut found: Option<(usize, usize)> = None;
    meeting_pairs(&boxes, |i, j| {
        let (a, b) = (&elems[i], elems[j]);
        let shared = (a.vertices().iter()).any(|v| b.vertices().contains(v));
        if !shared
            && found.is_none_or(|f| (i, j) < f)
            && (edge_crosses::<D>(points, a, points, b)
                || edge_crosses::<D>(points, &b, points, *a)
                || touches::<D>(points, a, points, b, tol)
                || touches::<D>(points, &b, points, *a, tol))
        {
            found = Some((i, j));
        }
    });
    found
}
