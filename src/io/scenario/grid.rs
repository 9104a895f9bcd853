//! The `[grid]` table: the background grid's extent, cell size and optional anchor.

use super::check::{R, positive, to_vec, vec3};
use super::schema::AnchorSpec;
use super::source::Source;
use crate::base::dim::Dim;
use crate::store::grid::GridGeom;

/// Largest grid (nodes) a scenario may ask for.
const MAX_NODES: f64 = 2.0e8;

/// The checked grid: its geometry, its extent padded to 3 (m) and its node count.
pub(super) struct GridPlan<D: Dim> {
    /// Origin, spacing and cell counts.
    pub geom: GridGeom<D>,
    /// Lower corner (m).
    pub min: [f64; 3],
    /// Upper corner (m).
    pub max: [f64; 3],
    /// Grid nodes.
    pub nodes: f64,
}

/// The `[grid]` table, checked: whole cells on every axis, at least two, at most
/// [`MAX_NODES`] nodes.
pub(super) fn grid<D: Dim>(src: &Source) -> R<GridPlan<D>> {
    let g = &src.scenario.grid;
    let mut gmin = vec3::<D>(src, "grid.min", &g.min)?;
    let mut gmax = vec3::<D>(src, "grid.max", &g.max)?;
    let cell = vec3::<D>(src, "grid.cell", &g.cell)?;
    let mut cells = [1usize; 3];
    let mut h = [1.0; 3];
    let mut node_count = 1.0;
    for a in 0..D::D {
        h[a] = positive(src, "grid.cell", cell[a], "m")?;
        if gmax[a] <= gmin[a] {
            return Err(src.error("grid.max", "grid max must exceed grid min on every axis"));
        }
    }
    if let Some(anchor) = &g.anchor {
        (gmin, gmax) = anchored::<D>(src, anchor, gmin, gmax, h)?;
    }
    for a in 0..D::D {
        let n = (gmax[a] - gmin[a]) / h[a];
        if (n - n.round()).abs() > 1e-6 * n.max(1.0) {
            return Err(src.error(
                "grid.cell",
                format!("the grid extent on axis {a} is {n:.6} cells; it must be a whole number"),
            ));
        }
        node_count *= n.round() + 1.0;
        if node_count > MAX_NODES {
            return Err(src.error("grid.cell", "grid too large (more than 2e8 nodes)"));
        }
        cells[a] = n.round() as usize;
        if cells[a] < 2 {
            return Err(src.error("grid.cell", "the grid needs at least 2 cells per axis"));
        }
    }
    Ok(GridPlan {
        geom: GridGeom::<D>::new(to_vec::<D>(gmin), to_vec::<D>(h), cells),
        min: gmin,
        max: gmax,
        nodes: node_count,
    })
}

/// The grid's extent widened to whole cells of the lattice `anchor` lays: nodes at
/// `point + (k + offset) h` per axis. A bound already on the lattice (to a billionth of a
/// cell) is kept as given, so an anchor that agrees with `min` changes nothing.
fn anchored<D: Dim>(
    src: &Source,
    anchor: &AnchorSpec,
    min: [f64; 3],
    max: [f64; 3],
    h: [f64; 3],
) -> R<([f64; 3], [f64; 3])> {
    let point = vec3::<D>(src, "grid.anchor.point", &anchor.point)?;
    let offset = match &anchor.offset {
        Some(o) => vec3::<D>(src, "grid.anchor.offset", o)?,
        None => [0.0; 3],
    };
    if offset.iter().any(|o| !(0.0..1.0).contains(o)) {
        return Err(src.error(
            "grid.anchor.offset",
            "offsets are fractions of a cell in [0, 1)",
        ));
    }
    let (mut lo, mut hi) = (min, max);
    for a in 0..D::D {
        let origin = point[a] + offset[a] * h[a];
        let node = |k: f64| origin + k * h[a];
        let snap = |x: f64, k: f64| {
            if (node(k) - x).abs() <= 1e-9 * h[a] {
                x
            } else {
                node(k)
            }
        };
        let first = ((min[a] - origin) / h[a] + 1e-9).floor();
        let last = ((max[a] - origin) / h[a] - 1e-9).ceil();
        lo[a] = snap(min[a], first);
        hi[a] = snap(max[a], last);
    }
    Ok((lo, hi))
}
