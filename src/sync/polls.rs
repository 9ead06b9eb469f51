//! How many polls of a hand-off's counters fit in a microsecond on this machine, so that a
//! spin can be bounded by a count instead of by clock reads. A poll is a load and a spin-loop
//! hint, whose cost differs tenfold between processors (`pause` is about 10 cycles before
//! Skylake, about 140 since), which is why it is measured rather than assumed.
//!
//! Measured once per process, on the thread that builds the first hand-off that asks: five
//! rounds of [`POLLS`] polls, the fastest kept (a round the scheduler interrupted reads slow).
//! That costs 5 × [`POLLS`] polls, about 0.3 ms where a poll takes 50 ns, once per run.

use std::hint::{black_box, spin_loop};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::OnceLock;
use std::time::{Duration, Instant};

/// Polls per round of the measurement.
const POLLS: u32 = 1_000;
/// Rounds of the measurement; the fastest is kept.
const ROUNDS: usize = 5;

/// Polls per microsecond on this machine, measured on the first call.
pub fn per_us() -> f64 {
    static PER_US: OnceLock<f64> = OnceLock::new();
    *PER_US.get_or_init(measure)
}

/// Polls that take about `ns` nanoseconds at `per_us` polls per microsecond.
pub fn in_ns(ns: u64, per_us: f64) -> u64 {
    (ns as f64 * per_us / 1_000.0) as u64
}

/// Nanoseconds that `polls` polls take at `per_us` polls per microsecond.
pub fn to_ns(polls: u64, per_us: f64) -> u64 {
    (polls as f64 * 1_000.0 / per_us) as u64
}

fn measure() -> f64 {
    // Not the loom facade's atomics: this is timing, not protocol, and runs outside any model.
    let word = AtomicU64::new(0);
    let fastest = (0..ROUNDS)
        .map(|_| {
            let start = Instant::now();
            for _ in 0..POLLS {
                black_box(word.load(Ordering::Acquire));
                spin_loop();
            }
            start.elapsed()
        })
        .min()
        .unwrap_or_default()
        .max(Duration::from_nanos(1));
    f64::from(POLLS) / (fastest.as_nanos() as f64 / 1_000.0)
}

#[cfg(all(test, not(loom)))]
mod tests {
    use super::*;

    #[test]
    fn the_rate_is_measured_once_and_converts_both_ways() {
        let rate = per_us();
        assert!(rate.is_finite() && rate > 0.0, "{rate}");
        assert_eq!(per_us(), rate, "measured once per process");
        assert_eq!(in_ns(1_000, 40.0), 40);
        assert_eq!(to_ns(40, 40.0), 1_000);
    }
}
