//! Keeping a thread pool's workers awake through a step.
//!
//! A step is about twenty parallel regions separated by serial work (the crack systems, the
//! systems' set-up). An idle rayon worker soon goes to sleep, and waking it costs tens of
//! microseconds on a virtual machine, which on scenes of ten thousand particles is as long
//! as the region it was woken for. While `f` runs, each other worker instead polls the pool
//! for work (`rayon::yield_now`, then the OS's `sched_yield` when there is none), so it picks
//! up the next region's work at once. This spends the idle workers' time spinning during the
//! serial parts of a step and nothing else; which thread runs which piece of work does not
//! change any result.

use std::sync::atomic::{AtomicBool, Ordering};

/// Runs `f` on the current thread while the pool's other workers wait for work spinning
/// rather than sleeping. With one thread, just runs `f`.
pub(crate) fn with_warm_workers<R: Send>(f: impl FnOnce() -> R + Send) -> R {
    let workers = rayon::current_num_threads();
    if workers == 1 {
        return f();
    }
    let done = &AtomicBool::new(false);
    rayon::scope(|s| {
        // The thread that runs `f` (a pool worker, even when called from outside the pool).
        let home = rayon::current_thread_index();
        for _ in 1..workers {
            s.spawn(move |_| {
                // Were `f`'s own thread to pick up a poller while it waits inside a parallel
                // region, the poller would keep it from ever returning to `f`, so it leaves
                // at once (a safeguard: idle workers steal the oldest jobs, the pollers,
                // before `f`'s thread could reach them).
                if rayon::current_thread_index() == home {
                    return;
                }
                while !done.load(Ordering::Acquire) {
                    // With nothing to run, let the OS run another thread, should there be
                    // more threads than cores.
                    if rayon::yield_now() != Some(rayon::Yield::Executed) {
                        std::thread::yield_now();
                    }
                }
            });
        }
        // Set even if `f` panics, so the scope's wait for the pollers ends.
        let _release = Release(done);
        f()
    })
}

/// Tells the pollers to stop when dropped.
struct Release<'a>(&'a AtomicBool);

impl Drop for Release<'_> {
    fn drop(&mut self) {
        self.0.store(true, Ordering::Release);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rayon::prelude::*;

    /// Parallel work inside `f` finishes and gives the sequential answer whether the call
    /// comes from outside any pool (then `f` runs on a worker of the global pool) or from
    /// inside pools of one, two and three threads, repeatedly.
    #[test]
    fn parallel_work_inside_completes_from_inside_and_outside_a_pool() {
        let want: u64 = (0..100_000u64).map(|i| i * i % 7).sum();
        let work = || {
            with_warm_workers(|| {
                (0..100)
                    .map(|_| {
                        (0..100_000u64)
                            .into_par_iter()
                            .map(|i| i * i % 7)
                            .sum::<u64>()
                    })
                    .max()
            })
        };
        assert_eq!(work(), Some(want));
        for threads in [1, 2, 3] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("pool");
            for _ in 0..20 {
                assert_eq!(pool.install(work), Some(want));
            }
        }
    }
}
