//! `atomic` and `spin`: the ring's counters in atomics, waiters polling them.

use super::primitives::{spin_loop, yield_now};
use super::ring::AtomicCounters;
use super::{Free, Handoff, TimedOut};
use std::marker::PhantomData;
use std::time::Instant;

/// How a polling waiter spends the time between two looks at the state.
pub trait Relax: Send + Sync + 'static {
    /// Called once per unsuccessful poll.
    fn relax();
}

/// Gives up the time slice, like the paper's `Sleep(0)`.
pub struct Yield;
impl Relax for Yield {
    fn relax() {
        yield_now();
    }
}

/// Stays on the core with a spin-loop hint.
pub struct Spin;
impl Relax for Spin {
    fn relax() {
        spin_loop();
    }
}

/// Polls `ready` until it returns `Some`, relaxing in between; looks at the clock only every 256
/// polls so that the deadline costs nothing on the fast path.
pub fn poll<T, R: Relax>(
    deadline: Instant,
    mut ready: impl FnMut() -> Option<T>,
) -> Result<T, TimedOut> {
    let mut polls: u32 = 0;
    loop {
        if let Some(v) = ready() {
            return Ok(v);
        }
        R::relax();
        polls = polls.wrapping_add(1);
        if polls.is_multiple_of(256) && Instant::now() >= deadline {
            return ready().ok_or(TimedOut);
        }
    }
}

/// The ring's counters in one cache line, each written by one side only and read by the
/// other with acquire/release; waiters poll them.
pub struct AtomicRing<R: Relax> {
    counters: AtomicCounters,
    relax: PhantomData<R>,
}

impl<R: Relax> AtomicRing<R> {
    /// A ring of `depth` free slots.
    pub fn new(depth: u64) -> Self {
        AtomicRing {
            counters: AtomicCounters::new(depth),
            relax: PhantomData,
        }
    }
}

impl<R: Relax> Handoff for AtomicRing<R> {
    fn wait_free(&self, deadline: Instant) -> Result<Free, TimedOut> {
        poll::<_, R>(deadline, self.counters.free())
    }

    fn publish(&self) {
        self.counters.publish();
    }

    fn wait_published(&self, frame: u64, deadline: Instant) -> Result<(), TimedOut> {
        poll::<_, R>(deadline, self.counters.filled(frame))
    }

    fn release(&self) {
        self.counters.release();
    }

    fn shutdown(&self) {
        self.counters.shutdown();
    }

    fn published(&self) -> u64 {
        self.counters.published()
    }
}
