//! Which rank owns which tiles: contiguous runs of tiles along a Morton curve, balanced by
//! particle count; and what follows from it for one rank: the nodes it owns, the ranks its
//! tiles' stencils share nodes with, and the shared nodes it sends after each colour class.

use bitvec::prelude::*;

/// The tile grid a partition divides: tiles per axis, cells per tile edge, cells per axis.
#[derive(Clone, Copy, Debug)]
pub struct TileGrid {
    /// Tiles per axis (1 on unused axes).
    pub counts: [usize; 3],
    /// Cells per tile edge.
    pub size: usize,
    /// Cells per axis (1 on unused axes... as the grid gives them).
    pub cells: [usize; 3],
    /// Axes in use (2 or 3).
    pub dims: usize,
}

impl TileGrid {
    /// Nodes per axis (one on unused axes).
    fn nodes(&self) -> [usize; 3] {
        std::array::from_fn(|a| if a < self.dims { self.cells[a] + 1 } else { 1 })
    }

    /// Tile coordinates of linear tile index `t`.
    fn coords(&self, t: usize) -> [usize; 3] {
        let [nx, ny, _] = self.counts;
        [t % nx, (t / nx) % ny, t / (nx * ny)]
    }

    /// Colour class of tile `t` (parity per axis, as `Tiles::colour`).
    fn colour(&self, t: usize) -> usize {
        let c = self.coords(t);
        (c[0] & 1) | ((c[1] & 1) << 1) | ((c[2] & 1) << 2)
    }

    /// The nodes (inclusive bounds per axis) the particles of tile `t` can reach: one node
    /// below its cells and two above (the widest stencil, as `tiles.rs` assumes).
    fn reach(&self, t: usize) -> ([usize; 3], [usize; 3]) {
        let (c, nodes) = (self.coords(t), self.nodes());
        let mut lo = [0; 3];
        let mut hi = [0; 3];
        for a in 0..self.dims {
            let first = c[a] * self.size;
            let last = ((c[a] + 1) * self.size).min(self.cells[a]) - 1;
            lo[a] = first.saturating_sub(1);
            hi[a] = (last + 2).min(nodes[a] - 1);
        }
        (lo, hi)
    }

    /// Calls `f` with every node index tile `t` can reach, x fastest.
    fn for_each_reached(&self, t: usize, mut f: impl FnMut(usize)) {
        let ([x0, y0, z0], [x1, y1, z1]) = self.reach(t);
        let [nx, ny, _] = self.nodes();
        for k in z0..=z1 {
            for j in y0..=y1 {
                for i in x0..=x1 {
                    f(i + nx * (j + ny * k));
                }
            }
        }
    }
}

/// The tiles' owners and this rank's share of the node traffic.
#[derive(Clone, Debug)]
pub struct Partition {
    /// Owner rank of each tile.
    pub owner: Vec<u32>,
    /// Nodes this rank owns (each node has one owner: that of the tile holding the node's
    /// cell, the last cell on the upper faces); node sums count owned nodes only.
    pub owned_nodes: BitVec,
    /// Ranks whose tiles reach a node this rank's tiles reach, ascending.
    pub peers: Vec<usize>,
    /// Per peer: the nodes both its tiles and this rank's reach.
    pub shared: Vec<BitVec>,
    /// Per colour class, per peer: the shared nodes this rank sends after the class.
    pub sends: Vec<Vec<Vec<u32>>>,
    /// Per colour class, per peer: the shared nodes this rank receives after the class.
    pub receives: Vec<Vec<Vec<u32>>>,
    /// Per tile: whether it is this rank's and reaches a node this rank receives after the
    /// colour class before the tile's own (class 0 waits for none).
    pub waits: BitVec,
    /// Per colour class: the peers (their indices in `peers`) this rank sends to or
    /// receives from after the class; the others are left out on both sides, since the
    /// lists are each other's mirror.
    pub talks: Vec<Vec<usize>>,
    /// The nodes from the first to the last this rank's tiles reach (those it scatters to,
    /// updates and gathers from).
    pub span: std::ops::Range<usize>,
}

/// Why tiles cannot be split across the ranks.
#[derive(Debug, thiserror::Error)]
#[error(
    "{ranks} MPI ranks but the grid has {tiles} tiles: every rank needs one (use fewer ranks, \
     smaller tiles: `simulation.tile`, or a finer grid)"
)]
pub struct TooManyRanks {
    /// Ranks asked.
    pub ranks: usize,
    /// Tiles in the grid.
    pub tiles: usize,
}

impl Partition {
    /// Splits the tiles among `ranks` (tile `t` holds `particles[t]` particles) and works
    /// out rank `me`'s nodes, peers and shared nodes.
    pub fn new(
        grid: TileGrid,
        particles: &[u32],
        ranks: usize,
        me: usize,
    ) -> Result<Self, TooManyRanks> {
        let owner = owners(&grid, particles, ranks)?;
        let nodes = grid.nodes();
        let total = nodes.iter().product::<usize>();
        // The nodes rank r's tiles reach; held for this rank and its peers only (a table
        // for every rank would cost a bit per node per rank).
        let reached_by = |r: usize| {
            let mut b = bitvec![0; total];
            for t in (0..owner.len()).filter(|&t| owner[t] as usize == r) {
                grid.for_each_reached(t, |n| b.set(n, true));
            }
            b
        };
        let mine = reached_by(me);
        let mut meets = vec![false; ranks];
        for (t, &r) in owner.iter().enumerate() {
            if r as usize != me && !meets[r as usize] {
                grid.for_each_reached(t, |n| meets[r as usize] |= mine[n]);
            }
        }
        let peers: Vec<usize> = (0..ranks).filter(|&q| meets[q]).collect();
        let theirs: Vec<BitVec> = peers.iter().map(|&q| reached_by(q)).collect();
        let reached = |r: usize| match peers.binary_search(&r) {
            Ok(k) => &theirs[k],
            Err(_) => {
                debug_assert_eq!(r, me, "nodes reached by a rank that is no peer");
                &mine
            }
        };
        let classes = 1 << grid.dims;
        // The shared nodes `from`'s tiles of class `c` reach that `to`'s tiles reach too,
        // tile by tile in index order: the same list on both sides.
        let shared = |from: usize, to: usize, c: usize| {
            let mut list = Vec::new();
            for t in (0..owner.len()).filter(|&t| owner[t] as usize == from) {
                if grid.colour(t) == c {
                    let to = reached(to);
                    grid.for_each_reached(t, |n| {
                        if to[n] {
                            list.push(n as u32);
                        }
                    });
                }
            }
            list
        };
        let sends: Vec<Vec<Vec<u32>>> = (0..classes)
            .map(|c| peers.iter().map(|&q| shared(me, q, c)).collect())
            .collect();
        let receives: Vec<Vec<Vec<u32>>> = (0..classes)
            .map(|c| peers.iter().map(|&q| shared(q, me, c)).collect())
            .collect();
        let talks = (0..classes)
            .map(|c| {
                (0..peers.len())
                    .filter(|&k| !(sends[c][k].is_empty() && receives[c][k].is_empty()))
                    .collect()
            })
            .collect();
        let mut waits = bitvec![0; owner.len()];
        for c in 1..classes {
            let mut arriving = bitvec![0; total];
            receives[c - 1]
                .iter()
                .flatten()
                .for_each(|&n| arriving.set(n as usize, true));
            for t in (0..owner.len()).filter(|&t| owner[t] as usize == me && grid.colour(t) == c) {
                let mut reaches = false;
                grid.for_each_reached(t, |n| reaches |= arriving[n]);
                waits.set(t, reaches);
            }
        }
        let shared = theirs.iter().map(|b| b.clone() & &mine).collect();
        let mut owned_nodes = bitvec![0; total];
        let [nx, ny, _] = nodes;
        for n in 0..total {
            let node = [n % nx, (n / nx) % ny, n / (nx * ny)];
            let mut t = 0;
            let mut stride = 1;
            for (a, &at) in node.iter().enumerate().take(grid.dims) {
                let cell = at.min(grid.cells[a] - 1);
                t += (cell / grid.size) * stride;
                stride *= grid.counts[a];
            }
            owned_nodes.set(n, owner[t] as usize == me);
        }
        let span = match (mine.first_one(), mine.last_one()) {
            (Some(a), Some(b)) => a..b + 1,
            _ => 0..0,
        };
        Ok(Partition {
            span,
            owner,
            owned_nodes,
            peers,
            shared,
            sends,
            receives,
            waits,
            talks,
        })
    }

    /// Whether this rank owns tile `t`.
    pub fn owns_tile(&self, t: u32, me: usize) -> bool {
        self.owner[t as usize] as usize == me
    }
}

/// Tile owners: the tiles in Morton order cut into `ranks` contiguous runs holding as
/// equal particle counts as whole tiles allow (each rank at least one tile).
fn owners(grid: &TileGrid, particles: &[u32], ranks: usize) -> Result<Vec<u32>, TooManyRanks> {
    let n = particles.len();
    if ranks > n {
        return Err(TooManyRanks { ranks, tiles: n });
    }
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by_key(|&t| morton(grid.coords(t)));
    let total: u64 = particles.iter().map(|&p| p as u64).sum();
    let mut owner = vec![0u32; n];
    let mut before = 0u64;
    for (k, &t) in order.iter().enumerate() {
        // The rank whose share of the particle count this tile's middle falls in, kept
        // within what leaves every later rank a tile and never going back.
        let mid = 2 * before + particles[t] as u64;
        let by_count = if total == 0 {
            k * ranks / n
        } else {
            ((mid as u128 * ranks as u128) / (2 * total as u128)) as usize
        };
        let prev = if k == 0 {
            0
        } else {
            owner[order[k - 1]] as usize
        };
        let least = ranks.saturating_sub(n - k).max(prev);
        let most = (prev + usize::from(k > 0)).min(k).min(ranks - 1);
        owner[t] = by_count.clamp(least, most.max(least)) as u32;
        before += particles[t] as u64;
    }
    Ok(owner)
}

/// Interleaves the bits of three tile coordinates (x lowest).
fn morton(c: [usize; 3]) -> u64 {
    let mut code = 0u64;
    for bit in 0..21 {
        for (a, &x) in c.iter().enumerate() {
            code |= (((x >> bit) & 1) as u64) << (3 * bit + a);
        }
    }
    code
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid2(tiles: [usize; 2], size: usize) -> TileGrid {
        TileGrid {
            counts: [tiles[0], tiles[1], 1],
            size,
            cells: [tiles[0] * size - 1, tiles[1] * size, 1],
            dims: 2,
        }
    }

    #[test]
    fn owners_are_contiguous_balanced_and_cover_every_rank() {
        let g = grid2([8, 6], 4);
        let particles: Vec<u32> = (0..48).map(|t| (t % 5) as u32 * 10 + 3).collect();
        for ranks in [1, 2, 3, 4, 7, 48] {
            let owner = owners(&g, &particles, ranks).unwrap();
            let mut order: Vec<usize> = (0..48).collect();
            order.sort_by_key(|&t| morton(g.coords(t)));
            let along: Vec<u32> = order.iter().map(|&t| owner[t]).collect();
            assert!(along.windows(2).all(|w| w[1] == w[0] || w[1] == w[0] + 1));
            assert_eq!(along[0], 0);
            assert_eq!(*along.last().unwrap() as usize, ranks - 1);
            let mut load = vec![0u32; ranks];
            owner
                .iter()
                .zip(&particles)
                .for_each(|(&r, &p)| load[r as usize] += p);
            let mean = particles.iter().sum::<u32>() as f64 / ranks as f64;
            let worst = *particles.iter().max().unwrap() as f64;
            if ranks <= 4 {
                assert!(
                    load.iter().all(|&l| (l as f64 - mean).abs() <= worst),
                    "{load:?}"
                );
            }
        }
        assert!(owners(&g, &particles, 49).is_err());
    }

    #[test]
    fn shared_nodes_match_between_peers_and_cover_every_shared_node() {
        let g = grid2([6, 5], 3);
        let particles = vec![1; 30];
        let parts: Vec<Partition> = (0..3)
            .map(|r| Partition::new(g, &particles, 3, r).unwrap())
            .collect();
        for (r, p) in parts.iter().enumerate() {
            for (k, &q) in p.peers.iter().enumerate() {
                let back = parts[q].peers.iter().position(|&x| x == r).unwrap();
                for c in 0..4 {
                    assert_eq!(p.sends[c][k], parts[q].receives[c][back]);
                }
            }
        }
        // Each node is owned once.
        let total = parts[0].owned_nodes.len();
        for n in 0..total {
            assert_eq!(parts.iter().filter(|p| p.owned_nodes[n]).count(), 1);
        }
        // A node reached by two ranks is sent by whichever reaches it in some class.
        let reached = |r: usize| {
            let mut b = bitvec![0; total];
            for t in 0..30 {
                if parts[0].owner[t] as usize == r {
                    g.for_each_reached(t, |n| b.set(n, true));
                }
            }
            b
        };
        let (r0, r1) = (reached(0), reached(1));
        let k = parts[0].peers.iter().position(|&q| q == 1).unwrap();
        for n in 0..total {
            if r0[n] && r1[n] {
                let sent = (0..4).any(|c| parts[0].sends[c][k].contains(&(n as u32)));
                assert!(sent, "node {n} shared but never sent");
            }
        }
    }

    /// On 7 ranks of a 3D grid, where not every two ranks meet, each rank's peers are the
    /// ranks whose tiles reach a node its own tiles reach, and its shared nodes those both
    /// reach (a brute-force table of every rank's nodes).
    #[test]
    fn peers_are_the_ranks_that_reach_a_common_node() {
        let g = TileGrid {
            counts: [5, 4, 3],
            size: 3,
            cells: [14, 12, 9],
            dims: 3,
        };
        let tiles = 60;
        let particles: Vec<u32> = (0..tiles).map(|t| (t * 7 % 11) as u32 + 1).collect();
        let ranks = 7;
        let parts: Vec<Partition> = (0..ranks)
            .map(|r| Partition::new(g, &particles, ranks, r).unwrap())
            .collect();
        let total = parts[0].owned_nodes.len();
        let reached: Vec<BitVec> = (0..ranks)
            .map(|r| {
                let mut b = bitvec![0; total];
                for t in (0..tiles).filter(|&t| parts[0].owner[t] as usize == r) {
                    g.for_each_reached(t, |n| b.set(n, true));
                }
                b
            })
            .collect();
        let mut apart = 0;
        for (r, p) in parts.iter().enumerate() {
            let meet: Vec<usize> = (0..ranks)
                .filter(|&q| q != r && (reached[q].clone() & &reached[r]).any())
                .collect();
            apart += ranks - 1 - meet.len();
            assert_eq!(p.peers, meet, "rank {r}");
            for (k, &q) in p.peers.iter().enumerate() {
                assert_eq!(p.shared[k], reached[q].clone() & &reached[r]);
            }
        }
        assert!(apart > 0, "some ranks do not meet");
    }
}
