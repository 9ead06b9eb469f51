//! `atomic` and `spin`: the state in one atomic byte, waiters polling it.

use super::primitives::{spin_loop, yield_now, AtomicU8, Ordering};
use super::{released_from, Handoff, Released, State, TimedOut};
use std::marker::PhantomData;
use std::time::Instant;

/// How a polling waiter spends the time between two looks at the state.
pub trait Relax: Send + Sync + 'static {
    /// Called once per unsuccessful poll.
    fn relax();
}

/// Gives up the time slice, like the paper's `Sleep(0)`.
pub struct Yield;
impl Relax for Yield {
    fn relax() {
        yield_now();
    }
}

/// Stays on the core with a spin-loop hint.
pub struct Spin;
impl Relax for Spin {
    fn relax() {
        spin_loop();
    }
}

/// Polls `ready` until it returns `Some`, relaxing in between; looks at the clock only every 256
/// polls so that the deadline costs nothing on the fast path.
pub fn poll<T, R: Relax>(
    deadline: Instant,
    mut ready: impl FnMut() -> Option<T>,
) -> Result<T, TimedOut> {
    let mut polls: u32 = 0;
    loop {
        if let Some(v) = ready() {
            return Ok(v);
        }
        R::relax();
        polls = polls.wrapping_add(1);
        if polls.is_multiple_of(256) && Instant::now() >= deadline {
            return ready().ok_or(TimedOut);
        }
    }
}

/// The slot's state in one cache line's atomic byte.
pub struct AtomicFlag<R: Relax> {
    state: AtomicU8,
    relax: PhantomData<R>,
}

impl<R: Relax> Default for AtomicFlag<R> {
    fn default() -> Self {
        AtomicFlag {
            state: AtomicU8::new(State::Empty as u8),
            relax: PhantomData,
        }
    }
}

impl<R: Relax> AtomicFlag<R> {
    fn load(&self) -> State {
        State::from_u8(self.state.load(Ordering::Acquire))
    }
}

impl<R: Relax> Handoff for AtomicFlag<R> {
    fn publish(&self) {
        // Empty → Full only: a shutdown that arrived while the helper computed must survive.
        let _ = self.state.compare_exchange(
            State::Empty as u8,
            State::Full as u8,
            Ordering::Release,
            Ordering::Relaxed,
        );
    }

    fn wait_published(&self, deadline: Instant) -> Result<(), TimedOut> {
        poll::<_, R>(deadline, || (self.load() == State::Full).then_some(()))
    }

    fn release(&self) {
        // Only the main thread moves Full → Empty or anything → Shutdown, so a plain store cannot
        // overwrite a shutdown.
        self.state.store(State::Empty as u8, Ordering::Release);
    }

    fn wait_released(&self, deadline: Instant) -> Result<Released, TimedOut> {
        poll::<_, R>(deadline, || released_from(self.load()))
    }

    fn shutdown(&self) {
        self.state.store(State::Shutdown as u8, Ordering::Release);
    }
}
