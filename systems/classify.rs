//! `classify`: the velocity field of every particle-node pair near a crack (Guo & Nairn 2D
//! (2004) section 2.1; 3D (2006) Appendix A) and the extra field rows of the grid. A line
//! from particle to node that crosses a crack an odd number of times puts the pair in the
//! node's field for that crack side; an even number counts as none. Only particles in tiles
//! near a crack are scanned.

use crate::crack::{Cracks, side_bit};
use crate::dim::Dim;
use crate::shape::Stencil;
use crate::with_nodes;
use crate::world::World;

/// Axis-aligned box (min, max).
type Aabb<D> = (<D as Dim>::Vec, <D as Dim>::Vec);

fn overlaps<D: Dim>(a: &Aabb<D>, b: &Aabb<D>) -> bool {
    (0..D::D).all(|k| a.0[k] <= b.1[k] && b.0[k] <= a.1[k])
}

fn span<D: Dim>(a: D::Vec, b: D::Vec) -> Aabb<D> {
    let (mut lo, mut hi) = (a, a);
    for k in 0..D::D {
        lo[k] = a[k].min(b[k]);
        hi[k] = a[k].max(b[k]);
    }
    (lo, hi)
}

/// Crack-side mask of the line from `xp` to `xn` against elements `near` (with boxes
/// `boxes` and the side of `xp` to each).
fn mask_of<D: Dim>(
    xp: D::Vec,
    xn: D::Vec,
    cracks: &Cracks<D>,
    near: &[(u32, i8)],
    boxes: &[Aabb<D>],
) -> u64 {
    let line = span::<D>(xp, xn);
    let (mut odd, mut above) = (0u32, 0u32);
    for &(e, sp) in near {
        let e = e as usize;
        if !overlaps::<D>(&line, &boxes[e]) {
            continue;
        }
        let s = D::crossing_from(xp, sp, xn, &cracks.x, cracks.elems[e]);
        if s != 0 {
            let bit = 1u32 << cracks.elem_crack[e];
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
        mask |= side_bit(c, if above >> c & 1 == 1 { 1 } else { -1 });
    }
    mask
}

/// Classifies the particles near cracks from their cached stencils and sizes the grid's
/// extra field rows. Nothing to do in a scene without cracks.
pub fn run<D: Dim>(world: &mut World<D>) {
    let Some(cracks) = world.cracks.as_mut() else {
        return;
    };
    let geom = &world.grid.geom;
    let tiles = &world.tiles;
    let p = &world.particles;
    let shape = world.settings.shape;
    let per = shape.nodes().pow(D::D as u32);
    let nodes = geom.node_count();
    let boxes: Vec<Aabb<D>> = cracks
        .elems
        .iter()
        .map(|e| {
            let v = |k: usize| cracks.x[e[k] as usize];
            let (mut lo, mut hi) = span::<D>(v(0), v(1));
            if D::D == 3 {
                let (l2, h2) = span::<D>(v(2), v(2));
                for k in 0..3 {
                    lo[k] = lo[k].min(l2[k]);
                    hi[k] = hi[k].max(h2[k]);
                }
            }
            (lo, hi)
        })
        .collect();
    // A stencil reaches at most two cells from its particle.
    let reach = geom.h * 2.0;
    let mut all = boxes[0];
    for b in &boxes {
        for k in 0..D::D {
            all.0[k] = all.0[k].min(b.0[k]);
            all.1[k] = all.1[k].max(b.1[k]);
        }
    }
    let mut t_lo = [0usize; 3];
    let mut t_hi = [0usize; 3];
    for k in 0..D::D {
        let cell = |x: f64| ((x - geom.origin[k]) * geom.inv_h[k]).max(0.0) as usize;
        t_lo[k] = (cell(all.0[k] - reach[k]) / tiles.size).min(tiles.counts[k] - 1);
        t_hi[k] = (cell(all.1[k] + reach[k]) / tiles.size).min(tiles.counts[k] - 1);
    }

    let mut coded: Vec<u32> = Vec::new();
    let mut node_ids: Vec<u32> = Vec::new();
    let mut masks: Vec<u64> = Vec::new();
    let mut near: Vec<(u32, i8)> = Vec::new();
    let mut tile_near: Vec<u32> = Vec::new();
    let mut local = vec![(0u32, 0u64); per];
    for tk in t_lo[2]..=t_hi[2] {
        for tj in t_lo[1]..=t_hi[1] {
            for ti in t_lo[0]..=t_hi[0] {
                let t = ti + tiles.counts[0] * (tj + tiles.counts[1] * tk);
                // Elements within reach of the tile, then of each of its particles.
                let (mut lo, mut hi) = (geom.origin, geom.origin);
                for (k, c) in [ti, tj, tk].into_iter().enumerate().take(D::D) {
                    lo[k] += (c * tiles.size) as f64 * geom.h[k] - reach[k];
                    hi[k] += ((c + 1) * tiles.size) as f64 * geom.h[k] + reach[k];
                }
                tile_near.clear();
                tile_near.extend(
                    (0..boxes.len() as u32)
                        .filter(|&e| overlaps::<D>(&(lo, hi), &boxes[e as usize])),
                );
                if tile_near.is_empty() {
                    continue;
                }
                // Sorted by the boxes' lower x, so the elements a node box can meet in x are
                // one run of the list, found by two binary searches.
                tile_near.sort_unstable_by(|&a, &b| {
                    boxes[a as usize].0[0].total_cmp(&boxes[b as usize].0[0])
                });
                let widest = tile_near
                    .iter()
                    .map(|&e| boxes[e as usize].1[0] - boxes[e as usize].0[0])
                    .fold(0.0, f64::max);
                let mut union = boxes[tile_near[0] as usize];
                for &e in &tile_near {
                    for k in 0..D::D {
                        union.0[k] = union.0[k].min(boxes[e as usize].0[k]);
                        union.1[k] = union.1[k].max(boxes[e as usize].1[k]);
                    }
                }
                for &i in tiles.particles(t as u32) {
                    let xp = p.x[i as usize];
                    if !overlaps::<D>(&(xp - reach, xp + reach), &union) {
                        continue;
                    }
                    let mut any = false;
                    with_nodes!(shape, N => {
                        let st = Stencil::<N>::cached::<D>(&tiles.stencils, i as usize);
                        // Every line from the particle to a node of its stencil lies in the
                        // stencil's node box (which holds the particle): only elements
                        // meeting that box can be crossed.
                        let mut corners = [D::zero(); 8];
                        for (k, c) in corners.iter_mut().enumerate().take(1 << D::D) {
                            *c = geom.origin;
                            for a in 0..D::D {
                                let i = st.base[a] + (N - 1) * (k >> a & 1);
                                c[a] += i as f64 * geom.h[a];
                            }
                        }
                        let node_box = (corners[0], corners[(1 << D::D) - 1]);
                        let first = tile_near.partition_point(|&e| {
                            boxes[e as usize].0[0] < node_box.0[0] - widest
                        });
                        let last = tile_near
                            .partition_point(|&e| boxes[e as usize].0[0] <= node_box.1[0]);
                        // Of those meeting the node box, keep the elements whose line or
                        // plane does not have the particle and every corner of the box on
                        // one side, with the particle's side.
                        let corners = &corners[..1 << D::D];
                        near.clear();
                        for &e in &tile_near[first..last.max(first)] {
                            if !overlaps::<D>(&node_box, &boxes[e as usize]) {
                                continue;
                            }
                            let el = cracks.elems[e as usize];
                            let sp = D::elem_side(xp, &cracks.x, el);
                            if corners.iter().any(|&c| D::elem_side(c, &cracks.x, el) != sp) {
                                near.push((e, sp));
                            }
                        }
                        if near.is_empty() {
                            continue;
                        }
                        let mut l = 0;
                        st.for_each::<D>(&geom.stride, |n, w, _| {
                            let m = if w != 0.0 {
                                mask_of::<D>(xp, geom.node_position(n), cracks, &near, &boxes)
                            } else {
                                0
                            };
                            any |= m != 0;
                            local[l] = (n as u32, m);
                            l += 1;
                        });
                    });
                    if any {
                        coded.push(i);
                        node_ids.extend(local.iter().map(|l| l.0));
                        masks.extend(local.iter().map(|l| l.1));
                    }
                }
            }
        }
    }

    // Coded particles in index order, so every later pass is deterministic.
    let mut order: Vec<usize> = (0..coded.len()).collect();
    order.sort_unstable_by_key(|&k| coded[k]);
    let mut rows: Vec<(u32, u64)> = node_ids
        .iter()
        .zip(&masks)
        .filter(|(_, m)| **m != 0)
        .map(|(n, m)| (*n, *m))
        .collect();
    rows.sort_unstable();
    rows.dedup();
    let f = &mut cracks.fields;
    f.per = per;
    f.nodes = nodes;
    f.slot.clear();
    f.slot.resize(p.len(), u32::MAX);
    f.coded.clear();
    f.targets.clear();
    for (slot, &k) in order.iter().enumerate() {
        f.coded.push(coded[k]);
        f.slot[coded[k] as usize] = slot as u32;
        for l in k * per..(k + 1) * per {
            let (n, m) = (node_ids[l], masks[l]);
            f.targets.push(if m == 0 {
                n
            } else {
                let r = rows.binary_search(&(n, m)).expect("row of a recorded pair");
                (nodes + r) as u32
            });
        }
    }
    f.node = rows.iter().map(|r| r.0).collect();
    f.mask = rows.iter().map(|r| r.1).collect();
    let extra = rows.len();
    world.grid.set_extra_fields(extra);
}
