//! The `[[boundary]]` tables: prescribed velocities on the grid nodes of a region or a
//! node plane.

use super::check::{R, axis_index, to_vec, vec3};
use super::region::region;
use super::source::Source;
use crate::base::dim::Dim;
use crate::physics::loads::VelocityBc;
use crate::store::grid::GridGeom;

/// Every `[[boundary]]`: its nodes (refused when it selects none), the components it
/// holds (`fix`, else a plane's normal, else all) and their velocity and time function.
pub(super) fn boundaries<D: Dim>(src: &Source, geom: &GridGeom<D>) -> R<Vec<VelocityBc<D>>> {
    let sc = &src.scenario;
    let h = D::to_xyz(geom.h);
    let mut bcs = Vec::new();
    for (i, bc) in sc.boundaries.iter().enumerate() {
        let key = |k: &str| format!("boundary[{i}].{k}");
        let (nodes, normal) = match (&bc.region, &bc.plane) {
            (Some(r), None) => {
                let r = region::<D>(src, &key("region"), r)?;
                let tol = 1e-6 * (0..D::D).map(|a| h[a]).fold(f64::INFINITY, f64::min);
                let nodes: Vec<u32> = (0..geom.node_count())
                    .filter(|&n| r.contains(D::to_xyz(geom.node_position(n)), D::D, tol))
                    .map(|n| n as u32)
                    .collect();
                (nodes, None)
            }
            (None, Some(p)) => {
                let a = axis_index::<D>(src, &key("plane.axis"), &p.axis)?;
                let nodes: Vec<u32> = (0..geom.node_count())
                    .filter(|&n| (geom.node_position(n)[a] - p.at).abs() <= 1e-6 * h[a])
                    .map(|n| n as u32)
                    .collect();
                (nodes, Some(a))
            }
            _ => {
                return Err(src.error(
                    &format!("boundary[{i}]"),
                    "give exactly one of `region` or `plane`",
                ));
            }
        };
        if nodes.is_empty() {
            return Err(src.error(
                &format!("boundary[{i}]"),
                "selects no grid node (a plane must lie on a grid line)",
            ));
        }
        let mut axes = [false; 3];
        match (&bc.fix, normal) {
            (Some(list), _) => {
                for (k, c) in list.iter().enumerate() {
                    axes[axis_index::<D>(src, &format!("boundary[{i}].fix[{k}]"), c)?] = true;
                }
            }
            (None, Some(a)) => axes[a] = true,
            (None, None) => axes[..D::D].iter_mut().for_each(|x| *x = true),
        }
        let velocity = match &bc.velocity {
            Some(v) => vec3::<D>(src, &key("velocity"), v)?,
            None => [0.0; 3],
        };
        if let Some(msg) = bc.time.check() {
            return Err(src.error(&key("time"), msg));
        }
        bcs.push(VelocityBc {
            reaction: vec![D::zero(); nodes.len()],
            nodes,
            axes,
            velocity: to_vec::<D>(velocity),
            time: bc.time.clone(),
        });
    }
    Ok(bcs)
}
