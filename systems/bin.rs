//! `bin`: sort particle indices into spatial tiles (counting sort), evaluate every particle's
//! stencil, and stop the run if a particle has left the grid or has a non-finite position.

use crate::dim::Dim;
use crate::error::Unstable;
use crate::world::{CHUNK, World};
use rayon::prelude::*;

/// Bins every particle by the tile of the cell that contains it. Nothing to do when the
/// particles have not moved since the last binning; no re-sort when none changed tile.
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
    let tiles_ref = &*tiles;
    // Per chunk: the first particle outside the grid, and whether any particle changed tile.
    let chunks: Vec<(Option<usize>, bool)> = tile_of
        .par_chunks_mut(CHUNK)
        .enumerate()
        .map(|(c, out)| {
            let mut moved = false;
            for (k, t) in out.iter_mut().enumerate() {
                let i = c * CHUNK + k;
                let x = p.x[i];
                if !geom.fits(shape, x, p.half_of(i)) {
                    return (Some(i), true);
                }
                let mut cell = [0; 3];
                for a in 0..D::D {
                    cell[a] = ((x[a] - geom.origin[a]) * geom.inv_h[a]) as usize;
                }
                let new = tiles_ref.tile_of_cell(cell);
                moved |= new != *t;
                *t = new;
            }
            (None, moved)
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
    tiles.stencils.fill(shape, geom, &p.x, &p.half);
    tiles.fresh = true;
    Ok(())
}
