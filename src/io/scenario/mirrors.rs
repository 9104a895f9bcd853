//! The image nodes of the symmetry planes on quadratic B-splines ([`Mirrors`]): a
//! B-spline stencil reaches the nodes a cell past a plane, which the plane itself does not
//! hold, so each such node stands for its reflection on the body's side.

use super::check::{R, axis_index};
use super::source::Source;
use crate::base::dim::Dim;
use crate::physics::loads::VelocityBc;
use crate::physics::shape::ShapeKind;
use crate::ranks::domain::Domain;
use crate::store::grid::GridGeom;
use crate::store::mirror::{Credit, Image, Mirrors, Share};

/// Nodes past a plane that can be images: a B-spline stencil reaches one cell past the
/// plane from a particle on the body's side; the second layer covers a particle on the
/// plane itself.
const DEPTH: i64 = 2;

/// A symmetry plane on the grid: its boundary, its axis, its node index on that axis, and
/// the side the body lies on (+1 towards higher indices).
#[derive(Clone, Copy, Debug)]
struct Plane {
    boundary: usize,
    axis: usize,
    at: f64,
    index: i64,
    side: i64,
}

/// The image nodes of the scene's symmetry planes when its stencil is the quadratic
/// B-spline (none otherwise), with the image nodes taken out of every support's nodes
/// (an image follows its source, which the support holds). `x` are this rank's particle
/// positions. Refuses a plane that is not a symmetry plane (one that holds more than its
/// normal, or moves), a body on both sides of a plane, and two planes on one axis facing
/// the same way.
pub(super) fn mirrors<D: Dim>(
    src: &Source,
    geom: &GridGeom<D>,
    x: &[D::Vec],
    domain: &Domain,
    bcs: &mut [VelocityBc<D>],
) -> R<Mirrors<D>> {
    let sc = &src.scenario;
    if sc.simulation.shape != ShapeKind::Bspline {
        return Ok(Mirrors::default());
    }
    let mut planes: Vec<Plane> = Vec::new();
    for (i, bc) in sc.boundaries.iter().enumerate() {
        let Some(p) = &bc.plane else { continue };
        let key = |k: &str| format!("boundary[{i}].{k}");
        let axis = axis_index::<D>(src, &key("plane.axis"), &p.axis)?;
        let normal_only = |f: &Vec<String>| f.iter().all(|c| c == &p.axis);
        if bc.fix.as_ref().is_some_and(|f| !normal_only(f)) {
            return Err(src.error(&key("fix"), HOLDS_MORE));
        }
        if bc
            .velocity
            .as_ref()
            .is_some_and(|v| v.iter().any(|&c| c != 0.0))
        {
            return Err(src.error(&key("velocity"), MOVES));
        }
        let h = geom.h[axis];
        let index = ((p.at - geom.origin[axis]) / h).round() as i64;
        let tol = 1e-9 * h;
        let lo = domain.min(
            x.iter()
                .map(|x| x[axis] - p.at)
                .fold(f64::INFINITY, f64::min),
        );
        let hi = domain.max(
            x.iter()
                .map(|x| x[axis] - p.at)
                .fold(f64::NEG_INFINITY, f64::max),
        );
        if lo < -tol && hi > tol {
            return Err(src.error(&key("plane"), BOTH_SIDES));
        }
        let side = if hi > tol { 1 } else { -1 };
        let plane = Plane {
            boundary: i,
            axis,
            at: p.at,
            index,
            side,
        };
        if planes.iter().any(|q| q.axis == axis && q.side == side) {
            return Err(src.error(&key("plane"), SAME_WAY));
        }
        planes.push(plane);
    }
    let images: Vec<Image<D::Vec>> = (0..geom.node_count())
        .filter_map(|n| image_of(geom, &planes, n))
        .collect();
    let mut mirrors = Mirrors {
        shares: vec![
            Share {
                mass: 0.0,
                momentum: D::zero(),
                force: D::zero(),
            };
            images.len()
        ],
        images,
        planes: planes.iter().map(|p| (p.axis, p.at)).collect(),
        credits: Vec::new(),
    };
    for bc in bcs.iter_mut() {
        bc.nodes.retain(|&n| !mirrors.is_image(n));
        bc.reaction.truncate(bc.nodes.len());
    }
    mirrors.credits = credits(geom, &planes, &mirrors.images, bcs);
    Ok(mirrors)
}

/// Per image and plane it lies past, the plane node its part of the plane's reaction goes
/// to: its source's foot on the plane (the image's own foot, reflected across any other
/// plane it lies past, onto a node the plane's boundary holds).
fn credits<D: Dim>(
    geom: &GridGeom<D>,
    planes: &[Plane],
    images: &[Image<D::Vec>],
    bcs: &[VelocityBc<D>],
) -> Vec<Credit> {
    let mut out = Vec::new();
    for (k, im) in images.iter().enumerate() {
        let at = geom.node_ijk(im.node as usize).map(|c| c as i64);
        let source = geom.node_ijk(im.source as usize);
        for p in planes {
            if (p.index - at[p.axis]) * p.side <= 0 {
                continue;
            }
            let mut foot = source;
            foot[p.axis] = p.index as usize;
            let node = (0..3).map(|a| foot[a] * geom.stride[a]).sum::<usize>() as u32;
            if let Ok(place) = bcs[p.boundary].nodes.binary_search(&node) {
                out.push(Credit {
                    image: k as u32,
                    boundary: p.boundary as u32,
                    place: place as u32,
                    axis: p.axis as u8,
                });
            }
        }
    }
    out
}

/// Node `n` as an image: past at least one plane, by at most [`DEPTH`] nodes past each,
/// reflected across each plane it lies past onto a node of the grid. None otherwise.
fn image_of<D: Dim>(geom: &GridGeom<D>, planes: &[Plane], n: usize) -> Option<Image<D::Vec>> {
    let mut ijk = geom.node_ijk(n).map(|k| k as i64);
    let mut sign = D::zero();
    (0..D::D).for_each(|a| sign[a] = 1.0);
    let mut past = false;
    for p in planes {
        let depth = (p.index - ijk[p.axis]) * p.side;
        if depth <= 0 {
            continue;
        }
        if depth > DEPTH {
            return None;
        }
        ijk[p.axis] = 2 * p.index - ijk[p.axis];
        sign[p.axis] = -sign[p.axis];
        past = true;
    }
    let inside = (0..3).all(|a| ijk[a] >= 0 && (ijk[a] as usize) < geom.nodes[a]);
    (past && inside).then(|| Image {
        node: n as u32,
        source: (0..3)
            .map(|a| ijk[a] as usize * geom.stride[a])
            .sum::<usize>() as u32,
        sign,
    })
}

/// Why a B-spline plane may hold only its normal component.
const HOLDS_MORE: &str = "on quadratic B-splines a plane is a symmetry plane: it holds its \
     normal component only (the nodes past it mirror the body's side); hold other components \
     with a `region` boundary";

/// Why a B-spline plane may not move.
const MOVES: &str = "on quadratic B-splines a plane is a symmetry plane and holds its normal \
     component at rest (the nodes past it mirror the body's side); move a support with a \
     `region` boundary";

/// Why a B-spline plane needs the body on one side.
const BOTH_SIDES: &str = "on quadratic B-splines a plane is a symmetry plane, and the bodies \
     lie on both sides of this one: the nodes past it must mirror the body's side";

/// Why two B-spline planes on one axis must face each other.
const SAME_WAY: &str = "on quadratic B-splines a plane is a symmetry plane, and another \
     symmetry plane on this axis has the body on the same side";
