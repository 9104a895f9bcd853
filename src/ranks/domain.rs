//! A rank's share of a scene: the ranks, the partition of the tiles, and the exchanges that
//! keep the shared nodes' sums those one rank would form.
//!
//! Node sums are bitwise those of one rank because one rank already adds them in a fixed
//! order: colour class after colour class, and within a class a node hears from one tile
//! only (`tiles.rs`). Split across ranks, each rank scatters its own tiles of a class,
//! then sends every shared node its tiles of that class reach to the peers that reach it
//! too, which take the value as theirs. Before each class every rank holding a shared node
//! therefore holds the one-rank running sum, and after the last class the full sum.

use crate::base::error::Unstable;
use crate::base::exact_sum::ExactSum;
use crate::ranks::comm::Comm;
use crate::ranks::partition::Partition;

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

    /// After colour class `class`: sends the shared nodes this rank's tiles of the class
    /// reached, in every column of `columns`, and takes the peers' (see the module doc).
    pub fn settle(&self, class: usize, columns: &[&dyn Shared]) {
        let Some(p) = &self.partition else {
            return;
        };
        let talks = &p.talks[class];
        let peers: Vec<usize> = talks.iter().map(|&k| p.peers[k]).collect();
        let out: Vec<Vec<u8>> = (talks.iter())
            .map(|&k| {
                let mut buf = Vec::new();
                columns
                    .iter()
                    .for_each(|c| c.pack(&p.sends[class][k], &mut buf));
                buf
            })
            .collect();
        let got = self.comm.exchange(&peers, &out);
        for (&k, bytes) in talks.iter().zip(&got) {
            let nodes = &p.receives[class][k];
            let mut at = 0;
            for c in columns {
                at += c.unpack(nodes, &bytes[at..]);
            }
        }
    }

    /// The grid entries, of `len`, that this rank's particles can reach: all of them on
    /// one rank (and every crack field's row), the partition's node span when split.
    pub fn span(&self, len: usize) -> std::ops::Range<usize> {
        self.partition.as_ref().map_or(0..len, |p| p.span.clone())
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
        if !self.is_split() {
            return x;
        }
        (self.comm.all_gather(x.to_le_bytes().to_vec()).iter())
            .map(|b| f64::from_le_bytes(b[..].try_into().expect("8 bytes per rank")))
            .fold(x, f64::max)
    }

    /// Whether `yes` holds on any rank.
    pub fn any(&self, yes: bool) -> bool {
        self.max(f64::from(u8::from(yes))) > 0.0
    }

    /// Adds the other ranks' terms into `sums` (nothing on one rank).
    pub fn sum(&self, sums: &mut [ExactSum]) {
        if self.is_split() {
            self.comm.sum_exact(sums);
        }
    }
}
