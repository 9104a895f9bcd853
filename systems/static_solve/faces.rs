//! Crack faces that close in a static load step. Where a node carries a field on each side
//! of a crack with frictionless or Coulomb contact, the two fields may not overlap along
//! the crack's normal (Guo & Nairn 3D (2006) Appendix B, Eq. 69, as a constraint): a closed
//! pair moves together along the normal; along the face it moves freely (frictionless),
//! together (Coulomb, stuck) or apart against a friction force mu times the normal one
//! (Coulomb, sliding). Which pairs are in which state is found by an active set: solve,
//! close the pairs that overlap, open the closed pairs whose faces pull on each other, let
//! slide the stuck pairs whose tangential force exceeds mu times the normal one, stick the
//! sliding pairs that no longer slide against their friction, and solve again until
//! nothing changes (the textbook active set for Coulomb friction, e.g. Wriggers 2006,
//! Computational Contact Mechanics, ch. 5-6).

use super::fields;
use crate::base::dim::Dim;
use crate::store::crack::{COLORS, ElementBins, Law};
use crate::store::world::World;
use crate::systems::contact::nearest;

/// A node's pair of fields across one crack with a contact law.
#[derive(Clone, Copy, Debug)]
pub(super) struct Pair<V> {
    /// The crack field's row (the tied entry).
    pub row: usize,
    /// The node's own entry.
    pub own: usize,
    /// Whether the row holds the side above the crack.
    pub row_above: bool,
    /// The crack's unit normal, pointing above.
    pub normal: V,
    /// The Coulomb friction coefficient, None on frictionless faces.
    pub friction: Option<f64>,
}

/// How a pair's faces meet in an active-set round.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Face<V> {
    /// Apart: each field moves on its own.
    Open,
    /// Closed without friction: the fields move together along the normal only.
    Closed,
    /// Closed and stuck (Coulomb, the tangential force within mu times the normal one): the
    /// fields move together.
    Stuck,
    /// Closed and sliding (Coulomb): together along the normal, while the face carries the
    /// friction force `force` on the field above (its negative on the one below).
    Sliding {
        /// The friction force on the field above (N), along the face.
        force: V,
    },
}

impl<V> Face<V> {
    /// Whether the faces touch.
    pub fn closed(&self) -> bool {
        !matches!(self, Face::Open)
    }
}

impl<V> Pair<V> {
    /// The entries above and below the crack.
    pub fn above_below(&self) -> (usize, usize) {
        if self.row_above {
            (self.row, self.own)
        } else {
            (self.own, self.row)
        }
    }
}

/// Every pair of fields across a crack with frictionless or Coulomb contact whose entries
/// both carry mass, in row order (a row behind two cracks at once has no single normal and
/// is left open, as in the explicit solver).
pub(super) fn pairs<D: Dim>(world: &World<D>) -> Vec<Pair<D::Vec>> {
    let (Some(cracks), Some(f)) = (world.cracks.as_ref(), fields(world)) else {
        return Vec::new();
    };
    let topo = &cracks.topology;
    let mut acts = [false; COLORS];
    for (c, crack) in topo.cracks().iter().enumerate() {
        acts[cracks.scratch.color(c) as usize] |= friction(crack.contact.law).is_some();
    }
    let g = &world.grid;
    let tol = world.settings.mass_tol;
    let h = D::to_xyz(g.geom.h);
    let cell = std::array::from_fn(|k| if k < D::D { h[k] } else { 1.0 });
    let mut bins: Vec<Option<ElementBins>> = Vec::new();
    bins.resize_with(COLORS, || None);
    let mut out = Vec::new();
    for (r, &mask) in f.mask.iter().enumerate() {
        if mask.count_ones() != 1 {
            continue;
        }
        let bit = mask.trailing_zeros() as usize;
        let (color, row_above) = (bit / 2, bit.is_multiple_of(2));
        let (own, row) = (f.node[r] as usize, f.nodes + r);
        if !acts[color] || g.mass[own] <= tol || g.mass[row] <= tol {
            continue;
        }
        let at = g.geom.node_position(own);
        let Some((c, normal)) = nearest::<D>(&mut bins, cracks, cell, color as u8, at) else {
            continue;
        };
        let Some(mu) = friction(topo.cracks()[c].contact.law) else {
            continue;
        };
        out.push(Pair {
            row,
            own,
            row_above,
            normal,
            friction: (mu > 0.0).then_some(mu),
        });
    }
    out
}

/// The friction coefficient of a law the static solver's faces act on (0 frictionless),
/// None for open cracks.
fn friction(law: Law) -> Option<f64> {
    match law {
        Law::Frictionless => Some(0.0),
        Law::Coulomb(mu) => Some(mu),
        Law::None | Law::Stick => None,
    }
}

/// What an active-set round changed: pairs closed (they overlapped), opened (they pulled),
/// set sliding or stuck, and sliding pairs whose friction force moved.
#[derive(Default)]
pub(super) struct Changes {
    pub closed: usize,
    pub opened: usize,
    pub slid: usize,
}

impl Changes {
    /// Whether the round changed nothing.
    pub fn none(&self) -> bool {
        self.closed + self.opened + self.slid == 0
    }
}

/// How far a sliding pair's friction force may move between two rounds and still count as
/// settled, relative to its size: the fixed point of the normal force and the slip
/// direction is then held to what a preconditioner's answer means.
pub(super) const FRICTION_TOL: f64 = 1e-6;

/// Updates each pair's `faces` state from the solution `u` (every entry's displacement;
/// `start`, the entries' displacement at the step's start, empty for zero) and
/// `ku_less_f`, K u - f_ext per entry without ties folded and without the friction forces,
/// so that on a closed pair's field above it is the force the face exerts on it (the
/// constraint's and the friction's): a pair whose fields overlap along the normal by more
/// than `gap_tol` closes, sliding freely; a closed pair whose face pulls (against the
/// normal beyond `force_tol`) opens; a closed pair with friction then takes mu times its
/// normal force against its slip over the step (stuck when it did not slip); a stuck pair
/// whose tangential force exceeds mu times the normal one slides, with the friction force
/// capped there; a sliding pair whose slip does not oppose its friction force sticks, and
/// otherwise takes mu times its normal force against its slip. Counts the changes of the
/// pairs `counted` takes.
pub(super) fn update<D: Dim>(
    pairs: &[Pair<D::Vec>],
    faces: &mut [Face<D::Vec>],
    (u, start): (&[D::Vec], &[D::Vec]),
    ku_less_f: &[D::Vec],
    (gap_tol, force_tol): (f64, f64),
    counted: impl Fn(&Pair<D::Vec>) -> bool,
) -> Changes {
    let mut changes = Changes::default();
    let along = |v: D::Vec, n: D::Vec| v - n * D::dot(v, n);
    let length = |v: D::Vec| D::dot(v, v).sqrt();
    for (p, face) in pairs.iter().zip(faces.iter_mut()) {
        let (a, b) = p.above_below();
        let count = counted(p) as usize;
        let n = p.normal;
        if !face.closed() {
            if D::dot(u[a] - u[b], n) < -gap_tol {
                *face = Face::Closed;
                changes.closed += count;
            }
            continue;
        }
        let push = D::dot(ku_less_f[a], n);
        if push < -force_tol {
            *face = Face::Open;
            changes.opened += count;
            continue;
        }
        let Some(mu) = p.friction else {
            continue;
        };
        let cap = mu * push.max(0.0);
        let moved = |e: usize| u[e] - start.get(e).copied().unwrap_or(D::zero());
        let slip = along(moved(a) - moved(b), n);
        let size = length(slip);
        match *face {
            Face::Closed => {
                *face = if size <= gap_tol {
                    Face::Stuck
                } else {
                    Face::Sliding {
                        force: slip * (-cap / size),
                    }
                };
                changes.slid += count;
            }
            Face::Stuck => {
                let t = along(ku_less_f[a], n);
                let size = length(t);
                if size > cap + force_tol {
                    *face = Face::Sliding {
                        force: t * (cap / size),
                    };
                    changes.slid += count;
                }
            }
            Face::Sliding { force } => {
                if size <= gap_tol || D::dot(slip, force) > 0.0 {
                    *face = Face::Stuck;
                    changes.slid += count;
                    continue;
                }
                let next = slip * (-cap / size);
                if length(next - force) > FRICTION_TOL * length(next) + force_tol {
                    *face = Face::Sliding { force: next };
                    changes.slid += count;
                }
            }
            Face::Open => {}
        }
    }
    changes
}

/// Adds each sliding pair's friction force to `f` (per entry): on the field above, and its
/// negative on the one below.
pub(super) fn add_friction<D: Dim>(
    pairs: &[Pair<D::Vec>],
    faces: &[Face<D::Vec>],
    f: &mut [D::Vec],
) {
    for (p, face) in pairs.iter().zip(faces) {
        if let Face::Sliding { force } = *face {
            let (a, b) = p.above_below();
            f[a] += force;
            f[b] -= force;
        }
    }
}

/// Per entry, what a stuck pair's field keeps of its slip: the field's displacement less
/// its partner's at the step's `start`, along the face, on the stuck pairs' rows that
/// `tied` holds (the rows tied to their node's entry); None when none keeps any. A load
/// step solves for the total displacement, and a face stuck over the step keeps the slip
/// it had at the step's start, not none.
pub(super) fn kept_slip<D: Dim>(
    pairs: &[Pair<D::Vec>],
    faces: &[Face<D::Vec>],
    start: &[D::Vec],
    tied: impl Fn(usize, usize) -> bool,
) -> Option<Vec<D::Vec>> {
    if start.is_empty() {
        return None;
    }
    let mut kept = vec![D::zero(); start.len()];
    let mut any = false;
    for (p, face) in pairs.iter().zip(faces) {
        if *face == Face::Stuck && tied(p.row, p.own) {
            let d = start[p.row] - start[p.own];
            kept[p.row] = d - p.normal * D::dot(d, p.normal);
            any = true;
        }
    }
    any.then_some(kept)
}
