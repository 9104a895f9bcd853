//! `bin`: sort particle indices into spatial tiles (counting sort), evaluate every particle's
//! stencil, and stop the run if a particle has left the grid or has a non-finite position.

use crate::dim::Dim;
use crate::error::Unstable;
use crate::shape::StencilCache;
use crate::with_shape;
use crate::world::{CHUNK, World};
use rayon::prelude::*;

/// Bins every particle by the tile of the cell that contains it and evaluates its stencil,
/// in one pass over the positions. Nothing to do when the particles have not moved since
/// the last binning; no re-sort when none changed tile.
pub fn run<D: Dim>(world: &mut World<D>) -> Result<(), Unstable> {
    if world.tiles.fresh {
        return Ok(());
    }
    let p = &world.particles;
    let geom = &world.grid.geom;
    let tiles = &mut world.tiles;
    let shape = world.settings.shape;
    let mut tile_of = std::mem::take(&mut tiles.tile_of);
    let sorted = tile_of.len() == p.len();
    tile_of.resize(p.len(), u32::MAX);
    let per = StencilCache::per::<D>();
    let cell_part = &tiles.cell_part;
    let (base, weights) = tiles.stencils.resize::<D>(p.len());
    // Per chunk: the first particle whose stencil leaves the grid, and whether any particle
    // changed tile.
    let chunks: Vec<(Option<usize>, bool)> = (
        tile_of.par_chunks_mut(CHUNK),
        base.par_chunks_mut(CHUNK),
        weights.par_chunks_mut(CHUNK * per),
    )
        .into_par_iter()
        .enumerate()
        .map(|(c, (out, base, weights))| {
            with_shape!(shape, S => {
                let mut moved = false;
                let rows = base.iter_mut().zip(weights.chunks_exact_mut(per));
                for (k, (t, (b, w))) in out.iter_mut().zip(rows).enumerate() {
                    let i = c * CHUNK + k;
                    let (x, half) = (p.x[i], p.half_of(i));
                    let mut tile = 0;
                    for a in 0..D::D {
                        let xi = (x[a] - geom.origin[a]) * geom.inv_h[a];
                        let l = half[a] * geom.inv_h[a];
                        // Also false for a non-finite position.
                        if !S.fits(xi, l, geom.cells[a]) {
                            return (Some(i), true);
                        }
                        tile += cell_part[a][xi as usize];
                        let (first, sw, sdw) = S.axis(xi, l, geom.inv_h[a]);
                        b[a] = first as u32;
                        w[6 * a..6 * a + 3].copy_from_slice(&sw);
                        w[6 * a + 3..6 * a + 6].copy_from_slice(&sdw);
                    }
                    moved |= tile != *t;
                    *t = tile;
                }
                (None, moved)
            })
        })
        .collect();
    tiles.tile_of = tile_of;
    let bad = chunks.iter().find_map(|c| c.0);
    let moved = chunks.iter().any(|c| c.1);
    if let Some(i) = bad {
        let x = D::to_xyz(p.x[i]);
        let what = if x.iter().all(|c| c.is_finite()) {
            format!(
                "left the grid at ({:.6e}, {:.6e}, {:.6e}) m (its stencil must stay inside the grid)",
                x[0], x[1], x[2]
            )
        } else {
            "has a non-finite position (NaN or infinity)".to_string()
        };
        return Err(Unstable {
            step: world.step,
            time: world.time,
            particle: i,
            what,
        });
    }
    if moved || !sorted {
        tiles.sort();
    }
    tiles.fresh = true;
    Ok(())
}
