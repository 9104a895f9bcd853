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

/// The particle columns; the optional ones (uGIMP size, gradients, plastic state) where
/// the rebuilt scene keeps them. `at`: the rows of `p` the file's rows go to (a piece of a
/// split run), else all of them in order.
pub fn read_particles<D: Dim>(
    r: &mut Reader,
    p: &mut Particles<D>,
    at: Option<&[u64]>,
) -> Result<(), SnapshotError> {
    put(r, "particles.x", &mut p.x, at)?;
    put(r, "particles.v", &mut p.v, at)?;
    put(r, "particles.x0", &mut p.x0, at)?;
    put(r, "particles.mass", &mut p.mass, at)?;
    put(r, "particles.volume", &mut p.volume, at)?;
    put(r, "particles.stress", &mut p.stress, at)?;
    put(r, "particles.material", &mut p.material, at)?;
    put(r, "particles.half", &mut p.half, at)?;
    if !p.grad_u.is_empty() {
        put(r, "particles.grad_u", &mut p.grad_u, at)?;
        put(r, "particles.grad_v", &mut p.grad_v, at)?;
    }
    if !p.hardened.is_empty() {
        put(r, "particles.plastic_strain", &mut p.plastic_strain, at)?;
        put(r, "particles.hardened", &mut p.hardened, at)?;
    }
    Ok(())
}

/// Appends rows `rows` of the `n` particle rows of `r` to `p`. Each optional column (uGIMP
/// size, gradients, plastic state) is taken where the file holds it: a split run's rank
/// builds its share of the scene, which may hold no particle to say which columns the
/// scene keeps.
pub fn append_rows<D: Dim>(
    r: &mut Reader,
    p: &mut Particles<D>,
    rows: &[usize],
    n: usize,
) -> Result<(), SnapshotError> {
    let at = (rows, n);
    append(r, "particles.x", &mut p.x, at)?;
    append(r, "particles.v", &mut p.v, at)?;
    append(r, "particles.x0", &mut p.x0, at)?;
    append(r, "particles.mass", &mut p.mass, at)?;
    append(r, "particles.volume", &mut p.volume, at)?;
    append(r, "particles.stress", &mut p.stress, at)?;
    append(r, "particles.material", &mut p.material, at)?;
    append(r, "particles.half", &mut p.half, at)?;
    append(r, "particles.grad_u", &mut p.grad_u, at)?;
    append(r, "particles.grad_v", &mut p.grad_v, at)?;
    append(r, "particles.plastic_strain", &mut p.plastic_strain, at)?;
    append(r, "particles.hardened", &mut p.hardened, at)
}

/// Appends rows `rows` of column `name` (of `n` rows, or none: a column the scene does
/// not keep) to `col`.
fn append<T: Columnar>(
    r: &mut Reader,
    name: &str,
    col: &mut Vec<T>,
    (rows, n): (&[usize], usize),
) -> Result<(), SnapshotError> {
    let all: Vec<T> = r.column_any(name)?;
    if all.is_empty() {
        return Ok(());
    }
    if all.len() != n {
        return Err(r.invalid(format!(
            "column `{name}` holds {} rows; expected {n} or none",
            all.len()
        )));
    }
    col.extend(rows.iter().map(|&k| all[k]));
    Ok(())
}

/// Reads column `name` into `col`: whole, or row k into `col[at[k]]`. A column the scene
/// does not keep (empty) must be empty in the file too.
fn put<T: Columnar>(
    r: &mut Reader,
    name: &str,
    col: &mut [T],
    at: Option<&[u64]>,
) -> Result<(), SnapshotError> {
    match at {
        _ if col.is_empty() => {
            r.column::<T>(name, 0)?;
        }
        None => col.copy_from_slice(&r.column::<T>(name, col.len())?),
        Some(rows) => {
            let values: Vec<T> = r.column(name, rows.len())?;
            for (&i, v) in rows.iter().zip(values) {
                col[i as usize] = v;
            }
        }
    }
    Ok(())
}
