//! `mutex` and `mutex-std`: the state inside a critical section, polled with a yield.

use super::flag::{poll, Yield};
use super::primitives::Lock;
use super::{released_from, Handoff, Released, State, TimedOut};
use std::marker::PhantomData;
use std::time::Instant;

/// The paper's critical-section build: every look at the flag enters the critical section.
pub struct PolledLock<L: Lock<State>> {
    lock: L,
    state: PhantomData<State>,
}

impl<L: Lock<State>> Default for PolledLock<L> {
    fn default() -> Self {
        PolledLock {
            lock: L::default(),
            state: PhantomData,
        }
    }
}

impl<L: Lock<State>> PolledLock<L> {
    fn get(&self) -> State {
        *self.lock.enter()
    }
}

impl<L: Lock<State>> Handoff for PolledLock<L> {
    fn publish(&self) {
        let mut s = self.lock.enter();
        // Empty → Full only: a shutdown that arrived while the helper computed must survive.
        if *s == State::Empty {
            *s = State::Full;
        }
    }

    fn wait_published(&self, deadline: Instant) -> Result<(), TimedOut> {
        poll::<_, Yield>(deadline, || (self.get() == State::Full).then_some(()))
    }

    fn release(&self) {
        *self.lock.enter() = State::Empty;
    }

    fn wait_released(&self, deadline: Instant) -> Result<Released, TimedOut> {
        poll::<_, Yield>(deadline, || released_from(self.get()))
    }

    fn shutdown(&self) {
        *self.lock.enter() = State::Shutdown;
    }
}
