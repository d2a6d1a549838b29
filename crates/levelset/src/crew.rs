//! Cooperative phases on the rayon pool, for builds too short to pay a pool wake-up per
//! parallel pass.
//!
//! A parallel region that starts after a sequential phase waits for the sleeping pool
//! threads to wake: measured 80–135 µs on a 2-vCPU virtual machine after 0.2–1 ms of
//! sequential work, as long as the whole assembly pass of a 45³ star build. [`run_phases`]
//! opens one region for a whole build instead: every pool thread runs the same lane, which
//! claims the items of the current phase from an atomic counter and spins until all of the
//! phase's items are done before it moves on. A lane only ever waits for items that a running
//! lane has claimed, so a lane that starts late, or never (its task may run on the calling
//! thread after the others finished), cannot stall the build; a single lane does all the
//! work in order.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

/// Counts an item as done when dropped, also while unwinding from a panic in the item (the
/// other lanes then stop spinning and the scope re-raises the panic).
struct Done<'a>(&'a AtomicUsize);

impl Drop for Done<'_> {
    fn drop(&mut self) {
        self.0.fetch_add(1, Ordering::Release);
    }
}

/// Runs `work(phase, item)` for every `item < counts[phase]`, phase after phase (every item
/// of a phase finishes before any item of the next starts): on all threads of the current
/// rayon pool if `parallel` (items of a phase in any order, on any thread), else in order on
/// the calling thread.
pub(crate) fn run_phases(counts: &[usize], parallel: bool, work: &(impl Fn(usize, usize) + Sync)) {
    let claimed: Vec<AtomicUsize> = counts.iter().map(|_| AtomicUsize::new(0)).collect();
    let done: Vec<AtomicUsize> = counts.iter().map(|_| AtomicUsize::new(0)).collect();
    let panicked = AtomicBool::new(false);
    let lane = || {
        for (p, &n) in counts.iter().enumerate() {
            loop {
                let i = claimed[p].fetch_add(1, Ordering::Relaxed);
                if i >= n || panicked.load(Ordering::Relaxed) {
                    break;
                }
                let guard = Done(&done[p]);
                let ok = PanicFlag(&panicked);
                work(p, i);
                std::mem::forget(ok);
                drop(guard);
            }
            let mut spins = 0u32;
            while done[p].load(Ordering::Acquire) < n {
                if panicked.load(Ordering::Relaxed) {
                    return;
                }
                // Spin (the wait is usually a few µs), then yield the core to whatever else
                // is runnable (an oversubscribed pool, a lane descheduled mid-item).
                if spins < 4096 {
                    spins += 1;
                    std::hint::spin_loop();
                } else {
                    std::thread::yield_now();
                }
            }
            if panicked.load(Ordering::Relaxed) {
                return;
            }
        }
    };
    let lanes = if parallel {
        rayon::current_num_threads()
    } else {
        1
    };
    if lanes <= 1 {
        lane();
        return;
    }
    rayon::scope(|s| {
        for _ in 1..lanes {
            s.spawn(|_| lane());
        }
        lane();
    });
}

/// Raises the panic flag when dropped (forgotten on success).
struct PanicFlag<'a>(&'a AtomicBool);

impl Drop for PanicFlag<'_> {
    fn drop(&mut self) {
        self.0.store(true, Ordering::Relaxed);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Mutex;

    #[test]
    fn phases_run_in_order_on_any_pool() {
        for threads in [1, 2, 3, 8] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("pool");
            let log = Mutex::new(Vec::new());
            let counts = [5, 0, 1, 17, 3];
            pool.install(|| {
                run_phases(&counts, threads > 1, &|p, i| {
                    log.lock().expect("log").push((p, i));
                });
            });
            let log = log.into_inner().expect("log");
            assert_eq!(log.len(), 26, "{threads} threads");
            // Phases never interleave; every item runs exactly once.
            assert!(
                log.windows(2).all(|w| w[0].0 <= w[1].0),
                "{threads} threads"
            );
            for (p, &n) in counts.iter().enumerate() {
                let mut items: Vec<usize> = log.iter().filter(|e| e.0 == p).map(|e| e.1).collect();
                items.sort_unstable();
                assert_eq!(items, (0..n).collect::<Vec<_>>());
            }
        }
    }

    #[test]
    fn a_panicking_item_does_not_hang_the_other_lanes() {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(3)
            .build()
            .expect("pool");
        let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            pool.install(|| {
                run_phases(&[4, 4], true, &|p, i| {
                    assert!(!(p == 0 && i == 2), "item failed");
                });
            });
        }));
        assert!(r.is_err());
    }
}
