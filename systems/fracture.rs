//! `fracture`: the dynamic J-integral around each crack tip on a square contour along grid
//! lines, split where the crack crosses it (Guo & Nairn 2D (2004) Eqs. 7, 11-13), with the
//! optional area term (Eq. 8), then G (Eq. 10) and K_I, K_II from the interaction integral
//! and from the crack opening (Eqs. 14-22); a tip running at a set speed takes K from the
//! amplitude of its opening instead. Runs on output steps only; it changes nothing.

use crate::base::dim::{D2, Dim};
use crate::base::sym::SymTensor;
use crate::fracture::interaction::{Tip, interaction_k, near};
use crate::fracture::plan::{
    FracturePlan, KMethod, Measured, PathResult, TipResult, k_from_g, k_from_mixity,
    k_from_opening, lower_g,
};
use crate::physics::growth::TipState;
use crate::physics::shape::Stencil;
use crate::store::crack::{Cracks, Front};
use crate::store::grid::GridGeom;
use crate::store::world::World;
use crate::with_shape;
use glam::DVec2;
use std::collections::HashMap;

/// Mass-weighted nodal values of one field (Eq. 11): stress xx, yy, xy; displacement
/// gradient du_i/dx_j as [00, 01, 10, 11]; strain and kinetic energy densities.
#[derive(Clone, Copy, Debug, Default)]
struct Nodal {
    s: [f64; 3],
    gu: [f64; 4],
    w: f64,
    k: f64,
}

impl Nodal {
    fn lerp(a: &Nodal, b: &Nodal, t: f64) -> Nodal {
        let l = |x: f64, y: f64| x + (y - x) * t;
        Nodal {
            s: [0, 1, 2].map(|i| l(a.s[i], b.s[i])),
            gu: [0, 1, 2, 3].map(|i| l(a.gu[i], b.gu[i])),
            w: l(a.w, b.w),
            k: l(a.k, b.k),
        }
    }

    /// The integrand F_m of Eq. 13 for outward normal `n`, m = x and y.
    fn integrand(&self, n: DVec2) -> [f64; 2] {
        let [sxx, syy, sxy] = self.s;
        let t = [sxx * n.x + sxy * n.y, sxy * n.x + syy * n.y];
        let e = self.w + self.k;
        [
            e * n.x - (t[0] * self.gu[0] + t[1] * self.gu[2]),
            e * n.y - (t[0] * self.gu[1] + t[1] * self.gu[3]),
        ]
    }
}

/// J and K at every tip of every crack, and J on the compared contours.
pub fn measure(world: &World<D2>, plan: &FracturePlan) -> Measured {
    let mut m = Measured::default();
    let Some(cracks) = &world.cracks else {
        return m;
    };
    for (f, front) in cracks.topology.fronts().iter().enumerate() {
        let (t, p) = tip(world, cracks, front, plan, cracks.tips.get(f));
        m.tips.push(t);
        m.paths.extend(p);
    }
    m
}

/// The square contour of half-size `n` cells around node (i0, j0), counterclockwise, as
/// node indices (closed: the first node is repeated at the end).
fn contour(i0: usize, j0: usize, n: usize) -> Vec<[usize; 2]> {
    let (lo_i, hi_i, lo_j, hi_j) = (i0 - n, i0 + n, j0 - n, j0 + n);
    let mut p = Vec::with_capacity(8 * n + 1);
    p.extend((lo_i..hi_i).map(|i| [i, lo_j]));
    p.extend((lo_j..hi_j).map(|j| [hi_i, j]));
    p.extend((lo_i + 1..=hi_i).rev().map(|i| [i, hi_j]));
    p.extend((lo_j + 1..=hi_j).rev().map(|j| [lo_i, j]));
    p.push([lo_i, lo_j]);
    p
}

/// Where segment a-b meets segment c-d: the parameter along a-b, if they properly cross.
fn intersect(a: DVec2, b: DVec2, c: DVec2, d: DVec2) -> Option<f64> {
    let (r, s) = (b - a, d - c);
    let den = r.perp_dot(s);
    if den == 0.0 {
        return None;
    }
    let q = c - a;
    let t = q.perp_dot(s) / den;
    let u = q.perp_dot(r) / den;
    ((0.0..1.0).contains(&t) && (0.0..=1.0).contains(&u)).then_some(t)
}

/// J and K at the tip of `front` (whose growth so far is `state`, if it can grow), and J on
/// the compared contours.
pub(crate) fn tip(
    world: &World<D2>,
    cracks: &Cracks<D2>,
    front: &Front,
    plan: &FracturePlan,
    state: Option<&TipState>,
) -> (TipResult, Vec<PathResult>) {
    let geom = &world.grid.geom;
    let topo = &cracks.topology;
    let (c, end) = (front.crack as usize, front.end as usize);
    let path: Vec<usize> = topo.cracks()[c]
        .vertices
        .iter()
        .map(|&k| k as usize)
        .collect();
    // The polyline's vertices from the tip inwards.
    let walk: Vec<usize> = if end == 1 {
        path.iter().rev().copied().collect()
    } else {
        path.clone()
    };
    let (kt, kp) = (walk[0], walk[1]);
    let speed = state.map_or(0.0, |s| s.speed);
    // A tip running at a set speed (not one that extends by a segment now and then).
    let set_speed = topo.cracks()[c].growth.is_some_and(|g| g.speed.is_some());
    let running = state.filter(|s| set_speed && s.speed > 0.0);
    let xt = cracks.geometry.x[kt];
    let mut res = TipResult {
        step: world.step,
        time: world.time,
        crack: c as u32,
        tip: end as u32,
        x: D2::to_xyz(cracks.geometry.x[kt]),
        j: [f64::NAN; 2],
        k: [f64::NAN, f64::NAN, 0.0],
        k_interaction: [f64::NAN, f64::NAN, 0.0],
        k_opening: [f64::NAN, f64::NAN, 0.0],
        domain: 0.0,
        length: path
            .windows(2)
            .map(|w| cracks.geometry.x[w[0]].distance(cracks.geometry.x[w[1]]))
            .sum(),
        speed,
    };

    let Some(main) = contour_j(world, cracks, c, &path, xt, plan.contour, plan.area_term) else {
        return (res, Vec::new());
    };
    let j = [main.line[0] + main.area[0], main.line[1] + main.area[1]];
    res.j = j;
    // The tip's direction: G = J . dir (Eq. 10).
    let xp = cracks.geometry.x[kp];
    let dir = (xt - xp) / (xt - xp).length();
    // Path independence: J on the main and compared contours, line and area parts apart.
    let paths = if plan.compare.is_empty() {
        Vec::new()
    } else {
        std::iter::once(plan.contour)
            .chain(plan.compare.iter().copied())
            .filter_map(|n| {
                // The main contour with its area term is already measured.
                let (line, area) = if n == plan.contour && plan.area_term {
                    (main.line, main.area)
                } else {
                    let m = contour_j(world, cracks, c, &path, xt, n, true)?;
                    (m.line, m.area)
                };
                Some(PathResult {
                    step: world.step,
                    time: world.time,
                    crack: c as u32,
                    tip: end as u32,
                    contour: n as u32,
                    line,
                    area,
                    direction: dir.to_array(),
                })
            })
            .collect()
    };

    // G along the tip direction (Eq. 10), split by the opening behind the tip (Eqs. 14-22).
    let gr = DVec2::from(j).dot(dir);
    let h = geom.h[0].max(geom.h[1]);
    // With a tip at each end, the fit stays in this tip's half of the crack.
    let mut window = plan.opening * h;
    let other_end = topo
        .fronts()
        .iter()
        .any(|f| f.crack == front.crack && f.end != front.end);
    if other_end {
        window = window.min(0.5 * res.length);
    }
    if let Some(s) = running {
        // A running tip's field is fitted over the faces it made while running.
        window = window.min(s.grown);
    }
    let [d_i, d_ii] = opening_amplitudes(cracks, &walk, end, xt, dir, h, window);
    let mat = &world.materials[main.material];
    let plane = world.settings.plane;
    let [o1, o2] = match running {
        // Until it has run three cells there are too few such faces to fit.
        Some(s) if s.grown < 3.0 * h => [f64::NAN; 2],
        Some(_) => k_from_opening(mat, plane, d_i, d_ii, speed),
        None => k_from_g(mat, plane, gr, d_i, d_ii),
    };
    res.k_opening = [o1, o2, 0.0];
    let at = Tip {
        crack: c,
        end,
        path: &path,
        x: xt,
        dir,
    };
    let ik = interaction_k(world, cracks, at, plan.domain * h, h, 2.0 * h, mat);
    res.k_interaction = [ik.k[0], ik.k[1], 0.0];
    res.domain = ik.radius;
    res.k = match plan.k_method {
        // A running tip's K is its opening's (see `k_from_opening`): J reads the energy the
        // discrete tip absorbs, and the interaction integral's auxiliary field is a tip's
        // at rest.
        _ if running.is_some() => res.k_opening,
        KMethod::Opening => res.k_opening,
        // Where no interaction domain fits (another crack or the body's edge within two
        // cells of the tip), the opening split is all there is.
        _ if ik.radius == 0.0 => res.k_opening,
        KMethod::Interaction => res.k_interaction,
        KMethod::Mixity | KMethod::LowerG => {
            let [k1, k2] = k_from_mixity(mat, world.settings.plane, gr, ik.k);
            let mixity = [k1, k2, 0.0];
            if plan.k_method == KMethod::Mixity {
                mixity
            } else {
                lower_g(res.k_interaction, mixity)
            }
        }
    };
    if main.plastic {
        // K comes from J only while the contour runs through elastic material.
        let none = [f64::NAN, f64::NAN, 0.0];
        (res.k, res.k_interaction, res.k_opening) = (none, none, none);
    }
    (res, paths)
}

/// J on one contour around a tip: the line integral (Eqs. 11-13) and the area term (Eq. 8;
/// zero unless asked for), with the particle nearest the tip (whose material converts G to
/// K).
struct ContourJ {
    /// Line integral, global x and y (J/m^2).
    line: [f64; 2],
    /// Area integral over the particles inside the contour (J/m^2).
    area: [f64; 2],
    /// Material of the particle nearest the tip.
    material: usize,
    /// Whether a particle within the interpolation reach of the contour has yielded: J is
    /// then taken through plastic material, and K (an elastic quantity) is not reported.
    plastic: bool,
}

/// J on the square contour `n` cells from the node nearest the tip `xt` of crack `c` (shrunk
/// to fit the grid), or None when no contour fits or the crack does not leave it.
fn contour_j(
    world: &World<D2>,
    cracks: &Cracks<D2>,
    c: usize,
    path: &[usize],
    xt: DVec2,
    n: usize,
    area_term: bool,
) -> Option<ContourJ> {
    let k = Contour::around(&world.grid.geom, cracks, path, xt, n)?;
    let fields = &cracks.scratch.fields;
    // Nodal values of every field at the contour nodes (Eq. 11).
    let mut acc: HashMap<usize, [f64; 10]> = HashMap::new();
    for q in &k.ring {
        let nidx = k.index(*q);
        acc.insert(nidx, [0.0; 10]);
        for r in fields.rows_of(nidx as u32) {
            acc.insert(r, [0.0; 10]);
        }
    }
    let gathered = gather(world, cracks, &k, xt, area_term, &mut acc);
    let value = |entry: usize| -> Nodal {
        let a = acc.get(&entry).copied().unwrap_or([0.0; 10]);
        if a[0] <= world.settings.mass_tol {
            return Nodal::default();
        }
        let m = a[0];
        Nodal {
            s: [a[1] / m, a[2] / m, a[3] / m],
            gu: [a[4] / m, a[5] / m, a[6] / m, a[7] / m],
            w: a[8] / m,
            k: a[9] / m,
        }
    };
    let color = cracks.scratch.color(c);
    let at = |q: usize, side: i8| value(fields.side_entry(k.index(k.ring[q]), color, side));
    Some(ContourJ {
        line: k.line_integral(at),
        ..gathered
    })
}

/// A square contour of n cells along grid lines about the node nearest a tip, and where
/// the crack leaves it.
struct Contour<'a> {
    geom: &'a GridGeom<D2>,
    /// Its nodes in order, the first repeated at the end.
    ring: Vec<[usize; 2]>,
    /// Its lower-left and upper-right corners (m).
    lo: DVec2,
    hi: DVec2,
    /// The edge the crack crosses (from ring[edge] to ring[edge + 1]) and where along it.
    edge: usize,
    s: f64,
    /// The side of the crack the path starts on: that of ring[edge + 1].
    first: i8,
}

impl<'a> Contour<'a> {
    /// The contour of `n` cells (shrunk to fit inside the grid) about the node nearest the
    /// tip `xt`, cut where it first crosses the crack `path`; None if it has no room or
    /// the crack does not cross it.
    fn around(
        geom: &'a GridGeom<D2>,
        cracks: &Cracks<D2>,
        path: &[usize],
        xt: DVec2,
        n: usize,
    ) -> Option<Self> {
        let node = |a: usize| ((xt[a] - geom.origin[a]) * geom.inv_h[a]).round().max(0.0) as usize;
        let (i0, j0) = (node(0), node(1));
        let room = i0
            .min(j0)
            .min(geom.cells[0] - i0.min(geom.cells[0]))
            .min(geom.cells[1] - j0.min(geom.cells[1]));
        let n = n.min(room);
        if n == 0 {
            return None;
        }
        let mut k = Contour {
            geom,
            ring: contour(i0, j0, n),
            lo: DVec2::ZERO,
            hi: DVec2::ZERO,
            edge: 0,
            s: 0.0,
            first: 1,
        };
        (k.lo, k.hi) = (k.pos([i0 - n, j0 - n]), k.pos([i0 + n, j0 + n]));
        // Where the crack leaves the contour: edge e at parameter s, crossing crack segment k.
        let mut cut = None;
        'find: for e in 0..k.ring.len() - 1 {
            let (a, b) = (k.pos(k.ring[e]), k.pos(k.ring[e + 1]));
            for w in path.windows(2) {
                let (ca, cb) = (cracks.geometry.x[w[0]], cracks.geometry.x[w[1]]);
                if let Some(s) = intersect(a, b, ca, cb) {
                    cut = Some((e, s, (ca, cb)));
                    break 'find;
                }
            }
        }
        let (e, s, (ca, cb)) = cut?;
        // The path starts on the side of the crack that ring[e + 1] is on and ends on the other.
        let after = k.pos(k.ring[e + 1]);
        let orient = (cb - ca).perp_dot(after - ca);
        k.first = if orient >= 0.0 { 1 } else { -1 };
        (k.edge, k.s) = (e, s);
        Some(k)
    }

    /// Position of grid node `q` (m).
    fn pos(&self, q: [usize; 2]) -> DVec2 {
        let geom = self.geom;
        DVec2::new(
            geom.origin[0] + q[0] as f64 * geom.h[0],
            geom.origin[1] + q[1] as f64 * geom.h[1],
        )
    }

    /// Linear index of grid node `q`.
    fn index(&self, q: [usize; 2]) -> usize {
        q[0] + self.geom.stride[1] * q[1]
    }

    /// The line integral (Eq. 7) along the split path: crossing point, ring[e + 1], ...,
    /// ring[e], crossing point (Eq. 12), by the trapezoidal rule on each edge, with `at(q,
    /// side)` the nodal values of contour node q on the given side of the crack.
    fn line_integral(&self, at: impl Fn(usize, i8) -> Nodal) -> [f64; 2] {
        let (e, s, first, ring) = (self.edge, self.s, self.first, &self.ring);
        let m = ring.len() - 1;
        let order: Vec<usize> = (1..=m).map(|q| (e + q) % m).collect();
        let cross = {
            let (a, b) = (self.pos(ring[e]), self.pos(ring[e + 1]));
            a + (b - a) * s
        };
        let mut pts = vec![cross];
        let mut vals = vec![Nodal::lerp(&at(e, first), &at(e + 1, first), s)];
        for (q, &r) in order.iter().enumerate() {
            let side = if 2 * q < order.len() { first } else { -first };
            pts.push(self.pos(ring[r]));
            vals.push(at(r, side));
        }
        pts.push(cross);
        vals.push(Nodal::lerp(&at(e, -first), &at(e + 1, -first), s));
        let mut j = [0.0; 2];
        for q in 0..pts.len() - 1 {
            let d = pts[q + 1] - pts[q];
            let len = d.length();
            if len == 0.0 {
                continue;
            }
            // Outward: the contour runs counterclockwise.
            let normal = DVec2::new(d.y, -d.x) / len;
            let (fa, fb) = (vals[q].integrand(normal), vals[q + 1].integrand(normal));
            for (mm, jm) in j.iter_mut().enumerate() {
                *jm += 0.5 * (fa[mm] + fb[mm]) * len;
            }
        }
        j
    }
}

/// One particle's mass-weighted values (Eq. 11) on one contour entry, the share `gather`
/// adds there.
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C)]
struct NodeShare {
    /// The particle's index in the whole scene.
    id: u64,
    entry: u64,
    f: [f64; 10],
}

/// What one particle near a contour adds besides its node shares.
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C)]
struct Near {
    /// The particle's index in the whole scene.
    id: u64,
    /// Its term of the area integral (Eq. 8), when `inside`.
    area: [f64; 2],
    /// Its squared distance to the tip (m^2).
    d2: f64,
    material: u32,
    /// Whether it lies inside the contour (and the area term is asked for).
    inside: u32,
    /// Whether it has yielded within the interpolation reach of the contour.
    plastic: u32,
    _pad: u32,
}

/// Extrapolates the particles near contour `k` to its nodes' fields (mass-weighted sums
/// into `acc`, Eq. 11) and, with `area_term`, integrates the area term (Eq. 8) over the
/// particles inside it. Also finds the particle nearest the tip `xt` and whether a
/// yielded particle lies on the contour's band (J is then not K's). The returned line
/// integral is left at zero. Every sum is taken in particle order; split across ranks,
/// each rank lists its particles' terms and all add every rank's, in that order.
fn gather(
    world: &World<D2>,
    cracks: &Cracks<D2>,
    k: &Contour,
    xt: DVec2,
    area_term: bool,
    acc: &mut HashMap<usize, [f64; 10]>,
) -> ContourJ {
    let g = &world.grid;
    let geom = &g.geom;
    let fields = &cracks.scratch.fields;
    let p = &world.particles;
    let shape = world.settings.shape;
    let (lo, hi) = (k.lo, k.hi);
    let reach = 2.0 * geom.h[0].max(geom.h[1]);
    let half = 0.5 * (hi - lo).max_element();
    let centre = 0.5 * (lo + hi);
    let (mut shares, mut nears) = (Vec::new(), Vec::new());
    for i in near(world, centre, half + reach) {
        let x = p.x[i];
        if x.cmplt(lo - reach).any() || x.cmpgt(hi + reach).any() {
            continue;
        }
        let id = p.id.get(i).copied().unwrap_or(i as u64);
        let well_inside = x.cmpgt(lo + reach).all() && x.cmplt(hi - reach).all();
        let plastic = !well_inside && p.hardened.get(i).is_some_and(|h| h.equivalent > 0.0);
        let m = p.mass[i];
        let mat = &world.materials[p.material[i] as usize];
        let st = p.stress[i].to_sym3();
        let gu = p.grad_u[i];
        let gu = [
            D2::entry(&gu, 0, 0),
            D2::entry(&gu, 0, 1),
            D2::entry(&gu, 1, 0),
            D2::entry(&gu, 1, 1),
        ];
        let v = p.v[i];
        let f = [
            m,
            m * st.xx,
            m * st.yy,
            m * st.xy,
            m * gu[0],
            m * gu[1],
            m * gu[2],
            m * gu[3],
            m * (mat.energy_density(&st) + p.plastic_work(i)),
            m * 0.5 * (m / p.volume[i]) * v.length_squared(),
        ];
        let targets = fields.targets_of(i);
        // Only the area term needs the particles inside the contour.
        let inside = area_term && x.cmpgt(lo).all() && x.cmplt(hi).all();
        let mut accel = DVec2::ZERO;
        with_shape!(shape, S, N => {
            let st = Stencil::<N>::cached::<D2>(S, &world.tiles.stencils, i);
            let mut visit = |entry: usize, w: f64| {
                if acc.contains_key(&entry) {
                    shares.push(NodeShare {
                        id,
                        entry: entry as u64,
                        f: f.map(|f| f * w),
                    });
                }
                if inside {
                    accel += g.accel[entry] * w;
                }
            };
            match targets {
                Some(t) => st.for_each_target::<D2>(&geom.stride, t, |n, w, _| visit(n, w)),
                None => st.for_each::<D2>(&geom.stride, |n, w, _| visit(n, w)),
            }
        });
        let mut area = [0.0; 2];
        if inside {
            // Eq. 8's area term: rho [a . du/dx_m - v . dv/dx_m] over the particle's area
            // V / thickness, with rho V = m.
            let gv = p.grad_v[i];
            let scale = m / world.settings.thickness;
            for (mm, a) in area.iter_mut().enumerate() {
                let du = DVec2::new(
                    D2::entry(&p.grad_u[i], 0, mm),
                    D2::entry(&p.grad_u[i], 1, mm),
                );
                let dv = DVec2::new(D2::entry(&gv, 0, mm), D2::entry(&gv, 1, mm));
                *a = scale * (accel.dot(du) - v.x * dv.x - v.y * dv.y);
            }
        }
        nears.push(Near {
            id,
            area,
            d2: x.distance_squared(xt),
            material: u32::from(p.material[i]),
            inside: u32::from(inside),
            plastic: u32::from(plastic),
            _pad: 0,
        });
    }
    let domain = &world.domain;
    for s in domain.in_order(shares, |s| s.id) {
        let a = acc.get_mut(&(s.entry as usize)).expect("a contour entry");
        for (a, f) in a.iter_mut().zip(&s.f) {
            *a += f;
        }
    }
    let mut area = [0.0; 2];
    let mut nearest = (f64::INFINITY, 0u32);
    let mut plastic = false;
    for n in domain.in_order(nears, |n| n.id) {
        if n.d2 < nearest.0 {
            nearest = (n.d2, n.material);
        }
        plastic |= n.plastic != 0;
        if n.inside != 0 {
            area[0] += n.area[0];
            area[1] += n.area[1];
        }
    }
    ContourJ {
        line: [0.0; 2],
        area,
        material: nearest.1 as usize,
        plastic,
    }
}

/// Opening and sliding amplitudes behind a tip, for splitting G (Eqs. 14-22). The paper reads
/// the opening at one crack point; near the tip the discrete crack opens and slides as if it
/// were longer (by about a cell in mode II), which biases that ratio by 10 % or more. Here
/// each component, in tip axes, is fitted as delta^2 = A^2 (r + r0) over the vertices from
/// one cell to `window` behind the tip (least squares, the offset r0 free), and the signed
/// amplitudes A take the place of the point values. With one vertex in the window its
/// opening is used as is; with none, NaN.
fn opening_amplitudes(
    cracks: &Cracks<D2>,
    walk: &[usize],
    end: usize,
    xt: DVec2,
    dir: DVec2,
    h: f64,
    window: f64,
) -> [f64; 2] {
    let mut samples: Vec<(f64, [f64; 2])> = Vec::new();
    for &k in walk.iter().skip(1) {
        let r = cracks.geometry.x[k].distance(xt);
        if r > window {
            break;
        }
        if r < h {
            continue;
        }
        // The surface left of the tip direction: the top one at an end tip, the bottom at a
        // start.
        let (upper, lower) = if end == 1 {
            (cracks.geometry.top[k], cracks.geometry.bottom[k])
        } else {
            (cracks.geometry.bottom[k], cracks.geometry.top[k])
        };
        let d = upper - lower;
        let (d_i, d_ii) = (dir.perp_dot(d), d.dot(dir));
        samples.push((r, [d_i, d_ii]));
    }
    match samples.len() {
        0 => [f64::NAN; 2],
        1 => samples[0].1,
        n => {
            let n = n as f64;
            let mean_r = samples.iter().map(|s| s.0).sum::<f64>() / n;
            let var: f64 = samples.iter().map(|s| (s.0 - mean_r).powi(2)).sum();
            [0, 1].map(|c| {
                let mean_sq = samples.iter().map(|s| s.1[c] * s.1[c]).sum::<f64>() / n;
                let cov: f64 = samples
                    .iter()
                    .map(|s| (s.0 - mean_r) * (s.1[c] * s.1[c] - mean_sq))
                    .sum();
                let sign = samples.iter().map(|s| s.1[c]).sum::<f64>().signum();
                sign * (cov / var).max(0.0).sqrt()
            })
        }
    }
}
