//! The mean dilatation of `[simulation] dilatation = "cell_mean"`, for the static solve and
//! the explicit step alike: each particle's
//! volumetric strain replaced by the volume-weighted mean over its group, the particles of
//! its cell with its material on its side of every crack (Nagtegaal, Parks & Rice 1974;
//! in the strain-operator form B-bar of Hughes 1980, Eq. 9). Isochoric plastic flow then
//! meets one volume constraint per cell instead of one per particle, which a cell's few
//! nodes cannot all satisfy in plane strain and 3D (volumetric locking). No mean spans a
//! crack or a material interface.
//!
//! With D the dimension and tr the trace over the D in-plane axes (plane strain keeps
//! eps_zz = 0), a particle's strain is eps + (mean(tr eps) - tr eps) / D I, and the force
//! of its stress, B-bar^T sigma, is B^T of sigma + (mean(tr sigma) - tr sigma) / D I: the
//! stress each particle scatters carries its group's mean pressure.

use crate::base::dim::Dim;
use crate::base::sym::{Sym3, SymTensor};
use crate::store::world::World;
use rayon::prelude::*;

/// The particles grouped by cell, material and crack side, tile by tile of the last binning
/// (a particle that left its tile's cells since joins its new cell's particles of the same
/// tile), each group's members in ascending index order (so every mean is summed in one
/// order for any thread count).
pub(crate) struct Groups {
    /// Group of each particle.
    of: Vec<u32>,
    /// `start[g]..start[g + 1]` indexes `members` for group `g`.
    start: Vec<u32>,
    /// Particle indices by group.
    members: Vec<u32>,
    /// Each group's volume (m^3).
    volume: Vec<f64>,
}

impl Groups {
    /// The groups of the particles at their positions, after `bin` and `classify`: each
    /// tile's particles sorted by (cell, material, crack sides, index), in parallel over the
    /// tiles (no sort spans the scene).
    pub fn new<D: Dim>(world: &World<D>) -> Self {
        let (p, tiles) = (&world.particles, &world.tiles);
        let geom = &world.grid.geom;
        let fields = world.cracks.as_ref().map(|c| &c.scratch.fields);
        // A particle's crack sides: the masks of the crack fields its stencil reaches
        // across a crack (zero away from cracks).
        let side = |i: usize| -> u64 {
            let (Some(f), Some(targets)) = (fields, fields.and_then(|f| f.targets_of(i))) else {
                return 0;
            };
            (targets.iter())
                .filter(|&&t| t as usize >= f.nodes)
                .fold(0, |m, &t| m | f.mask[t as usize - f.nodes])
        };
        let key = |i: u32| {
            let x = p.x[i as usize];
            let mut cell = 0;
            for a in (0..D::D).rev() {
                let c = ((x[a] - geom.origin[a]) * geom.inv_h[a]).floor();
                let c = c.clamp(0.0, (geom.cells[a] - 1) as f64) as u64;
                cell = cell * geom.cells[a] as u64 + c;
            }
            (cell, p.material[i as usize], side(i as usize), i)
        };
        let group = |k: &(u64, u16, u64, u32)| (k.0, k.1, k.2);
        // Per tile: its particles in group order, and where each of its groups starts.
        let per_tile: Vec<(Vec<u32>, Vec<u32>)> = (0..tiles.start.len().saturating_sub(1))
            .into_par_iter()
            .map(|t| {
                let mut keys: Vec<_> = tiles.particles(t as u32).iter().map(|&i| key(i)).collect();
                keys.sort_unstable();
                let starts = (0..keys.len())
                    .filter(|&k| k == 0 || group(&keys[k - 1]) != group(&keys[k]))
                    .map(|k| k as u32)
                    .collect();
                (keys.into_iter().map(|k| k.3).collect(), starts)
            })
            .collect();
        let mut of = vec![0; p.len()];
        let mut start = Vec::new();
        let mut members = Vec::with_capacity(p.len());
        for (list, starts) in per_tile {
            let base = members.len() as u32;
            start.extend(starts.iter().map(|s| base + s));
            members.extend(list);
        }
        start.push(members.len() as u32);
        let volume: Vec<f64> = (start.windows(2).enumerate())
            .map(|(g, w)| {
                (members[w[0] as usize..w[1] as usize].iter())
                    .map(|&i| {
                        of[i as usize] = g as u32;
                        p.volume[i as usize]
                    })
                    .sum()
            })
            .collect();
        Groups {
            of,
            start,
            members,
            volume,
        }
    }

    /// How many groups.
    pub fn len(&self) -> usize {
        self.volume.len()
    }

    /// Group `g`'s particles, ascending.
    pub fn members(&self, g: usize) -> &[u32] {
        &self.members[self.start[g] as usize..self.start[g + 1] as usize]
    }

    /// Group `g`'s volume (m^3).
    pub fn volume(&self, g: usize) -> f64 {
        self.volume[g]
    }

    /// Whether particle `i` comes first in its group.
    pub fn leads(&self, i: usize) -> bool {
        self.members(self.of[i] as usize)[0] as usize == i
    }

    /// The group of particle `i`.
    pub fn of(&self, i: usize) -> usize {
        self.of[i] as usize
    }

    /// Per group, the volume-weighted mean of `value` over its members.
    fn means(&self, volume: &[f64], value: &[f64]) -> Vec<f64> {
        (0..self.len())
            .into_par_iter()
            .map(|g| {
                let sum: f64 = (self.members(g).iter())
                    .map(|&i| volume[i as usize] * value[i as usize])
                    .sum();
                sum / self.volume[g]
            })
            .collect()
    }

    /// Every particle's gradient `gradient(i)` (of the displacements in a static solve, of
    /// the velocities in an explicit step), its in-plane trace replaced by its group's mean.
    pub fn gradients<D: Dim>(
        &self,
        world: &World<D>,
        gradient: impl Fn(usize) -> D::Mat + Sync + Send,
    ) -> Vec<D::Mat> {
        let l: Vec<D::Mat> = (0..world.particles.len())
            .into_par_iter()
            .map(gradient)
            .collect();
        let traces: Vec<f64> = l.par_iter().map(|l| trace::<D>(&D::sym_part(l))).collect();
        let means = self.means(&world.particles.volume, &traces);
        (l.into_par_iter().enumerate())
            .map(|(i, l)| l + isotropic::<D>((means[self.of(i)] - traces[i]) / D::D as f64))
            .collect()
    }

    /// The stresses the particles scatter as forces, sigma + (mean(tr sigma) - tr sigma) / D
    /// I, from their stresses `s`.
    pub fn effective<D: Dim>(&self, world: &World<D>, s: &[D::Sym]) -> Vec<D::Sym> {
        let traces: Vec<f64> = s.par_iter().map(|s| trace::<D>(&s.to_sym3())).collect();
        let means = self.means(&world.particles.volume, &traces);
        (s.par_iter().enumerate())
            .map(|(i, s)| {
                let shift = (means[self.of(i)] - traces[i]) / D::D as f64;
                D::Sym::from_sym3(s.to_sym3() + in_plane::<D>() * shift)
            })
            .collect()
    }
}

/// The trace over the scene's D axes.
#[inline(always)]
pub(crate) fn trace<D: Dim>(s: &Sym3) -> f64 {
    [s.xx, s.yy, s.zz][..D::D].iter().sum()
}

/// The identity on the scene's D axes, as a symmetric tensor.
#[inline(always)]
pub(crate) fn in_plane<D: Dim>() -> Sym3 {
    Sym3 {
        xx: 1.0,
        yy: 1.0,
        zz: if D::D == 3 { 1.0 } else { 0.0 },
        ..Sym3::default()
    }
}

/// `c` times the identity on the scene's D axes, as a gradient.
#[inline(always)]
pub(crate) fn isotropic<D: Dim>(c: f64) -> D::Mat {
    (0..D::D).fold(D::mat_zero(), |m, a| {
        let mut e = D::zero();
        e[a] = 1.0;
        m + D::outer(e * c, e)
    })
}
