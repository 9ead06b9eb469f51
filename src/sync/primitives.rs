//! The primitives the hand-off methods are built from, and one [`Lock`] and [`Monitor`] API
//! over parking_lot's and std's mutexes and condition variables, so each method family is
//! written once. Under `--cfg loom` they are loom's models, so every method's protocol can be
//! model-checked (tests/loom.rs); parking_lot's types are then stood in for by thin wrappers
//! over loom's with parking_lot's API.

use std::marker::PhantomData;
use std::ops::{Deref, DerefMut};
use std::time::Instant;

#[cfg(not(loom))]
pub(crate) use parking_lot::{Condvar as PlCondvar, Mutex as PlMutex, MutexGuard as PlGuard};
#[cfg(not(loom))]
pub(crate) use std::hint::spin_loop;
#[cfg(not(loom))]
pub(crate) use std::sync::atomic::{fence, AtomicBool, AtomicU64, AtomicU8, Ordering};
#[cfg(not(loom))]
pub(crate) use std::sync::Mutex as StdMutex;
#[cfg(not(loom))]
use std::sync::{Condvar as StdCondvar, MutexGuard as StdInnerGuard};
#[cfg(not(loom))]
pub(crate) use std::thread::yield_now;

#[cfg(loom)]
pub(crate) use loom::sync::atomic::{fence, AtomicBool, AtomicU64, AtomicU8, Ordering};
#[cfg(loom)]
pub(crate) use loom::sync::Mutex as StdMutex;
#[cfg(loom)]
use loom::sync::{Condvar as StdCondvar, MutexGuard as StdInnerGuard};
#[cfg(loom)]
pub(crate) use loom::thread::yield_now;
#[cfg(loom)]
pub(crate) use loom_parking_lot::{Condvar as PlCondvar, Mutex as PlMutex, MutexGuard as PlGuard};

/// loom explores a spin loop only if each turn yields to it.
#[cfg(loom)]
pub(crate) fn spin_loop() {
    loom::thread::yield_now();
}

/// A cell whose accesses a protocol orders: std's `UnsafeCell`, or under `--cfg loom` loom's,
/// which records every access so that an unordered pair is reported as a data race.
pub struct Cell<T> {
    #[cfg(not(loom))]
    value: std::cell::UnsafeCell<T>,
    #[cfg(loom)]
    value: loom::cell::UnsafeCell<T>,
}

impl<T> Cell<T> {
    /// A cell holding `value`.
    pub fn new(value: T) -> Self {
        Cell {
            value: value.into(),
        }
    }

    /// Reads the value.
    ///
    /// # Safety
    /// No access that writes may happen concurrently (the caller's protocol orders them).
    pub unsafe fn get(&self) -> &T {
        #[cfg(not(loom))]
        // SAFETY: the caller guarantees no concurrent write.
        return unsafe { &*self.value.get() };
        #[cfg(loom)]
        // SAFETY: as above; loom records the access.
        return self.value.with(|p| unsafe { &*p });
    }

    /// Writes the value.
    ///
    /// # Safety
    /// No other access may happen concurrently (the caller's protocol gives it exclusive use).
    #[allow(clippy::mut_from_ref)]
    pub unsafe fn get_mut(&self) -> &mut T {
        #[cfg(not(loom))]
        // SAFETY: the caller guarantees exclusive use.
        return unsafe { &mut *self.value.get() };
        #[cfg(loom)]
        // SAFETY: as above; loom records the access.
        return self.value.with_mut(|p| unsafe { &mut *p });
    }
}

/// A mutex over a `T`, whichever library's.
pub trait Lock<T>: Default + Send + Sync + 'static {
    /// The held lock.
    type Guard<'a>: DerefMut<Target = T>
    where
        Self: 'a;
    /// Takes the lock; a poisoned std lock still holds a whole value, so it is taken anyway.
    fn enter(&self) -> Self::Guard<'_>;
}

/// A lock with a condition variable: waiters block until a notification.
pub trait Monitor<T>: Lock<T> {
    /// Wakes every waiter.
    fn notify_all(&self);
    /// Releases the lock until notified (or spuriously woken) or the deadline passes, then
    /// takes it again; true when the deadline passed.
    fn wait_until(&self, guard: &mut Self::Guard<'_>, deadline: Instant) -> bool;
}

/// A condition variable that waits with the guards of lock `L`.
pub trait Condvar<T, L: Lock<T>>: Default + Send + Sync + 'static {
    /// Wakes every waiter.
    fn notify_all(&self);
    /// See [`Monitor::wait_until`].
    fn wait_until(&self, guard: &mut L::Guard<'_>, deadline: Instant) -> bool;
}

impl<T: Default + Send + 'static> Lock<T> for PlMutex<T> {
    type Guard<'a> = PlGuard<'a, T>;
    fn enter(&self) -> PlGuard<'_, T> {
        self.lock()
    }
}

impl<T: Default + Send + 'static> Condvar<T, PlMutex<T>> for PlCondvar {
    fn notify_all(&self) {
        PlCondvar::notify_all(self);
    }
    fn wait_until(&self, guard: &mut PlGuard<'_, T>, deadline: Instant) -> bool {
        PlCondvar::wait_until(self, guard, deadline).timed_out()
    }
}

/// std's mutex guard, held in an option so a condition-variable wait can take it and give it
/// back through `&mut`, as parking_lot's API does.
pub struct StdGuard<'a, T>(Option<StdInnerGuard<'a, T>>);

impl<T> Deref for StdGuard<'_, T> {
    type Target = T;
    fn deref(&self) -> &T {
        self.0.as_ref().expect("the guard is held outside a wait")
    }
}

impl<T> DerefMut for StdGuard<'_, T> {
    fn deref_mut(&mut self) -> &mut T {
        self.0.as_mut().expect("the guard is held outside a wait")
    }
}

impl<T: Default + Send + 'static> Lock<T> for StdMutex<T> {
    type Guard<'a> = StdGuard<'a, T>;
    fn enter(&self) -> StdGuard<'_, T> {
        StdGuard(Some(self.lock().unwrap_or_else(|e| e.into_inner())))
    }
}

impl<T: Default + Send + 'static> Condvar<T, StdMutex<T>> for StdCondvar {
    fn notify_all(&self) {
        StdCondvar::notify_all(self);
    }
    fn wait_until(&self, guard: &mut StdGuard<'_, T>, deadline: Instant) -> bool {
        let left = deadline.saturating_duration_since(Instant::now());
        if left.is_zero() {
            return true;
        }
        let inner = guard.0.take().expect("the guard is held outside a wait");
        let (inner, result) = self
            .wait_timeout(inner, left)
            .unwrap_or_else(|e| e.into_inner());
        guard.0 = Some(inner);
        result.timed_out()
    }
}

/// A lock `L` over a `T` with its library's condition variable `C`.
pub struct WithCondvar<T, L, C> {
    value: L,
    changed: C,
    of: PhantomData<T>,
}

impl<T, L: Default, C: Default> Default for WithCondvar<T, L, C> {
    fn default() -> Self {
        WithCondvar {
            value: L::default(),
            changed: C::default(),
            of: PhantomData,
        }
    }
}

impl<T: Send + Sync + 'static, L: Lock<T>, C: Condvar<T, L>> Lock<T> for WithCondvar<T, L, C> {
    type Guard<'a> = L::Guard<'a>;
    fn enter(&self) -> L::Guard<'_> {
        self.value.enter()
    }
}

impl<T: Send + Sync + 'static, L: Lock<T>, C: Condvar<T, L>> Monitor<T> for WithCondvar<T, L, C> {
    fn notify_all(&self) {
        self.changed.notify_all();
    }
    fn wait_until(&self, guard: &mut L::Guard<'_>, deadline: Instant) -> bool {
        self.changed.wait_until(guard, deadline)
    }
}

/// parking_lot's mutex and condition variable.
pub type PlMonitor<T> = WithCondvar<T, PlMutex<T>, PlCondvar>;

/// `std::sync`'s mutex and condition variable.
pub type StdMonitor<T> = WithCondvar<T, StdMutex<T>, StdCondvar>;

#[cfg(loom)]
mod loom_parking_lot {
    use super::StdGuard;
    use std::time::Instant;

    /// parking_lot's `Mutex` API over loom's mutex.
    #[derive(Default)]
    pub struct Mutex<T>(loom::sync::Mutex<T>);

    /// The guard is std's shape: loom's guard in an option, so a wait can take it and give it back.
    pub type MutexGuard<'a, T> = StdGuard<'a, T>;

    impl<T> Mutex<T> {
        pub fn lock(&self) -> MutexGuard<'_, T> {
            StdGuard(Some(self.0.lock().unwrap_or_else(|e| e.into_inner())))
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
