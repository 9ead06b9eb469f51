//! `condvar` and `condvar-std`: blocking waits on a condition variable, the paper's "OS-level
//! synchronisation object": the helper sleeps while every slot is full, the main thread while
//! none is.

use super::primitives::Monitor;
use super::{Free, Handoff, Ring, TimedOut};
use std::time::Instant;

/// The blocking hand-off over either library's mutex and condition variable: every change of
/// the counters wakes the waiters.
pub struct Blocking<M: Monitor<Ring>> {
    monitor: M,
    depth: u64,
}

impl<M: Monitor<Ring>> Blocking<M> {
    /// A ring of `depth` free slots.
    pub fn new(depth: u64) -> Self {
        Blocking {
            monitor: M::default(),
            depth,
        }
    }

    fn change(&self, f: impl FnOnce(&mut Ring)) {
        f(&mut self.monitor.enter());
        self.monitor.notify_all();
    }

    /// Blocks until `done` accepts the counters, or the deadline passes.
    fn wait_for<T>(
        &self,
        deadline: Instant,
        done: impl Fn(&Ring) -> Option<T>,
    ) -> Result<T, TimedOut> {
        let mut guard = self.monitor.enter();
        loop {
            if let Some(v) = done(&guard) {
                return Ok(v);
            }
            if self.monitor.wait_until(&mut guard, deadline) {
                return done(&guard).ok_or(TimedOut);
            }
        }
    }
}

impl<M: Monitor<Ring>> Handoff for Blocking<M> {
    fn wait_free(&self, deadline: Instant) -> Result<Free, TimedOut> {
        self.wait_for(deadline, |r| r.free(self.depth))
    }
    fn publish(&self) {
        self.change(|r| r.tail += 1);
    }
    fn wait_published(&self, frame: u64, deadline: Instant) -> Result<(), TimedOut> {
        self.wait_for(deadline, |r| r.filled(frame))
    }
    fn release(&self) {
        self.change(|r| r.head += 1);
    }
    fn shutdown(&self) {
        self.change(|r| r.shutdown = true);
    }
    fn published(&self) -> u64 {
        self.monitor.enter().tail
    }
}
