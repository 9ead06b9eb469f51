//! The primitives the hand-off methods are built from. Under `--cfg loom` they are loom's
//! models, so every method's protocol can be model-checked (tests/loom.rs); parking_lot's types
//! are then stood in for by thin wrappers over loom's with parking_lot's API.

#[cfg(not(loom))]
pub(crate) use parking_lot::{Condvar as PlCondvar, Mutex as PlMutex};
#[cfg(not(loom))]
pub(crate) use std::hint::spin_loop;
#[cfg(not(loom))]
pub(crate) use std::sync::atomic::{AtomicU8, Ordering};
#[cfg(not(loom))]
pub(crate) use std::sync::{Condvar as StdCondvar, Mutex as StdMutex};
#[cfg(not(loom))]
pub(crate) use std::thread::yield_now;

#[cfg(loom)]
pub(crate) use loom::sync::atomic::{AtomicU8, Ordering};
#[cfg(loom)]
pub(crate) use loom::sync::{Condvar as StdCondvar, Mutex as StdMutex};
#[cfg(loom)]
pub(crate) use loom::thread::yield_now;
#[cfg(loom)]
pub(crate) use loom_parking_lot::{Condvar as PlCondvar, Mutex as PlMutex};

/// loom explores a spin loop only if each turn yields to it.
#[cfg(loom)]
pub(crate) fn spin_loop() {
    loom::thread::yield_now();
}

#[cfg(loom)]
mod loom_parking_lot {
    use std::ops::{Deref, DerefMut};
    use std::time::Instant;

    /// parking_lot's `Mutex` API over loom's mutex.
    #[derive(Default)]
    pub struct Mutex<T>(loom::sync::Mutex<T>);

    /// Holds the loom guard in an option so a condvar wait can take and give it back.
    pub struct MutexGuard<'a, T>(Option<loom::sync::MutexGuard<'a, T>>);

    impl<T> Mutex<T> {
        pub fn lock(&self) -> MutexGuard<'_, T> {
            MutexGuard(Some(self.0.lock().unwrap_or_else(|e| e.into_inner())))
        }
    }

    impl<T> Deref for MutexGuard<'_, T> {
        type Target = T;
        fn deref(&self) -> &T {
            self.0.as_ref().expect("guard held")
        }
    }

    impl<T> DerefMut for MutexGuard<'_, T> {
        fn deref_mut(&mut self) -> &mut T {
            self.0.as_mut().expect("guard held")
        }
    }

    /// loom does not model time: every wait is untimed.
    pub struct WaitTimeoutResult;

    impl WaitTimeoutResult {
        pub fn timed_out(&self) -> bool {
            false
        }
    }

    /// parking_lot's `Condvar` API over loom's condition variable.
    #[derive(Default)]
    pub struct Condvar(loom::sync::Condvar);

    impl Condvar {
        pub fn wait_until<T>(
            &self,
            guard: &mut MutexGuard<'_, T>,
            _deadline: Instant,
        ) -> WaitTimeoutResult {
            let inner = guard.0.take().expect("guard held");
            guard.0 = Some(self.0.wait(inner).unwrap_or_else(|e| e.into_inner()));
            WaitTimeoutResult
        }

        pub fn notify_all(&self) {
            self.0.notify_all();
        }
    }
}
