//! K_I and K_II at a 2D crack tip from the interaction (M-) integral in domain form
//! (Yau, Wang & Corten 1980; the domain form of Moran & Shih 1987; used with auxiliary
//! fields by Belytschko et al. 1995 for mixed-mode dynamic K), integrated over the particles
//! around the tip.
//!
//! With the actual fields (sigma, u, u'') and the static Williams field of one mode with
//! unit K as the auxiliary field (sigma^a, u^a), in tip axes (x1 along the crack's
//! extension) and a weight q that is 1 at the tip and 0 on the domain's edge,
//!
//!   I = sum_p A_p [ (sigma_ij u^a_i,1 + sigma^a_ij u_i,1 - sigma_ik u^a_i,k delta_1j) q,j
//!                   + rho u''_i u^a_i,1 q ]
//!
//! (A_p the particle's area) and K = E' I / 2 for that mode (E' = E in plane stress,
//! E / (1 - nu^2) in plane strain). The auxiliary fields are static, so the kinetic terms of
//! the dynamic J cancel in the interaction and only the inertia term remains; the
//! auxiliary fields are those of a stationary tip. The weight is q = (1 - r^2/R^2)^2, whose
//! gradient vanishes at the tip and on the edge, so the integrand stays bounded where the
//! fields are singular and particles straddling the edge contribute little.

use crate::base::dim::{D2, Dim};
use crate::base::geometry::point_segment;
use crate::base::sym::SymTensor;
use crate::fracture::plan::{e_prime, kappa};
use crate::physics::material::Material;
use crate::physics::near_tip;
use crate::physics::shape::Stencil;
use crate::store::crack::Cracks;
use crate::store::world::World;
use crate::with_shape;
use glam::DVec2;
use std::f64::consts::PI;

/// A crack tip and the direction the crack would extend in (unit vector).
#[derive(Clone, Copy, Debug)]
pub struct Tip<'a> {
    /// Crack index.
    pub crack: usize,
    /// 0 for the crack's start vertex, 1 for its end vertex.
    pub end: usize,
    /// The crack's polyline vertices, start to end.
    pub path: &'a [usize],
    /// Tip position (m).
    pub x: DVec2,
    /// Unit direction of extension.
    pub dir: DVec2,
}

/// The interaction integral's K at one tip, with the domain it was taken over.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InteractionK {
    /// K_I and K_II (Pa sqrt(m)); NaN when no domain fits.
    pub k: [f64; 2],
    /// Domain radius used (m); smaller than asked when the asked one reached another
    /// crack, a material of other elastic constants or past the body's edge, 0 when none
    /// fitted.
    pub radius: f64,
}

/// Smallest fraction of the domain's weighted area that particles must fill; below it the
/// domain reaches past the body's edge (where the auxiliary field's traction would add a
/// boundary term) and is shrunk.
const FILLED: f64 = 0.98;

/// One particle's data in tip axes.
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C)]
struct Sample {
    /// The particle's index in the whole scene (the order one rank adds the samples in).
    id: u64,
    /// Position relative to the tip (m).
    x: DVec2,
    /// Area (m^2) and mass per unit thickness (kg/m).
    area: f64,
    mass: f64,
    /// Stress xx, yy, xy (Pa).
    s: [f64; 3],
    /// du_i/dx_j.
    gu: [[f64; 2]; 2],
    /// Acceleration (m/s^2).
    a: DVec2,
    /// Auxiliary stress and displacement gradient of modes I and II at unit K.
    aux_s: [[f64; 3]; 2],
    aux_g: [[[f64; 2]; 2]; 2],
}

impl Sample {
    /// A particle at `x` (tip axes) and polar angle `theta` with its `[area, mass]`, stress,
    /// displacement gradient and acceleration, and the auxiliary fields for `[kappa, mu]`.
    fn new(
        x: DVec2,
        theta: f64,
        [area, mass]: [f64; 2],
        s: [f64; 3],
        gu: [[f64; 2]; 2],
        a: DVec2,
        [kap, mu]: [f64; 2],
    ) -> Sample {
        let (aux_s, aux_g) = near_tip::unit_fields(x.x.hypot(x.y), theta, kap, mu);
        Sample {
            id: 0,
            x,
            area,
            mass,
            s,
            gu,
            a,
            aux_s,
            aux_g,
        }
    }
}

/// K_I and K_II at `tip` from the interaction integral over a disc of radius `radius` (m),
/// shrunk by `step` (m) at a time while it reaches another crack, another material or past
/// the body's edge, down to `min_radius`.
pub fn interaction_k(
    world: &World<D2>,
    cracks: &Cracks<D2>,
    tip: Tip,
    radius: f64,
    step: f64,
    min_radius: f64,
    mat: &Material,
) -> InteractionK {
    let plane = world.settings.plane;
    let kap = kappa(mat, plane);
    let mut r_max = radius
        .min(other_crack_distance(cracks, tip) - step)
        .min(other_material_distance(world, tip, radius, mat) - step);
    let samples = gather(world, cracks, tip, r_max.max(0.0), kap, mat.mu);
    let e_prime = e_prime(mat, plane);
    while r_max >= min_radius {
        if let Some(i) = integrate(&samples, r_max) {
            return InteractionK {
                k: [0.5 * e_prime * i[0], 0.5 * e_prime * i[1]],
                radius: r_max,
            };
        }
        r_max -= step;
    }
    InteractionK {
        k: [f64::NAN; 2],
        radius: 0.0,
    }
}

/// Distance from the tip to the nearest segment of any other crack (m).
fn other_crack_distance(cracks: &Cracks<D2>, tip: Tip) -> f64 {
    let x = tip.x;
    let at = |k: u32| cracks.geometry.x[k as usize];
    cracks
        .topology
        .cracks()
        .iter()
        .enumerate()
        .filter(|(c, _)| *c != tip.crack)
        .flat_map(|(_, cr)| cr.vertices.windows(2))
        .map(|w| point_segment(x, at(w[0]), at(w[1])))
        .fold(f64::INFINITY, f64::min)
}

/// Distance from the tip to the nearest particle within `reach` whose elastic constants
/// differ from the tip's material `mat` (m; infinite when none): the auxiliary field is
/// that of a homogeneous body, so the domain stays in the tip's material.
fn other_material_distance(world: &World<D2>, tip: Tip, reach: f64, mat: &Material) -> f64 {
    let p = &world.particles;
    let x = tip.x;
    let foreign: Vec<bool> = (world.materials.iter())
        .map(|m| m.youngs != mat.youngs || m.poisson != mat.poisson)
        .collect();
    if !foreign.contains(&true) {
        return f64::INFINITY;
    }
    let mine = (near(world, x, reach).into_iter())
        .filter(|&i| foreign[p.material[i] as usize])
        .map(|i| p.x[i].distance(x))
        .fold(f64::INFINITY, f64::min);
    world.domain.min(mine)
}

/// The interaction integrals of modes I and II over the disc of radius `r_max`, or None
/// when particles fill less than [`FILLED`] of its weighted area.
fn integrate(samples: &[Sample], r_max: f64) -> Option<[f64; 2]> {
    let inv = 1.0 / (r_max * r_max);
    let (mut filled, mut i) = (0.0, [0.0; 2]);
    for p in samples {
        let rr = p.x.length_squared() * inv;
        if rr >= 1.0 {
            continue;
        }
        let q = (1.0 - rr) * (1.0 - rr);
        let gq = [
            -4.0 * (1.0 - rr) * p.x.x * inv,
            -4.0 * (1.0 - rr) * p.x.y * inv,
        ];
        filled += p.area * q;
        let [sxx, syy, sxy] = p.s;
        let s = [[sxx, sxy], [sxy, syy]];
        for (m, im) in i.iter_mut().enumerate() {
            let g = &p.aux_g[m];
            let [axx, ayy, axy] = p.aux_s[m];
            let sa = [[axx, axy], [axy, ayy]];
            let w_int = sxx * g[0][0] + syy * g[1][1] + sxy * (g[0][1] + g[1][0]);
            let mut f = -w_int * gq[0];
            for (ii, (si, sai)) in s.iter().zip(&sa).enumerate() {
                for (j, gqj) in gq.iter().enumerate() {
                    f += (si[j] * g[ii][0] + sai[j] * p.gu[ii][0]) * gqj;
                }
            }
            *im += p.area * f + p.mass * (p.a.x * g[0][0] + p.a.y * g[1][0]) * q;
        }
    }
    // The weight's integral over the disc is pi R^2 / 3.
    (filled >= FILLED * PI * r_max * r_max / 3.0).then_some(i)
}

/// The particles within `r_max` of the tip, in tip axes, with the auxiliary fields at
/// their positions. Behind the tip, the side of the crack (theta = +pi or -pi) comes from
/// the crack's own nearest segment, so that a crack that is not straight still puts each
/// particle on its own face's branch.
fn gather(
    world: &World<D2>,
    cracks: &Cracks<D2>,
    tip: Tip,
    r_max: f64,
    kap: f64,
    mu: f64,
) -> Vec<Sample> {
    let p = &world.particles;
    let (c, s) = (tip.dir.x, tip.dir.y);
    // Components along the tip direction and across it (to its left).
    let to_local = |v: DVec2| DVec2::new(tip.dir.dot(v), tip.dir.perp_dot(v));
    let rot = |m: [[f64; 2]; 2]| {
        // R m R^T with R = [[c, s], [-s, c]].
        let rm = [
            [c * m[0][0] + s * m[1][0], c * m[0][1] + s * m[1][1]],
            [-s * m[0][0] + c * m[1][0], -s * m[0][1] + c * m[1][1]],
        ];
        [
            [c * rm[0][0] + s * rm[0][1], -s * rm[0][0] + c * rm[0][1]],
            [c * rm[1][0] + s * rm[1][1], -s * rm[1][0] + c * rm[1][1]],
        ]
    };
    let vx = |k: usize| cracks.geometry.x[k];
    // Segments that can be nearest to a particle in the disc, oriented start -> end.
    let segs: Vec<(DVec2, DVec2)> = (tip.path.windows(2))
        .map(|w| (vx(w[0]), vx(w[1])))
        .filter(|&(a, b)| point_segment(tip.x, a, b) < 2.0 * r_max)
        .collect();
    // Only a particle within a cell of the band the crack's vertices span about the tip's
    // line can be on the other side of the crack from where theta's sign puts it.
    let band = segs
        .iter()
        .flat_map(|(a, b)| [a, b])
        .map(|&v| to_local(v - tip.x).y.abs())
        .fold(0.0, f64::max)
        + world.grid.geom.h[0].max(world.grid.geom.h[1]);
    // Left of the tip direction is left of the segments at an end tip, right at a start.
    let handed = if tip.end == 1 { 1.0 } else { -1.0 };
    let thickness = world.settings.thickness;
    let mut out = Vec::new();
    for i in near(world, tip.x, r_max) {
        let d = p.x[i] - tip.x;
        if d.x.abs() >= r_max || d.y.abs() >= r_max || d.x.hypot(d.y) >= r_max {
            continue;
        }
        let x = to_local(d);
        let mut theta = x.y.atan2(x.x);
        if x.x < 0.0 && x.y.abs() <= band {
            let pos = p.x[i];
            let side = segs
                .iter()
                .map(|&(a, b)| (point_segment(pos, a, b), (a, b)))
                .min_by(|u, v| u.0.total_cmp(&v.0))
                .map(|(_, (a, b))| handed * (b - a).perp_dot(pos - a));
            if let Some(side) = side {
                theta = theta.abs().copysign(side);
            }
        }
        let st = p.stress[i].to_sym3();
        let sl = rot([[st.xx, st.xy], [st.xy, st.yy]]);
        let g = &p.grad_u[i];
        let gu = rot([
            [D2::entry(g, 0, 0), D2::entry(g, 0, 1)],
            [D2::entry(g, 1, 0), D2::entry(g, 1, 1)],
        ]);
        let sample = Sample::new(
            x,
            theta,
            [p.volume[i] / thickness, p.mass[i] / thickness],
            [sl[0][0], sl[1][1], sl[0][1]],
            gu,
            to_local(accel(world, cracks, i)),
            [kap, mu],
        );
        out.push(Sample {
            id: p.id.get(i).copied().unwrap_or(i as u64),
            ..sample
        });
    }
    // Split across ranks, every rank integrates every rank's samples, in particle order.
    world.domain.in_order(out, |s| s.id)
}

/// The particles that can lie within `reach` of `x`, in ascending index order: those binned
/// in the tiles around it (padded by a cell for the particles' moves since binning), or
/// every particle before the first binning.
pub(crate) fn near<D: Dim>(world: &World<D>, x: D::Vec, reach: f64) -> Vec<usize> {
    let mut r = D::zero();
    (0..D::D).for_each(|a| r[a] = reach);
    near_box(world, x - r, x + r)
}

/// The particles that can lie in the box from `lo` to `hi`, in ascending index order: those
/// binned in the tiles it reaches (padded by a cell for the particles' moves since
/// binning), or every particle before the first binning.
pub(crate) fn near_box<D: Dim>(world: &World<D>, lo: D::Vec, hi: D::Vec) -> Vec<usize> {
    let geom = &world.grid.geom;
    let (mut pad, h) = (D::zero(), (0..D::D).map(|a| geom.h[a]).fold(0.0, f64::max));
    (0..D::D).for_each(|a| pad[a] = h);
    let (lo, hi) = geom.cell_range(lo - pad, hi + pad);
    let n = world.particles.len();
    match world.tiles.particles_in_cells(lo, hi, n) {
        Some(p) => p.into_iter().map(|i| i as usize).collect(),
        None => (0..n).collect(),
    }
}

/// Particle `i`'s acceleration interpolated from its grid entries (its own crack side's
/// fields near a crack), global axes.
pub(crate) fn accel<D: Dim>(world: &World<D>, cracks: &Cracks<D>, i: usize) -> D::Vec {
    let g = &world.grid;
    let mut a = D::zero();
    let mut visit = |entry: usize, w: f64| a += g.accel[entry] * w;
    with_shape!(world.settings.shape, S, N => {
        let st = Stencil::<N>::cached::<D>(S, &world.tiles.stencils, i);
        match cracks.scratch.fields.targets_of(i) {
            Some(t) => st.for_each_target::<D>(&g.geom.stride, t, |n, w, _| visit(n, w)),
            None => st.for_each::<D>(&g.geom.stride, |n, w, _| visit(n, w)),
        }
    });
    a
}

#[cfg(test)]
mod tests {
    use super::*;

    const MU: f64 = 80e9;
    const NU: f64 = 0.3;

    /// Particles on a lattice of spacing `h` filling the square of half-size `half` around a
    /// tip at the origin (crack along -x, rows offset half a spacing so none lies on it),
    /// carrying the plane-strain Williams field of `k` plus a uniform stress `s0` (xx, yy,
    /// xy) with its strain and a rigid rotation `spin`.
    fn lattice(k: [f64; 2], h: f64, half: f64, s0: [f64; 3], spin: f64) -> Vec<Sample> {
        let kap = 3.0 - 4.0 * NU;
        let lam = 2.0 * MU * NU / (1.0 - 2.0 * NU);
        // Plane-strain compliance of the uniform stress.
        let e0 = {
            let szz = NU * (s0[0] + s0[1]);
            let tr = s0[0] + s0[1] + szz;
            let c = lam / (2.0 * MU * (3.0 * lam + 2.0 * MU));
            [
                s0[0] / (2.0 * MU) - c * tr,
                s0[1] / (2.0 * MU) - c * tr,
                s0[2] / (2.0 * MU),
            ]
        };
        let n = (half / h) as i64;
        let mut out = Vec::new();
        for i in -n..n {
            for j in -n..n {
                let x = DVec2::new(i as f64 + 0.5, j as f64 + 0.5) * h;
                let (r, t) = (x.x.hypot(x.y), x.y.atan2(x.x));
                let s = near_tip::stress(k[0], k[1], r, t);
                let g = near_tip::displacement_gradient(k[0], k[1], r, t, kap, MU);
                let gu = [
                    [g[0][0] + e0[0], g[0][1] + e0[2] - spin],
                    [g[1][0] + e0[2] + spin, g[1][1] + e0[1]],
                ];
                let s = [s[0] + s0[0], s[1] + s0[1], s[2] + s0[2]];
                out.push(Sample::new(
                    x,
                    t,
                    [h * h, 0.0],
                    s,
                    gu,
                    DVec2::ZERO,
                    [kap, MU],
                ));
            }
        }
        out
    }

    fn k_of(samples: &[Sample], r: f64) -> [f64; 2] {
        let e_prime = 2.0 * MU * (1.0 + NU) / (1.0 - NU * NU);
        integrate(samples, r)
            .map(|i| [0.5 * e_prime * i[0], 0.5 * e_prime * i[1]])
            .unwrap()
    }

    /// On the exact near-tip field the interaction integral returns the K imposed, on
    /// domains of 5 to 20 particle spacings (particle quadrature of a bounded integrand;
    /// the coarsest domain is 0.23 % off, the tolerance twice that).
    #[test]
    fn recovers_imposed_k_on_every_domain() {
        let k = [1.0e6, -0.6e6];
        let samples = lattice(k, 1e-4, 2.2e-3, [0.0; 3], 0.0);
        for r in [0.5e-3, 1.0e-3, 2.0e-3] {
            let got = k_of(&samples, r);
            for m in 0..2 {
                assert!(
                    (got[m] - k[m]).abs() < 5e-3 * k[m].abs(),
                    "R {r}: mode {m}: {} vs {}",
                    got[m],
                    k[m]
                );
            }
        }
    }

    /// A T-stress (the uniform stress parallel to the crack that leaves its faces free) with
    /// its strain, and a rigid rotation, carry no K: adding them changes K by less than
    /// 0.5 % though they are two to three times the singular field at the domain's edge.
    #[test]
    fn uniform_fields_and_rotation_add_nothing() {
        let k = [0.8e6, 0.5e6];
        let r = 1.5e-3;
        let base = k_of(&lattice(k, 1e-4, 2.2e-3, [0.0; 3], 0.0), r);
        let size = k[0] / (2.0 * PI * r).sqrt();
        let with = k_of(
            &lattice(k, 1e-4, 2.2e-3, [-2.0 * size, 0.0, 0.0], 3.0 * size / MU),
            r,
        );
        for m in 0..2 {
            assert!(
                (with[m] - base[m]).abs() < 5e-3 * k[0],
                "mode {m}: {} vs {}",
                with[m],
                base[m]
            );
        }
    }

    /// A domain that particles do not fill (it reaches past the body's edge) is refused.
    #[test]
    fn unfilled_domain_is_refused() {
        let samples: Vec<Sample> = lattice([1e6, 0.0], 1e-4, 2.2e-3, [0.0; 3], 0.0)
            .into_iter()
            .filter(|s| s.x.y < 1.0e-3)
            .collect();
        assert!(integrate(&samples, 0.8e-3).is_some());
        assert!(integrate(&samples, 1.5e-3).is_none());
    }
}
