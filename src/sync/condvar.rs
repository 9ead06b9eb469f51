//! `condvar` and `condvar-std`: blocking waits on a condition variable, the paper's "OS-level
//! synchronisation object".

use super::primitives::{PlCondvar, PlMutex, StdCondvar as StdCv, StdMutex};
use super::{released_from, Handoff, Released, State, TimedOut};
use std::time::Instant;

/// parking_lot's mutex and condition variable.
#[derive(Default)]
pub struct ParkingLotCondvar {
    state: PlMutex<State>,
    changed: PlCondvar,
}

impl ParkingLotCondvar {
    fn set(&self, state: State) {
        *self.state.lock() = state;
        self.changed.notify_all();
    }

    /// Empty → Full only, so a shutdown that arrived meanwhile survives.
    fn set_if_empty(&self, state: State) {
        let mut s = self.state.lock();
        if *s == State::Empty {
            *s = state;
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

impl Handoff for ParkingLotCondvar {
    fn publish(&self) {
        self.set_if_empty(State::Full);
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

/// `std::sync`'s mutex and condition variable.
#[derive(Default)]
pub struct StdCondvar {
    state: StdMutex<State>,
    changed: StdCv,
}

impl StdCondvar {
    fn set(&self, state: State) {
        *self.state.lock().unwrap_or_else(|e| e.into_inner()) = state;
        self.changed.notify_all();
    }

    /// Empty → Full only, so a shutdown that arrived meanwhile survives.
    fn set_if_empty(&self, state: State) {
        let mut s = self.state.lock().unwrap_or_else(|e| e.into_inner());
        if *s == State::Empty {
            *s = state;
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

impl Handoff for StdCondvar {
    fn publish(&self) {
        self.set_if_empty(State::Full);
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
