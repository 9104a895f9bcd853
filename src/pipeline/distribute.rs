//! Splitting a built scene across ranks, and moving particles to the rank that owns their
//! tile as they cross into it.

use crate::base::columnar::Columnar;
use crate::base::dim::Dim;
use crate::base::error::Unstable;
use crate::ranks::ABSENT;
use crate::ranks::comm::Comm;
use crate::ranks::domain::Domain;
use crate::ranks::partition::{Partition, TileGrid};
use crate::record::probe::Probe;
use crate::store::particles::{ColumnOp, Particles};
use crate::store::world::{Solver, World};
use crate::systems::bin;

/// Keeps this rank's particles of a scene every rank built whole: those in the tiles the
/// partition gives it, numbered by their index in the whole scene. Loads and probes keep
/// their whole lists, with the entries of other ranks' particles marked [`ABSENT`].
pub fn split<D: Dim>(world: &mut World<D>, probes: &mut [Probe], comm: Comm) -> anyhow::Result<()> {
    if !comm.is_split() {
        world.domain = Domain {
            comm,
            partition: None,
        };
        return Ok(());
    }
    refuse_unsupported(world)?;
    bin::run(world).map_err(|u| anyhow::anyhow!("{u}"))?;
    let tiles = &world.tiles;
    let counts: Vec<u32> = tiles.start.windows(2).map(|w| w[1] - w[0]).collect();
    let grid = TileGrid {
        counts: tiles.counts,
        size: tiles.size,
        cells: world.grid.geom.cells,
        dims: D::D,
    };
    let partition = Partition::new(grid, &counts, comm.size(), comm.rank())?;
    let me = comm.rank();
    let keep: Vec<u32> = (0..world.particles.len() as u32)
        .filter(|&i| partition.owns_tile(world.tiles.tile_of[i as usize], me))
        .collect();
    world.particles.id = (0..world.particles.len() as u64).collect();
    world.particles.permute(&keep);
    for load in &mut world.loads {
        load.ids = load.particles.clone();
    }
    for probe in probes.iter_mut() {
        probe.ids = probe.particles.clone();
    }
    world.tiles.tile_of.clear();
    world.tiles.fresh = false;
    world.domain = Domain {
        comm,
        partition: Some(partition),
    };
    localize(world, probes);
    Ok(())
}

/// What a split run cannot do yet, refused by name.
fn refuse_unsupported<D: Dim>(world: &World<D>) -> anyhow::Result<()> {
    let no = |what: &str| anyhow::anyhow!("{what} cannot yet run on more than one MPI rank");
    if world.cracks.is_some() {
        return Err(no("a scene with cracks"));
    }
    if world.settings.solver == Solver::Static {
        return Err(no("a static scene"));
    }
    Ok(())
}

/// Points the loads' and probes' whole lists at this rank's particles (ascending ids).
pub fn localize<D: Dim>(world: &mut World<D>, probes: &mut [Probe]) {
    let ids = &world.particles.id;
    let local = |g: &u32| ids.binary_search(&(*g as u64)).map_or(ABSENT, |i| i as u32);
    for load in &mut world.loads {
        load.particles = load.ids.iter().map(local).collect();
    }
    for probe in probes {
        probe.particles = probe.ids.iter().map(local).collect();
    }
}

/// Sends the particles now in another rank's tiles to it and takes in those entering this
/// rank's tiles; returns whether any particle left or arrived (the bins are then stale).
/// Every rank of a split run calls it at the same point of each step.
pub fn migrate<D: Dim>(world: &mut World<D>, probes: &mut [Probe]) -> Result<bool, Unstable> {
    let Some(partition) = &world.domain.partition else {
        return Ok(false);
    };
    let me = world.domain.comm.rank();
    let geom = &world.grid.geom;
    let p = &world.particles;
    let mut leaving: Vec<Vec<u32>> = vec![Vec::new(); partition.peers.len()];
    // The closing stress update binned the particles where they are now: their tiles are
    // known (else they are found from the positions).
    let binned = world.tiles.fresh && world.tiles.tile_of.len() == p.len();
    let (mut lost, mut far) = (None, None);
    for i in 0..p.len() {
        let t = if binned {
            world.tiles.tile_of[i]
        } else {
            let mut cell = [0usize; 3];
            for (a, slot) in cell.iter_mut().enumerate().take(D::D) {
                let c = ((p.x[i][a] - geom.origin[a]) * geom.inv_h[a]).floor();
                if !(c >= 0.0 && c < geom.cells[a] as f64) {
                    lost.get_or_insert(i);
                }
                *slot = (c.max(0.0) as usize).min(geom.cells[a] - 1);
            }
            world.tiles.tile_of_cell(cell)
        };
        let owner = partition.owner[t as usize] as usize;
        if owner == me {
            continue;
        } else if let Some(k) = partition.peers.iter().position(|&q| q == owner) {
            leaving[k].push(i as u32);
        } else {
            far.get_or_insert((i, owner));
        }
    }
    // Every rank takes part in the exchange, then all stop if one found a particle lost.
    let found = match (lost, far) {
        (Some(i), _) => Err(bin::outside(world, i, world.step, world.time)),
        (None, Some((i, owner))) => Err(Unstable {
            step: world.step,
            time: world.time,
            what: format!(
                "particle {} crossed more than a tile in one step (to rank {owner})",
                p.id[i]
            ),
        }),
        (None, None) => Ok(()),
    };
    let out: Vec<Vec<u8>> = leaving
        .iter()
        .map(|rows| pack(&mut world.particles, rows))
        .collect();
    let got = world.domain.comm.exchange(&partition.peers, &out);
    world.domain.agree(found)?;
    let moved = leaving.iter().any(|l| !l.is_empty()) || got.iter().any(|g| !g.is_empty());
    if !moved {
        return Ok(false);
    }
    let mut left = bitvec::bitvec![0; world.particles.len()];
    leaving
        .iter()
        .flatten()
        .for_each(|&i| left.set(i as usize, true));
    let stay: Vec<u32> = left.iter_zeros().map(|i| i as u32).collect();
    world.particles.permute(&stay);
    for bytes in &got {
        unpack(&mut world.particles, bytes);
    }
    let mut order: Vec<u32> = (0..world.particles.len() as u32).collect();
    order.sort_by_key(|&i| world.particles.id[i as usize]);
    world.particles.permute(&order);
    world.tiles.tile_of.clear();
    world.tiles.fresh = false;
    localize(world, probes);
    Ok(true)
}

/// The rows `rows` of every allocated column, column after column, after the row count and
/// a mask of the allocated columns (a rank that holds no particles has no column
/// allocated, and takes the sender's).
fn pack<D: Dim>(p: &mut Particles<D>, rows: &[u32]) -> Vec<u8> {
    struct Pack<'a> {
        rows: &'a [u32],
        out: Vec<u8>,
        mask: u32,
        k: u32,
    }
    impl ColumnOp for Pack<'_> {
        fn column<T: Columnar>(&mut self, col: &mut Vec<T>) {
            if !col.is_empty() {
                self.mask |= 1 << self.k;
                for &i in self.rows {
                    (self.out).extend_from_slice(bytemuck::bytes_of(&col[i as usize]));
                }
            }
            self.k += 1;
        }
    }
    if rows.is_empty() {
        return Vec::new();
    }
    let mut op = Pack {
        rows,
        out: vec![0; 8],
        mask: 0,
        k: 0,
    };
    p.for_each_column(&mut op);
    op.out[..4].copy_from_slice(&(rows.len() as u32).to_le_bytes());
    op.out[4..8].copy_from_slice(&op.mask.to_le_bytes());
    op.out
}

/// Appends the rows [`pack`] wrote.
fn unpack<D: Dim>(p: &mut Particles<D>, bytes: &[u8]) {
    struct Unpack<'a> {
        bytes: &'a [u8],
        at: usize,
        rows: usize,
        mask: u32,
        k: u32,
    }
    impl ColumnOp for Unpack<'_> {
        fn column<T: Columnar>(&mut self, col: &mut Vec<T>) {
            if self.mask & (1 << self.k) != 0 {
                let size = std::mem::size_of::<T>();
                for _ in 0..self.rows {
                    let b = &self.bytes[self.at..self.at + size];
                    col.push(bytemuck::pod_read_unaligned(b));
                    self.at += size;
                }
            }
            self.k += 1;
        }
    }
    if bytes.is_empty() {
        return;
    }
    let word = |k: usize| u32::from_le_bytes(bytes[k..k + 4].try_into().expect("4 bytes"));
    let mut op = Unpack {
        bytes,
        at: 8,
        rows: word(0) as usize,
        mask: word(4),
        k: 0,
    };
    p.for_each_column(&mut op);
}
