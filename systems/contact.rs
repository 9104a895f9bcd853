//! `contact`: crack-face contact on the nodes that carry a field on each side of a crack
//! (Guo & Nairn 3D (2006) Appendix B). Contact is detected where the nodal displacements of
//! the two fields overlap along the crack normal (Eq. 69), optionally only while the faces
//! approach (Eq. 70); the law's momentum change goes to the field above and its negative to
//! the field below, so momentum is conserved exactly.

use crate::crack::Law;
use crate::dim::Dim;
use crate::shape::Stencil;
use crate::with_shape;
use crate::world::World;
use std::collections::HashMap;

/// Unit normal (pointing above) of the element of crack `c` nearest to `x`.
fn normal<D: Dim>(
    verts: &[D::Vec],
    elems: &[D::Elem],
    elem_crack: &[u16],
    c: usize,
    x: D::Vec,
) -> D::Vec {
    let mut best = (f64::INFINITY, D::zero());
    for (e, &el) in elems.iter().enumerate() {
        if elem_crack[e] as usize != c {
            continue;
        }
        let d = D::elem_distance_sq(x, verts, el);
        if d < best.0 {
            best = (d, D::elem_normal(verts, el));
        }
    }
    best.1
}

/// Mass-weighted displacement sums m u at every entry of the nodes with crack fields, from
/// the particles of the tiles around them (Eq. 68), in a fixed order.
fn nodal_displacements<D: Dim>(world: &World<D>) -> HashMap<usize, D::Vec> {
    let cracks = world.cracks.as_ref().expect("contact runs with cracks");
    let f = &cracks.scratch.fields;
    let geom = &world.grid.geom;
    let tiles = &world.tiles;
    let p = &world.particles;
    let mut disp: HashMap<usize, D::Vec> = HashMap::new();
    let (mut lo, mut hi) = ([usize::MAX; 3], [0usize; 3]);
    for (r, &n) in f.node.iter().enumerate() {
        disp.insert(n as usize, D::zero());
        disp.insert(f.nodes + r, D::zero());
        let ijk = geom.node_ijk(n as usize);
        for a in 0..D::D {
            lo[a] = lo[a].min(ijk[a]);
            hi[a] = hi[a].max(ijk[a]);
        }
    }
    if disp.is_empty() {
        return disp;
    }
    let mut t_lo = [0; 3];
    let mut t_hi = [0; 3];
    for a in 0..D::D {
        t_lo[a] = lo[a].saturating_sub(2) / tiles.size;
        t_hi[a] = ((hi[a] + 2) / tiles.size).min(tiles.counts[a] - 1);
    }
    let shape = world.settings.shape;
    for tk in t_lo[2]..=t_hi[2] {
        for tj in t_lo[1]..=t_hi[1] {
            for ti in t_lo[0]..=t_hi[0] {
                let t = ti + tiles.counts[0] * (tj + tiles.counts[1] * tk);
                for &i in tiles.particles(t as u32) {
                    let i = i as usize;
                    let mu = p.displacement(i) * p.mass[i];
                    let mut add = |entry: usize, w: f64| {
                        if let Some(d) = disp.get_mut(&entry) {
                            *d += mu * w;
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
    disp
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
        let disp = nodal_displacements(world);
        if let Some(c) = world.cracks.as_mut() {
            c.scratch.disp = disp;
            c.scratch.contact_dp.clear();
        }
    }
    let Some(cracks) = world.cracks.as_mut() else {
        return;
    };
    let f = &cracks.scratch.fields;
    let g = &mut world.grid;
    let mut changes = Vec::new();
    for r in 0..f.node.len() {
        let mask = f.mask[r];
        if mask.count_ones() != 1 {
            // A row behind two cracks at once: no single crack normal to act along.
            continue;
        }
        let bit = mask.trailing_zeros() as usize;
        let (c, above) = (bit / 2, bit.is_multiple_of(2));
        let contact = cracks.topology.cracks()[c].contact;
        if contact.law == Law::None {
            continue;
        }
        let (n, row) = (f.node[r] as usize, f.nodes + r);
        let (a, b) = if above { (row, n) } else { (n, row) };
        let (ma, mb) = (g.mass[a], g.mass[b]);
        if ma <= tol || mb <= tol {
            continue;
        }
        let nrm = normal::<D>(
            &cracks.geometry.x,
            cracks.topology.elems(),
            cracks.topology.elem_crack(),
            c,
            g.geom.node_position(n),
        );
        let d = |e: usize, m: f64| {
            cracks.scratch.disp.get(&e).copied().unwrap_or(D::zero()) * (1.0 / m)
        };
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
    if !update {
        cracks.scratch.contact_dp = changes;
    }
}
