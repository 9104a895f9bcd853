//! `bin`: sort particle indices into spatial tiles (counting sort) and stop the run if a
//! particle has left the grid or has a non-finite position.

use crate::dim::Dim;
use crate::error::Unstable;
use crate::world::{CHUNK, World};
use rayon::prelude::*;

/// Bins every particle by the tile of the cell that contains it (nothing to do when the
/// particles have not moved since the last binning).
pub fn run<D: Dim>(world: &mut World<D>) -> Result<(), Unstable> {
    if world.tiles.fresh {
        return Ok(());
    }
    let p = &world.particles;
    let geom = &world.grid.geom;
    let tiles = &mut world.tiles;
    let shape = world.settings.shape;
    let mut tile_of = std::mem::take(&mut tiles.tile_of);
    let tiles_ref = &*tiles;
    tile_of.resize(p.len(), 0);
    let bad = tile_of
        .par_chunks_mut(CHUNK)
        .enumerate()
        .map(|(c, out)| {
            for (k, t) in out.iter_mut().enumerate() {
                let i = c * CHUNK + k;
                let x = p.x[i];
                if !geom.fits(shape, x, p.half_of(i)) {
                    return Some(i);
                }
                let mut cell = [0; 3];
                for a in 0..D::D {
                    cell[a] = ((x[a] - geom.origin[a]) * geom.inv_h[a]) as usize;
                }
                *t = tiles_ref.tile_of_cell(cell);
            }
            None
        })
        .collect::<Vec<_>>()
        .into_iter()
        .flatten()
        .next();
    tiles.tile_of = tile_of;
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
    tiles.sort();
    Ok(())
}
