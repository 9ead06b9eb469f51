//! `condvar` and `condvar-std`: blocking waits on a condition variable, the paper's "OS-level
//! synchronisation object".

use super::primitives::Monitor;
use super::{released_from, Handoff, Released, State, TimedOut};
use std::marker::PhantomData;
use std::time::Instant;

/// The blocking hand-off over either library's mutex and condition variable: every change of
/// the state wakes the waiters.
pub struct Blocking<M: Monitor<State>> {
    monitor: M,
    state: PhantomData<State>,
}

impl<M: Monitor<State>> Default for Blocking<M> {
    fn default() -> Self {
        Blocking {
            monitor: M::default(),
            state: PhantomData,
        }
    }
}

impl<M: Monitor<State>> Blocking<M> {
    fn set(&self, state: State) {
        *self.monitor.enter() = state;
        self.monitor.notify_all();
    }

    /// Blocks until `done` accepts the state, or the deadline passes.
    fn wait_for<T>(
        &self,
        deadline: Instant,
        done: impl Fn(State) -> Option<T>,
    ) -> Result<T, TimedOut> {
        let mut guard = self.monitor.enter();
        loop {
            if let Some(v) = done(*guard) {
                return Ok(v);
            }
            if self.monitor.wait_until(&mut guard, deadline) {
                return done(*guard).ok_or(TimedOut);
            }
        }
    }
}

impl<M: Monitor<State>> Handoff for Blocking<M> {
    fn publish(&self) {
        let mut s = self.monitor.enter();
        // Empty → Full only: a shutdown that arrived while the helper computed must survive.
        if *s == State::Empty {
            *s = State::Full;
            drop(s);
            self.monitor.notify_all();
        }
    }
    fn wait_published(&self, deadline: Instant) -> Result<(), TimedOut> {
        self.wait_for(deadline, |s| (s == State::Full).then_some(()))
    }
    fn release(&self) {
        self.set(State::Empty);
    }
    fn wait_released(&self, deadline: Instant) -> Result<Released, TimedOut> {
        self.wait_for(deadline, released_from)
    }
    fn shutdown(&self) {
        self.set(State::Shutdown);
    }
}
