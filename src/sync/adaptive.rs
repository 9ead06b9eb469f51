//! `adaptive`: each wait spins with a pause hint, then yields, then blocks on a futex, and each
//! phase's length follows the waits the side has seen (as parking_lot's `SpinWait` and Linux's
//! adaptive mutexes do). Across two cores a short wait is caught while spinning, at the
//! cache-line floor; on one core spinning cannot succeed (the other side needs the core), so the
//! spin shrinks to nothing and the yield hands the core over; a waiter that always waits long
//! stops polling and sleeps, which costs a wake-up but no CPU.
//!
//! The counters are the same as `atomic`'s. Blocking uses parking_lot's mutex and condition
//! variable (futex-backed, with timed waits, which `atomic-wait` lacks; and already model-checked
//! here through the loom facade). A waiter registers itself as a sleeper before its last look at
//! the counters, and a signaller looks for sleepers after changing them, both sequentially
//! consistent, so a wake-up cannot be lost between the look and the sleep.

use super::primitives::{
    spin_loop, yield_now, AtomicBool, AtomicU64, Ordering, PlCondvar, PlMutex,
};
use super::{Free, Handoff, Ring, TimedOut};
use std::time::{Duration, Instant};

/// Longest spin: a few cross-core round trips, far below a scheduler tick.
const SPIN_MAX_NS: u64 = 20_000;
/// Longest time spent yielding before sleeping.
const YIELD_MAX_NS: u64 = 1_000_000;
/// A spin that has shrunk to nothing is tried again this often, in case the threads moved to
/// two cores.
const PROBE_EVERY: u32 = 64;
/// The spin tried then.
const PROBE_NS: u64 = 2_000;

/// One side's wait phases, adapted after every wait.
#[derive(Default)]
struct Phases {
    spin_ns: AtomicU64,
    yield_ns: AtomicU64,
    waits: AtomicU64,
}

/// How a wait ended.
enum Phase {
    Spin,
    Yield,
    Sleep,
}

impl Phases {
    fn new() -> Phases {
        Phases {
            spin_ns: AtomicU64::new(PROBE_NS),
            yield_ns: AtomicU64::new(100_000),
            waits: AtomicU64::new(0),
        }
    }

    /// Grows the phase that caught the wait, shrinks the ones it went past.
    fn learn(&self, phase: Phase, waited: Duration) {
        let waited = waited.as_nanos() as u64;
        let (spin, yielded) = (
            self.spin_ns.load(Ordering::Relaxed),
            self.yield_ns.load(Ordering::Relaxed),
        );
        let (spin, yielded) = match phase {
            Phase::Spin => ((2 * waited).clamp(spin, SPIN_MAX_NS), yielded),
            Phase::Yield => (spin / 2, (2 * waited).clamp(yielded, YIELD_MAX_NS)),
            // A short sleep says polling would have caught it; a long one that it would not.
            Phase::Sleep if waited < YIELD_MAX_NS / 2 => (spin / 2, 2 * waited),
            Phase::Sleep => (spin / 2, yielded / 2),
        };
        self.spin_ns.store(spin, Ordering::Relaxed);
        self.yield_ns.store(yielded, Ordering::Relaxed);
    }

    /// This wait's spin: the learnt one, or a probe now and then when it has shrunk away.
    fn spin_for(&self) -> u64 {
        let waits = self.waits.fetch_add(1, Ordering::Relaxed);
        let spin = self.spin_ns.load(Ordering::Relaxed);
        if spin < 100 && waits.is_multiple_of(u64::from(PROBE_EVERY)) {
            PROBE_NS
        } else {
            spin
        }
    }
}

/// The ring's counters, polled, then slept on.
pub struct AdaptiveRing {
    head: AtomicU64,
    tail: AtomicU64,
    shutdown: AtomicBool,
    depth: u64,
    sleepers: AtomicU64,
    lock: PlMutex<()>,
    changed: PlCondvar,
    producer: Phases,
    consumer: Phases,
}

impl AdaptiveRing {
    /// A ring of `depth` free slots.
    pub fn new(depth: u64) -> Self {
        AdaptiveRing {
            head: AtomicU64::new(0),
            tail: AtomicU64::new(0),
            shutdown: AtomicBool::new(false),
            depth,
            sleepers: AtomicU64::new(0),
            lock: PlMutex::default(),
            changed: PlCondvar::default(),
            producer: Phases::new(),
            consumer: Phases::new(),
        }
    }

    fn ring(&self) -> Ring {
        Ring {
            head: self.head.load(Ordering::SeqCst),
            tail: self.tail.load(Ordering::SeqCst),
            shutdown: self.shutdown.load(Ordering::SeqCst),
        }
    }

    /// After a change of the counters: wakes a sleeping waiter, if there is one.
    fn signal(&self) {
        if self.sleepers.load(Ordering::SeqCst) > 0 {
            let _guard = self.lock.lock();
            self.changed.notify_all();
        }
    }

    /// Waits until `ready` accepts the counters: spin, yield, then sleep, as `phases` says.
    fn wait<T>(
        &self,
        phases: &Phases,
        deadline: Instant,
        ready: impl Fn(&Ring) -> Option<T>,
    ) -> Result<T, TimedOut> {
        if let Some(v) = ready(&self.ring()) {
            return Ok(v);
        }
        let start = Instant::now();
        let spin_until = start + Duration::from_nanos(phases.spin_for());
        let yield_until =
            spin_until + Duration::from_nanos(phases.yield_ns.load(Ordering::Relaxed));
        let mut polls: u32 = 0;
        loop {
            if let Some(v) = ready(&self.ring()) {
                phases.learn(Phase::Spin, start.elapsed());
                return Ok(v);
            }
            spin_loop();
            polls = polls.wrapping_add(1);
            // loom does not model time: a few polls per phase let it explore every path.
            if (polls.is_multiple_of(32) && Instant::now() >= spin_until)
                || (cfg!(loom) && polls > 2)
            {
                break;
            }
        }
        let mut yields: u32 = 0;
        while Instant::now() < yield_until.min(deadline) && !(cfg!(loom) && yields > 2) {
            if let Some(v) = ready(&self.ring()) {
                phases.learn(Phase::Yield, start.elapsed());
                return Ok(v);
            }
            yield_now();
            yields += 1;
        }
        let outcome = self.sleep(deadline, &ready);
        phases.learn(Phase::Sleep, start.elapsed());
        outcome
    }

    fn sleep<T>(
        &self,
        deadline: Instant,
        ready: &impl Fn(&Ring) -> Option<T>,
    ) -> Result<T, TimedOut> {
        self.sleepers.fetch_add(1, Ordering::SeqCst);
        let mut guard = self.lock.lock();
        let outcome = loop {
            if let Some(v) = ready(&self.ring()) {
                break Ok(v);
            }
            if self.changed.wait_until(&mut guard, deadline).timed_out() {
                break ready(&self.ring()).ok_or(TimedOut);
            }
        };
        drop(guard);
        self.sleepers.fetch_sub(1, Ordering::SeqCst);
        outcome
    }
}

impl Handoff for AdaptiveRing {
    fn wait_free(&self, deadline: Instant) -> Result<Free, TimedOut> {
        self.wait(&self.producer, deadline, |r| r.free(self.depth))
    }

    fn publish(&self) {
        self.tail.fetch_add(1, Ordering::SeqCst);
        self.signal();
    }

    fn wait_published(&self, frame: u64, deadline: Instant) -> Result<(), TimedOut> {
        self.wait(&self.consumer, deadline, |r| r.filled(frame))
    }

    fn release(&self) {
        self.head.fetch_add(1, Ordering::SeqCst);
        self.signal();
    }

    fn shutdown(&self) {
        self.shutdown.store(true, Ordering::SeqCst);
        self.signal();
    }

    fn published(&self) -> u64 {
        self.tail.load(Ordering::Acquire)
    }
}

#[cfg(all(test, not(loom)))]
mod tests {
    use super::*;

    #[test]
    fn a_phase_that_catches_waits_grows_and_one_they_pass_shrinks() {
        let p = Phases::new();
        p.learn(Phase::Spin, Duration::from_nanos(3_000));
        assert_eq!(p.spin_ns.load(Ordering::Relaxed), 6_000);
        for _ in 0..20 {
            p.learn(Phase::Yield, Duration::from_micros(50));
        }
        assert!(
            p.spin_ns.load(Ordering::Relaxed) < 100,
            "spinning that never works stops"
        );
        assert_eq!(p.yield_ns.load(Ordering::Relaxed), 100_000);
        for _ in 0..20 {
            p.learn(Phase::Sleep, Duration::from_millis(12));
        }
        assert_eq!(
            p.yield_ns.load(Ordering::Relaxed),
            0,
            "long waits stop polling"
        );
        p.learn(Phase::Sleep, Duration::from_micros(30));
        assert_eq!(
            p.yield_ns.load(Ordering::Relaxed),
            60_000,
            "short sleeps bring it back"
        );
        let probes = (0..PROBE_EVERY).filter(|_| p.spin_for() > 0).count();
        assert_eq!(
            probes, 1,
            "a shrunk spin is probed once every {PROBE_EVERY} waits"
        );
    }
}
