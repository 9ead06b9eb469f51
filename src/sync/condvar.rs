//! `condvar` and `condvar-std`: blocking waits on a condition variable, the paper's "OS-level
//! synchronisation object".

use super::primitives::{PlCondvar, PlMutex, StdCondvar as StdCv, StdMutex};
use super::{released_from, Handoff, Released, State, TimedOut};
use std::time::Instant;

/// A mutex-protected state with a condition variable signalled on every change.
pub trait CondState: Default + Send + Sync + 'static {
    /// Sets the state and wakes the waiters.
    fn set(&self, state: State);
    /// Moves Empty → Full and wakes the waiters; a shutdown that arrived meanwhile survives.
    fn publish(&self);
    /// Blocks until `done` accepts the state, or the deadline passes.
    fn wait_for<T>(
        &self,
        deadline: Instant,
        done: impl Fn(State) -> Option<T>,
    ) -> Result<T, TimedOut>;
}

/// The blocking hand-off over either library's mutex and condition variable.
#[derive(Default)]
pub struct Blocking<C: CondState> {
    state: C,
}

impl<C: CondState> Handoff for Blocking<C> {
    fn publish(&self) {
        self.state.publish();
    }
    fn wait_published(&self, deadline: Instant) -> Result<(), TimedOut> {
        self.state
            .wait_for(deadline, |s| (s == State::Full).then_some(()))
    }
    fn release(&self) {
        self.state.set(State::Empty);
    }
    fn wait_released(&self, deadline: Instant) -> Result<Released, TimedOut> {
        self.state.wait_for(deadline, released_from)
    }
    fn shutdown(&self) {
        self.state.set(State::Shutdown);
    }
}

/// parking_lot's mutex and condition variable.
#[derive(Default)]
pub struct ParkingLot {
    state: PlMutex<State>,
    changed: PlCondvar,
}

impl CondState for ParkingLot {
    fn set(&self, state: State) {
        *self.state.lock() = state;
        self.changed.notify_all();
    }

    fn publish(&self) {
        let mut s = self.state.lock();
        if *s == State::Empty {
            *s = State::Full;
            drop(s);
            self.changed.notify_all();
        }
    }

    fn wait_for<T>(
        &self,
        deadline: Instant,
        done: impl Fn(State) -> Option<T>,
    ) -> Result<T, TimedOut> {
        let mut guard = self.state.lock();
        loop {
            if let Some(v) = done(*guard) {
                return Ok(v);
            }
            if self.changed.wait_until(&mut guard, deadline).timed_out() {
                return done(*guard).ok_or(TimedOut);
            }
        }
    }
}

/// `std::sync`'s mutex and condition variable.
#[derive(Default)]
pub struct Std {
    state: StdMutex<State>,
    changed: StdCv,
}

impl CondState for Std {
    fn set(&self, state: State) {
        *self.state.lock().unwrap_or_else(|e| e.into_inner()) = state;
        self.changed.notify_all();
    }

    fn publish(&self) {
        let mut s = self.state.lock().unwrap_or_else(|e| e.into_inner());
        if *s == State::Empty {
            *s = State::Full;
            drop(s);
            self.changed.notify_all();
        }
    }

    fn wait_for<T>(
        &self,
        deadline: Instant,
        done: impl Fn(State) -> Option<T>,
    ) -> Result<T, TimedOut> {
        let mut guard = self.state.lock().unwrap_or_else(|e| e.into_inner());
        loop {
            if let Some(v) = done(*guard) {
                return Ok(v);
            }
            let left = deadline.saturating_duration_since(Instant::now());
            if left.is_zero() {
                return Err(TimedOut);
            }
            guard = self
                .changed
                .wait_timeout(guard, left)
                .unwrap_or_else(|e| e.into_inner())
                .0;
        }
    }
}
