//! The columns a whole snapshot and a split run's piece share: the particles' and the
//! header's.

use super::format::{ColumnSet, Header, Reader, SnapshotError};
use crate::base::columnar::Columnar;
use crate::base::dim::Dim;
use crate::io::scenario::Source;
use crate::store::particles::Particles;
use crate::store::world::World;
use xxhash_rust::xxh3::xxh3_64;

/// The particle columns (ids aside).
pub fn add_particles<'a, D: Dim>(c: &mut ColumnSet<'a>, p: &'a Particles<D>) {
    c.add("particles.x", &p.x);
    c.add("particles.v", &p.v);
    c.add("particles.x0", &p.x0);
    c.add("particles.mass", &p.mass);
    c.add("particles.volume", &p.volume);
    c.add("particles.stress", &p.stress);
    c.add("particles.grad_v", &p.grad_v);
    c.add("particles.material", &p.material);
    c.add("particles.half", &p.half);
    c.add("particles.grad_u", &p.grad_u);
    c.add("particles.plastic_strain", &p.plastic_strain);
    c.add("particles.hardened", &p.hardened);
}

/// The header of a snapshot of `world` holding `particles` particles.
pub fn header<D: Dim>(src: &Source, world: &World<D>, particles: u64) -> Header {
    Header {
        dimension: D::D as u8,
        particles,
        nodes: world.grid.geom.node_count() as u64,
        step: world.step,
        time: world.time,
        dt: world.settings.dt,
        scenario: src.name(),
        scenario_hash: xxh3_64(src.text.as_bytes()),
        build: env!("CARGO_PKG_VERSION").to_string(),
        data_len: 0,
        columns: Vec::new(),
    }
}

/// Which optional particle columns a scene keeps: uGIMP's size, the gradients J needs, the
/// plastic state.
#[derive(Clone, Copy, Debug)]
pub struct Kept {
    pub half: bool,
    pub gradients: bool,
    pub plastic: bool,
}

/// Appends rows `rows` (None: all) of the `n` particle rows of `r` to `p`, whose columns
/// are sized for `total` particles in all: every column the scene keeps (`kept`) must hold
/// `n` rows, every other none.
pub fn append_rows<D: Dim>(
    r: &mut Reader,
    p: &mut Particles<D>,
    (rows, n, total): (Option<&[usize]>, usize, usize),
    kept: Kept,
) -> Result<(), SnapshotError> {
    let at = |k: bool| (rows, if k { n } else { 0 }, total);
    append(r, "particles.x", &mut p.x, at(true))?;
    append(r, "particles.v", &mut p.v, at(true))?;
    append(r, "particles.x0", &mut p.x0, at(true))?;
    append(r, "particles.mass", &mut p.mass, at(true))?;
    append(r, "particles.volume", &mut p.volume, at(true))?;
    append(r, "particles.stress", &mut p.stress, at(true))?;
    append(r, "particles.material", &mut p.material, at(true))?;
    append(r, "particles.half", &mut p.half, at(kept.half))?;
    append(r, "particles.grad_u", &mut p.grad_u, at(kept.gradients))?;
    append(r, "particles.grad_v", &mut p.grad_v, at(kept.gradients))?;
    append(
        r,
        "particles.plastic_strain",
        &mut p.plastic_strain,
        at(kept.plastic),
    )?;
    append(r, "particles.hardened", &mut p.hardened, at(kept.plastic))
}

/// Appends rows `rows` (None: all) of column `name`, which must hold `n` items, to `col`,
/// sized for `total` items at once (nothing when `n` is 0: a column the scene does not
/// keep).
fn append<T: Columnar>(
    r: &mut Reader,
    name: &str,
    col: &mut Vec<T>,
    (rows, n, total): (Option<&[usize]>, usize, usize),
) -> Result<(), SnapshotError> {
    let all: Vec<T> = r.column(name, n)?;
    if n > 0 {
        col.reserve_exact(total.saturating_sub(col.len()));
        match rows {
            None => col.extend_from_slice(&all),
            Some(rows) => col.extend(rows.iter().map(|&k| all[k])),
        }
    }
    Ok(())
}
