//! `classify`: the velocity field of every particle-node pair near a crack (Guo & Nairn 2D
//! (2004) section 2.1; 3D (2006) Appendix A) and the extra field rows of the grid. A line
//! from particle to node that crosses a crack an odd number of times puts the pair in the
//! node's field for that crack side; an even number counts as none.
//!
//! A full pass classifies the particles within reach of a crack and records, for each, how
//! far it and the cracks may move before a crossing can change (its clearance, capped at a
//! skin of a quarter cell). Later steps reclassify only the particles whose record no
//! longer holds (clearance used up, or a new stencil) until the skin itself is used up; the
//! result is exactly that of a full pass.

use crate::base::dim::Dim;
use crate::base::error::Unstable;
use crate::base::geometry::{Aabb, Element};
use crate::physics::shape::{ShapeKind, Stencil, StencilCache};
use crate::ranks::domain::Domain;
use crate::store::crack::{self, Classified, Cracks, Fields, Split, side_bit};
use crate::store::grid::GridGeom;
use crate::store::tiles::Tiles;
use crate::store::world::World;
use crate::with_shape;
use rayon::prelude::*;
use std::collections::HashMap;

/// The crack elements with their boxes, sorted along the axis in which the cracks spread
/// most, so the elements a box can meet are one run of the list.
struct Elements<'a, D: Dim> {
    x: &'a [D::Vec],
    elems: &'a [D::Elem],
    elem_crack: &'a [u16],
    /// Each crack's colour: the pair of mask bits its crossings set.
    color: &'a [u8],
    boxes: Vec<Aabb<D::Vec>>,
    order: Vec<u32>,
    axis: usize,
    widest: f64,
    /// Per element and boundary feature, the one other element sharing that feature when
    /// a crossing through it is parity-safe ([`Dim::SHARED_FEATURE_SAFE`]), else `NONE`.
    neighbour: &'a [[u32; 3]],
    /// Box of all the elements (None without elements).
    all: Option<Aabb<D::Vec>>,
    /// Per crack, whether it splits only pairs whose feet lie inside it ([`Split::Inside`]).
    inside: Vec<bool>,
    /// Per element, whether it belongs to such a crack and has a boundary feature (a front,
    /// or an edge where the crack ends): the feet near it can move in or out.
    inside_edge: Vec<bool>,
}

/// No element.
const NONE: u32 = u32::MAX;

impl<'a, D: Dim> Elements<'a, D> {
    fn new(
        x: &'a [D::Vec],
        elems: &'a [D::Elem],
        elem_crack: &'a [u16],
        color: &'a [u8],
        neighbour: &'a [[u32; 3]],
        split: impl Iterator<Item = Split>,
    ) -> Self {
        let boxes: Vec<Aabb<D::Vec>> = elems.iter().map(|e| e.bounds(x)).collect();
        let all = (boxes.iter().copied()).reduce(|a, b| a.union(&b));
        let extent = |k: usize| all.map_or(0.0, |b| b.hi[k] - b.lo[k]);
        let axis = (0..D::D)
            .max_by(|&a, &b| extent(a).total_cmp(&extent(b)))
            .unwrap_or(0);
        let mut order: Vec<u32> = (0..boxes.len() as u32).collect();
        order.sort_by(|&a, &b| boxes[a as usize].lo[axis].total_cmp(&boxes[b as usize].lo[axis]));
        let widest = boxes
            .iter()
            .map(|b| b.hi[axis] - b.lo[axis])
            .fold(0.0, f64::max);
        let inside: Vec<bool> = split.map(|s| s == Split::Inside).collect();
        let features = <D::Elem as Element>::FEATURES;
        let inside_edge = (elem_crack.iter().zip(neighbour))
            .map(|(&c, nb)| inside[c as usize] && nb[..features].contains(&NONE))
            .collect();
        Elements {
            x,
            elems,
            elem_crack,
            color,
            boxes,
            order,
            axis,
            widest,
            neighbour,
            all,
            inside,
            inside_edge,
        }
    }

    /// The run of `order` whose boxes can meet `b` along the sorting axis.
    fn run(&self, b: &Aabb<D::Vec>) -> &[u32] {
        let (ax, boxes) = (self.axis, &self.boxes);
        let first = self
            .order
            .partition_point(|&e| boxes[e as usize].lo[ax] < b.lo[ax] - self.widest);
        let last = self
            .order
            .partition_point(|&e| boxes[e as usize].lo[ax] <= b.hi[ax]);
        &self.order[first..last.max(first)]
    }

    /// Whether some element's box meets `b`.
    fn any_meeting(&self, b: &Aabb<D::Vec>) -> bool {
        (self.run(b).iter()).any(|&e| b.overlaps(&self.boxes[e as usize]))
    }

    /// Whether an element of a [`Split::Inside`] crack with a boundary feature meets `b`.
    fn any_inside_edge(&self, b: &Aabb<D::Vec>) -> bool {
        (self.run(b).iter())
            .any(|&e| self.inside_edge[e as usize] && b.overlaps(&self.boxes[e as usize]))
    }

    /// Whether the foot of `y` on the plane of element `e0` lies inside `e0`'s crack: the
    /// line from `y` to its mirror image in that plane crosses the crack an odd number of
    /// times (a point on the plane is moved off it by a rounding's width first).
    fn foot_inside(&self, y: D::Vec, e0: usize) -> bool {
        let el = self.elems[e0];
        let n = el.normal(self.x);
        let a = self.x[el.vertices()[0] as usize];
        let b = &self.boxes[e0];
        let size = (0..D::D).map(|k| b.hi[k] - b.lo[k]).fold(0.0, f64::max);
        let d = D::dot(n, y - a);
        let y2 = y - n * (2.0 * d + (1e-9 * size).copysign(d));
        let line = Aabb::span(y, y2);
        let crack = self.elem_crack[e0];
        let crossings = (self.run(&line).iter())
            .map(|&e| e as usize)
            .filter(|&e| self.elem_crack[e] == crack && line.overlaps(&self.boxes[e]))
            .filter(|&e| self.elems[e].crossing(y, y2, self.x) != 0)
            .count();
        crossings % 2 == 1
    }

    /// Replaces `out` with the elements whose boxes meet `b`, in increasing element order.
    fn meeting(&self, b: &Aabb<D::Vec>, out: &mut Vec<u32>) {
        out.clear();
        out.extend((self.run(b).iter()).filter(|&&e| b.overlaps(&self.boxes[e as usize])));
        out.sort_unstable();
    }

    /// Crack-side mask of the line from `xp` to `xn` against elements `near` (with the side
    /// of `xp` to each), taken in increasing element order so the result never depends on
    /// how the elements were found. A [`Split::Inside`] crack also needs both feet inside
    /// it, taken on the plane of the first element crossed.
    fn mask(&self, xp: D::Vec, xn: D::Vec, near: &[(u32, i8)]) -> u64 {
        let line = Aabb::span(xp, xn);
        let (mut odd, mut above) = (0u32, 0u32);
        let mut first = [NONE; 32];
        for &(e, sp) in near {
            let e = e as usize;
            if !line.overlaps(&self.boxes[e]) {
                continue;
            }
            let s = self.elems[e].crossing_from(xp, sp, xn, self.x);
            if s != 0 {
                let c = self.color[self.elem_crack[e] as usize];
                if first[c as usize] == NONE {
                    first[c as usize] = e as u32;
                }
                let bit = 1u32 << c;
                odd ^= bit;
                if s > 0 {
                    above |= bit;
                } else {
                    above &= !bit;
                }
            }
        }
        let mut mask = 0;
        while odd != 0 {
            let c = odd.trailing_zeros() as usize;
            odd &= odd - 1;
            let e0 = first[c] as usize;
            if self.inside[self.elem_crack[e0] as usize]
                && !(self.foot_inside(xp, e0) && self.foot_inside(xn, e0))
            {
                continue;
            }
            mask |= side_bit(c, if above >> c & 1 == 1 { 1 } else { -1 });
        }
        mask
    }
}

/// Per element and boundary feature, the one other element sharing that feature when a
/// crossing through it is parity-safe ([`Dim::SHARED_FEATURE_SAFE`]), else `NONE`. Depends
/// on the elements' connectivity only, so `run` rebuilds it only when that changes.
fn neighbours<D: Dim>(elems: &[D::Elem]) -> Vec<[u32; 3]> {
    let mut neighbour = vec![[NONE; 3]; elems.len()];
    if D::Elem::SHARED_FEATURE_SAFE {
        let mut sharing: HashMap<[u32; 2], Vec<u32>> = HashMap::new();
        for (e, &el) in elems.iter().enumerate() {
            for k in 0..<D::Elem as Element>::FEATURES {
                let mut f = el.feature(k);
                f.sort_unstable();
                sharing.entry(f).or_default().push(e as u32);
            }
        }
        for (e, &el) in elems.iter().enumerate() {
            for (k, nb) in neighbour[e]
                .iter_mut()
                .enumerate()
                .take(<D::Elem as Element>::FEATURES)
            {
                let mut f = el.feature(k);
                f.sort_unstable();
                if let [a, b] = sharing[&f][..] {
                    *nb = if a == e as u32 { b } else { a };
                }
            }
        }
    }
    neighbour
}

/// One watched particle's entries in the classification record.
struct Slot<'a> {
    first: &'a mut u32,
    budget: &'a mut f64,
    crosses: &'a mut bool,
    masks: &'a mut [u64],
}

/// Scratch lists reused from particle to particle.
struct Scratch<D: Dim> {
    close: Vec<u32>,
    near: Vec<(u32, i8)>,
    nodes: Vec<D::Vec>,
}

impl<D: Dim> Scratch<D> {
    fn new() -> Self {
        Scratch {
            close: Vec::new(),
            near: Vec::new(),
            nodes: Vec::new(),
        }
    }
}

/// What one classification step reads.
struct Pass<'a, D: Dim> {
    geom: &'a GridGeom<D>,
    shape: ShapeKind,
    stencils: &'a StencilCache,
    elements: Elements<'a, D>,
    /// Largest clearance recorded (m).
    skin: f64,
    /// Round-off allowance on the distances and on the sums of displacements (m).
    slack: f64,
}

impl<D: Dim> Pass<'_, D> {
    /// Stencil nodes per particle.
    fn per(&self) -> usize {
        self.shape.nodes().pow(D::D as u32)
    }

    /// Classifies particle `xp` with stencil `st`: writes the crack-side mask of every
    /// stencil node to `masks` and, when `clear`, returns its clearance (at most the skin),
    /// the distance it and the cracks may move before any of those masks can change;
    /// otherwise zero.
    fn classify_one<const N: usize>(
        &self,
        xp: D::Vec,
        st: &Stencil<N>,
        clear: bool,
        s: &mut Scratch<D>,
        masks: &mut [u64],
    ) -> f64 {
        let (geom, elements) = (self.geom, &self.elements);
        // Every line from the particle to a node of its stencil lies in the stencil's node
        // box (which holds the particle).
        let base = geom.node_ijk(st.first);
        let mut corners = [D::zero(); 8];
        for (k, c) in corners.iter_mut().enumerate().take(1 << D::D) {
            *c = geom.origin;
            for a in 0..D::D {
                let i = base[a] + (N - 1) * (k >> a & 1);
                c[a] += i as f64 * geom.h[a];
            }
        }
        let corners = &corners[..1 << D::D];
        let node_box = Aabb {
            lo: corners[0],
            hi: corners[corners.len() - 1],
        };
        let reach = if clear { self.skin } else { 0.0 };
        elements.meeting(&node_box.grown(reach), &mut s.close);
        // Node positions in the stencil's order (x fastest, then y, then z), from the base
        // rather than `node_position` (which divides), when some element is close.
        s.nodes.clear();
        if !s.close.is_empty() {
            let nk = if D::D == 3 { N } else { 1 };
            for k in 0..nk {
                for j in 0..N {
                    for i in 0..N {
                        let mut xn = geom.origin;
                        for (a, o) in [i, j, k].into_iter().enumerate().take(D::D) {
                            xn[a] += (base[a] + o) as f64 * geom.h[a];
                        }
                        s.nodes.push(xn);
                    }
                }
            }
        }
        // Elements meeting the node box whose line or plane does not have the particle and
        // every corner on one side can be crossed now. Every element within the skin bounds
        // the clearance: a crossing can change only when the particle or a node meets the
        // element or one of its features meets the particle-node line; a feature shared with
        // an element the particle sees from the same side matters only once the particle
        // reaches either's line or plane. Once the clearance is zero the particle is redone
        // every step anyway.
        s.near.clear();
        let x = elements.x;
        let mut clearance = if clear { self.skin } else { 0.0 };
        // Feet of the box's points on a plane through it lie within its diagonal of it:
        // near the edge of a `Split::Inside` crack they may move in or out with any motion,
        // so such a particle is redone every step.
        let diagonal = D::dot(node_box.hi - node_box.lo, node_box.hi - node_box.lo).sqrt();
        if clearance > 0.0 && elements.any_inside_edge(&node_box.grown(diagonal + reach)) {
            clearance = 0.0;
        }
        for &e in &s.close {
            let el = elements.elems[e as usize];
            let sp = el.side(xp, x);
            if node_box.overlaps(&elements.boxes[e as usize])
                && corners.iter().any(|&c| el.side(c, x) != sp)
            {
                s.near.push((e, sp));
            }
            if clearance <= self.slack {
                continue;
            }
            clearance = clearance.min(el.distance(xp, x));
            let mut open = [false; 3];
            for (k, o) in open
                .iter_mut()
                .enumerate()
                .take(<D::Elem as Element>::FEATURES)
            {
                let nb = elements.neighbour[e as usize][k];
                if nb != NONE && elements.elems[nb as usize].side(xp, x) == sp {
                    let both = el
                        .plane_distance(xp, x)
                        .min(elements.elems[nb as usize].plane_distance(xp, x));
                    clearance = clearance.min(both);
                } else {
                    *o = true;
                }
            }
            // A node (or its line from the particle, when a feature is open) whose box
            // lies farther from the element's box than the clearance cannot lower it.
            let any_open = open.iter().any(|&o| o);
            let bx = &elements.boxes[e as usize];
            for &xn in &s.nodes {
                let from = if any_open {
                    Aabb::span(xp, xn)
                } else {
                    Aabb::at(xn)
                };
                if from.gap_sq(bx) > clearance * clearance * (1.0 + 1e-9) {
                    continue;
                }
                let mut c = el.distance(xn, x);
                for k in (0..<D::Elem as Element>::FEATURES).filter(|&k| open[k]) {
                    c = c.min(el.feature_distance(xp, xn, x, k));
                }
                clearance = clearance.min(c);
            }
        }
        // A record that must hold over later steps needs every node's mask; one redone
        // every step needs only those of this step's non-zero weights.
        masks.fill(0);
        if !s.near.is_empty() {
            let mut l = 0;
            st.for_each::<D>(&geom.stride, |_, w, _| {
                if clear || w != 0.0 {
                    masks[l] = elements.mask(xp, s.nodes[l], &s.near);
                }
                l += 1;
            });
        }
        clearance
    }

    /// Classifies watched particle `j` at `xp`: its masks, first stencil node and budget,
    /// with `used` the movement since the full pass that the budget no longer has to
    /// absorb. A particle whose clearance was zero with the same stencil keeps a zero one
    /// until the next full pass (a node on a crack line, a line through a crack tip): it is
    /// redone every step, and its clearance is not worth measuring each time.
    fn one(&self, i: usize, slot: Slot, xp: D::Vec, used: f64, s: &mut Scratch<D>) {
        let clear = *slot.budget > f64::NEG_INFINITY || self.stencils.first[i] != *slot.first;
        let clearance = with_shape!(self.shape, S, N => {
            let st = Stencil::<N>::cached::<D>(S, self.stencils, i);
            self.classify_one(xp, &st, clear, s, slot.masks)
        });
        *slot.crosses = slot.masks.iter().any(|&m| m != 0);
        *slot.first = self.stencils.first[i];
        *slot.budget = if clearance > self.slack {
            clearance - self.slack + used
        } else {
            f64::NEG_INFINITY
        };
    }

    /// Runs `visit` on every watched particle's record entries in parallel, each with its
    /// index and a scratch of its thread (every particle's entries are its own, so the
    /// result does not depend on the thread count).
    fn each_watched(
        &self,
        rec: &mut Classified<D>,
        visit: impl Fn(usize, Slot, &mut Scratch<D>) + Sync,
    ) {
        let per = self.per();
        (rec.watched.par_iter())
            .zip(rec.first.par_iter_mut())
            .zip(rec.budget.par_iter_mut())
            .zip(rec.crosses.par_iter_mut())
            .zip(rec.masks.par_chunks_mut(per))
            .for_each_init(
                Scratch::new,
                |s, ((((&i, first), budget), crosses), masks)| {
                    let slot = Slot {
                        first,
                        budget,
                        crosses,
                        masks,
                    };
                    visit(i as usize, slot, s);
                },
            );
    }

    /// Finds the particles a crack could reach before the skin is used up (a stencil
    /// reaches at most two cells from its particle) and classifies each.
    fn full(&self, tiles: &Tiles, xs: &[D::Vec], rec: &mut Classified<D>) {
        let geom = self.geom;
        let mut reach = geom.h * 2.0;
        for k in 0..D::D {
            reach[k] += self.skin;
        }
        rec.watched.clear();
        if let Some(all) = self.elements.all {
            let mut t_lo = [0usize; 3];
            let mut t_hi = [0usize; 3];
            for k in 0..D::D {
                let cell = |x: f64| ((x - geom.origin[k]) * geom.inv_h[k]).max(0.0) as usize;
                t_lo[k] = (cell(all.lo[k] - reach[k]) / tiles.size).min(tiles.counts[k] - 1);
                t_hi[k] = (cell(all.hi[k] + reach[k]) / tiles.size).min(tiles.counts[k] - 1);
            }
            for tk in t_lo[2]..=t_hi[2] {
                for tj in t_lo[1]..=t_hi[1] {
                    for ti in t_lo[0]..=t_hi[0] {
                        let t = ti + tiles.counts[0] * (tj + tiles.counts[1] * tk);
                        rec.watched
                            .extend(tiles.particles(t as u32).iter().filter(|&&i| {
                                let xp = xs[i as usize];
                                self.elements.any_meeting(&Aabb {
                                    lo: xp - reach,
                                    hi: xp + reach,
                                })
                            }));
                    }
                }
            }
        }
        rec.watched.sort_unstable();
        let n = rec.watched.len();
        rec.first.resize(n, 0);
        rec.budget.clear();
        rec.budget.resize(n, f64::INFINITY);
        rec.crosses.resize(n, false);
        rec.masks.resize(n * self.per(), 0);
        self.each_watched(rec, |i, slot, s| self.one(i, slot, xs[i], 0.0, s));
    }

    /// Reclassifies the watched particles whose record no longer holds: a new stencil, or
    /// more movement than their clearance allows. `moved` is how far the cracks moved since
    /// the full pass.
    fn refresh(&self, xs: &[D::Vec], moved: f64, rec: &mut Classified<D>) {
        let (drift, first) = (rec.drift, &self.stencils.first);
        self.each_watched(rec, |i, slot, s| {
            if first[i] == *slot.first && drift + moved < *slot.budget {
                return;
            }
            // From now on the particle moves at most the drift still to come, and the cracks
            // at most their movement from the full pass plus `moved` back to it.
            self.one(i, slot, xs[i], drift - moved, s);
        });
    }

    /// The grid entries of the particles whose lines cross a crack, with this step's
    /// weights (a node of zero weight keeps its own field), and the extra field rows;
    /// returns how many rows.
    fn fields(
        &self,
        rec: &Classified<D>,
        particles: usize,
        domain: &Domain,
        f: &mut Fields,
    ) -> usize {
        let per = self.per();
        let geom = self.geom;
        f.per = per;
        f.nodes = geom.node_count();
        // Only last step's coded particles have a slot to clear.
        for &i in &f.coded {
            f.slot[i as usize] = u32::MAX;
        }
        f.slot.resize(particles, u32::MAX);
        f.coded.clear();
        let mut local = vec![(0u32, 0u64); per];
        let mut pairs: Vec<(u32, u64)> = Vec::new();
        for (j, &i) in rec.watched.iter().enumerate() {
            if !rec.crosses[j] {
                continue;
            }
            let masks = &rec.masks[j * per..(j + 1) * per];
            let mut any = false;
            with_shape!(self.shape, S, N => {
                let st = Stencil::<N>::cached::<D>(S, self.stencils, i as usize);
                let mut l = 0;
                st.for_each::<D>(&geom.stride, |n, w, _| {
                    let m = if w != 0.0 { masks[l] } else { 0 };
                    any |= m != 0;
                    local[l] = (n as u32, m);
                    l += 1;
                });
            });
            if any {
                f.slot[i as usize] = f.coded.len() as u32;
                f.coded.push(i);
                pairs.extend(local.iter().copied());
            }
        }
        // The distinct (node, mask) of the pairs with a mask, found through a chain per
        // node, then given grid entries in increasing (node, mask) order.
        f.head.resize(f.nodes, u32::MAX);
        let mut rows: Vec<(u32, u64)> = Vec::new();
        let mut next: Vec<u32> = Vec::new();
        let row_of: Vec<u32> = (pairs.iter())
            .map(|&(n, m)| {
                if m == 0 {
                    return u32::MAX;
                }
                let mut r = f.head[n as usize];
                while r != u32::MAX && rows[r as usize].1 != m {
                    r = next[r as usize];
                }
                if r == u32::MAX {
                    r = rows.len() as u32;
                    rows.push((n, m));
                    next.push(f.head[n as usize]);
                    f.head[n as usize] = r;
                }
                r
            })
            .collect();
        // Split across ranks, the rows are those of every rank's particles, so that an
        // entry means one field on every rank.
        let mut mine: Vec<[u64; 2]> = (rows.iter()).map(|&(n, m)| [u64::from(n), m]).collect();
        mine.sort_unstable();
        let all = domain.union(mine);
        let mut entry = vec![0u32; rows.len()];
        for (r, &(n, m)) in rows.iter().enumerate() {
            let k = all
                .binary_search(&[u64::from(n), m])
                .expect("a row of the union");
            entry[r] = (f.nodes + k) as u32;
            f.head[n as usize] = u32::MAX;
        }
        f.targets.clear();
        f.targets
            .extend((pairs.iter().zip(&row_of)).map(|(&(n, _), &r)| {
                if r == u32::MAX { n } else { entry[r as usize] }
            }));
        f.node = all.iter().map(|r| r[0] as u32).collect();
        f.mask = all.iter().map(|r| r[1]).collect();
        all.len()
    }
}

/// Classifies the particles near cracks (afresh, or reusing the last record where it still
/// holds) and sizes the grid's extra field rows. Nothing to do in a scene without cracks.
///
/// Fails when more than [`crate::store::crack::COLORS`] cracks have come within reach of one
/// another (their masks would have no bits left).
pub fn run<D: Dim>(world: &mut World<D>) -> Result<(), Unstable> {
    let (step, time) = (world.step, world.time);
    let Some(Cracks {
        topology,
        geometry,
        scratch:
            crate::store::crack::Scratch {
                fields,
                classified: rec,
                links,
                colors,
                ..
            },
        ..
    }) = world.cracks.as_mut()
    else {
        return Ok(());
    };
    let x = &geometry.x;
    if links.version != Some(topology.version()) {
        links.neighbour = neighbours::<D>(topology.elems());
        links.version = Some(topology.version());
        // Elements or vertices changed: the record's crossings no longer apply.
        rec.x0.clear();
    }
    let geom = &world.grid.geom;
    let tiles = &world.tiles;
    let h_min = (0..D::D).map(|k| geom.h[k]).fold(f64::INFINITY, f64::min);
    let h_max = (0..D::D).map(|k| geom.h[k]).fold(0.0, f64::max);
    let now = crack::colors::<D>(topology, x, h_max).map_err(|c| {
        let name = |k: usize| &topology.cracks()[k].name;
        Unstable {
            step,
            time,
            what: format!(
                "crack `{}` came within reach of {} other cracks (`{}` among them): a field \
                 mask has room for {} cracks near one place",
                name(c.crack),
                crack::COLORS,
                name(c.near),
                crack::COLORS
            ),
        }
    })?;
    if *colors != now {
        // Crossings were recorded under the old colours.
        *colors = now;
        rec.x0.clear();
    }
    let pass = Pass {
        geom,
        shape: world.settings.shape,
        stencils: &tiles.stencils,
        elements: Elements::<D>::new(
            x,
            topology.elems(),
            topology.elem_crack(),
            colors,
            &links.neighbour,
            topology.cracks().iter().map(|c| c.split),
        ),
        skin: 0.25 * h_min,
        slack: 1e-6 * h_min,
    };
    // A record exists once a full pass has stored the vertices it saw (a crack has some).
    let moved = if rec.x0.len() == x.len() {
        x.iter()
            .zip(&rec.x0)
            .map(|(&a, &b)| D::dot(a - b, a - b))
            .fold(0.0, f64::max)
            .sqrt()
    } else {
        f64::INFINITY
    };
    if rec.every_step || rec.drift + moved + pass.slack >= pass.skin {
        pass.full(tiles, &world.particles.x, rec);
        rec.x0.clone_from(x);
        rec.drift = 0.0;
    } else {
        pass.refresh(&world.particles.x, moved, rec);
    }
    let extra = pass.fields(rec, world.particles.len(), &world.domain, fields);
    world.grid.set_extra_fields(extra);
    clear_of_mirrors(world)
}

/// Refuses crack fields on a B-spline symmetry plane's image nodes or their sources: the
/// images stand for one field of their source, and the crack's mirror half is not modelled.
fn clear_of_mirrors<D: Dim>(world: &World<D>) -> Result<(), Unstable> {
    let (Some(c), mirrors) = (world.cracks.as_ref(), &world.grid.mirrors) else {
        return Ok(());
    };
    let split = |n: u32| !c.scratch.fields.rows_of(n).is_empty();
    let Some(im) = (mirrors.images.iter()).find(|im| split(im.node) || split(im.source)) else {
        return Ok(());
    };
    let x = D::to_xyz(world.grid.geom.node_position(im.source as usize));
    let at: Vec<String> = (0..D::D).map(|a| format!("{:.6}", x[a])).collect();
    Err(Unstable {
        step: world.step,
        time: world.time,
        what: format!(
            "a crack splits the grid node at ({}) m next to a symmetry plane \
             on quadratic B-splines, whose nodes past the plane mirror the body's side: keep \
             cracks three cells clear of such a plane, or give simulation.shape = \"ugimp\"",
            at.join(", ")
        ),
    })
}
