//! The hand-off round trip of every synchronisation method, next to the raw cache-line
//! ping-pong between the same two pinned threads (the floor any hand-off pays).

use crate::affinity;
use crate::crosscore;
use crate::sched;
use crate::stats::{self, quantile};
use crate::sync::{Free, Handoff, MailboxOut, Policy, SyncMethod};
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
    /// CPU time both threads spent per round trip (ns; each thread's CPU clock over its trips):
    /// a method that waits by polling shows about the wall time per thread, one that sleeps
    /// far less. Absent for the ping-pong and where the thread CPU clock is unavailable.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cpu_ns: Option<f64>,
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
            cpu_ns: None,
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
            let (cpu0, mut trips) = (sched::thread_cpu_ns(), 0u64);
            while let Ok(Free::Slot) = handoff.wait_free(Instant::now() + timeout) {
                handoff.publish();
                trips += 1;
            }
            let cpu = cpu0.zip(sched::thread_cpu_ns()).map(|(a, b)| b - a);
            (pin.held, cpu.map(|ns| ns as f64 / trips.max(1) as f64))
        })
    };
    let (ns, main_cpu, main_held) = std::thread::scope(|s| {
        s.spawn(|| {
            let pin = affinity::pin_current(main);
            let mut ns = Vec::with_capacity(samples);
            let start = Instant::now();
            let mut ok = handoff.wait_published(0, start + timeout).is_ok();
            // The first trips warm caches and the scheduler; they are not kept.
            let warmup = 16;
            let mut trip: u64 = 0;
            let mut cpu0 = None;
            while ok && ns.len() < samples {
                if trip == warmup {
                    cpu0 = sched::thread_cpu_ns();
                }
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
            let cpu = cpu0.zip(sched::thread_cpu_ns()).map(|(a, b)| b - a);
            let per_trip = cpu.map(|c| c as f64 / ns.len().max(1) as f64);
            (ns, per_trip, pin.held)
        })
        .join()
        .unwrap_or_default()
    });
    handoff.shutdown();
    let (helper_held, helper_cpu) = echo.join().unwrap_or((false, None));
    LatencyRow {
        cpu_ns: main_cpu.zip(helper_cpu).map(|(m, h)| m + h),
        ..LatencyRow::from_samples(method.name(), main, helper, ns, main_held && helper_held)
    }
}

/// Times `samples` round trips through two `latest` mailboxes of `method`, one each way: the
/// main thread publishes a number, the helper takes it and publishes it back, both polling
/// with a yield. What a mailbox adds to a mesh's age when the reader looks right away.
pub fn mailbox_round_trip(
    method: SyncMethod,
    main: usize,
    helper: usize,
    samples: usize,
) -> Option<LatencyRow> {
    let (mut to_helper, mut from_main) = method.mailbox(&0u64)?;
    let (mut to_main, mut from_helper) = method.mailbox(&0u64)?;
    let timeout = Duration::from_secs(10);
    let take = |out: &mut dyn MailboxOut<u64>, want: u64, deadline: Instant| loop {
        if out.update() && *out.buffer() >= want {
            return *out.buffer();
        }
        if Instant::now() >= deadline {
            return u64::MAX;
        }
        std::thread::yield_now();
    };
    let echo = std::thread::spawn(move || {
        let pin = affinity::pin_current(helper);
        let (cpu0, mut trips) = (sched::thread_cpu_ns(), 0u64);
        loop {
            let v = take(&mut *from_main, 1, Instant::now() + timeout);
            if v == u64::MAX {
                break;
            }
            *to_main.buffer() = v;
            to_main.publish();
            trips += 1;
        }
        let cpu = cpu0.zip(sched::thread_cpu_ns()).map(|(a, b)| b - a);
        (pin.held, cpu.map(|ns| ns as f64 / trips.max(1) as f64))
    });
    let (ns, main_cpu, main_held) = std::thread::scope(|s| {
        s.spawn(|| {
            let pin = affinity::pin_current(main);
            let warmup = 16;
            let mut ns = Vec::with_capacity(samples);
            let mut cpu0 = None;
            let start = Instant::now();
            for trip in 1.. {
                if trip == warmup + 1 {
                    cpu0 = sched::thread_cpu_ns();
                }
                let t0 = Instant::now();
                *to_helper.buffer() = trip;
                to_helper.publish();
                if take(&mut *from_helper, trip, t0 + timeout) != trip {
                    break;
                }
                if trip > warmup {
                    ns.push(t0.elapsed().as_nanos() as f64);
                }
                if ns.len() >= samples || (start.elapsed() > ROW_BUDGET && !ns.is_empty()) {
                    break;
                }
            }
            let cpu = cpu0
                .zip(sched::thread_cpu_ns())
                .map(|(a, b)| (b - a) as f64 / ns.len().max(1) as f64);
            *to_helper.buffer() = u64::MAX;
            to_helper.publish();
            (ns, cpu, pin.held)
        })
        .join()
        .unwrap_or_default()
    });
    let (helper_held, helper_cpu) = echo.join().unwrap_or((false, None));
    let name = format!("{} latest", method.name());
    Some(LatencyRow {
        cpu_ns: main_cpu.zip(helper_cpu).map(|(m, h)| m + h),
        ..LatencyRow::from_samples(&name, main, helper, ns, main_held && helper_held)
    })
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
        for method in SyncMethod::of_policy(Policy::Latest) {
            rows.extend(mailbox_round_trip(method, main, helper, samples));
        }
    }
    rows
}

/// The rows as an aligned text table.
pub fn to_text(rows: &[LatencyRow]) -> String {
    let mut out = format!(
        "{:<20} {:>5} {:>6} {:>12} {:>12} {:>12} {:>8}\n",
        "method", "main", "helper", "median ns", "p99 ns", "CPU ns", "samples"
    );
    for r in rows {
        let cpu = r.cpu_ns.map_or("–".to_string(), |c| format!("{c:.0}"));
        out.push_str(&format!(
            "{:<20} {:>5} {:>6} {:>12.0} {:>12.0} {:>12} {:>8}{}\n",
            r.method,
            r.main_core,
            r.helper_core,
            r.median_ns,
            r.p99_ns,
            cpu,
            r.samples,
            if r.pinned { "" } else { "  (pin did not hold)" }
        ));
    }
    out
}
