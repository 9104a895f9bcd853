//! `fracture` in 3D: J and K_I, K_II, K_III at every vertex of every crack front, from
//! domain integrals over a tube around the front (`crate::fracture::front_integral`), and K split
//! from G = J by the opening, sliding and tearing of the crack behind the front (Guo &
//! Nairn 3D (2006) Eqs. 40, 46-57). With `[fracture] compare`, also J on tubes of the main
//! and the compared sizes, none shrunk, with their volume terms apart (paths.csv). A tube
//! stays clear of other cracks: it is shrunk (a compared one given up) until its reach,
//! sqrt(2) times its radius, is short of the nearest of their triangles. Runs on output
//! steps only; it reads the world and changes nothing.

use crate::base::dim::D3;
use crate::base::geometry::Element;
use crate::base::geometry::point_triangle;
use crate::fracture::front::{FrontFrame, FrontLine, front_line};
use crate::fracture::front_integral::{
    Elastic3, Facet, FrontIntegrals, Tube, TubeSamples, front_integrals, tube_samples,
};
use crate::fracture::plan::{FracturePlan, KMethod, Measured, PathResult, TipResult, lower_g};
use crate::store::crack::Cracks;
use crate::store::world::World;
use glam::DVec3;
use rayon::prelude::*;
use std::f64::consts::SQRT_2;

/// J and K at every vertex of every front, each crack's fronts numbered on from one to the
/// next.
pub fn measure(world: &World<D3>, plan: &FracturePlan) -> Measured {
    let mut m = Measured::default();
    let Some(cracks) = &world.cracks else {
        return m;
    };
    let scope = Scope::new(world, cracks, plan);
    let mut ordinal = vec![0u32; cracks.topology.cracks().len()];
    for front in cracks.topology.fronts() {
        let c = front.crack as usize;
        let line = front_line(cracks, front);
        let n = line.frames.len();
        // Each batch takes every `batches`-th vertex, so that it spans the whole front and
        // every rank holds a like share of its samples.
        let batches = n.div_ceil(BATCH);
        let mut slots: Vec<Option<(TipResult, Vec<PathResult>)>> = vec![None; n];
        for first in 0..batches {
            // The batch's tubes, and their samples on this rank: the vertices in parallel.
            let ks: Vec<usize> = (first..n).step_by(batches).collect();
            let asks: Vec<Asks> = (ks.into_par_iter())
                .map(|k| scope.ask(&line, c, k))
                .collect();
            let local: Vec<TubeSamples> = (asks.par_iter())
                .flat_map_iter(|a| {
                    let (line, scope) = (&line, &scope);
                    (a.tubes()).map(move |(t, near)| {
                        tube_samples(world, cracks, line, a.k, near, t, |m| scope.elastic(m))
                    })
                })
                .collect();
            let mut integrals = scope.integrals(&asks, local).into_iter();
            let measured: Vec<(&Asks, Vec<FrontIntegrals>)> = (asks.iter())
                .map(|a| (a, integrals.by_ref().take(a.tubes().count()).collect()))
                .collect();
            let rows: Vec<(TipResult, Vec<PathResult>)> = (measured.par_iter())
                .map(|(a, fis)| scope.rows(&line, c, ordinal[c] + a.k as u32, a, fis))
                .collect();
            for (a, row) in asks.iter().zip(rows) {
                slots[a.k] = Some(row);
            }
        }
        for (row, path_rows) in slots.into_iter().flatten() {
            m.tips.push(row);
            m.paths.extend(path_rows);
        }
        ordinal[c] += n as u32;
    }
    m
}

/// What the measurement of every front vertex shares: the scene, the tubes' sizes and the
/// crack triangles.
struct Scope<'a> {
    world: &'a World<D3>,
    cracks: &'a Cracks<D3>,
    plan: &'a FracturePlan,
    /// The largest cell side (m).
    h: f64,
    /// The main tube as asked.
    tube: Tube,
    /// Path independence: the tubes of the main and the compared sizes, none shrunk (empty
    /// without `compare`).
    paths: Vec<Tube>,
    /// The largest radius of them all (m).
    reach: f64,
    /// Every crack triangle, in element order.
    facets: Vec<Facet>,
}

impl<'a> Scope<'a> {
    fn new(world: &'a World<D3>, cracks: &'a Cracks<D3>, plan: &'a FracturePlan) -> Self {
        let geom = &world.grid.geom;
        let h = (0..3).map(|a| geom.h[a]).fold(0.0, f64::max);
        let tube = Tube {
            radius: plan.domain * h,
            step: h,
            min_radius: 2.0 * h,
            length: plan.domain * h,
        };
        let paths: Vec<Tube> = if plan.compare.is_empty() {
            Vec::new()
        } else {
            std::iter::once(plan.contour)
                .chain(plan.compare.iter().copied())
                .map(|n| {
                    let r = n as f64 * h;
                    Tube {
                        radius: r,
                        step: h,
                        min_radius: r,
                        length: r,
                    }
                })
                .collect()
        };
        let reach = paths.iter().fold(tube.radius, |r, t| r.max(t.radius));
        Scope {
            world,
            cracks,
            plan,
            h,
            tube,
            paths,
            reach,
            facets: facets(cracks),
        }
    }

    /// The elastic constants of material `m`.
    fn elastic(&self, m: u16) -> Elastic3 {
        let e = &self.world.materials[m as usize];
        Elastic3 {
            mu: e.mu,
            nu: e.poisson,
        }
    }

    /// What vertex `k` of `line`, on crack `c`, measures.
    fn ask(&self, line: &FrontLine, c: usize, k: usize) -> Asks {
        let (frame, h) = (&line.frames[k], self.h);
        let elem_crack = self.cracks.topology.elem_crack();
        let within = |r: f64| -> Vec<Facet> {
            (self.facets.iter().zip(elem_crack))
                .filter(|&(f, &e)| e as usize == c && (f.centroid - frame.x).length() < 2.0 * r + h)
                .map(|(f, _)| *f)
                .collect()
        };
        // A tube reaches sqrt(2) R from the vertex; it stays clear of other cracks.
        let room = room(self.cracks, c, frame.x, SQRT_2 * self.reach + h) / SQRT_2;
        let mut own = self.tube;
        while own.radius > room && own.radius >= own.min_radius {
            own.radius -= h;
            own.length -= h;
        }
        Asks {
            k,
            own,
            near: within(self.tube.radius),
            paths: (self.paths.iter())
                .map(|t| (t.radius <= room).then_some(*t))
                .collect(),
            wide: if self.paths.is_empty() {
                Vec::new()
            } else {
                within(self.reach)
            },
        }
    }

    /// The integrals over every tube of the vertices `asks` (in their order, each
    /// vertex's own tube first) from this rank's samples of them, `local`. Split across
    /// ranks, the tubes are dealt out in turn: each tube's samples travel to its rank,
    /// which integrates them in whole-scene particle order, and the integrals are then
    /// shared (the same bits as one rank's).
    fn integrals(&self, asks: &[Asks], local: Vec<TubeSamples>) -> Vec<FrontIntegrals> {
        let domain = &self.world.domain;
        let (me, size) = (domain.comm.rank(), domain.comm.size());
        let tubes: Vec<Tube> = asks
            .iter()
            .flat_map(|a| a.tubes().map(|(t, _)| t))
            .collect();
        let routed = TubeSamples::routed(domain, local, |t| t % size);
        let mine: Vec<[f64; 1 + FrontIntegrals::VALUES]> = (routed.par_iter().zip(&tubes))
            .enumerate()
            .filter(|(t, _)| t % size == me)
            .map(|(t, (samples, tube))| {
                let fi = front_integrals(samples, *tube, |m| self.elastic(m));
                let mut row = [t as f64; 1 + FrontIntegrals::VALUES];
                row[1..].copy_from_slice(&fi.values());
                row
            })
            .collect();
        (domain.in_order(mine, |row| row[0] as u64).iter())
            .map(|row| FrontIntegrals::from_values(row[1..].try_into().expect("the values")))
            .collect()
    }

    /// The rows of vertex `a.k` of `line` on crack `c`, numbered `tip`, from the integrals
    /// over its tubes (the own first): its fracture.csv row and its paths.csv rows.
    fn rows(
        &self,
        line: &FrontLine,
        c: usize,
        tip: u32,
        a: &Asks,
        integrals: &[FrontIntegrals],
    ) -> (TipResult, Vec<PathResult>) {
        let (world, h) = (self.world, self.h);
        let elastic = |m| self.elastic(m);
        let mut integrals = integrals.iter();
        let fi = *integrals.next().expect("the own tube");
        let path_rows = (a.paths.iter().zip(&self.paths))
            .map(|(fits, t)| {
                let p = match fits {
                    Some(_) => *integrals.next().expect("a compared tube"),
                    None => FrontIntegrals::NONE,
                };
                PathResult {
                    step: world.step,
                    time: world.time,
                    crack: c as u32,
                    tip,
                    contour: (t.radius / h).round() as u32,
                    line: [p.j - p.j_volume, f64::NAN],
                    area: [p.j_volume, f64::NAN],
                    direction: [1.0, 0.0],
                }
            })
            .collect();
        let frame = &line.frames[a.k];
        let opening = opening(self.cracks, c, frame, h, self.plan.opening * h);
        let [k, k_interaction, k_opening] = vertex_k(self.plan, &fi, opening, elastic);
        let row = TipResult {
            step: world.step,
            time: world.time,
            crack: c as u32,
            tip,
            x: frame.x.to_array(),
            j: [fi.j, f64::NAN],
            k,
            k_interaction,
            k_opening,
            domain: fi.radius,
            length: f64::NAN,
            speed: 0.0,
        };
        (row, path_rows)
    }
}

/// Most front vertices measured together: split across ranks, one exchange carries all
/// their tubes' samples, each to the rank that integrates the tube. Bounds the samples
/// held at once (a tube of 3 cells holds some 1,400 particles at 8 per cell, 144 bytes
/// each).
const BATCH: usize = 64;

/// What vertex `k` measures: its own tube (shrunk to stay clear of other cracks) over the
/// crack triangles `near`, and the compared tubes (those that fit) over `wide`.
struct Asks {
    k: usize,
    own: Tube,
    near: Vec<Facet>,
    paths: Vec<Option<Tube>>,
    wide: Vec<Facet>,
}

impl Asks {
    /// The tubes to sample, the own first, with the triangles each reaches.
    fn tubes(&self) -> impl Iterator<Item = (Tube, &[Facet])> {
        std::iter::once((self.own, &self.near[..]))
            .chain(self.paths.iter().flatten().map(|t| (*t, &self.wide[..])))
    }
}

/// The K a vertex reports from its integrals `fi` and the crack's `opening` behind it: the
/// plan's choice (the interaction integral, the mixity split of J or the opening split),
/// the interaction integral's and the opening split's; all NaN where the tube's surface
/// has yielded, for K comes from J only while it runs through elastic material.
fn vertex_k(
    plan: &FracturePlan,
    fi: &FrontIntegrals,
    opening: [f64; 3],
    elastic: impl Fn(u16) -> Elastic3,
) -> [[f64; 3]; 3] {
    if fi.plastic {
        return [[f64::NAN; 3]; 3];
    }
    let (k_opening, k_mixity) = match fi.material.map(elastic) {
        Some(el) => (
            k_split(
                el,
                fi.j,
                [opening[0] / el.c1(), opening[1] / el.c1(), opening[2] / 4.0],
            ),
            k_split(el, fi.j, fi.k),
        ),
        None => ([f64::NAN; 3], [f64::NAN; 3]),
    };
    let k = match plan.k_method {
        KMethod::Interaction => fi.k,
        KMethod::Mixity => k_mixity,
        KMethod::LowerG => lower_g(fi.k, k_mixity),
        KMethod::Opening => k_opening,
    };
    [k, fi.k, k_opening]
}

/// How far `x` lies from the nearest triangle of a crack other than `c`, looking no further
/// than `reach` (m; `f64::INFINITY` when none is that near).
pub(crate) fn room(cracks: &Cracks<D3>, c: usize, x: DVec3, reach: f64) -> f64 {
    let topo = &cracks.topology;
    let v = &cracks.geometry.x;
    (topo.elems().iter().zip(topo.elem_crack()))
        .filter(|&(_, &e)| e as usize != c)
        .map(|(t, _)| {
            let [a, b, d] = [0, 1, 2].map(|i| v[t.vertices()[i] as usize]);
            point_triangle(x, a, b, d)
        })
        .filter(|&d| d < reach)
        .fold(f64::INFINITY, f64::min)
}

/// Centroid and unit normal of every crack triangle.
fn facets(cracks: &Cracks<D3>) -> Vec<Facet> {
    let x = &cracks.geometry.x;
    (cracks.topology.elems().iter())
        .map(|e| Facet {
            centroid: e
                .vertices()
                .iter()
                .map(|&k| x[k as usize])
                .sum::<glam::DVec3>()
                / 3.0,
            normal: e.normal(x),
        })
        .collect()
}

/// Amplitudes of the opening (mode I), sliding (II) and tearing (III) displacements behind
/// the front vertex, each fitted as c sqrt(r) over the crack's vertices from one cell to
/// `window` behind it and within a cell of its normal plane (the top face less the bottom
/// one, in front axes). NaN when no vertex lies there.
fn opening(cracks: &Cracks<D3>, c: usize, frame: &FrontFrame, h: f64, window: f64) -> [f64; 3] {
    let g = &cracks.geometry;
    let (mut num, mut den) = ([0.0; 3], 0.0);
    for &k in &cracks.topology.cracks()[c].vertices {
        let d = frame.local(g.x[k as usize] - frame.x);
        let r = -d[0];
        if r < h || r > window || d[2].abs() > h || d[1].abs() > h {
            continue;
        }
        let du = frame.local(g.top[k as usize] - g.bottom[k as usize]);
        let s = r.sqrt();
        for (n, u) in num.iter_mut().zip([du[1], du[0], du[2]]) {
            *n += u * s;
        }
        den += r;
    }
    if den == 0.0 {
        return [f64::NAN; 3];
    }
    num.map(|n| n / den)
}

/// K_I, K_II, K_III of a stationary front in proportion to `d`, scaled so that
/// G = (A_I K_I^2 + A_II K_II^2 + A_III K_III^2) / (2 mu) with A_I = A_II = (kappa + 1)/4
/// and A_III = 1 (Guo & Nairn 3D (2006) Eq. 40 at zero speed; Eqs. 49-57 are its three
/// cases). NaN when `d` is zero or NaN, or G is NaN (no tube fitted).
fn k_split(el: Elastic3, g: f64, d: [f64; 3]) -> [f64; 3] {
    let a = 0.25 * el.c1();
    let den = a * (d[0] * d[0] + d[1] * d[1]) + d[2] * d[2];
    if den.is_nan() || den == 0.0 || g.is_nan() {
        return [f64::NAN; 3];
    }
    let scale = (2.0 * el.mu * g.max(0.0) / den).sqrt();
    d.map(|v| v * scale)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Split in proportion to the displacements of a known (K_I, K_II, K_III), G gives that
    /// K back, G = (K_I^2 + K_II^2) / E' + K_III^2 / (2 mu) with E' = 2 mu / (1 - nu); with
    /// no G (a tube that did not fit) it gives NaN, not zero.
    #[test]
    fn split_recovers_k_and_keeps_nan() {
        let el = Elastic3 { mu: 80e9, nu: 0.3 };
        let k = [2.0e6, -0.7e6, 1.1e6];
        let e_prime = 2.0 * el.mu / (1.0 - el.nu);
        let g = (k[0] * k[0] + k[1] * k[1]) / e_prime + k[2] * k[2] / (2.0 * el.mu);
        let got = k_split(el, g, k.map(|v| 3.0e-13 * v));
        for m in 0..3 {
            assert!((got[m] - k[m]).abs() < 1e-9 * k[0], "mode {m}: {got:?}");
        }
        assert!(k_split(el, f64::NAN, k).iter().all(|v| v.is_nan()));
    }
}
