//! `bin`: sort particle indices into spatial tiles (counting sort), evaluate every particle's
//! stencil, and stop the run if a particle has left the grid or has a non-finite position.

use crate::base::dim::Dim;
use crate::base::error::Unstable;
use crate::physics::shape::{ShapeKind, StencilCache};
use crate::store::grid::GridGeom;
use crate::store::tiles::Tiles;
use crate::store::world::{CHUNK, World};
use crate::with_shape;
use rayon::prelude::*;

/// Bins every particle by the tile of the cell that contains it and evaluates its stencil,
/// in one pass over the positions. Nothing to do when the particles have not moved since
/// the last binning; no re-sort when none changed tile.
pub fn run<D: Dim>(world: &mut World<D>) -> Result<(), Unstable> {
    if world.tiles.fresh {
        return Ok(());
    }
    let p = &world.particles;
    let (geom, shape) = (&world.grid.geom, world.settings.shape);
    match place(&p.x, &p.half, geom, shape, &mut world.tiles, &()) {
        Ok(()) => Ok(()),
        Err(i) => Err(outside(world, i, world.step, world.time)),
    }
}

/// Work fused into the binning: a system's last use of each particle's old stencil.
pub(crate) trait BeforeBin: Sync {
    /// Called with particle `i`'s cached stencil (shape `s` of `N` nodes per axis: first
    /// node `first`, parameters `params`) just before the new one overwrites it.
    fn before<const N: usize>(&self, s: ShapeKind, i: usize, first: u32, params: &[f64]);
}

/// Plain binning: nothing before.
impl BeforeBin for () {
    #[inline(always)]
    fn before<const N: usize>(&self, _: ShapeKind, _: usize, _: u32, _: &[f64]) {}
}

/// Evaluates every particle's stencil and tile in one pass over particle chunks, calling
/// `work.before` with particle `i`'s cached stencil just before it is overwritten (so a
/// system can fuse its last use of the old stencils into the binning), then sorts the
/// tiles if any particle changed tile. Returns the first particle whose stencil leaves the
/// grid (the bins are then left stale).
pub(crate) fn place<D: Dim>(
    x: &[D::Vec],
    half: &[D::Vec],
    geom: &GridGeom<D>,
    shape: ShapeKind,
    tiles: &mut Tiles,
    work: &impl BeforeBin,
) -> Result<(), usize> {
    let mut tile_of = std::mem::take(&mut tiles.tile_of);
    let sorted = tile_of.len() == x.len();
    tile_of.resize(x.len(), u32::MAX);
    let per = StencilCache::per::<D>(shape);
    let cell_part = &tiles.cell_part;
    let (first, params) = tiles.stencils.resize::<D>(x.len(), shape, geom.inv_h);
    // Per chunk: the first particle whose stencil leaves the grid, and whether any particle
    // changed tile.
    let chunks: Vec<(Option<usize>, bool)> = (
        tile_of.par_chunks_mut(CHUNK),
        first.par_chunks_mut(CHUNK),
        params.par_chunks_mut(CHUNK * per),
    )
        .into_par_iter()
        .enumerate()
        .map(|(c, (out, first, params))| {
            with_shape!(shape, S, N => {
                let (mut moved, p) = (false, S.params());
                let rows = first.iter_mut().zip(params.chunks_exact_mut(per));
                for (k, (t, (f, w))) in out.iter_mut().zip(rows).enumerate() {
                    let i = c * CHUNK + k;
                    work.before::<N>(S, i, *f, w);
                    let half = if half.is_empty() { D::zero() } else { half[i] };
                    let (mut tile, mut node) = (0, 0);
                    for a in 0..D::D {
                        let xi = (x[i][a] - geom.origin[a]) * geom.inv_h[a];
                        let l = half[a] * geom.inv_h[a];
                        // Also false for a non-finite position.
                        if !S.fits(xi, l, geom.cells[a]) {
                            return (Some(i), true);
                        }
                        // A non-negative cell index (fits), converted through i64 (see
                        // ShapeKind::locate).
                        tile += cell_part[a][xi as i64 as usize];
                        let (base, sp) = S.locate(xi, l);
                        node += base * geom.stride[a];
                        w[p * a..p * (a + 1)].copy_from_slice(&sp[..p]);
                    }
                    // Below the node count (the stencil fits), which scenarios cap at 2e8,
                    // so it fits in u32.
                    *f = node as u32;
                    moved |= tile != *t;
                    *t = tile;
                }
                (None, moved)
            })
        })
        .collect();
    tiles.tile_of = tile_of;
    if let Some(i) = chunks.iter().find_map(|c| c.0) {
        tiles.fresh = false;
        return Err(i);
    }
    // With no particle (a rank whose particles all left) nothing says whether the bins are
    // stale: they are rebuilt, which is then free.
    if chunks.iter().any(|c| c.1) || !sorted || x.is_empty() {
        tiles.sort();
    }
    tiles.fresh = true;
    Ok(())
}

/// The instability of particle `i`, whose stencil left the grid (or whose position is not
/// finite), at the positions of `step` and `time`.
pub(crate) fn outside<D: Dim>(world: &World<D>, i: usize, step: u64, time: f64) -> Unstable {
    let x = D::to_xyz(world.particles.x[i]);
    // The particle's number in the whole scene (split across ranks, not its place here).
    let i = world.particles.id.get(i).map_or(i as u64, |&id| id);
    let what = if x.iter().all(|c| c.is_finite()) {
        format!(
            "particle {i} left the grid at ({:.6e}, {:.6e}, {:.6e}) m (its stencil must stay \
             inside the grid)",
            x[0], x[1], x[2]
        )
    } else {
        format!("particle {i} has a non-finite position (NaN or infinity)")
    };
    Unstable { step, time, what }
}
