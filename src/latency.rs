//! The hand-off round trip of every synchronisation method, next to the raw cache-line
//! ping-pong between the same two pinned threads (the floor any hand-off pays).

use crate::affinity;
use crate::crosscore;
use crate::stats::{self, quantile};
use crate::sync::{Free, Handoff, Policy, SyncMethod};
use serde::{Deserialize, Serialize};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Most time one row of the table may take: `spin` on one core needs a scheduler tick per trip.
const ROW_BUDGET: Duration = Duration::from_secs(2);

/// One measured row: a method on one placement.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LatencyRow {
    /// `ping-pong` for the raw cache line, else the hand-off method's name.
    pub method: String,
    /// Main thread's core.
    pub main_core: usize,
    /// Helper's core (equal to `main_core` on one core).
    pub helper_core: usize,
    /// Median round trip (ns).
    pub median_ns: f64,
    /// 99th percentile round trip (ns).
    pub p99_ns: f64,
    /// Round trips timed (fewer than asked when the row's time budget ran out).
    pub samples: usize,
    /// Whether both pins held.
    pub pinned: bool,
}

impl LatencyRow {
    fn from_samples(method: &str, main: usize, helper: usize, ns: Vec<f64>, pinned: bool) -> Self {
        let ns = stats::sorted(&ns);
        LatencyRow {
            method: method.to_string(),
            main_core: main,
            helper_core: helper,
            median_ns: quantile(&ns, 0.5),
            p99_ns: quantile(&ns, 0.99),
            samples: ns.len(),
            pinned,
        }
    }
}

/// Times `samples` hand-off round trips: the main thread releases the slot, the helper sees
/// it, publishes again, and the main thread sees the publication.
pub fn handoff_round_trip(
    method: SyncMethod,
    main: usize,
    helper: usize,
    samples: usize,
) -> LatencyRow {
    let handoff: Arc<dyn Handoff> = Arc::from(method.handoff(1));
    let timeout = Duration::from_secs(10);
    let echo = {
        let handoff = Arc::clone(&handoff);
        std::thread::spawn(move || {
            let pin = affinity::pin_current(helper);
            loop {
                match handoff.wait_free(Instant::now() + timeout) {
                    Ok(Free::Slot) => handoff.publish(),
                    Ok(Free::Shutdown) | Err(_) => return pin.held,
                }
            }
        })
    };
    let (ns, main_held) = std::thread::scope(|s| {
        s.spawn(|| {
            let pin = affinity::pin_current(main);
            let mut ns = Vec::with_capacity(samples);
            let start = Instant::now();
            let mut ok = handoff.wait_published(0, start + timeout).is_ok();
            // The first trips warm caches and the scheduler; they are not kept.
            let warmup = 16;
            let mut trip: u64 = 0;
            while ok && ns.len() < samples {
                let t0 = Instant::now();
                handoff.release();
                ok = handoff.wait_published(trip + 1, t0 + timeout).is_ok();
                if trip >= warmup {
                    ns.push(t0.elapsed().as_nanos() as f64);
                }
                trip += 1;
                if start.elapsed() > ROW_BUDGET && !ns.is_empty() {
                    break;
                }
            }
            (ns, pin.held)
        })
        .join()
        .unwrap_or_default()
    });
    handoff.shutdown();
    let helper_held = echo.join().unwrap_or(false);
    LatencyRow::from_samples(method.name(), main, helper, ns, main_held && helper_held)
}

/// The raw floor: one cache line bounced between the two cores, each trip timed.
pub fn ping_pong(main: usize, helper: usize, samples: usize) -> LatencyRow {
    let trips = crosscore::round_trip_samples(main, helper, samples);
    LatencyRow::from_samples("ping-pong", main, helper, trips.ns, trips.pinned)
}

/// Every method on one core (`a`,`a`) and across two (`a`,`b`), each placement led by its floor.
pub fn table(a: usize, b: usize, samples: usize) -> Vec<LatencyRow> {
    let mut rows = Vec::new();
    let mut placements = vec![(a, a)];
    if a != b {
        placements.push((a, b));
    }
    for (main, helper) in placements {
        if main != helper {
            rows.push(ping_pong(main, helper, samples));
        }
        for method in SyncMethod::of_policy(Policy::Fifo) {
            rows.push(handoff_round_trip(method, main, helper, samples));
        }
    }
    rows
}

/// The rows as an aligned text table.
pub fn to_text(rows: &[LatencyRow]) -> String {
    let mut out = format!(
        "{:<12} {:>5} {:>6} {:>12} {:>12} {:>8}\n",
        "method", "main", "helper", "median ns", "p99 ns", "samples"
    );
    for r in rows {
        out.push_str(&format!(
            "{:<12} {:>5} {:>6} {:>12.0} {:>12.0} {:>8}{}\n",
            r.method,
            r.main_core,
            r.helper_core,
            r.median_ns,
            r.p99_ns,
            r.samples,
            if r.pinned { "" } else { "  (pin did not hold)" }
        ));
    }
    out
}
