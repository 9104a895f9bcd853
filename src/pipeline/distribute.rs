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
use crate::store::world::{Dilatation, LinearSolver, Solver, World};
use crate::systems::bin;
use std::borrow::Cow;

/// Splits a scene across the ranks of `comm`: a scene built rank by rank
/// ([`build_share`](crate::io::scenario::build_share)) already holds this rank's share; one
/// every rank built whole (a resumed run's) keeps the particles in the tiles the partition
/// gives this rank, numbered by their index in the whole scene. Loads and probes keep
/// their whole lists, with the entries of other ranks' particles marked [`ABSENT`].
pub fn split<D: Dim>(world: &mut World<D>, probes: &mut [Probe], comm: Comm) -> anyhow::Result<()> {
    if !comm.is_split() {
        world.domain = Domain {
            comm,
            ..Domain::default()
        };
        return Ok(());
    }
    refuse_unsupported(world)?;
    if world.domain.partition.is_none() {
        keep_share(world, comm)?;
    }
    if let Some(c) = world.cracks.as_mut() {
        c.scratch.forget_particles();
    }
    for load in &mut world.loads {
        load.ids = load.particles.clone();
    }
    for probe in probes.iter_mut() {
        probe.ids = probe.particles.clone();
    }
    world.tiles.tile_of.clear();
    world.tiles.fresh = false;
    localize(world, probes);
    Ok(())
}

/// Divides the tiles of a scene this rank holds whole and keeps its own tiles' particles.
fn keep_share<D: Dim>(world: &mut World<D>, comm: Comm) -> anyhow::Result<()> {
    bin_for_split(world).map_err(|u| anyhow::anyhow!("{u}"))?;
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
    world.domain = Domain {
        comm,
        partition: Some(partition),
        rebalances: 0,
    };
    Ok(())
}

/// Bins the particles where the run will use them: where they are, or, in a static scene
/// (whose solves place its particles at their initial positions), where they started.
fn bin_for_split<D: Dim>(world: &mut World<D>) -> Result<(), Unstable> {
    if world.settings.solver != Solver::Static {
        return bin::run(world);
    }
    let p = &world.particles;
    let (geom, shape) = (&world.grid.geom, world.settings.shape);
    bin::place(&p.x0, &p.half, geom, shape, &mut world.tiles, &())
        .map_err(|i| bin::outside(world, i, world.step, world.time))
}

/// What a split run cannot do yet, refused by name.
fn refuse_unsupported<D: Dim>(world: &World<D>) -> anyhow::Result<()> {
    if !world.grid.mirrors.is_empty() {
        anyhow::bail!(
            "a symmetry plane on quadratic B-splines runs on one process only (its image \
             nodes mirror nodes that another rank may hold); run on one process, or give \
             simulation.shape = \"ugimp\""
        );
    }
    if world.settings.solver != Solver::Static {
        if world.settings.dilatation == Dilatation::CellMean {
            anyhow::bail!(
                "simulation.dilatation = \"cell_mean\" in an explicit scene runs on one \
                 process only (a particle that crosses into another rank's cell within a \
                 step would join that cell's mean there); run on one process, or give \
                 solver = \"static\""
            );
        }
        return Ok(());
    }
    if world.settings.linear == LinearSolver::Direct {
        anyhow::bail!(
            "simulation.linear = \"direct\": the sparse direct solver runs on one process \
             only; give linear = \"two_level\" or \"cg\" (or \"auto\", which takes \
             the coarse grid's conjugate gradients on several ranks)"
        );
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
    // A static scene's particles are quadrature points at their initial places: each keeps
    // the tile (and the rank) it started in.
    if world.settings.solver == Solver::Static {
        return Ok(false);
    }
    let me = world.domain.comm.rank();
    let p = &world.particles;
    let mut leaving: Vec<Vec<u32>> = vec![Vec::new(); partition.peers.len()];
    let (tile_of, lost) = tiles_now(world);
    let mut far = None;
    for (i, &t) in tile_of.iter().enumerate() {
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
    let peers = partition.peers.clone();
    let got = exchange_rows(world, &peers, &leaving);
    world.domain.agree(found)?;
    Ok(settle_rows(world, probes, &leaving, &got))
}

/// Each particle's tile from its position (the closing stress update's bins when they are
/// fresh), and the first particle outside the grid, if any.
fn tiles_now<D: Dim>(world: &World<D>) -> (Cow<'_, [u32]>, Option<usize>) {
    let p = &world.particles;
    if world.tiles.fresh && world.tiles.tile_of.len() == p.len() {
        return (Cow::Borrowed(&world.tiles.tile_of), None);
    }
    let geom = &world.grid.geom;
    let mut lost = None;
    let tiles = (0..p.len())
        .map(|i| {
            let (t, inside) = world.tiles.tile_nearest(geom, p.x[i]);
            if !inside {
                lost.get_or_insert(i);
            }
            t
        })
        .collect();
    (Cow::Owned(tiles), lost)
}

/// Sends the rows `leaving[k]` to `peers[k]` and returns what each sent here.
fn exchange_rows<D: Dim>(
    world: &mut World<D>,
    peers: &[usize],
    leaving: &[Vec<u32>],
) -> Vec<Vec<u8>> {
    let out: Vec<Vec<u8>> = (leaving.iter())
        .map(|rows| pack(&mut world.particles, rows))
        .collect();
    world.domain.comm.exchange(peers, &out)
}

/// Drops the rows that left, appends those that arrived, restores the ascending ids and
/// points loads and probes at the new places; returns whether anything moved.
fn settle_rows<D: Dim>(
    world: &mut World<D>,
    probes: &mut [Probe],
    leaving: &[Vec<u32>],
    got: &[Vec<u8>],
) -> bool {
    let moved = leaving.iter().any(|l| !l.is_empty()) || got.iter().any(|g| !g.is_empty());
    if !moved {
        return false;
    }
    let mut left = bitvec::bitvec![0; world.particles.len()];
    (leaving.iter().flatten()).for_each(|&i| left.set(i as usize, true));
    let stay: Vec<u32> = left.iter_zeros().map(|i| i as u32).collect();
    world.particles.permute(&stay);
    for bytes in got {
        unpack(&mut world.particles, bytes);
    }
    let mut order: Vec<u32> = (0..world.particles.len() as u32).collect();
    order.sort_by_key(|&i| world.particles.id[i as usize]);
    world.particles.permute(&order);
    world.tiles.tile_of.clear();
    world.tiles.fresh = false;
    if let Some(c) = world.cracks.as_mut() {
        c.scratch.forget_particles();
    }
    localize(world, probes);
    true
}

/// Steps between looks at the ranks' balance.
const BALANCE_EVERY: u64 = 64;
/// The most particles on a rank over the mean past which the tiles are divided anew.
const IMBALANCE: f64 = 1.25;

/// Every [`BALANCE_EVERY`] steps, when a rank holds more than [`IMBALANCE`] times the mean
/// particle count, divides the tiles anew by where the particles are now and moves each to
/// its tile's new owner. The results do not change (node sums and reductions do not depend
/// on the split). Every rank of a split run calls it at the same point of each step. A
/// static scene keeps its split: its particles do not move from where its solves use them.
pub fn rebalance<D: Dim>(world: &mut World<D>, probes: &mut [Probe]) -> Result<bool, Unstable> {
    if !world.domain.is_split()
        || !world.step.is_multiple_of(BALANCE_EVERY)
        || world.settings.solver == Solver::Static
    {
        return Ok(false);
    }
    let comm = world.domain.comm.clone();
    let held: Vec<u64> = (comm
        .all_gather((world.particles.len() as u64).to_le_bytes().to_vec())
        .iter())
    .map(|b| u64::from_le_bytes(b[..].try_into().expect("8 bytes per rank")))
    .collect();
    let mean = held.iter().sum::<u64>() as f64 / held.len() as f64;
    if (*held.iter().max().unwrap_or(&0) as f64) <= IMBALANCE * mean {
        return Ok(false);
    }
    let (tile_of, lost) = tiles_now(world);
    world.domain.agree(match lost {
        Some(i) => Err(bin::outside(world, i, world.step, world.time)),
        None => Ok(()),
    })?;
    let mut counts = vec![0u32; world.tiles.len()];
    tile_of.iter().for_each(|&t| counts[t as usize] += 1);
    let mut total = vec![0u32; counts.len()];
    for b in comm.all_gather(bytemuck::cast_slice(&counts).to_vec()) {
        let theirs: Vec<u32> = bytemuck::pod_collect_to_vec(&b);
        total.iter_mut().zip(theirs).for_each(|(t, c)| *t += c);
    }
    let tiles = &world.tiles;
    let grid = TileGrid {
        counts: tiles.counts,
        size: tiles.size,
        cells: world.grid.geom.cells,
        dims: D::D,
    };
    let (me, ranks) = (comm.rank(), comm.size());
    let partition = Partition::new(grid, &total, ranks, me).map_err(|e| Unstable {
        step: world.step,
        time: world.time,
        what: e.to_string(),
    })?;
    // Whole tiles may not divide better than now: then nothing moves.
    let mut shares = vec![0u64; ranks];
    (total.iter().zip(&partition.owner)).for_each(|(&c, &r)| shares[r as usize] += c as u64);
    if shares.iter().max() >= held.iter().max() {
        return Ok(false);
    }
    // Particles may go to any rank: every other rank is a peer of this exchange.
    let others: Vec<usize> = (0..ranks).filter(|&r| r != me).collect();
    let mut leaving: Vec<Vec<u32>> = vec![Vec::new(); others.len()];
    for (i, &t) in tile_of.iter().enumerate() {
        let owner = partition.owner[t as usize] as usize;
        if owner != me {
            let k = others
                .iter()
                .position(|&r| r == owner)
                .expect("another rank");
            leaving[k].push(i as u32);
        }
    }
    let got = exchange_rows(world, &others, &leaving);
    world.domain.partition = Some(partition);
    world.domain.rebalances += 1;
    settle_rows(world, probes, &leaving, &got);
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
