//! Crack colours: a field's crack-side mask has two bits per colour, not per crack, so a
//! scene may hold more cracks than a mask has bits for. Cracks that no particle's stencil
//! can see at once may share a colour; with at most [`COLORS`] cracks each is its own.

use super::Topology;
use crate::base::dim::Dim;
use crate::base::geometry::{Aabb, Element, meeting_pairs};
use glam::DVec3;

/// Colours a mask has room for (two bits each in a `u64`).
pub const COLORS: usize = 32;

/// Cells by which each crack's box is widened before two boxes that meet rule out a shared
/// colour: a stencil's node box spans at most three cells, and classification reuses its
/// record while nothing moves more than a quarter cell.
const REACH_CELLS: f64 = 3.5;

/// Two cracks that would need the same colour, in a scene whose cracks need more than
/// [`COLORS`] colours near one place.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Crowded {
    /// The crack left without a colour.
    pub crack: usize,
    /// One of the cracks near it.
    pub near: usize,
}

/// Each crack's colour: the index itself with at most [`COLORS`] cracks; otherwise the least
/// colour not taken by an earlier crack whose box, widened by [`REACH_CELLS`] cells of size
/// `cell` (m), meets this crack's box widened the same way (a deterministic function of the
/// present geometry, so a resumed run colours as the original did).
pub fn colors<D: Dim>(topology: &Topology<D>, x: &[D::Vec], cell: f64) -> Result<Vec<u8>, Crowded> {
    let n = topology.cracks().len();
    if n <= COLORS {
        return Ok((0..n as u8).collect());
    }
    let grow = REACH_CELLS * cell;
    // Each crack's box, widened along the scene's axes.
    let empty = Aabb {
        lo: DVec3::INFINITY,
        hi: DVec3::NEG_INFINITY,
    };
    let mut boxes: Vec<Aabb<DVec3>> = vec![empty; n];
    for (el, &c) in topology.elems().iter().zip(topology.elem_crack()) {
        let e = el.bounds(x).padded();
        let b = &mut boxes[c as usize];
        for k in 0..3 {
            let g = if k < D::D { grow } else { 0.0 };
            b.lo[k] = b.lo[k].min(e.lo[k] - g);
            b.hi[k] = b.hi[k].max(e.hi[k] + g);
        }
    }
    // Each crack's earlier (lower-index) neighbours: the widened boxes that meet its own.
    let mut earlier: Vec<Vec<usize>> = vec![Vec::new(); n];
    meeting_pairs(&boxes, |a, b| earlier[b].push(a));
    let mut color = vec![0u8; n];
    for c in 0..n {
        let taken = (earlier[c].iter()).fold(0u64, |t, &d| t | 1 << color[d]);
        let free = (!taken).trailing_zeros() as usize;
        if free >= COLORS {
            return Err(Crowded {
                crack: c,
                near: earlier[c].iter().copied().max().unwrap_or(c),
            });
        }
        color[c] = free as u8;
    }
    Ok(color)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::base::dim::D2;
    use crate::store::crack::Contact;
    use glam::DVec2;

    /// `n` short vertical cracks at x = k * `gap` (m), 1 mm long.
    fn row(n: usize, gap: f64) -> (Topology<D2>, Vec<DVec2>) {
        let open = Contact::OPEN;
        let mut t = Topology::<D2>::default();
        let mut x = Vec::new();
        for k in 0..n {
            t.add_crack(format!("c{k}"), open, None, 2, &[[0, 1]], &[]);
            let at = k as f64 * gap;
            x.extend([DVec2::new(at, 0.0), DVec2::new(at, 1e-3)]);
        }
        (t, x)
    }

    /// At most 32 cracks keep their own colours; more get colours that cracks within reach
    /// of each other never share, and too many within reach of one place are refused.
    #[test]
    fn near_cracks_never_share_a_colour() {
        let (t, x) = row(32, 1e-3);
        assert_eq!(
            colors::<D2>(&t, &x, 1e-3).unwrap(),
            (0..32).collect::<Vec<u8>>()
        );
        let (t, x) = row(200, 2e-3);
        let c = colors::<D2>(&t, &x, 1e-3).unwrap();
        // Boxes widened by 3.5 mm meet up to 3 cracks away (6 mm apart, 7 mm of reach).
        for a in 0..200 {
            for b in a + 1..(a + 4).min(200) {
                assert_ne!(c[a], c[b], "cracks {a} and {b}");
            }
        }
        assert!(c.iter().all(|&k| k < 4));
        let (t, x) = row(40, 1e-4);
        let e = colors::<D2>(&t, &x, 1e-3).unwrap_err();
        assert_eq!(e.crack, 32);
    }
}
