//! `park`: the ring's counters in atomics, each waiter parking its thread with
//! `std::thread::park_timeout` and each change unparking the other side's registered thread.
//!
//! A waiter registers its thread before it looks at the counters, and a signaller looks for the
//! registration after changing them, both under the registration's lock: if the signaller
//! locked first, the waiter's look sees the change; if the waiter did, the signaller unparks it.
//! So a wake-up is never lost. Registration is per wait, since under `spawn` every frame has a
//! new helper thread.

use super::{Free, Handoff, Ring, TimedOut};
use parking_lot::Mutex;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::thread::Thread;
use std::time::Instant;

/// The ring's counters and the two sides' parked threads.
pub struct ParkRing {
    head: AtomicU64,
    tail: AtomicU64,
    shutdown: AtomicBool,
    /// The helper, while it waits for a free slot.
    helper: Mutex<Option<Thread>>,
    /// The main thread, while it waits for a frame.
    main: Mutex<Option<Thread>>,
    depth: u64,
}

impl ParkRing {
    /// A ring of `depth` free slots.
    pub fn new(depth: u64) -> Self {
        ParkRing {
            head: AtomicU64::new(0),
            tail: AtomicU64::new(0),
            shutdown: AtomicBool::new(false),
            helper: Mutex::new(None),
            main: Mutex::new(None),
            depth,
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
        let tail = self.tail.load(Ordering::Relaxed);
        wait(&self.helper, deadline, || {
            Ring {
                head: self.head.load(Ordering::Acquire),
                tail,
                shutdown: self.shutdown.load(Ordering::Acquire),
            }
            .free(self.depth)
        })
    }

    fn publish(&self) {
        self.tail.fetch_add(1, Ordering::Release);
        wake(&self.main);
    }

    fn wait_published(&self, frame: u64, deadline: Instant) -> Result<(), TimedOut> {
        wait(&self.main, deadline, || {
            (self.tail.load(Ordering::Acquire) > frame).then_some(())
        })
    }

    fn release(&self) {
        self.head.fetch_add(1, Ordering::Release);
        wake(&self.helper);
    }

    fn shutdown(&self) {
        self.shutdown.store(true, Ordering::Release);
        wake(&self.helper);
    }

    fn published(&self) -> u64 {
        self.tail.load(Ordering::Acquire)
    }
}
