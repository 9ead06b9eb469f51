//! `rtrb`: the ring's slots travel as tokens through two of rtrb's wait-free single-producer,
//! single-consumer rings of `depth` places, as `channel.rs` does with channels. rtrb never
//! blocks, so each side polls with crossbeam's `Backoff`: exponentially longer spins with a
//! pause hint, then yields; it never sleeps, so a waiter costs a core (or, on one core, a time
//! slice) while it waits.

use super::{Free, Handoff, TimedOut};
use crossbeam_utils::Backoff;
use parking_lot::Mutex;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::Instant;

/// One rtrb ring. Each end is `Send` but not `Sync`, so each sits behind a lock that only its
/// own side ever takes (uncontended).
struct Tokens {
    push: Mutex<rtrb::Producer<u64>>,
    pop: Mutex<rtrb::Consumer<u64>>,
}

impl Tokens {
    fn new(capacity: usize) -> Tokens {
        let (push, pop) = rtrb::RingBuffer::new(capacity);
        Tokens {
            push: Mutex::new(push),
            pop: Mutex::new(pop),
        }
    }

    fn put(&self, token: u64) -> bool {
        self.push.lock().push(token).is_ok()
    }

    /// Polls for a token until `deadline`, or until `stop` says to give up.
    fn take(&self, deadline: Instant, stop: impl Fn() -> bool) -> Result<Option<u64>, TimedOut> {
        let mut pop = self.pop.lock();
        let backoff = Backoff::new();
        let mut polls: u32 = 0;
        loop {
            if let Ok(token) = pop.pop() {
                return Ok(Some(token));
            }
            if stop() {
                return Ok(None);
            }
            backoff.snooze();
            polls = polls.wrapping_add(1);
            if polls.is_multiple_of(64) && Instant::now() >= deadline {
                return pop.pop().map(Some).map_err(|_| TimedOut);
            }
        }
    }
}

/// The ring over two rtrb rings.
pub struct RtrbRing {
    filled: Tokens,
    free: Tokens,
    published: AtomicU64,
    received: AtomicU64,
    shutdown: AtomicBool,
}

impl RtrbRing {
    /// A ring of `depth` free slots.
    pub fn new(depth: u64) -> Self {
        let free = Tokens::new(depth as usize);
        for slot in 0..depth {
            free.put(slot);
        }
        RtrbRing {
            filled: Tokens::new(depth as usize),
            free,
            published: AtomicU64::new(0),
            received: AtomicU64::new(0),
            shutdown: AtomicBool::new(false),
        }
    }

    fn stopped(&self) -> bool {
        self.shutdown.load(Ordering::Acquire)
    }
}

impl Handoff for RtrbRing {
    fn wait_free(&self, deadline: Instant) -> Result<Free, TimedOut> {
        match self.free.take(deadline, || self.stopped())? {
            Some(_) if !self.stopped() => Ok(Free::Slot),
            _ => Ok(Free::Shutdown),
        }
    }

    fn publish(&self) {
        let frame = self.published.fetch_add(1, Ordering::Release);
        let sent = self.filled.put(frame);
        debug_assert!(sent, "filled holds at most depth tokens");
    }

    fn wait_published(&self, frame: u64, deadline: Instant) -> Result<(), TimedOut> {
        while self.received.load(Ordering::Relaxed) <= frame {
            self.filled.take(deadline, || false)?;
            self.received.fetch_add(1, Ordering::Relaxed);
        }
        Ok(())
    }

    fn release(&self) {
        let sent = self.free.put(0);
        debug_assert!(sent || self.stopped());
    }

    fn shutdown(&self) {
        self.shutdown.store(true, Ordering::Release);
    }

    fn published(&self) -> u64 {
        self.published.load(Ordering::Acquire)
    }
}
