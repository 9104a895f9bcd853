//! Image nodes of the symmetry planes on quadratic B-splines: the grid nodes past a plane
//! that the body's stencils reach, each standing for a node on the body's side reflected
//! across the plane (as the whole body's mirror half would move it).

use crate::base::dim::Dim;

/// One image node and the node on the body's side it reflects.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Image<V> {
    /// The node past the plane (or planes, at a corner).
    pub node: u32,
    /// The node it reflects, on the body's side of every plane.
    pub source: u32,
    /// Per axis, -1 on the normal of each plane between them, +1 on the others: the
    /// image's velocity is `sign` times the source's, component by component.
    pub sign: V,
}

/// What this step's scatter left on one image before the fold: the body's own share of the
/// node, from which the image's part of the force across its planes follows.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Share<V> {
    /// Mass (kg).
    pub mass: f64,
    /// Momentum (kg m/s).
    pub momentum: V,
    /// Force (N): the loads, and the internal force once scattered.
    pub force: V,
}

/// Where an image's part of a plane's reaction is booked: on the plane's normal `axis`,
/// at the plane node `place` of boundary `boundary`'s nodes (the image's foot on the plane,
/// reflected into the body's side across the other planes).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Credit {
    /// The image's index in [`Mirrors::images`].
    pub image: u32,
    /// The plane's boundary, by its index among the scene's boundaries.
    pub boundary: u32,
    /// The foot's place in that boundary's node list.
    pub place: u32,
    /// The plane's normal axis.
    pub axis: u8,
}

/// The scene's image nodes, in node order; none without a B-spline symmetry plane.
#[derive(Clone, Debug)]
pub struct Mirrors<D: Dim> {
    /// The images, sorted by `node`; no source is an image.
    pub images: Vec<Image<D::Vec>>,
    /// The symmetry planes: their normal axis and coordinate (m).
    pub planes: Vec<(usize, f64)>,
    /// Per image, what the last scatter left on it (scratch, remade every step).
    pub shares: Vec<Share<D::Vec>>,
    /// Per image and plane it lies past, where its part of that plane's reaction goes.
    pub credits: Vec<Credit>,
}

impl<D: Dim> Default for Mirrors<D> {
    fn default() -> Self {
        Mirrors {
            images: Vec::new(),
            planes: Vec::new(),
            shares: Vec::new(),
            credits: Vec::new(),
        }
    }
}

impl<D: Dim> Mirrors<D> {
    /// Whether the scene has no image nodes.
    pub fn is_empty(&self) -> bool {
        self.images.is_empty()
    }

    /// Whether grid node `n` is an image.
    pub fn is_image(&self, n: u32) -> bool {
        self.images.binary_search_by_key(&n, |i| i.node).is_ok()
    }

    /// The component-wise reflection of `v` by `sign`.
    #[inline(always)]
    pub fn reflect(sign: D::Vec, v: D::Vec) -> D::Vec {
        let mut out = v;
        (0..D::D).for_each(|a| out[a] *= sign[a]);
        out
    }
}
