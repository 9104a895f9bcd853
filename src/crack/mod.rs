//! Explicit cracks (CRAMP: Nairn 2003; Guo & Nairn 2D (2004) section 2.1; 3D (2006)
//! section 2): massless crack vertices joined into elements, with top and bottom surface
//! positions for the crack opening.
//!
//! The store keeps three kinds of data apart: the [`Topology`] (vertex lists, elements,
//! fronts; changes only when a crack grows, with a version number), the per-step
//! [`Geometry`] of the vertices, and the systems' [`Scratch`] (the extra velocity fields
//! and what classification and contact keep between steps).

mod element;
mod fields;
mod law;
mod topology;

pub use element::{Element, Segment, Triangle};
pub use fields::{Classified, Fields, Links, Scratch, side_bit};
pub use law::{Contact, Law};
pub use topology::{Crack, Front, Topology, TopologyError};

use crate::dim::Dim;
use crate::growth::TipState;

/// Most cracks a scene may hold (each takes two bits of a node field's side mask).
pub const MAX_CRACKS: usize = 32;

/// Where each crack vertex is (struct of arrays, one entry per vertex).
#[derive(Clone, Debug)]
pub struct Geometry<D: Dim> {
    /// Crack-plane position of each vertex (m); moves with the centre-of-mass field.
    pub x: Vec<D::Vec>,
    /// Top-surface position (m); moves with the field above the crack.
    pub top: Vec<D::Vec>,
    /// Bottom-surface position (m); moves with the field below the crack.
    pub bottom: Vec<D::Vec>,
}

impl<D: Dim> Default for Geometry<D> {
    fn default() -> Self {
        Geometry {
            x: Vec::new(),
            top: Vec::new(),
            bottom: Vec::new(),
        }
    }
}

/// The crack store: topology, vertex geometry and the crack systems' scratch.
#[derive(Clone, Debug, Default)]
pub struct Cracks<D: Dim> {
    /// What is connected to what.
    pub topology: Topology<D>,
    /// Where the vertices are.
    pub geometry: Geometry<D>,
    /// What each front's tip has grown (one per front, in the topology's order).
    pub tips: Vec<TipState>,
    /// Rebuilt or kept by the systems; not part of a snapshot.
    pub scratch: Scratch<D>,
}

impl<D: Dim<Elem = Segment>> Cracks<D> {
    /// Advances the tip of 2D front `front` to `to`: a new vertex takes the tip's place
    /// (position and both surfaces) and the tip vertex, keeping its index, moves to `to`
    /// with both surfaces closed on it. Returns the new vertex's index.
    pub fn extend_tip(&mut self, front: usize, to: D::Vec) -> u32 {
        let f = &self.topology.fronts()[front];
        let (c, end, tip) = (f.crack as usize, f.end, f.vertices[0]);
        let new = self.topology.insert_behind_tip(c, end, tip);
        let g = &mut self.geometry;
        let t = tip as usize;
        g.x.push(g.x[t]);
        g.top.push(g.top[t]);
        g.bottom.push(g.bottom[t]);
        g.x[t] = to;
        g.top[t] = to;
        g.bottom[t] = to;
        new
    }
}
