//! `park`: the ring's counters in atomics, each waiter parking its thread with
//! `std::thread::park_timeout` and each change unparking the other side's registered thread.
//!
//! A waiter registers its thread before it looks at the counters, and a signaller looks for the
//! registration after changing them, both under the registration's lock: if the signaller
//! locked first, the waiter's look sees the change; if the waiter did, the signaller unparks it.
//! So a wake-up is never lost. Registration is per wait, since under `spawn` every frame has a
//! new helper thread.

use super::ring::AtomicCounters;
use super::{Free, Handoff, TimedOut};
use parking_lot::Mutex;
use std::thread::Thread;
use std::time::Instant;

/// The ring's counters and the two sides' parked threads.
pub struct ParkRing {
    counters: AtomicCounters,
    /// The helper, while it waits for a free slot.
    helper: Mutex<Option<Thread>>,
    /// The main thread, while it waits for a frame.
    main: Mutex<Option<Thread>>,
}

impl ParkRing {
    /// A ring of `depth` free slots.
    pub fn new(depth: u64) -> Self {
        ParkRing {
            counters: AtomicCounters::new(depth),
            helper: Mutex::new(None),
            main: Mutex::new(None),
        }
    }
}

/// Parks the calling thread, registered in `me`, until `ready` or the deadline.
fn wait<T>(
    me: &Mutex<Option<Thread>>,
    deadline: Instant,
    ready: impl Fn() -> Option<T>,
) -> Result<T, TimedOut> {
    *me.lock() = Some(std::thread::current());
    loop {
        if let Some(v) = ready() {
            return Ok(v);
        }
        let left = deadline.saturating_duration_since(Instant::now());
        if left.is_zero() {
            return ready().ok_or(TimedOut);
        }
        std::thread::park_timeout(left);
    }
}

fn wake(other: &Mutex<Option<Thread>>) {
    if let Some(t) = other.lock().as_ref() {
        t.unpark();
    }
}

impl Handoff for ParkRing {
    fn wait_free(&self, deadline: Instant) -> Result<Free, TimedOut> {
        wait(&self.helper, deadline, self.counters.free())
    }

    fn publish(&self) {
        self.counters.publish();
        wake(&self.main);
    }

    fn wait_published(&self, frame: u64, deadline: Instant) -> Result<(), TimedOut> {
        wait(&self.main, deadline, self.counters.filled(frame))
    }

    fn release(&self) {
        self.counters.release();
        wake(&self.helper);
    }

    fn shutdown(&self) {
        self.counters.shutdown();
        wake(&self.helper);
    }

    fn published(&self) -> u64 {
        self.counters.published()
    }
}
