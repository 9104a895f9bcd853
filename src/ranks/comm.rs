//! The processes of a run (MPI ranks) and the few collective operations the kernel needs:
//! exact sums, byte exchanges with neighbours, gathers, and agreeing on an error. One rank
//! (every build without the `mpi` feature) does all of them locally.

use crate::base::exact_sum::ExactSum;
use std::fmt;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};

/// This process's place among the run's ranks, and the channel to the others.
#[derive(Clone)]
pub struct Comm {
    /// This rank (0-based).
    rank: usize,
    /// Number of ranks.
    size: usize,
    /// The MPI world when there is more than one rank.
    #[cfg(feature = "mpi")]
    world: Option<Arc<mpi_world::World>>,
    /// What this rank has sent.
    traffic: Arc<Traffic>,
}

impl Default for Comm {
    /// The only rank.
    fn default() -> Self {
        Comm::single()
    }
}

/// Messages and bytes this rank has sent to its peers, and collective operations it took
/// part in.
#[derive(Debug, Default)]
pub struct Traffic {
    /// Point-to-point messages sent (empty ones too).
    pub messages: AtomicU64,
    /// Bytes in them.
    pub bytes: AtomicU64,
    /// Collective operations (sums, gathers).
    pub collectives: AtomicU64,
    /// Nanoseconds spent inside the MPI calls: sending, receiving and waiting for peers.
    pub inside: AtomicU64,
}

impl Traffic {
    /// Runs `call`, adding its wall time to `inside`.
    #[cfg(feature = "mpi")]
    fn timed<T>(&self, call: impl FnOnce() -> T) -> T {
        let t0 = std::time::Instant::now();
        let out = call();
        let nanos = u64::try_from(t0.elapsed().as_nanos()).unwrap_or(u64::MAX);
        self.inside.fetch_add(nanos, Ordering::Relaxed);
        out
    }
}

impl fmt::Debug for Comm {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "rank {} of {}", self.rank, self.size)
    }
}

impl Comm {
    /// The only rank.
    pub fn single() -> Self {
        Comm {
            rank: 0,
            size: 1,
            #[cfg(feature = "mpi")]
            world: None,
            traffic: Default::default(),
        }
    }

    /// Messages, bytes and collectives this rank has sent so far, and the nanoseconds it
    /// spent inside MPI calls.
    pub fn traffic(&self) -> [u64; 4] {
        let t = &self.traffic;
        [&t.messages, &t.bytes, &t.collectives, &t.inside].map(|c| c.load(Ordering::Relaxed))
    }

    /// This rank (0-based).
    pub fn rank(&self) -> usize {
        self.rank
    }

    /// Number of ranks.
    pub fn size(&self) -> usize {
        self.size
    }

    /// Whether this is the rank that writes the run's outputs.
    pub fn is_root(&self) -> bool {
        self.rank == 0
    }

    /// Whether the run is split across more than one rank.
    pub fn is_split(&self) -> bool {
        self.size() > 1
    }

    /// Adds every rank's terms into each sum, on every rank (exact: the same bits whatever
    /// the ranks hold).
    pub fn sum_exact(&self, sums: &mut [ExactSum]) {
        #[cfg(feature = "mpi")]
        if let Some(w) = &self.world {
            self.traffic.collectives.fetch_add(1, Ordering::Relaxed);
            self.traffic.timed(|| w.sum_exact(sums));
        }
        let _ = sums;
    }

    /// Sends `out[k]` to `peers[k]` and returns what each peer sent back, in the same
    /// order; every peer must name this rank among its own in the same round.
    pub fn exchange(&self, peers: &[usize], out: &[Vec<u8>]) -> Vec<Vec<u8>> {
        #[cfg(feature = "mpi")]
        if let Some(w) = &self.world {
            let t = &self.traffic;
            t.messages.fetch_add(out.len() as u64, Ordering::Relaxed);
            let bytes = out.iter().map(|b| b.len() as u64).sum();
            t.bytes.fetch_add(bytes, Ordering::Relaxed);
            return t.timed(|| w.exchange(peers, out));
        }
        debug_assert!(peers.is_empty(), "one rank has no peers");
        let _ = out;
        Vec::new()
    }

    /// A scatter pass over `classes` colour classes with an exchange after each: `run(c,
    /// false)` runs class c's tiles that need nothing from the class before, `run(c,
    /// true)` the others once `unpack(c - 1, got)` has taken what `peers(c - 1)` sent
    /// (in their order); then `pack(c)` gives what goes to each of `peers(c)`. Sends do
    /// not wait to be received: a rank early with a class works on the next while its
    /// values travel, and waits only for values its next tiles need.
    pub fn colour_pass(
        &self,
        classes: usize,
        peers: impl Fn(usize) -> Vec<usize>,
        mut pack: impl FnMut(usize) -> Vec<Vec<u8>>,
        mut unpack: impl FnMut(usize, Vec<Vec<u8>>),
        mut run: impl FnMut(usize, bool),
    ) {
        #[cfg(feature = "mpi")]
        if let Some(w) = &self.world {
            let t = &self.traffic;
            let mut pack = |c: usize| {
                let out = pack(c);
                t.messages.fetch_add(out.len() as u64, Ordering::Relaxed);
                let bytes = out.iter().map(|b| b.len() as u64).sum();
                t.bytes.fetch_add(bytes, Ordering::Relaxed);
                out
            };
            w.colour_pass(classes, peers, &mut pack, &mut unpack, &mut run, t);
            return;
        }
        for c in 0..classes {
            debug_assert!(peers(c).is_empty(), "one rank has no peers");
            run(c, false);
            run(c, true);
        }
        let _ = (&mut pack, &mut unpack);
    }

    /// Every rank's bytes, in rank order.
    pub fn all_gather(&self, mine: Vec<u8>) -> Vec<Vec<u8>> {
        #[cfg(feature = "mpi")]
        if let Some(w) = &self.world {
            self.traffic.collectives.fetch_add(1, Ordering::Relaxed);
            return self.traffic.timed(|| w.all_gather(&mine));
        }
        vec![mine]
    }

    /// The lowest rank's error among `mine` and the other ranks' (every rank calls it at
    /// the same point), so that all stop together with that message.
    pub fn first_error(&self, mine: Option<String>) -> Option<(usize, String)> {
        if !self.is_split() {
            return mine.map(|m| (0, m));
        }
        let flag = vec![u8::from(mine.is_some())];
        let flags = self.all_gather(flag);
        let first = flags.iter().position(|f| f[0] == 1)?;
        let text = if self.rank == first {
            mine.unwrap_or_default().into_bytes()
        } else {
            Vec::new()
        };
        let texts = self.all_gather(text);
        Some((first, String::from_utf8_lossy(&texts[first]).into_owned()))
    }
}

/// Starts MPI when the process was launched by `mpirun` (or a like launcher) and the build
/// has the `mpi` feature; a build without it refuses more than one rank. The guard must
/// live until the run ends (dropping it finalizes MPI).
pub fn start() -> anyhow::Result<(Comm, Guard)> {
    let launched = launcher_size();
    #[cfg(feature = "mpi")]
    if launched.is_some() {
        return mpi_world::start();
    }
    if let Some(n) = launched.filter(|&n| n > 1) {
        anyhow::bail!(
            "started as one of {n} MPI ranks, but this build of fissure has no MPI: rebuild \
             with `cargo build --release --features mpi` (needs an MPI library such as \
             OpenMPI), or run without mpirun"
        );
    }
    Ok((Comm::single(), Guard::default()))
}

/// The number of ranks an MPI launcher started, read from its environment (OpenMPI,
/// MPICH and Intel MPI, MVAPICH); None when not started by one.
fn launcher_size() -> Option<usize> {
    ["OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "MV2_COMM_WORLD_SIZE"]
        .iter()
        .find_map(|k| std::env::var(k).ok()?.parse().ok())
}

/// Keeps MPI initialised while it lives.
#[derive(Default)]
pub struct Guard {
    #[cfg(feature = "mpi")]
    _universe: Option<mpi::environment::Universe>,
}

#[cfg(feature = "mpi")]
mod mpi_world {
    //! The MPI side of [`Comm`](super::Comm).

    use super::{Comm, Guard};
    use crate::base::exact_sum::ExactSum;
    use mpi::collective::SystemOperation;
    use mpi::datatype::PartitionMut;
    use mpi::environment::Threading;
    use mpi::topology::SimpleCommunicator;
    use mpi::traits::*;
    use std::cell::OnceCell;
    use std::sync::Arc;

    /// The MPI world communicator.
    pub struct World(SimpleCommunicator);

    // SAFETY: MPI is initialised with MPI_THREAD_SERIALIZED and the kernel calls it only
    // from the thread that runs the step loop, never inside a parallel region, so the
    // handle is never used by two threads at once.
    unsafe impl Send for World {}
    // SAFETY: as above.
    unsafe impl Sync for World {}

    /// Initialises MPI (calls from any one thread at a time).
    pub fn start() -> anyhow::Result<(Comm, Guard)> {
        let (universe, _) = mpi::initialize_with_threading(Threading::Serialized)
            .ok_or_else(|| anyhow::anyhow!("MPI was already initialised"))?;
        let world = universe.world();
        let (rank, size) = (world.rank() as usize, world.size() as usize);
        if size > 1 {
            // A panic on one rank would leave the others waiting for it: abort them all.
            let report = std::panic::take_hook();
            std::panic::set_hook(Box::new(move |info| {
                report(info);
                eprintln!("rank {rank} panicked: stopping every rank");
                // SAFETY: MPI is initialised (the universe outlives the run); MPI_Abort
                // does not return.
                unsafe { mpi::ffi::MPI_Abort(mpi::ffi::RSMPI_COMM_WORLD, 101) };
            }));
        }
        let comm = Comm {
            rank,
            size,
            world: (size > 1).then(|| Arc::new(World(world))),
            traffic: Default::default(),
        };
        let guard = Guard {
            _universe: Some(universe),
        };
        Ok((comm, guard))
    }

    impl World {
        pub fn sum_exact(&self, sums: &mut [ExactSum]) {
            let mut mine = Vec::new();
            let mut special = Vec::new();
            for s in sums.iter() {
                let (digits, sp) = s.parts();
                mine.extend_from_slice(&digits);
                special.push(sp);
            }
            let mut total = vec![0i64; mine.len()];
            self.0
                .all_reduce_into(&mine[..], &mut total[..], SystemOperation::sum());
            let mut special_total = vec![0.0f64; special.len()];
            self.0
                .all_reduce_into(&special[..], &mut special_total[..], SystemOperation::sum());
            let per = total.len() / sums.len().max(1);
            for (k, s) in sums.iter_mut().enumerate() {
                *s = ExactSum::from_parts(&total[k * per..(k + 1) * per], special_total[k]);
            }
        }

        pub fn exchange(&self, peers: &[usize], out: &[Vec<u8>]) -> Vec<Vec<u8>> {
            mpi::request::scope(|scope| {
                let sends: Vec<_> = (peers.iter().zip(out))
                    .map(|(&p, buf)| {
                        self.0
                            .process_at_rank(p as i32)
                            .immediate_send(scope, &buf[..])
                    })
                    .collect();
                let got = peers
                    .iter()
                    .map(|&p| self.0.process_at_rank(p as i32).receive_vec::<u8>().0)
                    .collect();
                sends.into_iter().for_each(|r| {
                    r.wait();
                });
                got
            })
        }

        pub fn colour_pass(
            &self,
            classes: usize,
            peers: impl Fn(usize) -> Vec<usize>,
            pack: &mut dyn FnMut(usize) -> Vec<Vec<u8>>,
            unpack: &mut dyn FnMut(usize, Vec<Vec<u8>>),
            run: &mut dyn FnMut(usize, bool),
            traffic: &super::Traffic,
        ) {
            let to: Vec<Vec<usize>> = (0..classes).map(&peers).collect();
            // Every class's messages, made before the scope so that its sends may borrow
            // them until the pass ends.
            let out: Vec<OnceCell<Vec<Vec<u8>>>> = (0..classes).map(|_| OnceCell::new()).collect();
            mpi::request::scope(|scope| {
                let mut sends = Vec::new();
                for c in 0..=classes {
                    if c < classes {
                        run(c, false);
                    }
                    if let Some(b) = c.checked_sub(1) {
                        let got = traffic.timed(|| {
                            (to[b].iter())
                                .map(|&p| self.0.process_at_rank(p as i32).receive_vec::<u8>().0)
                                .collect()
                        });
                        unpack(b, got);
                    }
                    if c == classes {
                        break;
                    }
                    run(c, true);
                    let bufs = out[c].get_or_init(|| pack(c));
                    traffic.timed(|| {
                        for (&p, buf) in to[c].iter().zip(bufs) {
                            let r = self.0.process_at_rank(p as i32);
                            sends.push(r.immediate_send(scope, &buf[..]));
                        }
                    });
                }
                traffic.timed(|| {
                    sends.into_iter().for_each(|r| {
                        r.wait();
                    })
                });
            });
        }

        pub fn all_gather(&self, mine: &[u8]) -> Vec<Vec<u8>> {
            let n = self.0.size() as usize;
            let mut counts = vec![0i32; n];
            self.0
                .all_gather_into(&(mine.len() as i32), &mut counts[..]);
            let displs: Vec<i32> = counts
                .iter()
                .scan(0, |at, &c| {
                    let d = *at;
                    *at += c;
                    Some(d)
                })
                .collect();
            let total: usize = counts.iter().map(|&c| c as usize).sum();
            // OpenMPI refuses a gather of no bytes at all (MPI_ERR_ARG): every rank knows
            // the counts, so all skip it alike.
            if total == 0 {
                return vec![Vec::new(); n];
            }
            let mut all = vec![0u8; total];
            let mut part = PartitionMut::new(&mut all[..], &counts[..], &displs[..]);
            self.0.all_gather_varcount_into(mine, &mut part);
            (0..n)
                .map(|r| {
                    let d = displs[r] as usize;
                    all[d..d + counts[r] as usize].to_vec()
                })
                .collect()
        }
    }
}
