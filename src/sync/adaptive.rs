//! `adaptive`: each wait spins with a pause hint, then yields, then blocks on a futex, and each
//! phase's length follows the waits the side has seen (as parking_lot's `SpinWait` and Linux's
//! adaptive mutexes do). Across two cores a short wait is caught while spinning, at the
//! cache-line floor; on one core spinning cannot succeed (the other side needs the core), so the
//! spin shrinks to nothing and the yield hands the core over; a waiter that always waits long
//! stops polling and sleeps, which costs a wake-up but no CPU. A waiter whose other side is not
//! waiting on it (its last wait was over at once), or whose waits have been learnt to be long,
//! sleeps only until shortly before the change is due and then spins for it: a plain sleep would
//! make the other side pay a futex wake in its own frame.
//!
//! The spin is counted in polls, converted from time with the machine's poll rate measured once
//! per process (`polls`), so a wait the spin catches never reads the clock; the clock is read
//! from the end of the spin on, where a yield or a sleep costs far more than a clock read. Each
//! side's learnt phases, the counters and the sleepers each have a cache line of their own.
//!
//! The counters are `atomic`'s, each written by one side only, so a change is a plain store.
//! Blocking uses parking_lot's mutex and condition variable (futex-backed, with timed waits,
//! which `atomic-wait` lacks; and model-checked here through the loom facade). A waiter
//! registers itself as a sleeper, then fences, then looks at the counters a last time; a
//! signaller stores, fences, then looks for sleepers; the two `fence(SeqCst)` order each side's
//! store before its load, so one of them sees the other's store and a wake-up cannot be lost.
//! The fences are symmetric on purpose: an asymmetric pair (a compiler barrier for the
//! signaller, `membarrier(MEMBARRIER_CMD_PRIVATE_EXPEDITED)` for the sleeper) measured no faster
//! at the floor on a 2-vCPU KVM guest and cost about 17 µs more CPU per sleep (docs/handoffs.md).

use super::polls;
use super::primitives::{fence, AtomicBool, AtomicU64, Ordering, PlCondvar, PlMutex};
use super::{Free, Handoff, Ring, TimedOut};
use crossbeam_utils::CachePadded;
// The learnt phase lengths are hints each side keeps for itself, no part of the protocol, so
// they are std's atomics even under loom (which then has fewer states to explore).
use std::sync::atomic::{AtomicBool as HintBool, AtomicU64 as HintU64, Ordering::Relaxed};
use std::time::{Duration, Instant};

/// Longest spin: a few cross-core round trips, far below a scheduler tick.
const SPIN_MAX_NS: u64 = 20_000;
/// Longest time spent yielding before sleeping.
const YIELD_MAX_NS: u64 = 1_000_000;
/// A spin that has shrunk to nothing is tried again this often, in case the threads moved to
/// two cores.
const PROBE_EVERY: u64 = 64;
/// The spin tried then.
const PROBE_NS: u64 = 2_000;
/// A spin shorter than this has shrunk to nothing.
const SHRUNK_NS: u64 = 100;
/// How long a waiter woken ahead of the other side's change should spin before it comes: enough
/// for a timer's jitter on a VM, little beside a frame.
const AHEAD_NS: u64 = 4_000;
/// Wake-ups ahead that missed in a row (the other side did not come within a spin, as on one
/// core, where it cannot run while the waiter spins) before waking ahead stops until a probe.
const AHEAD_MISSES: u64 = 4;
/// A side whose waits ahead of the change have been learnt to last this long keeps waking ahead
/// though the other side had to wait once (its last wait was not over at once): a long wait is
/// cheaper asleep than yielding, and the learning moves it back if the waits shorten.
const AHEAD_LONG_NS: u64 = 4 * SPIN_MAX_NS;

/// The spin's bounds in polls, from this machine's poll rate.
struct SpinBounds {
    per_us: f64,
    max: u64,
    probe: u64,
    shrunk: u64,
}

impl SpinBounds {
    fn at(per_us: f64) -> SpinBounds {
        SpinBounds {
            per_us,
            max: polls::in_ns(SPIN_MAX_NS, per_us).max(1),
            probe: polls::in_ns(PROBE_NS, per_us).max(1),
            shrunk: polls::in_ns(SHRUNK_NS, per_us).max(1),
        }
    }
}

/// One side's wait phases, adapted after every wait: the spin in polls, the yield in time.
struct Phases {
    spin_polls: HintU64,
    yield_ns: HintU64,
    waits: HintU64,
    /// Whether this side's last wait was over at its first look: it is not waiting for the
    /// other side, which then has time to spare.
    unhurried: HintBool,
    /// When a sleep for a side that is not waiting on this one should end, in ns from the start
    /// of the wait, so that this side is spinning when the change comes; 0 until learnt.
    wake_ns: HintU64,
    /// Wake-ups ahead in a row whose spin the change did not come within.
    wake_misses: HintU64,
}

/// How a sleep that was to end ahead of the other side's change went.
enum Ahead {
    /// The change came first and woke this side: `waited` ns into the wait.
    Late { waited: u64 },
    /// The change came `spun` ns into the spin after the wake-up.
    Caught { spun: u64 },
    /// The change did not come within the spin.
    Missed { spun: u64 },
}

/// How a wait ended.
enum Phase {
    Spin,
    Yield,
    Sleep,
}

impl Phases {
    fn new(bounds: &SpinBounds) -> Phases {
        Phases {
            spin_polls: HintU64::new(bounds.probe),
            yield_ns: HintU64::new(100_000),
            waits: HintU64::new(0),
            unhurried: HintBool::new(false),
            wake_ns: HintU64::new(0),
            wake_misses: HintU64::new(0),
        }
    }

    /// How far into this wait a sleep should end so that the change finds this side spinning:
    /// `None` while waking ahead keeps missing (one core), but for a probe now and then.
    /// `Some(ZERO)` until a first sleep has been learnt from.
    fn wake_after(&self) -> Option<Duration> {
        let misses = self.wake_misses.load(Relaxed);
        let probe = self.waits.load(Relaxed).is_multiple_of(PROBE_EVERY);
        (misses < AHEAD_MISSES || probe).then(|| Duration::from_nanos(self.wake_ns.load(Relaxed)))
    }

    /// Moves the wake-up so that the change comes about [`AHEAD_NS`] into the spin after it:
    /// back by an eighth of the wait when it came first, forward by half the error otherwise.
    fn learn_ahead(&self, outcome: Ahead) {
        // loom does not model time, and a model must not branch on the clock: how long a wait
        // under loom took depends on how busy the machine is, and a wake-up learnt from it would
        // take `AHEAD_LONG_NS`'s branch in some explorations of a schedule and not in others.
        let ns = |v: u64| if cfg!(loom) { 0 } else { v };
        let outcome = match outcome {
            Ahead::Late { waited } => Ahead::Late { waited: ns(waited) },
            Ahead::Caught { spun } => Ahead::Caught { spun: ns(spun) },
            Ahead::Missed { spun } => Ahead::Missed { spun: ns(spun) },
        };
        let wake = self.wake_ns.load(Relaxed);
        let misses = self.wake_misses.load(Relaxed);
        let (wake, misses) = match outcome {
            Ahead::Late { waited } if wake == 0 => (waited * 7 / 8, misses),
            Ahead::Late { waited } => (wake.min(waited) * 7 / 8, misses),
            Ahead::Caught { spun } => ((wake + spun / 2).saturating_sub(AHEAD_NS / 2), 0),
            Ahead::Missed { spun } => (wake + spun, misses + 1),
        };
        self.wake_ns.store(wake, Relaxed);
        self.wake_misses.store(misses, Relaxed);
    }

    /// Grows the phase that caught the wait, shrinks the ones it went past: `spun` polls were
    /// made, and `after` is the time since the spin ended (zero when the spin caught it).
    fn learn(&self, bounds: &SpinBounds, phase: Phase, spun: u64, after: Duration) {
        // As in `learn_ahead`: nothing learnt under loom may come from the clock.
        let after = if cfg!(loom) { Duration::ZERO } else { after };
        let waited = polls::to_ns(spun, bounds.per_us) + after.as_nanos() as u64;
        let (spin, yielded) = (self.spin_polls.load(Relaxed), self.yield_ns.load(Relaxed));
        // A spin that caught a wait keeps at least a probe's length, and one that missed loses a
        // quarter: a few waits stretched by a preemption (a busy machine) do not undo it, while
        // on one core, where it never catches, it is gone within a dozen waits.
        let missed = spin * 3 / 4;
        let (spin, yielded) = match phase {
            Phase::Spin => (
                (2 * spun).max(spin).max(bounds.probe).min(bounds.max),
                yielded,
            ),
            Phase::Yield => (missed, (2 * waited).clamp(yielded, YIELD_MAX_NS)),
            // A short sleep says polling would have caught it; a long one that it would not.
            Phase::Sleep if waited < YIELD_MAX_NS / 2 => (missed, 2 * waited),
            Phase::Sleep => (missed, yielded / 2),
        };
        self.spin_polls.store(spin, Relaxed);
        self.yield_ns.store(yielded, Relaxed);
    }

    /// This wait's spin in polls: the learnt one, or a probe now and then when it has shrunk
    /// away.
    fn spin_for(&self, bounds: &SpinBounds) -> u64 {
        // Only this side waits on its phases: a load and a store, no read-modify-write.
        let waits = self.waits.load(Relaxed);
        self.waits.store(waits.wrapping_add(1), Relaxed);
        let spin = self.spin_polls.load(Relaxed);
        if spin < bounds.shrunk && waits.is_multiple_of(PROBE_EVERY) {
            bounds.probe
        } else {
            spin
        }
    }
}

/// The ring's counters and stop flag, on one cache line as `atomic`'s are: each is written by
/// one side and polled by the other.
struct Counters {
    head: AtomicU64,
    tail: AtomicU64,
    shutdown: AtomicBool,
}

/// What a sleeping waiter blocks on, and how many do: read by every change of the counters,
/// written only when a waiter goes to sleep, so it stays cached on both sides.
struct Sleepers {
    count: AtomicU64,
    lock: PlMutex<()>,
    changed: PlCondvar,
}

/// The ring's counters, polled, then slept on. The counters, the sleepers and each side's
/// phases sit on cache lines of their own, so that learning after a wait does not disturb the
/// line the other side polls.
pub struct AdaptiveRing {
    counters: CachePadded<Counters>,
    sleepers: CachePadded<Sleepers>,
    producer: CachePadded<Phases>,
    consumer: CachePadded<Phases>,
    bounds: SpinBounds,
    depth: u64,
}

impl AdaptiveRing {
    /// A ring of `depth` free slots (the first in the process also measures the poll rate).
    pub fn new(depth: u64) -> Self {
        let bounds = SpinBounds::at(polls::per_us());
        AdaptiveRing {
            counters: CachePadded::new(Counters {
                head: AtomicU64::new(0),
                tail: AtomicU64::new(0),
                shutdown: AtomicBool::new(false),
            }),
            sleepers: CachePadded::new(Sleepers {
                count: AtomicU64::new(0),
                lock: PlMutex::default(),
                changed: PlCondvar::default(),
            }),
            producer: CachePadded::new(Phases::new(&bounds)),
            consumer: CachePadded::new(Phases::new(&bounds)),
            bounds,
            depth,
        }
    }

    fn ring(&self) -> Ring {
        Ring {
            head: self.counters.head.load(Ordering::Acquire),
            tail: self.counters.tail.load(Ordering::Acquire),
            shutdown: self.counters.shutdown.load(Ordering::Acquire),
        }
    }

    /// Adds one to `counter`, which only the calling side writes: a plain store, no
    /// read-modify-write. Then wakes a sleeping waiter, if there is one.
    fn bump(&self, counter: &AtomicU64) {
        counter.store(counter.load(Ordering::Relaxed) + 1, Ordering::Release);
        self.signal();
    }

    /// After a change of the counters: wakes a sleeping waiter, if there is one.
    fn signal(&self) {
        // Pairs with the sleeper's fence: either it sees the change or we see it.
        fence(Ordering::SeqCst);
        if self.sleepers.count.load(Ordering::Relaxed) > 0 {
            let _guard = self.sleepers.lock.lock();
            self.sleepers.changed.notify_all();
        }
    }

    /// Waits until `ready` accepts the counters: spin, yield, then sleep, as `phases` says.
    /// `other` is the other side's phases, read for whether it is waiting on this side.
    fn wait<T>(
        &self,
        (phases, other): (&Phases, &Phases),
        deadline: Instant,
        ready: impl Fn(&Ring) -> Option<T>,
    ) -> Result<T, TimedOut> {
        let at_once = ready(&self.ring());
        // Written only when it changes, so the line the other side reads stays shared.
        if phases.unhurried.load(Relaxed) != at_once.is_some() {
            phases.unhurried.store(at_once.is_some(), Relaxed);
        }
        if let Some(v) = at_once {
            return Ok(v);
        }
        let spin = phases.spin_for(&self.bounds);
        // loom does not model time: a few polls per phase let it explore every path.
        let spin = if cfg!(loom) { spin.min(3) } else { spin };
        for polls in 1..=spin {
            relax(std::hint::spin_loop);
            if let Some(v) = ready(&self.ring()) {
                phases.learn(&self.bounds, Phase::Spin, polls, Duration::ZERO);
                return Ok(v);
            }
        }
        // The clock is read from here on only: a wait the spin caught never reads it.
        let spun = Instant::now();
        // Past the spin, polling only burns the core when the other side is not waiting on
        // this one (the helper ahead of a busy main thread): the wait sleeps, without a yield
        // phase, but wakes ahead of the change, so that the other side, which would otherwise
        // pay the wake-up in its frame, finds it spinning.
        if other.unhurried.load(Relaxed) || phases.wake_ns.load(Relaxed) >= AHEAD_LONG_NS {
            let started = spun - Duration::from_nanos(polls::to_ns(spin, self.bounds.per_us));
            let outcome = self.sleep_ahead(phases, started, deadline, &ready);
            phases.learn(&self.bounds, Phase::Sleep, spin, spun.elapsed());
            return outcome;
        }
        let yield_ns = phases.yield_ns.load(Relaxed);
        let yield_until = (spun + Duration::from_nanos(yield_ns)).min(deadline);
        let (mut now, mut yields) = (spun, 0u32);
        // Under loom the phase is three looks whatever the clock says: a model must not depend on
        // time.
        while if cfg!(loom) {
            yields < 3
        } else {
            now < yield_until
        } {
            relax(std::thread::yield_now);
            yields += 1;
            if let Some(v) = ready(&self.ring()) {
                // The clock before the yield: a lower bound, which is all growing needs.
                phases.learn(&self.bounds, Phase::Yield, spin, now - spun);
                return Ok(v);
            }
            now = Instant::now();
        }
        let outcome = self.sleep(deadline, &ready);
        phases.learn(&self.bounds, Phase::Sleep, spin, spun.elapsed());
        outcome
    }

    /// Sleeps until shortly before the change is due, as `phases` learnt it from the waits
    /// since `started`, then spins for it; sleeps on if it has not come within the spin.
    fn sleep_ahead<T>(
        &self,
        phases: &Phases,
        started: Instant,
        deadline: Instant,
        ready: &impl Fn(&Ring) -> Option<T>,
    ) -> Result<T, TimedOut> {
        let Some(after) = phases.wake_after() else {
            return self.sleep(deadline, ready);
        };
        // The first such wait sleeps through and is learnt from (under loom, which has no time,
        // every one wakes ahead, so that the model explores the path).
        if after.is_zero() && !cfg!(loom) {
            let v = self.sleep(deadline, ready)?;
            let waited = started.elapsed().as_nanos() as u64;
            phases.learn_ahead(Ahead::Late { waited });
            return Ok(v);
        }
        precise_timers();
        let wake = (started + after).min(deadline);
        if let Some(v) = self.sleep_until(wake, deadline, ready)? {
            let waited = started.elapsed().as_nanos() as u64;
            phases.learn_ahead(Ahead::Late { waited });
            return Ok(v);
        }
        // Timed out ahead of the change: not counted as a sleeper any more, so the change is a
        // plain store on the other side.
        let spin = if cfg!(loom) { 3 } else { self.bounds.max };
        let woke = Instant::now();
        for _ in 0..spin {
            relax(std::hint::spin_loop);
            if let Some(v) = ready(&self.ring()) {
                let spun = woke.elapsed().as_nanos() as u64;
                phases.learn_ahead(Ahead::Caught { spun });
                return Ok(v);
            }
        }
        let spun = woke.elapsed().as_nanos() as u64;
        phases.learn_ahead(Ahead::Missed { spun });
        self.sleep(deadline, ready)
    }

    fn sleep<T>(
        &self,
        deadline: Instant,
        ready: &impl Fn(&Ring) -> Option<T>,
    ) -> Result<T, TimedOut> {
        loop {
            if let Some(v) = self.sleep_until(deadline, deadline, ready)? {
                return Ok(v);
            }
        }
    }

    /// Sleeps until `ready` accepts the counters, or until `wake` (then `None`), or until
    /// `deadline` (then [`TimedOut`]). `wake` is no later than `deadline`; under loom, which does
    /// not model time, a `wake` before the deadline ends the sleep after its first look.
    fn sleep_until<T>(
        &self,
        wake: Instant,
        deadline: Instant,
        ready: &impl Fn(&Ring) -> Option<T>,
    ) -> Result<Option<T>, TimedOut> {
        let sleepers = &self.sleepers;
        sleepers.count.fetch_add(1, Ordering::Relaxed);
        // Pairs with the signaller's fence: either it sees us or we see its change.
        fence(Ordering::SeqCst);
        let mut guard = sleepers.lock.lock();
        let outcome = loop {
            if let Some(v) = ready(&self.ring()) {
                break Ok(Some(v));
            }
            if cfg!(loom) && wake < deadline {
                break Ok(None);
            }
            if sleepers.changed.wait_until(&mut guard, wake).timed_out() {
                break match ready(&self.ring()) {
                    Some(v) => Ok(Some(v)),
                    None if wake < deadline => Ok(None),
                    None => Err(TimedOut),
                };
            }
        };
        drop(guard);
        sleepers.count.fetch_sub(1, Ordering::Relaxed);
        outcome
    }
}

/// Makes the calling thread's timed sleeps end when asked, once per thread: Linux lets a
/// normal thread's timers fire up to 50 µs late (its timer slack), most of a wake-up ahead.
fn precise_timers() {
    thread_local!(static PRECISE: std::cell::Cell<bool> = const { std::cell::Cell::new(false) });
    if !cfg!(loom) && !PRECISE.get() {
        PRECISE.set(true);
        // SAFETY: PR_SET_TIMERSLACK takes a value and touches only the calling thread's
        // scheduling attributes; 1 ns is the smallest slack (0 would restore the default).
        unsafe { libc::prctl(libc::PR_SET_TIMERSLACK, 1 as libc::c_ulong) };
    }
}

/// Pauses between two looks, outside loom. A pause or yield under loom hands its scheduler to
/// the other side until that side moves, so a waiter would never reach its sleep while the
/// other side has yet to change the counters, the very race the sleep protocol must survive;
/// there the phases are a few extra looks, which loom interleaves freely.
fn relax(pause: fn()) {
    if !cfg!(loom) {
        pause();
    }
}

impl Handoff for AdaptiveRing {
    fn wait_free(&self, deadline: Instant) -> Result<Free, TimedOut> {
        self.wait((&self.producer, &self.consumer), deadline, |r| {
            r.free(self.depth)
        })
    }

    fn publish(&self) {
        self.bump(&self.counters.tail);
    }

    fn wait_published(&self, frame: u64, deadline: Instant) -> Result<(), TimedOut> {
        self.wait((&self.consumer, &self.producer), deadline, |r| {
            r.filled(frame)
        })
    }

    fn release(&self) {
        self.bump(&self.counters.head);
    }

    fn shutdown(&self) {
        self.counters.shutdown.store(true, Ordering::Release);
        self.signal();
    }

    fn published(&self) -> u64 {
        self.counters.tail.load(Ordering::Acquire)
    }
}

#[cfg(all(test, not(loom)))]
mod tests {
    use super::*;

    #[test]
    fn a_phase_that_catches_waits_grows_and_one_they_pass_shrinks() {
        // 100 polls per µs: a spin of at most 2 000 polls, probes of 200, shrunk below 10.
        let bounds = SpinBounds::at(100.0);
        let p = Phases::new(&bounds);
        let spin = || p.spin_polls.load(Relaxed);
        let yielded = || p.yield_ns.load(Relaxed);
        p.learn(&bounds, Phase::Spin, 30, Duration::ZERO);
        assert_eq!(
            spin(),
            200,
            "a spin that caught a wait keeps a probe's length"
        );
        p.learn(&bounds, Phase::Spin, 300, Duration::ZERO);
        assert_eq!(spin(), 600, "a spin that caught the wait doubles past it");
        p.learn(&bounds, Phase::Spin, 5_000, Duration::ZERO);
        assert_eq!(spin(), 2_000, "up to {SPIN_MAX_NS} ns of polls");
        p.learn(&bounds, Phase::Yield, spin(), Duration::from_micros(50));
        assert_eq!(spin(), 1_500, "a spin that missed loses a quarter");
        for _ in 0..20 {
            p.learn(&bounds, Phase::Yield, spin(), Duration::from_micros(50));
        }
        assert!(spin() < bounds.shrunk, "spinning that never works stops");
        // The longest wait the yield caught: 20 µs of spin (2 000 polls) and 50 µs of yield.
        assert_eq!(
            yielded(),
            2 * 70_000,
            "a yield that caught waits grows to twice them"
        );
        for _ in 0..20 {
            p.learn(&bounds, Phase::Sleep, spin(), Duration::from_millis(12));
        }
        assert_eq!(yielded(), 0, "long waits stop polling");
        p.learn(&bounds, Phase::Sleep, 0, Duration::from_micros(30));
        assert_eq!(yielded(), 60_000, "short sleeps bring it back");
        let probes: Vec<u64> = (0..PROBE_EVERY)
            .map(|_| p.spin_for(&bounds))
            .filter(|&polls| polls > 0)
            .collect();
        assert_eq!(
            probes,
            [bounds.probe],
            "a shrunk spin is probed once every {PROBE_EVERY} waits"
        );
    }

    #[test]
    fn a_wake_up_ahead_moves_until_the_change_comes_a_short_spin_after_it() {
        let bounds = SpinBounds::at(100.0);
        let p = Phases::new(&bounds);
        let wake = || p.wake_ns.load(Relaxed);
        assert_eq!(
            p.wake_after(),
            Some(Duration::ZERO),
            "not learnt: sleep through"
        );
        p.learn_ahead(Ahead::Late { waited: 160_000 });
        assert_eq!(
            wake(),
            140_000,
            "the first sleep sets it an eighth short of the wait"
        );
        p.learn_ahead(Ahead::Caught { spun: 24_000 });
        assert_eq!(
            wake(),
            140_000 + 12_000 - AHEAD_NS / 2,
            "a change long after the wake-up moves it half the error later"
        );
        let before = wake();
        p.learn_ahead(Ahead::Caught { spun: AHEAD_NS });
        assert_eq!(
            wake(),
            before,
            "a change {AHEAD_NS} ns after the wake-up keeps it"
        );
        p.learn_ahead(Ahead::Caught { spun: 0 });
        assert_eq!(
            wake(),
            before - AHEAD_NS / 2,
            "one at once moves it earlier"
        );
        p.learn_ahead(Ahead::Late { waited: 200_000 });
        assert_eq!(
            wake(),
            (before - AHEAD_NS / 2) * 7 / 8,
            "a change before the wake-up moves it an eighth earlier"
        );
        p.learn_ahead(Ahead::Late { waited: 80_000 });
        assert_eq!(wake(), 70_000, "or to an eighth short of a shorter wait");
        for miss in 1..=AHEAD_MISSES {
            // Not a probe's turn: a wait counted.
            p.spin_for(&bounds);
            assert!(
                p.wake_after().is_some(),
                "still waking ahead after {} misses",
                miss - 1
            );
            p.learn_ahead(Ahead::Missed { spun: 20_000 });
        }
        assert_eq!(wake(), 70_000 + AHEAD_MISSES * 20_000);
        let ahead: Vec<bool> = (0..PROBE_EVERY)
            .map(|_| {
                p.spin_for(&bounds);
                p.wake_after().is_some()
            })
            .collect();
        assert_eq!(
            ahead.iter().filter(|&&a| a).count(),
            1,
            "after {AHEAD_MISSES} misses in a row only a probe every {PROBE_EVERY} waits wakes ahead"
        );
        p.learn_ahead(Ahead::Caught { spun: AHEAD_NS });
        p.spin_for(&bounds);
        assert!(
            p.wake_after().is_some(),
            "a probe that caught the change resumes it"
        );
    }
}
