//! The ring every hand-off method implements: `depth` mesh slots, the helper's count of frames
//! published (the tail) and the main thread's count of frames released (the head). Frame k lives
//! in slot k mod depth. Depth 1 is the paper's one-slot loop.

use super::primitives::{AtomicBool, AtomicU64, Ordering};
use super::Free;

/// A ring's counters and the shutdown flag, as the lock-based methods keep them.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Ring {
    /// Frames the main thread has released.
    pub head: u64,
    /// Frames the helper has published.
    pub tail: u64,
    /// The main thread has stopped the loop.
    pub shutdown: bool,
}

impl Ring {
    /// The helper's wait is over: a slot is free, or the loop is stopped (which wins).
    pub fn free(&self, depth: u64) -> Option<Free> {
        if self.shutdown {
            Some(Free::Shutdown)
        } else if self.tail - self.head < depth {
            Some(Free::Slot)
        } else {
            None
        }
    }

    /// The main thread's wait for frame `frame` is over: it is published.
    pub fn filled(&self, frame: u64) -> Option<()> {
        (self.tail > frame).then_some(())
    }
}

/// A ring's counters and stop flag in atomics, each counter written by one side only and read
/// by the other with acquire/release: the state of the methods whose waiters look at the
/// counters themselves (polling or parking), which differ only in how they wait and wake.
pub(super) struct AtomicCounters {
    /// Frames released, written by the main thread.
    head: AtomicU64,
    /// Frames published, written by the helper.
    tail: AtomicU64,
    shutdown: AtomicBool,
    depth: u64,
}

impl AtomicCounters {
    /// The counters of a ring of `depth` free slots.
    pub(super) fn new(depth: u64) -> Self {
        AtomicCounters {
            head: AtomicU64::new(0),
            tail: AtomicU64::new(0),
            shutdown: AtomicBool::new(false),
            depth,
        }
    }

    /// The helper's look for a free slot, to call until it answers.
    pub(super) fn free(&self) -> impl Fn() -> Option<Free> + '_ {
        // Only the helper writes the tail, so its own relaxed read is current.
        let tail = self.tail.load(Ordering::Relaxed);
        move || {
            Ring {
                head: self.head.load(Ordering::Acquire),
                tail,
                shutdown: self.shutdown.load(Ordering::Acquire),
            }
            .free(self.depth)
        }
    }

    /// The main thread's look for frame `frame`, to call until it answers.
    pub(super) fn filled(&self, frame: u64) -> impl Fn() -> Option<()> + '_ {
        move || (self.tail.load(Ordering::Acquire) > frame).then_some(())
    }

    /// The helper has published one more frame.
    pub(super) fn publish(&self) {
        self.tail.fetch_add(1, Ordering::Release);
    }

    /// The main thread has released one more frame.
    pub(super) fn release(&self) {
        self.head.fetch_add(1, Ordering::Release);
    }

    /// The main thread has stopped the loop.
    pub(super) fn shutdown(&self) {
        self.shutdown.store(true, Ordering::Release);
    }

    /// Frames published so far.
    pub(super) fn published(&self) -> u64 {
        self.tail.load(Ordering::Acquire)
    }
}
