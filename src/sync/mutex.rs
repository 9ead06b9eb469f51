//! `mutex` and `mutex-std`: the state inside a critical section, polled with a yield.

use super::flag::{poll, Yield};
use super::primitives::{PlMutex, StdMutex};
use super::{released_from, Handoff, Released, State, TimedOut};
use std::time::Instant;

/// A mutex holding the state: parking_lot's or std's.
pub trait StateLock: Default + Send + Sync + 'static {
    /// Reads the state inside the critical section.
    fn get(&self) -> State;
    /// Writes the state inside the critical section.
    fn set(&self, state: State);
    /// Moves Empty → Full inside the critical section, leaving a shutdown in place.
    fn publish(&self);
}

impl StateLock for PlMutex<State> {
    fn get(&self) -> State {
        *self.lock()
    }
    fn set(&self, state: State) {
        *self.lock() = state;
    }
    fn publish(&self) {
        let mut s = self.lock();
        if *s == State::Empty {
            *s = State::Full;
        }
    }
}

impl StateLock for StdMutex<State> {
    fn get(&self) -> State {
        // A poisoned lock still holds a valid state: the flag is written whole.
        *self.lock().unwrap_or_else(|e| e.into_inner())
    }
    fn set(&self, state: State) {
        *self.lock().unwrap_or_else(|e| e.into_inner()) = state;
    }
    fn publish(&self) {
        let mut s = self.lock().unwrap_or_else(|e| e.into_inner());
        if *s == State::Empty {
            *s = State::Full;
        }
    }
}

/// The paper's critical-section build: every look at the flag enters the critical section.
#[derive(Default)]
pub struct PolledLock<L: StateLock> {
    lock: L,
}

impl<L: StateLock> Handoff for PolledLock<L> {
    fn publish(&self) {
        self.lock.publish();
    }

    fn wait_published(&self, deadline: Instant) -> Result<(), TimedOut> {
        poll::<_, Yield>(deadline, || (self.lock.get() == State::Full).then_some(()))
    }

    fn release(&self) {
        self.lock.set(State::Empty);
    }

    fn wait_released(&self, deadline: Instant) -> Result<Released, TimedOut> {
        poll::<_, Yield>(deadline, || released_from(self.lock.get()))
    }

    fn shutdown(&self) {
        self.lock.set(State::Shutdown);
    }
}
