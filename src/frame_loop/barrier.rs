//! The barrier helpers meet at between the phases of a banded step (a model whose phases read
//! each other's bands, such as the FFT ocean's column pass after its row pass).
//!
//! A mutex and condition variable rather than a spinning barrier: with more helpers than cores
//! (UP, or DP with two helpers beside the main thread) a spinning helper would take the core
//! another helper or the main thread needs, and a phase lasts milliseconds, so the wake-up
//! (tens of µs) is small beside it. Rather than `std::sync::Barrier`, because a waiter must
//! return when the loop shuts down or a helper stalls: std's barrier waits forever for a helper
//! that has returned.

use parking_lot::{Condvar, Mutex};
use std::time::Instant;

/// Why a wait at the barrier ended without every helper arriving.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Broken {
    /// The loop is shutting down.
    Shutdown,
    /// The deadline passed (a helper stalled).
    Timeout,
}

#[derive(Debug, Default)]
struct State {
    arrived: usize,
    generation: u64,
    cancelled: bool,
}

/// A reusable barrier for `parties` threads that a shutdown breaks.
#[derive(Debug)]
pub struct PhaseBarrier {
    parties: usize,
    state: Mutex<State>,
    changed: Condvar,
}

impl PhaseBarrier {
    /// A barrier for `parties` threads.
    pub fn new(parties: usize) -> Self {
        PhaseBarrier {
            parties,
            state: Mutex::new(State::default()),
            changed: Condvar::new(),
        }
    }

    /// Waits until every party has arrived, the barrier is cancelled, or `deadline` passes
    /// (after which the barrier is broken: the loop ends as stalled and does not reuse it).
    pub fn wait(&self, deadline: Instant) -> Result<(), Broken> {
        let mut state = self.state.lock();
        if state.cancelled {
            return Err(Broken::Shutdown);
        }
        state.arrived += 1;
        if state.arrived == self.parties {
            state.arrived = 0;
            state.generation += 1;
            self.changed.notify_all();
            return Ok(());
        }
        let generation = state.generation;
        while state.generation == generation {
            if state.cancelled {
                return Err(Broken::Shutdown);
            }
            if self.changed.wait_until(&mut state, deadline).timed_out()
                && state.generation == generation
            {
                return Err(Broken::Timeout);
            }
        }
        Ok(())
    }

    /// Breaks the barrier for good: every waiter and every later arrival returns `Shutdown`.
    pub fn cancel(&self) {
        self.state.lock().cancelled = true;
        self.changed.notify_all();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Arc;
    use std::time::Duration;

    fn soon() -> Instant {
        Instant::now() + Duration::from_secs(10)
    }

    #[test]
    fn every_party_passes_together_generation_after_generation() {
        let barrier = Arc::new(PhaseBarrier::new(3));
        let counter = Arc::new(std::sync::atomic::AtomicUsize::new(0));
        let threads: Vec<_> = (0..3)
            .map(|_| {
                let (barrier, counter) = (Arc::clone(&barrier), Arc::clone(&counter));
                std::thread::spawn(move || {
                    for round in 0..100 {
                        counter.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
                        barrier.wait(soon()).unwrap();
                        // Everyone has counted this round before anyone passes.
                        let seen = counter.load(std::sync::atomic::Ordering::SeqCst);
                        assert!(seen >= 3 * (round + 1), "round {round}: {seen}");
                        barrier.wait(soon()).unwrap();
                    }
                })
            })
            .collect();
        for t in threads {
            t.join().unwrap();
        }
    }

    #[test]
    fn a_cancel_frees_a_waiter_and_refuses_later_arrivals() {
        let barrier = Arc::new(PhaseBarrier::new(2));
        let waiter = {
            let barrier = Arc::clone(&barrier);
            std::thread::spawn(move || barrier.wait(soon()))
        };
        std::thread::sleep(Duration::from_millis(50));
        barrier.cancel();
        assert_eq!(waiter.join().unwrap(), Err(Broken::Shutdown));
        assert_eq!(barrier.wait(soon()), Err(Broken::Shutdown));
    }

    #[test]
    fn a_missing_party_times_out() {
        let barrier = PhaseBarrier::new(2);
        let deadline = Instant::now() + Duration::from_millis(20);
        assert_eq!(barrier.wait(deadline), Err(Broken::Timeout));
    }
}
