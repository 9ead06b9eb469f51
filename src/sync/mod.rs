//! The per-frame hand-off between the helper (producer of meshes) and the main thread (consumer):
//! one [`Handoff`] trait, one implementation per synchronisation method, and the one-frame slot
//! the protocol protects.

mod condvar;
mod flag;
mod mutex;
mod primitives;
mod slot;

pub use slot::Slot;

use primitives::{PlMonitor, PlMutex, StdMonitor, StdMutex};

use std::time::Instant;

crate::named! {
    /// The synchronisation methods a sweep can compare.
    pub enum SyncMethod {
        /// Atomic flag, acquire/release; waiters poll with a yield (the paper's Interlocked + Sleep(0)).
        Atomic,
        /// The same flag, busy-waiting with a spin hint and never yielding.
        Spin,
        /// parking_lot mutex as a critical section around the flag, polled with a yield.
        Mutex,
        /// parking_lot mutex and condition variable, blocking waits (an OS-level object).
        Condvar,
        /// `std::sync::Mutex` around the flag, polled with a yield.
        MutexStd,
        /// `std::sync::Mutex` and `Condvar`, blocking waits.
        CondvarStd,
    }
}

impl SyncMethod {
    /// A fresh hand-off of this method, in the state "slot empty, helper may write".
    pub fn handoff(self) -> Box<dyn Handoff> {
        match self {
            SyncMethod::Atomic => Box::new(flag::AtomicFlag::<flag::Yield>::default()),
            SyncMethod::Spin => Box::new(flag::AtomicFlag::<flag::Spin>::default()),
            SyncMethod::Mutex => Box::new(mutex::PolledLock::<PlMutex<State>>::default()),
            SyncMethod::MutexStd => Box::new(mutex::PolledLock::<StdMutex<State>>::default()),
            SyncMethod::Condvar => Box::new(condvar::Blocking::<PlMonitor<State>>::default()),
            SyncMethod::CondvarStd => Box::new(condvar::Blocking::<StdMonitor<State>>::default()),
        }
    }
}

/// Who owns the slot: the protocol's whole state.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[repr(u8)]
pub enum State {
    /// The helper owns the slot and may write the next mesh.
    #[default]
    Empty = 0,
    /// A mesh is published; the main thread owns the slot until it releases it.
    Full = 1,
    /// The main thread has stopped the loop; the helper must exit.
    Shutdown = 2,
}

impl State {
    fn from_u8(v: u8) -> State {
        match v {
            0 => State::Empty,
            1 => State::Full,
            _ => State::Shutdown,
        }
    }
}

/// A wait that did not complete before its deadline.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error("hand-off wait timed out")]
pub struct TimedOut;

/// What the helper learns when its wait for the release ends.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Released {
    /// The main thread copied the mesh; compute the next one.
    Next,
    /// The main thread stopped the loop.
    Shutdown,
}

/// One synchronisation method's implementation of the one-slot producer/consumer protocol.
///
/// Writes to the slot made before `publish` are visible to the main thread after
/// `wait_published` returns, and reads made before `release` happen before the helper's writes
/// after `wait_released` returns: each pair is a release/acquire edge.
pub trait Handoff: Send + Sync {
    /// Helper: the slot holds a finished mesh (Empty → Full).
    fn publish(&self);
    /// Main: blocks until a mesh is published.
    fn wait_published(&self, deadline: Instant) -> Result<(), TimedOut>;
    /// Main: the mesh is copied; the helper may overwrite the slot (Full → Empty).
    fn release(&self);
    /// Helper: blocks until the main thread releases the slot or shuts the loop down.
    fn wait_released(&self, deadline: Instant) -> Result<Released, TimedOut>;
    /// Main: stops the loop; any waiting helper returns [`Released::Shutdown`].
    fn shutdown(&self);
}

/// The shared condition of both polling waits: returns `Some` when the wait is over.
fn released_from(state: State) -> Option<Released> {
    match state {
        State::Full => None,
        State::Empty => Some(Released::Next),
        State::Shutdown => Some(Released::Shutdown),
    }
}
