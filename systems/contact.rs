//! `contact`: crack-face contact on the nodes that carry a field on each side of a crack
//! (Guo & Nairn 3D (2006) Appendix B). Contact is detected where the nodal displacements of
//! the two fields overlap along the crack normal (Eq. 69), optionally only while the faces
//! approach (Eq. 70); the law's momentum change goes to the field above and its negative to
//! the field below, so momentum is conserved exactly. Coulomb friction's dissipation is
//! booked as work.

use crate::base::dim::Dim;
use crate::base::exact_sum::ExactSum;
use crate::base::geometry::Element;
use crate::physics::shape::Stencil;
use crate::store::crack::{COLORS, Cracks, ElementBins, Law};
use crate::store::world::World;
use crate::with_shape;

/// The crack of colour `color` nearest to `x` and the unit normal (pointing above) of its
/// element nearest to `x`, from that colour's bins (built on first use: scenes without
/// contact rows pay nothing). Cracks sharing a colour are never within a stencil's reach of
/// one another, so the nearest is the one the row's particles crossed.
pub(crate) fn nearest<D: Dim>(
    bins: &mut [Option<ElementBins>],
    cracks: &Cracks<D>,
    cell: [f64; 3],
    color: u8,
    x: D::Vec,
) -> Option<(usize, D::Vec)> {
    let (verts, topology) = (&cracks.geometry.x, &cracks.topology);
    let (elems, elem_crack) = (topology.elems(), topology.elem_crack());
    let colors = &cracks.scratch.colors;
    let bins = bins[color as usize].get_or_insert_with(|| {
        let keep = |e: usize| colors[elem_crack[e] as usize] == color;
        ElementBins::new::<D>(verts, elems, keep, cell, 3)
    });
    let e = bins.nearest::<D>(x, verts, elems)? as usize;
    Some((elem_crack[e] as usize, elems[e].normal(verts)))
}

/// One particle's term m u S on one crack field's entry, and where one rank adds it: the
/// particle's tile, then the particle's index in the whole scene.
#[derive(Clone, Copy, Debug)]
#[repr(C)]
struct Term<D: Dim> {
    tile: u64,
    id: u64,
    entry: u64,
    mu: D::Vec,
}

// SAFETY: three u64 and a vector of f64 (2 or 3): no padding, and every bit pattern is
// valid.
unsafe impl<D: Dim> bytemuck::Zeroable for Term<D> {}
// SAFETY: as above; `D::Vec` is Pod (a DVec2 or DVec3).
unsafe impl<D: Dim> bytemuck::Pod for Term<D> {}

/// Mass-weighted displacement sums m u at every entry of the nodes with crack fields, from
/// the particles of the tiles around them (Eq. 68), tile by tile in index order and in
/// particle order within a tile. Split across ranks, each rank adds its own terms and its
/// peers' on the nodes it shares with them, in that order.
fn nodal_displacements<D: Dim>(world: &mut World<D>) {
    let Some(cracks) = world.cracks.as_mut() else {
        return;
    };
    let f = &cracks.scratch.fields;
    let disp = &mut cracks.scratch.disp;
    disp.reset(f);
    if f.node.is_empty() {
        return;
    }
    let geom = &world.grid.geom;
    let tiles = &world.tiles;
    let p = &world.particles;
    let (mut lo, mut hi) = ([usize::MAX; 3], [0usize; 3]);
    for &n in &f.node {
        let ijk = geom.node_ijk(n as usize);
        for a in 0..D::D {
            lo[a] = lo[a].min(ijk[a]);
            hi[a] = hi[a].max(ijk[a]);
        }
    }
    let mut t_lo = [0; 3];
    let mut t_hi = [0; 3];
    for a in 0..D::D {
        t_lo[a] = lo[a].saturating_sub(2) / tiles.size;
        t_hi[a] = ((hi[a] + 2) / tiles.size).min(tiles.counts[a] - 1);
    }
    let shape = world.settings.shape;
    // One rank adds each term as it comes; split, the terms are merged first.
    let split = world.domain.is_split();
    let mut mine = Vec::new();
    for tk in t_lo[2]..=t_hi[2] {
        for tj in t_lo[1]..=t_hi[1] {
            for ti in t_lo[0]..=t_hi[0] {
                let t = ti + tiles.counts[0] * (tj + tiles.counts[1] * tk);
                for &i in tiles.particles(t as u32) {
                    let i = i as usize;
                    let mu = p.displacement(i) * p.mass[i];
                    let id = p.id.get(i).copied().unwrap_or(i as u64);
                    let mut add = |entry: usize, w: f64| {
                        let Some(s) = disp.entry(entry) else {
                            return;
                        };
                        if split {
                            mine.push(Term::<D> {
                                tile: t as u64,
                                id,
                                entry: entry as u64,
                                mu: mu * w,
                            });
                        } else {
                            disp.sums[s] += mu * w;
                        }
                    };
                    with_shape!(shape, S, N => {
                        let st = Stencil::<N>::cached::<D>(S, &tiles.stencils, i);
                        match f.targets_of(i) {
                            Some(ts) => st.for_each_target::<D>(&geom.stride, ts, |n, w, _| add(n, w)),
                            None => st.for_each::<D>(&geom.stride, |n, w, _| add(n, w)),
                        }
                    });
                }
            }
        }
    }
    let node = |t: &Term<D>| f.node_of(t.entry as usize);
    for term in (world.domain).with_shared(mine, node, |t| (t.tile, t.id)) {
        if let Some(s) = disp.entry(term.entry as usize) {
            disp.sums[s] += term.mu;
        }
    }
}

/// Applies each crack's contact law: to the nodal momenta after the scatter (`update`
/// false, which also measures the nodal displacements), or to the updated velocities and
/// accelerations after the grid update (`update` true).
pub fn run<D: Dim>(world: &mut World<D>, update: bool) {
    let (dt, tol) = (world.settings.dt, world.settings.mass_tol);
    if update {
        // The changes made to the scattered momenta are part of this step's acceleration:
        // the FLIP velocity update reads it, not the momenta.
        if let Some(c) = world.cracks.as_ref() {
            let g = &mut world.grid;
            for &(e, dp) in &c.scratch.contact_dp {
                g.accel[e] += dp * (1.0 / (g.mass[e] * dt));
            }
        }
    } else {
        nodal_displacements(world);
        if let Some(c) = world.cracks.as_mut() {
            c.scratch.contact_dp.clear();
        }
    }
    let Some(cracks) = world.cracks.as_mut() else {
        return;
    };
    let f = &cracks.scratch.fields;
    let g = &mut world.grid;
    let mut changes = Vec::new();
    // The first pass of a step finds each row's crack and normal, the second reuses them.
    let mut normals = std::mem::take(&mut cracks.scratch.contact_normals);
    let fresh = !update || normals.len() != f.node.len();
    if fresh {
        normals.clear();
        normals.resize(f.node.len(), None);
    }
    let mut bins: Vec<Option<ElementBins>> = Vec::new();
    bins.resize_with(COLORS, || None);
    // Whether some crack of each colour has a contact law.
    let mut acts = [false; COLORS];
    for (c, crack) in cracks.topology.cracks().iter().enumerate() {
        acts[cracks.scratch.color(c) as usize] |= crack.contact.law != Law::None;
    }
    // Whether friction can work (every rank has the same cracks).
    let coulomb =
        (cracks.topology.cracks().iter()).any(|c| matches!(c.contact.law, Law::Coulomb(_)));
    let domain = &world.domain;
    let h = D::to_xyz(g.geom.h);
    let cell = std::array::from_fn(|k| if k < D::D { h[k] } else { 1.0 });
    let mut friction = ExactSum::new();
    for (r, normal_r) in normals.iter_mut().enumerate() {
        let mask = f.mask[r];
        if mask.count_ones() != 1 {
            // A row behind two cracks at once: no single crack normal to act along.
            continue;
        }
        let bit = mask.trailing_zeros() as usize;
        let (color, above) = (bit / 2, bit.is_multiple_of(2));
        if !acts[color] {
            continue;
        }
        let (n, row) = (f.node[r] as usize, f.nodes + r);
        let (a, b) = if above { (row, n) } else { (n, row) };
        let (ma, mb) = (g.mass[a], g.mass[b]);
        if ma <= tol || mb <= tol {
            continue;
        }
        if fresh {
            *normal_r = nearest::<D>(
                &mut bins,
                cracks,
                cell,
                color as u8,
                g.geom.node_position(n),
            );
        }
        let Some((c, nrm)) = *normal_r else {
            continue;
        };
        let contact = cracks.topology.cracks()[c].contact;
        if contact.law == Law::None {
            continue;
        }
        let d = |e: usize, m: f64| cracks.scratch.disp.at(e) * (1.0 / m);
        if D::dot(d(a, ma) - d(b, mb), nrm) >= 0.0 {
            continue;
        }
        let (va, vb) = if update {
            (g.velocity[a], g.velocity[b])
        } else {
            (g.momentum[a] * (1.0 / ma), g.momentum[b] * (1.0 / mb))
        };
        if contact.approach_check && D::dot(va - vb, nrm) > 0.0 {
            continue;
        }
        let dp = contact.law.momentum_change::<D>(ma, va, mb, vb, nrm);
        // Split across ranks, the node's owner books the work.
        if let Law::Coulomb(_) = contact.law
            && domain.owns_node(n)
        {
            friction.add(friction_work::<D>(
                dp,
                va + dp * (1.0 / ma) - (vb - dp * (1.0 / mb)),
                nrm,
            ));
        }
        if update {
            g.velocity[a] += dp * (1.0 / ma);
            g.accel[a] += dp * (1.0 / (ma * dt));
            g.velocity[b] -= dp * (1.0 / mb);
            g.accel[b] -= dp * (1.0 / (mb * dt));
        } else {
            g.momentum[a] += dp;
            g.momentum[b] -= dp;
            changes.push((a, dp));
            changes.push((b, -dp));
        }
    }
    cracks.scratch.contact_normals = normals;
    if !update {
        cracks.scratch.contact_dp = changes;
    }
    if coulomb {
        domain.sum(std::slice::from_mut(&mut friction));
    }
    world.work.friction += friction.value();
}

/// The energy friction dissipates at a contact row: its tangential impulse against the
/// slip it leaves, -dp_t . v_t with `dp` the momentum change of the field above and `slip`
/// the velocity of that field relative to the one below after the change (`n` the crack's
/// normal). Zero while the faces stick (no slip left) and for frictionless faces (no
/// tangential impulse). Merging the faces' tangential velocities is the grid's projection,
/// which the particles do not lose (a stick law closes the energy balance without it);
/// what friction takes is the force working through the slip that goes on.
fn friction_work<D: Dim>(dp: D::Vec, slip: D::Vec, n: D::Vec) -> f64 {
    let dp_t = dp - n * D::dot(dp, n);
    let slip_t = slip - n * D::dot(slip, n);
    -D::dot(dp_t, slip_t)
}
