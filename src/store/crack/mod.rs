//! Explicit cracks (CRAMP: Nairn 2003; Guo & Nairn 2D (2004) section 2.1; 3D (2006)
//! section 2): massless crack vertices joined into elements, with top and bottom surface
//! positions for the crack opening.
//!
//! The store keeps three kinds of data apart: the [`Topology`] (vertex lists, elements,
//! fronts; changes only when a crack grows, with a version number), the per-step
//! [`Positions`] of the vertices, and the systems' [`Scratch`] (the extra velocity fields
//! and what classification and contact keep between steps).

mod bins;
mod colors;
mod fields;
mod law;
mod node_lines;
mod on_particles;
mod split;
mod tip_lines;
mod topology;

pub use bins::ElementBins;
pub use colors::{COLORS, Crowded, colors};
pub use fields::{Classified, Displacements, Fields, Links, Scratch, side_bit};
pub use law::{Contact, Law};
pub use node_lines::{NodeLine, on_node_lines};
pub use on_particles::particles_on;
pub use split::Split;
pub use tip_lines::tips_on_lines;
pub use topology::{Crack, Front, Topology, TopologyError};

use crate::base::dim::Dim;
use crate::base::geometry::{Segment, Triangle};
use crate::physics::growth::TipState;

/// Most cracks a scene may hold (element-to-crack indices are `u16`); at most
/// [`COLORS`] of them may lie within reach of one another.
pub const MAX_CRACKS: usize = u16::MAX as usize;

/// Where each crack vertex is (struct of arrays, one entry per vertex).
#[derive(Clone, Debug)]
pub struct Positions<D: Dim> {
    /// Crack-plane position of each vertex (m); moves with the centre-of-mass field.
    pub x: Vec<D::Vec>,
    /// Top-surface position (m); moves with the field above the crack.
    pub top: Vec<D::Vec>,
    /// Bottom-surface position (m); moves with the field below the crack.
    pub bottom: Vec<D::Vec>,
    /// Static scenes: each vertex's crack-plane position in the undeformed body (m), where
    /// the classification takes the crack, the particles being at their initial places
    /// there; empty in explicit runs.
    pub x0: Vec<D::Vec>,
}

impl<D: Dim> Positions<D> {
    /// A new vertex (the next index) where vertex `v` is, with its surfaces, and `v` moved
    /// to `to` with both surfaces closed on it: how a tip or front vertex advances.
    /// Where undeformed places are kept (`x0`), the new vertex takes `v`'s, and `v`'s moves
    /// as `v` does: each vertex keeps its displacement.
    fn leave_behind(&mut self, v: usize, to: D::Vec) {
        if !self.x0.is_empty() {
            self.x0.push(self.x0[v]);
            self.x0[v] = to - (self.x[v] - self.x0[v]);
        }
        self.x.push(self.x[v]);
        self.top.push(self.top[v]);
        self.bottom.push(self.bottom[v]);
        self.x[v] = to;
        self.top[v] = to;
        self.bottom[v] = to;
    }
}

impl<D: Dim> Default for Positions<D> {
    fn default() -> Self {
        Positions {
            x: Vec::new(),
            top: Vec::new(),
            bottom: Vec::new(),
            x0: Vec::new(),
        }
    }
}

/// The crack store: topology, vertex geometry and the crack systems' scratch.
#[derive(Clone, Debug, Default)]
pub struct Cracks<D: Dim> {
    /// What is connected to what.
    pub topology: Topology<D>,
    /// Where the vertices are.
    pub geometry: Positions<D>,
    /// What each front's tip has grown (one per front, in the topology's order).
    pub tips: Vec<TipState>,
    /// The topology's version at the last static solve (None before one): a static load
    /// step after growth solves again.
    pub solved: Option<u64>,
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
        self.geometry.leave_behind(tip as usize, to);
        new
    }
}

impl<D: Dim<Elem = Triangle>> Cracks<D> {
    /// Advances 3D front `front`: each front vertex with a place in `to` leaves a new
    /// vertex where it was (position and both surfaces) and, keeping its index, moves
    /// there with both surfaces closed on it; a strip of triangles fills the band between
    /// (see [`Topology::insert_behind_front`]). `closed` says whether the front is a loop.
    pub fn advance_front(
        &mut self,
        front: usize,
        to: &[Option<D::Vec>],
        closed: bool,
    ) -> Result<(), TopologyError> {
        let moves: Vec<bool> = to.iter().map(Option::is_some).collect();
        let behind = self.topology.insert_behind_front(front, &moves, closed)?;
        let fv = &self.topology.fronts()[front].vertices;
        for ((&v, &b), t) in fv.iter().zip(&behind).zip(to) {
            if let Some(t) = *t {
                debug_assert_eq!(b as usize, self.geometry.x.len());
                self.geometry.leave_behind(v as usize, t);
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::base::dim::D3;
    use glam::DVec3;
    use std::collections::HashSet;

    /// A hexagon of radius 1 in the plane z = 0 fanned from its centre (counterclockwise
    /// seen from +z), its six rim vertices the closed front.
    fn hexagon() -> Cracks<D3> {
        let mut c = Cracks::<D3>::default();
        let tris: Vec<Triangle> = (0..6).map(|i| [0, 1 + i, 1 + (i + 1) % 6]).collect();
        let front = vec![(0, (1..7).collect())];
        let open = Contact::OPEN;
        c.topology
            .add_crack("h".into(), open, None, 7, &tris, &front);
        let rim = (0..6).map(|i| {
            let t = i as f64 * std::f64::consts::FRAC_PI_3;
            DVec3::new(t.cos(), t.sin(), 0.0)
        });
        c.geometry.x = std::iter::once(DVec3::ZERO).chain(rim).collect();
        c.geometry.top = c.geometry.x.clone();
        c.geometry.bottom = c.geometry.x.clone();
        c
    }

    /// Area of the crack and whether its triangles are consistently oriented (no directed
    /// edge twice, so neighbours run their shared edge in opposite directions), all facing
    /// +z.
    fn area_and_orientation(c: &Cracks<D3>) -> (f64, bool) {
        let x = &c.geometry.x;
        let mut edges = HashSet::new();
        let mut area = 0.0;
        let mut ok = true;
        for t in c.topology.elems() {
            let n =
                (x[t[1] as usize] - x[t[0] as usize]).cross(x[t[2] as usize] - x[t[0] as usize]);
            ok &= n.z > 0.0;
            area += 0.5 * n.length();
            for k in 0..3 {
                ok &= edges.insert((t[k], t[(k + 1) % 3]));
            }
        }
        (area, ok)
    }

    /// Every rim vertex moved out by 0.5 along its radius: the crack is the hexagon of
    /// radius 1.5 (area 3 sqrt(3)/2 r^2), the front keeps its indices, and the band holds
    /// two triangles per front edge, all oriented as the rest.
    #[test]
    fn advancing_a_closed_front_fills_the_band_it_leaves() {
        let mut c = hexagon();
        let to: Vec<Option<DVec3>> = (1..7).map(|v| Some(c.geometry.x[v] * 1.5)).collect();
        let version = c.topology.version();
        c.advance_front(0, &to, true).unwrap();
        assert_eq!(
            c.topology.fronts()[0].vertices,
            (1..7).collect::<Vec<u32>>()
        );
        assert_eq!(c.topology.vertex_count(), 13);
        assert_eq!(c.topology.elems().len(), 6 + 12);
        assert!(c.topology.version() > version);
        let (area, ok) = area_and_orientation(&c);
        assert!(ok, "consistently oriented");
        let exact = 1.5 * 3f64.sqrt() * 1.5 * 1.5;
        assert!((area - exact).abs() < 1e-12, "{area} against {exact}");
        // The vertices left behind sit where the front was.
        assert!((c.geometry.x[7] - DVec3::new(1.0, 0.0, 0.0)).length() < 1e-15);
    }

    /// A front vertex that does not move keeps its triangles; each edge next to it gains
    /// one triangle, not two.
    #[test]
    fn a_vertex_that_stays_closes_its_band_to_triangles() {
        let mut c = hexagon();
        let mut to: Vec<Option<DVec3>> = (1..7).map(|v| Some(c.geometry.x[v] * 1.5)).collect();
        to[0] = None;
        c.advance_front(0, &to, true).unwrap();
        assert_eq!(c.topology.vertex_count(), 12);
        assert_eq!(c.topology.elems().len(), 6 + 10);
        let (area, ok) = area_and_orientation(&c);
        assert!(ok, "consistently oriented");
        // The radius-1.5 hexagon less the two triangles cut off at the vertex that stayed:
        // each has base 0.5 along the radius and height sqrt(3)/2 * 1.5 from it.
        let exact = 1.5 * 3f64.sqrt() * 2.25 - 2.0 * 0.5 * 0.5 * 1.5 * 3f64.sqrt() / 2.0;
        assert!((area - exact).abs() < 1e-12, "{area} against {exact}");
    }
}
