//! `crossbeam`, `std-channel`, `flume` and `rtrb`: the ring's slots travel as tokens through two
//! bounded channels (or rtrb's SPSC rings) of `depth` places, the paper's one-slot queue built
//! from the queues engines use.
//! The helper receives a free slot's token from `free`, computes into that slot and sends the
//! frame's token on `filled`; the main thread receives it, consumes the slot and sends the token
//! back on `free`. Only tokens move, never a mesh, so `consume` means the same as for every
//! other method, and each channel's own send/receive is the release/acquire edge.
//!
//! A stop raises a flag and pushes one extra token into `free` (when it has room; when it has
//! none, the helper is not blocked on it), which wakes a helper blocked in its receive.

use super::{Free, Handoff, TimedOut};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::Instant;

/// One bounded channel of tokens, both ends held together: the ring's side of each crate's API.
pub trait Pipe: Send + Sync + 'static {
    /// A channel with room for `capacity` tokens.
    fn bounded(capacity: usize) -> Self;
    /// Sends without blocking; `false` when the channel is full.
    fn put(&self, token: u64) -> bool;
    /// Receives the oldest token, blocking at most until `deadline`.
    fn take(&self, deadline: Instant) -> Result<u64, TimedOut>;
}

/// A [`Pipe`] over a crate's bounded channel with `try_send` and `recv_deadline`: crossbeam's
/// and flume's have the same API under their own names.
macro_rules! deadline_pipe {
    ($(#[$doc:meta])* $name:ident, $channel:ident) => {
        $(#[$doc])*
        pub struct $name($channel::Sender<u64>, $channel::Receiver<u64>);

        impl Pipe for $name {
            fn bounded(capacity: usize) -> Self {
                let (s, r) = $channel::bounded(capacity);
                $name(s, r)
            }
            fn put(&self, token: u64) -> bool {
                self.0.try_send(token).is_ok()
            }
            fn take(&self, deadline: Instant) -> Result<u64, TimedOut> {
                self.1.recv_deadline(deadline).map_err(|_| TimedOut)
            }
        }
    };
}

deadline_pipe!(
    /// crossbeam-channel's bounded channel.
    Crossbeam,
    crossbeam_channel
);

deadline_pipe!(
    /// flume's bounded channel.
    Flume,
    flume
);

/// std's `sync_channel`. Its receiver is not `Sync`, so it sits behind a lock only the
/// receiving side ever takes (uncontended: a few nanoseconds).
pub struct StdChannel(
    std::sync::mpsc::SyncSender<u64>,
    parking_lot::Mutex<std::sync::mpsc::Receiver<u64>>,
);

impl Pipe for StdChannel {
    fn bounded(capacity: usize) -> Self {
        let (s, r) = std::sync::mpsc::sync_channel(capacity);
        StdChannel(s, parking_lot::Mutex::new(r))
    }
    fn put(&self, token: u64) -> bool {
        self.0.try_send(token).is_ok()
    }
    fn take(&self, deadline: Instant) -> Result<u64, TimedOut> {
        // `recv_deadline` is unstable in std; the timeout is the same wait.
        let left = deadline.saturating_duration_since(Instant::now());
        self.1.lock().recv_timeout(left).map_err(|_| TimedOut)
    }
}

/// rtrb's wait-free single-producer, single-consumer ring. It never blocks, so a receive polls
/// with crossbeam's `Backoff`: exponentially longer spins with a pause hint, then yields; it
/// never sleeps, so a waiter costs a core (or, on one core, time slices) while it waits. Each
/// end is `Send` but not `Sync`, so each sits behind a lock only its own side takes.
pub struct Rtrb(
    parking_lot::Mutex<rtrb::Producer<u64>>,
    parking_lot::Mutex<rtrb::Consumer<u64>>,
);

impl Pipe for Rtrb {
    fn bounded(capacity: usize) -> Self {
        let (push, pop) = rtrb::RingBuffer::new(capacity);
        Rtrb(parking_lot::Mutex::new(push), parking_lot::Mutex::new(pop))
    }
    fn put(&self, token: u64) -> bool {
        self.0.lock().push(token).is_ok()
    }
    fn take(&self, deadline: Instant) -> Result<u64, TimedOut> {
        let mut pop = self.1.lock();
        let backoff = crossbeam_utils::Backoff::new();
        let mut polls: u32 = 0;
        loop {
            if let Ok(token) = pop.pop() {
                return Ok(token);
            }
            backoff.snooze();
            polls = polls.wrapping_add(1);
            if polls.is_multiple_of(64) && Instant::now() >= deadline {
                return pop.pop().map_err(|_| TimedOut);
            }
        }
    }
}

/// The ring over two channels of one crate.
pub struct ChannelRing<P: Pipe> {
    /// Frames published, helper to main: the frame's number.
    filled: P,
    /// Free slots, main to helper: the slot's index.
    free: P,
    published: AtomicU64,
    /// Frames the main thread has received from `filled` (only it touches this).
    received: AtomicU64,
    shutdown: AtomicBool,
    depth: u64,
}

impl<P: Pipe> ChannelRing<P> {
    /// A ring of `depth` free slots: `free` starts holding every slot's token.
    pub fn new(depth: u64) -> Self {
        let free = P::bounded(depth as usize);
        for slot in 0..depth {
            free.put(slot);
        }
        ChannelRing {
            filled: P::bounded(depth as usize),
            free,
            published: AtomicU64::new(0),
            received: AtomicU64::new(0),
            shutdown: AtomicBool::new(false),
            depth,
        }
    }

    fn stopped(&self) -> bool {
        self.shutdown.load(Ordering::Acquire)
    }
}

impl<P: Pipe> Handoff for ChannelRing<P> {
    fn wait_free(&self, deadline: Instant) -> Result<Free, TimedOut> {
        if self.stopped() {
            return Ok(Free::Shutdown);
        }
        let taken = self.free.take(deadline);
        match (taken, self.stopped()) {
            (_, true) => Ok(Free::Shutdown),
            (Ok(_), false) => Ok(Free::Slot),
            (Err(e), false) => Err(e),
        }
    }

    fn publish(&self) {
        let frame = self.published.fetch_add(1, Ordering::Release);
        // The helper holds a free slot's token, so `filled` has room for this one.
        let sent = self.filled.put(frame);
        debug_assert!(sent, "filled holds at most depth = {} tokens", self.depth);
    }

    fn wait_published(&self, frame: u64, deadline: Instant) -> Result<(), TimedOut> {
        while self.received.load(Ordering::Relaxed) <= frame {
            self.filled.take(deadline)?;
            self.received.fetch_add(1, Ordering::Relaxed);
        }
        Ok(())
    }

    fn release(&self) {
        // Room is certain before a stop; after one, the stop's token may have taken it, and the
        // helper no longer needs the slot.
        let sent = self.free.put(0);
        debug_assert!(sent || self.stopped());
    }

    fn shutdown(&self) {
        self.shutdown.store(true, Ordering::Release);
        self.free.put(u64::MAX);
    }

    fn published(&self) -> u64 {
        self.published.load(Ordering::Acquire)
    }
}
