//! The cache-line ping-pong between two pinned threads: the floor under any hand-off, and the
//! tell-tale of where a VM's two vCPUs sit right now (near or far from each other).

use crate::affinity;
use crate::stats::{self, quantile};
use serde::{Deserialize, Serialize};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;
use std::time::Instant;

/// Round trips per timed batch: large enough that reading the clock costs nothing.
pub const BATCH: u64 = 200;

/// Slowest ÷ fastest median round trip that still counts as the same placement: further apart,
/// the two cores moved between near and far.
pub const PLACEMENT_CHANGE_RATIO: f64 = 2.0;

#[repr(align(128))]
struct Line(AtomicU64);

/// Round-trip time of one cache line bouncing between two cores.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RoundTrip {
    /// The two cores.
    pub cores: [usize; 2],
    /// Median round trip (ns) over the batches.
    pub median_ns: f64,
    /// 99th percentile round trip (ns) over the batches.
    pub p99_ns: f64,
    /// Fastest batch's round trip (ns).
    pub min_ns: f64,
    /// Number of timed batches.
    pub batches: usize,
    /// Whether both pins held.
    pub pinned: bool,
}

/// Bounces a cache line `total` times between a thread pinned to `a` (which starts each trip)
/// and one pinned to `b`; `after_trip(i)` runs on `a`'s thread after trip `i` completes.
/// Returns whether both pins held.
fn bounce(a: usize, b: usize, total: u64, mut after_trip: impl FnMut(u64) + Send) -> bool {
    let line = Arc::new(Line(AtomicU64::new(0)));
    let echo = {
        let line = Arc::clone(&line);
        std::thread::spawn(move || {
            let pin = affinity::pin_current(b);
            for i in 0..total {
                while line.0.load(Ordering::Acquire) != 2 * i + 1 {
                    std::hint::spin_loop();
                }
                line.0.store(2 * i + 2, Ordering::Release);
            }
            pin.held
        })
    };
    let held = std::thread::scope(|s| {
        s.spawn(|| {
            let pin = affinity::pin_current(a);
            for i in 0..total {
                line.0.store(2 * i + 1, Ordering::Release);
                while line.0.load(Ordering::Acquire) != 2 * i + 2 {
                    std::hint::spin_loop();
                }
                after_trip(i);
            }
            pin.held
        })
        .join()
        .unwrap_or(false)
    });
    held && echo.join().unwrap_or(false)
}

/// Measures `batches` batches of round trips between threads pinned to `a` and `b`.
pub fn round_trip(a: usize, b: usize, batches: usize) -> RoundTrip {
    let batches = batches.max(1);
    let total = (batches as u64 + 1) * BATCH;
    let mut per_trip = Vec::with_capacity(batches);
    let mut start = Instant::now();
    let pinned = bounce(a, b, total, |i| {
        if (i + 1).is_multiple_of(BATCH) {
            // The first batch is a warm-up and is not kept.
            if i + 1 > BATCH {
                per_trip.push(start.elapsed().as_nanos() as f64 / BATCH as f64);
            }
            start = Instant::now();
        }
    });
    let per_trip = stats::sorted(&per_trip);
    RoundTrip {
        cores: [a, b],
        median_ns: quantile(&per_trip, 0.5),
        p99_ns: quantile(&per_trip, 0.99),
        min_ns: quantile(&per_trip, 0.0),
        batches: per_trip.len(),
        pinned,
    }
}

/// Round trips timed one by one, for percentiles.
#[derive(Clone, Debug, PartialEq)]
pub struct TripSamples {
    /// Nanoseconds of each round trip after the warm-up.
    pub ns: Vec<f64>,
    /// Whether both pins held.
    pub pinned: bool,
}

/// Times `samples` single round trips between threads pinned to `a` and `b` (reading the clock
/// adds a few tens of nanoseconds to each, as it does to every hand-off timed the same way).
pub fn round_trip_samples(a: usize, b: usize, samples: usize) -> TripSamples {
    let warmup = 1000u64;
    let mut ns = Vec::with_capacity(samples);
    let mut last = Instant::now();
    let pinned = bounce(a, b, samples as u64 + warmup, |i| {
        let now = Instant::now();
        if i >= warmup {
            ns.push((now - last).as_nanos() as f64);
        }
        last = now;
    });
    TripSamples { ns, pinned }
}
