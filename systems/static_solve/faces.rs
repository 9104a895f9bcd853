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
use super::scatter::lone_entries;
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
        /// How fast the force turns with the slip across its direction (N/m): mu times the
        /// normal force over the slip, the friction's tangent ([`Spring`]); the cap
        /// ([`turn_cap`]) on a pair just come unstuck, whose slip is not known yet, so that
        /// it starts to slide along its stuck force.
        turn: f64,
        /// How the force's size changed in the round that set it (N; 0 when the pair came
        /// from another state).
        rise: f64,
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
/// is left open, as in the explicit solver). A pair with an entry that one particle alone
/// reaches ([`lone_entries`]) is frictionless: a friction force there loads motions that
/// nothing but the ghost stiffness holds, and they moved without bound.
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
    let rubs = (topo.cracks().iter()).any(|c| friction(c.contact.law).is_some_and(|mu| mu > 0.0));
    let lone = if rubs {
        lone_entries(world)
    } else {
        Vec::new()
    };
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
            friction: (mu > 0.0 && !lone[row] && !lone[own]).then_some(mu),
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

/// A sliding pair's friction linearized about its last slip s (Newton's tangent of the
/// force -mu p s / |s|, 3D only: along a 2D face the direction cannot turn): the force on
/// the field above changes by -k (P - d d^T) (its slip less s), P the projection on the face,
/// d the slip's direction, k = mu p / |s| (capped at [`turn_cap`]). The rounds of the
/// active set are then Newton iterations on the slip's direction, which a fixed point of
/// force and slip alone did not settle on faces oblique to the grid; at the settled round
/// the slip is along d and the spring carries nothing.
#[derive(Clone, Copy, Debug)]
pub(super) struct Spring<V> {
    /// The entry above the crack.
    pub above: usize,
    /// The entry below it.
    pub below: usize,
    /// The crack's unit normal.
    pub normal: V,
    /// The slip's unit direction (against the friction force).
    pub along: V,
    /// k (N/m).
    pub k: f64,
}

/// Spring `s`'s force on the field above for a relative displacement `x` (above less
/// below): -k (P - d d^T) x.
pub(super) fn spring_force<D: Dim>(s: &Spring<D::Vec>, x: D::Vec) -> D::Vec {
    let t = x - s.normal * D::dot(x, s.normal);
    (t - s.along * D::dot(t, s.along)) * -s.k
}

/// The springs of the sliding pairs with a known slip whose row `acting` takes (none in
/// 2D).
pub(super) fn springs<D: Dim>(
    pairs: &[Pair<D::Vec>],
    faces: &[Face<D::Vec>],
    acting: impl Fn(usize) -> bool,
) -> Vec<Spring<D::Vec>> {
    if D::D < 3 {
        return Vec::new();
    }
    let length = |v: D::Vec| D::dot(v, v).sqrt();
    (pairs.iter().zip(faces))
        .filter_map(|(p, face)| match *face {
            Face::Sliding { force, turn, .. }
                if turn > 0.0 && length(force) > 0.0 && acting(p.row) =>
            {
                let (above, below) = p.above_below();
                Some(Spring {
                    above,
                    below,
                    normal: p.normal,
                    along: force * (-1.0 / length(force)),
                    k: turn,
                })
            }
            _ => None,
        })
        .collect()
}

/// Adds the springs' share of K x to `y` (x every entry's displacement): minus each
/// spring's force on the field above, plus it on the one below.
pub(super) fn add_spring_forces<D: Dim>(
    springs: &[Spring<D::Vec>],
    x: &[D::Vec],
    y: &mut [D::Vec],
) {
    for s in springs {
        let f = spring_force::<D>(s, x[s.above] - x[s.below]);
        y[s.above] -= f;
        y[s.below] += f;
    }
}

/// The largest `turn` a sliding pair takes, in units of a grid entry's stiffness E h (the
/// largest Young's modulus, the smallest cell edge): a slip of next to nothing would
/// otherwise tie its direction without bound. Ten: at 1 (E h itself) a pair whose slip
/// asked for twice that still settled only at 0.83 a round (a random oblique penny; 13
/// rounds at 10, the same at 100).
const TURN_CAP: f64 = 10.0;

/// The largest `turn` a sliding pair takes (N/m): [`TURN_CAP`] times E h.
pub(super) fn turn_cap<D: Dim>(world: &World<D>) -> f64 {
    let e = (world.materials.iter())
        .map(|m| m.youngs)
        .fold(0.0, f64::max);
    let h = D::to_xyz(world.grid.geom.h);
    TURN_CAP * e * (0..D::D).map(|a| h[a]).fold(f64::INFINITY, f64::min)
}

/// How often a pair may open in one load step. A pair that overlaps while open and pulls
/// while closed would open and close for ever (on a random oblique penny, one pair pulled
/// by 0.3 N where the pressed ones carried 20 to 50 N); the third time it closes it stays
/// closed, so that the faces never overlap, at the price of that small pull.
const MOST_OPENINGS: u8 = 2;

/// Updates each pair's `faces` state from the solution `u` (every entry's displacement;
/// `start`, the entries' displacement at the step's start, empty for zero) and
/// `ku_less_f`, K u - f_ext per entry without ties folded and without the friction forces,
/// so that on a closed pair's field above it is the force the face exerts on it (the
/// constraint's and the friction's): a pair whose fields overlap along the normal by more
/// than `gap_tol` closes, sliding freely; a closed pair whose face pulls (against the
/// normal beyond `force_tol`) opens, unless it has `opened` [`MOST_OPENINGS`] times in
/// the step already; a closed pair with friction then takes mu times its
/// normal force against its slip over the step (stuck when it did not slip); a stuck pair
/// whose tangential force exceeds mu times the normal one slides, with the friction force
/// capped there; a sliding pair whose slip does not oppose its friction force sticks, and
/// otherwise takes mu times its normal force against its slip (half way there when the
/// force's size would turn back on its last change: the sizes swung between rounds, and
/// the fixed point is the same). Each sliding pair's `turn` is set from its slip and the
/// force's size, at most `most_turn`. Counts the changes of the pairs `counted` takes.
pub(super) fn update<D: Dim>(
    pairs: &[Pair<D::Vec>],
    (faces, opened): (&mut [Face<D::Vec>], &mut [u8]),
    (u, start): (&[D::Vec], &[D::Vec]),
    ku_less_f: &[D::Vec],
    (gap_tol, force_tol, most_turn): (f64, f64, f64),
    counted: impl Fn(&Pair<D::Vec>) -> bool,
) -> Changes {
    let mut changes = Changes::default();
    let along = |v: D::Vec, n: D::Vec| v - n * D::dot(v, n);
    let length = |v: D::Vec| D::dot(v, v).sqrt();
    for ((p, face), opened) in pairs.iter().zip(faces.iter_mut()).zip(opened) {
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
        if push < -force_tol && *opened < MOST_OPENINGS {
            *face = Face::Open;
            *opened += 1;
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
        let turn = (cap / size).min(most_turn);
        match *face {
            Face::Closed => {
                *face = if size <= gap_tol {
                    Face::Stuck
                } else {
                    Face::Sliding {
                        force: slip * (-cap / size),
                        turn,
                        rise: 0.0,
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
                        turn: most_turn,
                        rise: 0.0,
                    };
                    changes.slid += count;
                }
            }
            Face::Sliding { force, rise, .. } => {
                if size <= gap_tol || D::dot(slip, force) > 0.0 {
                    *face = Face::Stuck;
                    changes.slid += count;
                    continue;
                }
                let was = length(force);
                // A size that turns back on its last change swings between rounds (the
                // normal forces and the friction forces feed each other): half the step.
                let by = match (cap - was) * rise < 0.0 {
                    true => 0.5 * (cap - was),
                    false => cap - was,
                };
                let next = slip * (-(was + by) / size);
                if length(next - force) > FRICTION_TOL * length(next) + force_tol {
                    let turn = ((was + by) / size).min(most_turn);
                    *face = Face::Sliding {
                        force: next,
                        turn,
                        rise: by,
                    };
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
        if let Face::Sliding { force, .. } = *face {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::base::dim::D3;
    use glam::DVec3;

    /// The spring is the friction force's derivative: f(s) = -c s / |s| on a face of
    /// oblique normal n, s a slip along it; for a small change ds in the face, the change
    /// f(s + ds) - f(s) is the spring's force for ds to first order (within 1e-3 of it at
    /// |ds| = 1e-4 |s|, the second-order term being about |ds| / |s| of it), whatever part
    /// of ds lies along s (which turns nothing) or along n (which the face's tie carries).
    #[test]
    fn a_spring_is_the_friction_forces_tangent() {
        let n = DVec3::new(0.3, 0.9, 0.3).normalize();
        let along = |v: DVec3| v - n * v.dot(n);
        let s = along(DVec3::new(1.0, -2.0, 0.5)) * 1e-6;
        let c = 3.0;
        let friction = |s: DVec3| s * (-c / s.length());
        let spring = Spring {
            above: 0,
            below: 1,
            normal: n,
            along: s.normalize(),
            k: c / s.length(),
        };
        for ds in [DVec3::new(0.2, 0.1, -0.7), DVec3::new(-1.0, 0.4, 0.3)] {
            let ds = ds * (1e-4 * s.length());
            let exact = friction(s + along(ds)) - friction(s);
            let tangent = spring_force::<D3>(&spring, ds);
            assert!(
                (exact - tangent).length() <= 1e-3 * exact.length(),
                "{exact} vs {tangent}"
            );
        }
        assert!(spring_force::<D3>(&spring, s).length() < 1e-12 * c);
    }
}
