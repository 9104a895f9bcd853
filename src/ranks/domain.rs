//! A rank's share of a scene: the ranks, the partition of the tiles, and the exchanges that
//! keep the shared nodes' sums those one rank would form.
//!
//! Node sums are bitwise those of one rank because one rank already adds them in a fixed
//! order: colour class after colour class, and within a class a node hears from one tile
//! only (`tiles.rs`). Split across ranks, each rank scatters its own tiles of a class,
//! then sends every shared node its tiles of that class reach to the peers that reach it
//! too, which take the value as theirs. Before each class every rank holding a shared node
//! therefore holds the one-rank running sum, and after the last class the full sum. While
//! a class's values travel, each rank scatters the next class's tiles that reach none of
//! the nodes it receives (`Partition::waits`): those tiles add to no node whose running
//! sum is on its way, so the order of every sum stays that of one rank, and a rank ahead
//! of its peer works instead of waiting.

use crate::base::error::Unstable;
use crate::base::exact_sum::ExactSum;
use crate::ranks::comm::Comm;
use crate::ranks::partition::Partition;
use bitvec::slice::BitSlice;
use bytemuck::Pod;
use std::ops::Range;

/// The ranks and, when there is more than one, this rank's partition.
#[derive(Clone, Debug, Default)]
pub struct Domain {
    /// The ranks.
    pub comm: Comm,
    /// This rank's tiles and shared nodes (None on one rank).
    pub partition: Option<Partition>,
    /// How many times the tiles were divided anew as the particles moved.
    pub rebalances: u32,
}

/// A grid column a colour class's exchange carries.
pub trait Shared {
    /// Appends the values of `nodes` as bytes.
    fn pack(&self, nodes: &[u32], out: &mut Vec<u8>);
    /// Overwrites `nodes` with values from `bytes`; returns the bytes read.
    fn unpack(&self, nodes: &[u32], bytes: &[u8]) -> usize;
}

impl Domain {
    /// One rank: nothing shared.
    pub fn single() -> Self {
        Domain::default()
    }

    /// Whether the scene is split across ranks.
    pub fn is_split(&self) -> bool {
        self.partition.is_some()
    }

    /// A scatter pass over `classes` colour classes, settling the shared nodes of every
    /// column of `columns` after each (see the module doc): `run(c, held)` scatters class
    /// c's tiles that [`wait`](Self::waits) (`held`) or the others. After each class this
    /// rank sends the shared nodes its tiles of the class reached and takes the peers'
    /// before running the next class's held tiles; on one rank it runs the classes in turn.
    pub fn settle_pass(
        &self,
        classes: usize,
        columns: &[&dyn Shared],
        run: impl FnMut(usize, bool),
    ) {
        let Some(p) = &self.partition else {
            return self
                .comm
                .colour_pass(classes, |_| Vec::new(), |_| Vec::new(), |_, _| {}, run);
        };
        let peers = |c: usize| p.talks[c].iter().map(|&k| p.peers[k]).collect();
        let pack = |c: usize| {
            (p.talks[c].iter())
                .map(|&k| {
                    let mut buf = Vec::new();
                    columns
                        .iter()
                        .for_each(|col| col.pack(&p.sends[c][k], &mut buf));
                    buf
                })
                .collect()
        };
        let unpack = |c: usize, got: Vec<Vec<u8>>| {
            for (&k, bytes) in p.talks[c].iter().zip(&got) {
                let nodes = &p.receives[c][k];
                let mut at = 0;
                for col in columns {
                    at += col.unpack(nodes, &bytes[at..]);
                }
            }
        };
        self.comm.colour_pass(classes, peers, pack, unpack, run);
    }

    /// The tiles whose scatter must wait for the colour class before their own to settle
    /// (they reach a node a peer sends after it), None on one rank: the others of the
    /// class run while that class's values travel ([`settle_pass`](Self::settle_pass)).
    pub fn waits(&self) -> Option<&BitSlice> {
        self.partition.as_ref().map(|p| p.waits.as_bitslice())
    }

    /// The grid entries, of `len` with the crack fields' extra rows from `nodes` on, that
    /// this rank's particles can reach: all of them on one rank; split, the partition's
    /// node span and every extra row (those of other ranks' nodes stay massless).
    pub fn spans(&self, len: usize, nodes: usize) -> [Range<usize>; 2] {
        match &self.partition {
            None => [0..len, len..len],
            Some(p) => [p.span.clone(), nodes.min(len)..len],
        }
    }

    /// Whether this rank owns tile `t` (every tile on one rank).
    pub fn owns_tile(&self, t: u32) -> bool {
        (self.partition.as_ref()).is_none_or(|p| p.owns_tile(t, self.comm.rank()))
    }

    /// Whether this rank counts node `n` in node sums (every node on one rank).
    #[inline(always)]
    pub fn owns_node(&self, n: usize) -> bool {
        self.partition.as_ref().is_none_or(|p| p.owned_nodes[n])
    }

    /// Whether every rank's `stepped` is Ok: split, every rank calls it at the same point
    /// and all get the lowest failing rank's error (its own if it failed), so that none
    /// goes on to wait for one that stopped.
    pub fn agree(&self, stepped: Result<(), Unstable>) -> Result<(), Unstable> {
        if !self.is_split() {
            return stepped;
        }
        // The step, the time's bits and what happened, space-separated.
        let mine =
            (stepped.as_ref().err()).map(|u| format!("{} {} {}", u.step, u.time.to_bits(), u.what));
        match self.comm.first_error(mine) {
            None => Ok(()),
            Some(_) if stepped.is_err() => stepped,
            Some((rank, text)) => {
                let mut parts = text.splitn(3, ' ');
                let mut next = || parts.next().unwrap_or_default();
                let (step, time) = (next().parse().unwrap_or(0), next().parse().unwrap_or(0));
                Err(Unstable {
                    step,
                    time: f64::from_bits(time),
                    what: format!("on rank {rank}: {}", next()),
                })
            }
        }
    }

    /// The largest of every rank's `x`.
    pub fn max(&self, x: f64) -> f64 {
        if !self.comm.is_split() {
            return x;
        }
        (self.comm.all_gather(x.to_le_bytes().to_vec()).iter())
            .map(|b| f64::from_le_bytes(b[..].try_into().expect("8 bytes per rank")))
            .fold(x, f64::max)
    }

    /// The smallest of every rank's `x`.
    pub fn min(&self, x: f64) -> f64 {
        -self.max(-x)
    }

    /// Whether `yes` holds on any rank.
    pub fn any(&self, yes: bool) -> bool {
        self.max(f64::from(u8::from(yes))) > 0.0
    }

    /// Every rank's `mine` (each in `key` order) as one list in `key` order, ties in rank
    /// order: what one rank, holding every particle, would have listed (`mine` on one
    /// rank).
    pub fn in_order<T: Pod, K: Ord>(&self, mine: Vec<T>, key: impl Fn(&T) -> K) -> Vec<T> {
        let mut all = self.in_order_each(vec![mine], key);
        all.pop().expect("one list")
    }

    /// [`in_order`](Self::in_order) for several lists at once, in one collective: the
    /// `j`-th list returned holds every rank's `j`-th list (every rank passes as many).
    pub fn in_order_each<T: Pod, K: Ord>(
        &self,
        mine: Vec<Vec<T>>,
        key: impl Fn(&T) -> K,
    ) -> Vec<Vec<T>> {
        if !self.comm.is_split() {
            return mine;
        }
        // Each rank's message: the lists' lengths, then their items.
        let lens: Vec<u64> = mine.iter().map(|l| l.len() as u64).collect();
        let mut bytes = bytemuck::cast_slice(&lens).to_vec();
        for list in &mine {
            bytes.extend_from_slice(bytemuck::cast_slice(list));
        }
        let size = std::mem::size_of::<T>();
        let mut all: Vec<Vec<T>> = vec![Vec::new(); mine.len()];
        for b in self.comm.all_gather(bytes) {
            let (head, mut rest) = b.split_at(8 * mine.len());
            let lens: Vec<u64> = bytemuck::pod_collect_to_vec(head);
            for (list, &n) in all.iter_mut().zip(&lens) {
                let (items, tail) = rest.split_at(n as usize * size);
                list.extend(bytemuck::pod_collect_to_vec::<u8, T>(items));
                rest = tail;
            }
        }
        // Stable: equal keys keep rank order.
        for list in &mut all {
            list.sort_by_key(&key);
        }
        all
    }

    /// Each of `mine`'s lists sent to the rank `owner` names (every rank passes as many):
    /// the `j`-th list returned is, on its owner, every rank's `j`-th list as
    /// [`in_order_each`](Self::in_order_each) gives it, and empty elsewhere (`mine` on one
    /// rank). Each item travels once, to one rank.
    pub fn to_owners<T: Pod, K: Ord>(
        &self,
        mut mine: Vec<Vec<T>>,
        owner: impl Fn(usize) -> usize,
        key: impl Fn(&T) -> K,
    ) -> Vec<Vec<T>> {
        if !self.is_split() {
            return mine;
        }
        let me = self.comm.rank();
        let everyone: Vec<usize> = (0..self.comm.size()).filter(|&r| r != me).collect();
        // To each rank: the lengths of the lists it owns, then their items.
        let out: Vec<Vec<u8>> = (everyone.iter())
            .map(|&r| {
                let theirs: Vec<&Vec<T>> = (mine.iter().enumerate())
                    .filter(|&(j, _)| owner(j) == r)
                    .map(|(_, l)| l)
                    .collect();
                let lens: Vec<u64> = theirs.iter().map(|l| l.len() as u64).collect();
                let mut bytes = (theirs.len() as u64).to_le_bytes().to_vec();
                bytes.extend_from_slice(bytemuck::cast_slice(&lens));
                theirs
                    .iter()
                    .for_each(|l| bytes.extend_from_slice(bytemuck::cast_slice(l)));
                bytes
            })
            .collect();
        let got = self.comm.exchange(&everyone, &out);
        let owned: Vec<usize> = (0..mine.len()).filter(|&j| owner(j) == me).collect();
        // Per rank in rank order, its items of each list this rank owns.
        let mut all: Vec<Vec<T>> = vec![Vec::new(); mine.len()];
        let mut from_peer = got.iter();
        for r in 0..self.comm.size() {
            if r == me {
                for &j in &owned {
                    all[j].append(&mut mine[j]);
                }
                continue;
            }
            let bytes = from_peer.next().expect("one message per peer");
            let (head, rest) = bytes.split_at(8);
            let n = u64::from_le_bytes(head.try_into().expect("8 bytes")) as usize;
            let (lens, mut rest) = rest.split_at(8 * n);
            let lens: Vec<u64> = bytemuck::pod_collect_to_vec(lens);
            for (&j, &len) in owned.iter().zip(&lens) {
                let (items, tail) = rest.split_at(len as usize * std::mem::size_of::<T>());
                all[j].extend(bytemuck::pod_collect_to_vec::<u8, T>(items));
                rest = tail;
            }
        }
        // Stable: equal keys keep rank order.
        for &j in &owned {
            all[j].sort_by_key(&key);
        }
        all
    }

    /// `mine` and what the peers' lists hold on the nodes this rank shares with them, in
    /// `key` order (each list in `key` order, no key on two ranks): the terms one rank,
    /// holding every particle, would add on the nodes this rank reaches. `node` gives an
    /// item's node.
    pub fn with_shared<T: Pod, K: Ord>(
        &self,
        mut mine: Vec<T>,
        node: impl Fn(&T) -> usize,
        key: impl Fn(&T) -> K,
    ) -> Vec<T> {
        let Some(p) = &self.partition else {
            return mine;
        };
        let out: Vec<Vec<u8>> = (p.shared.iter())
            .map(|shared| {
                let theirs: Vec<T> = mine.iter().filter(|t| shared[node(t)]).copied().collect();
                bytemuck::cast_slice(&theirs).to_vec()
            })
            .collect();
        for bytes in self.comm.exchange(&p.peers, &out) {
            mine.extend(bytemuck::pod_collect_to_vec::<u8, T>(&bytes));
        }
        mine.sort_by_key(key);
        mine
    }

    /// The union of every rank's `mine`, sorted and without repeats (`mine` on one rank,
    /// which must be sorted and distinct).
    pub fn union<T: Pod + Ord>(&self, mine: Vec<T>) -> Vec<T> {
        let mut all = self.in_order(mine, |&t| t);
        all.dedup();
        all
    }

    /// Every rank's `values` (rows of `width`, the same length on each) added row by row
    /// in rank order, on every rank (`values` on one rank). Only rows holding a nonzero
    /// value travel. The bits are those of one rank only where the terms add exactly
    /// (multiples of a quantum whose sums stay well inside the doubles' precision).
    pub fn add_rows(&self, values: &mut [f64], width: usize) {
        if !self.comm.is_split() {
            return;
        }
        // Each rank's message: per nonzero row its index, then the row.
        let mut mine = Vec::new();
        for (r, row) in values.chunks_exact(width).enumerate() {
            if row.iter().any(|&v| v != 0.0) {
                mine.extend_from_slice(&(r as u64).to_le_bytes());
                mine.extend_from_slice(bytemuck::cast_slice(row));
            }
        }
        values.fill(0.0);
        for bytes in self.comm.all_gather(mine) {
            for chunk in bytes.chunks_exact(8 * (width + 1)) {
                let (head, row) = chunk.split_at(8);
                let r = u64::from_le_bytes(head.try_into().expect("8 bytes")) as usize;
                let row: Vec<f64> = bytemuck::pod_collect_to_vec(row);
                (values[r * width..(r + 1) * width].iter_mut())
                    .zip(row)
                    .for_each(|(v, x)| *v += x);
            }
        }
    }

    /// Adds the other ranks' terms into `sums` (nothing on one rank).
    pub fn sum(&self, sums: &mut [ExactSum]) {
        if self.is_split() {
            self.comm.sum_exact(sums);
        }
    }
}
