//! The per-frame hand-off between the helper (producer of meshes) and the main thread (consumer):
//! one [`Handoff`] trait, the ring of `depth` slots every method implements, one implementation
//! per family of methods, and the slot cell the protocol protects.

mod adaptive;
mod channel;
mod condvar;
mod flag;
mod futex;
mod mailbox;
mod mutex;
mod park;
mod polls;
mod primitives;
mod ring;
mod slot;

pub use mailbox::{MailboxIn, MailboxOut};
pub use ring::Ring;
pub use slot::Slot;

use primitives::{PlMonitor, PlMutex, StdMonitor, StdMutex};

use std::time::Instant;

crate::named! {
    /// The synchronisation methods a sweep can compare.
    pub enum SyncMethod {
        /// Atomic counters, acquire/release; waiters poll with a yield (the paper's Interlocked +
        /// Sleep(0)). Under `latest`, the in-house triple buffer: one atomic index swapped each
        /// way.
        Atomic,
        /// The same counters, busy-waiting with a spin hint and never yielding.
        Spin,
        /// parking_lot mutex as a critical section around the counters, polled with a yield.
        Mutex,
        /// parking_lot mutex and condition variable, blocking waits (an OS-level object).
        Condvar,
        /// `std::sync::Mutex` around the counters, polled with a yield.
        MutexStd,
        /// `std::sync::Mutex` and `Condvar`, blocking waits.
        CondvarStd,
        /// Spins briefly, then yields, then sleeps on a futex, each phase as long as the waits it
        /// has seen call for: at the cache-line floor across cores, without losing a tick on one.
        Adaptive,
        /// crossbeam-channel: slot tokens through two bounded channels of `depth` places.
        Crossbeam,
        /// std's `sync_channel`, bounded the same way.
        StdChannel,
        /// flume's bounded channel, the same way.
        Flume,
        /// rtrb's single-producer, single-consumer ring of `depth` places, polled with
        /// crossbeam's `Backoff` (spins, then yields; never sleeps).
        Rtrb,
        /// The counters as futex words: every wait sleeps in the kernel, every change wakes.
        Futex,
        /// The counters in atomics, waiters parked with `std::thread::park_timeout`.
        Park,
        /// The `latest` policy's triple buffer from the `triple_buffer` crate: the helper never
        /// waits, the main thread takes the newest mesh.
        TripleBuffer,
    }
}

crate::named! {
    /// Which frames the main thread consumes (Vulkan's present modes name the two).
    pub enum Policy {
        /// Every frame, in order; the helper waits when the ring is full (the paper's loop).
        Fifo,
        /// The newest finished frame; the helper never waits and older frames are dropped
        /// (MAILBOX).
        Latest,
    }
}

impl SyncMethod {
    /// Whether the method can hand over under `policy`: through a ring under `fifo`, through a
    /// mailbox under `latest`.
    pub fn serves(self, policy: Policy) -> bool {
        match self {
            SyncMethod::Atomic => true,
            SyncMethod::TripleBuffer => policy == Policy::Latest,
            _ => policy == Policy::Fifo,
        }
    }

    /// The methods that can hand over under `policy`, in declaration order.
    pub fn of_policy(policy: Policy) -> impl Iterator<Item = SyncMethod> {
        use strum::VariantArray;
        SyncMethod::VARIANTS
            .iter()
            .copied()
            .filter(move |m| m.serves(policy))
    }

    /// A fresh mailbox of this method over three copies of `initial`, for the `latest` policy;
    /// `None` for a method that cannot serve it.
    #[allow(clippy::type_complexity)]
    pub fn mailbox<T: Clone + Send + 'static>(
        self,
        initial: &T,
    ) -> Option<(Box<dyn MailboxIn<T>>, Box<dyn MailboxOut<T>>)> {
        match self {
            SyncMethod::TripleBuffer => {
                let (i, o) = triple_buffer::triple_buffer(initial);
                Some((Box::new(i), Box::new(o)))
            }
            SyncMethod::Atomic => {
                let (i, o) = mailbox::swap(initial);
                Some((Box::new(i), Box::new(o)))
            }
            _ => None,
        }
    }

    /// A fresh hand-off of this method over a ring of `depth` slots, every slot free.
    ///
    /// # Panics
    /// For a method that serves only `latest` (through [`SyncMethod::mailbox`]); configs and
    /// flags refuse it under `fifo` before anything runs.
    pub fn handoff(self, depth: usize) -> Box<dyn Handoff> {
        let depth = depth.max(1) as u64;
        match self {
            SyncMethod::Atomic => Box::new(flag::AtomicRing::<flag::Yield>::new(depth)),
            SyncMethod::Spin => Box::new(flag::AtomicRing::<flag::Spin>::new(depth)),
            SyncMethod::Mutex => Box::new(mutex::PolledLock::<PlMutex<Ring>>::new(depth)),
            SyncMethod::MutexStd => Box::new(mutex::PolledLock::<StdMutex<Ring>>::new(depth)),
            SyncMethod::Condvar => Box::new(condvar::Blocking::<PlMonitor<Ring>>::new(depth)),
            SyncMethod::CondvarStd => Box::new(condvar::Blocking::<StdMonitor<Ring>>::new(depth)),
            SyncMethod::Adaptive => Box::new(adaptive::AdaptiveRing::new(depth)),
            SyncMethod::Crossbeam => {
                Box::new(channel::ChannelRing::<channel::Crossbeam>::new(depth))
            }
            SyncMethod::StdChannel => {
                Box::new(channel::ChannelRing::<channel::StdChannel>::new(depth))
            }
            SyncMethod::Flume => Box::new(channel::ChannelRing::<channel::Flume>::new(depth)),
            SyncMethod::Rtrb => Box::new(channel::ChannelRing::<channel::Rtrb>::new(depth)),
            SyncMethod::Futex => Box::new(futex::FutexRing::new(depth)),
            SyncMethod::Park => Box::new(park::ParkRing::new(depth)),
            SyncMethod::TripleBuffer => {
                panic!("{self} hands over the latest mesh only; it has no ring")
            }
        }
    }
}

/// A wait that did not complete before its deadline.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error("hand-off wait timed out")]
pub struct TimedOut;

/// What the helper learns when its wait for a free slot ends.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Free {
    /// A slot is free: compute the next frame into it.
    Slot,
    /// The main thread stopped the loop.
    Shutdown,
}

/// One synchronisation method's implementation of the ring protocol between one helper (the
/// producer) and the main thread (the consumer), over `depth` slots.
///
/// The helper waits for a free slot, writes frame k into slot k mod depth and publishes it; the
/// main thread waits for the next published frame, uses its slot, and releases it, oldest first.
/// Writes to a slot before `publish` are visible to the main thread after its `wait_published`
/// returns, and reads before `release` happen before the helper's writes after its `wait_free`
/// returns: each pair is a release/acquire edge. At depth 1 this is the paper's one-slot loop.
pub trait Handoff: Send + Sync {
    /// Helper: blocks until a slot is free or the loop is shut down (which wins).
    fn wait_free(&self, deadline: Instant) -> Result<Free, TimedOut>;
    /// Helper: the slot it wrote holds a finished frame.
    fn publish(&self);
    /// Main: blocks until frame `frame` (counting from 0) is published. With frames still held
    /// from earlier (`handle` consumption), this is not the oldest unreleased one.
    fn wait_published(&self, frame: u64, deadline: Instant) -> Result<(), TimedOut>;
    /// Main: done with the oldest published frame; the helper may reuse its slot.
    fn release(&self);
    /// Main: stops the loop; a waiting helper returns [`Free::Shutdown`].
    fn shutdown(&self);
    /// Frames published so far (a snapshot; the main thread reads it for a mesh's age).
    fn published(&self) -> u64;
}
