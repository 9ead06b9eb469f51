//! `mutex` and `mutex-std`: the ring's counters inside a critical section, polled with a yield.

use super::flag::{poll, Yield};
use super::primitives::Lock;
use super::{Free, Handoff, Ring, TimedOut};
use std::time::Instant;

/// The paper's critical-section build: every look at the counters enters the critical section.
pub struct PolledLock<L: Lock<Ring>> {
    ring: L,
    depth: u64,
}

impl<L: Lock<Ring>> PolledLock<L> {
    /// A ring of `depth` free slots.
    pub fn new(depth: u64) -> Self {
        PolledLock {
            ring: L::default(),
            depth,
        }
    }

    fn get(&self) -> Ring {
        *self.ring.enter()
    }
}

impl<L: Lock<Ring>> Handoff for PolledLock<L> {
    fn wait_free(&self, deadline: Instant) -> Result<Free, TimedOut> {
        poll::<_, Yield>(deadline, || self.get().free(self.depth))
    }

    fn publish(&self) {
        self.ring.enter().tail += 1;
    }

    fn wait_published(&self, frame: u64, deadline: Instant) -> Result<(), TimedOut> {
        poll::<_, Yield>(deadline, || self.get().filled(frame))
    }

    fn release(&self) {
        self.ring.enter().head += 1;
    }

    fn shutdown(&self) {
        self.ring.enter().shutdown = true;
    }

    fn published(&self) -> u64 {
        self.get().tail
    }
}
