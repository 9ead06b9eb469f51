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

pub use crate::results::latency::{LatencyRow, MethodRepeats, BATCH};

impl LatencyRow {
    fn from_samples(method: &str, main: usize, helper: usize, ns: Vec<f64>, pinned: bool) -> Self {
        let ns = stats::sorted(&ns);
        LatencyRow {
            method: method.to_string(),
            main_core: main,
            helper_core: helper,
            batched_ns: None,
            median_ns: quantile(&ns, 0.5),
            p99_ns: quantile(&ns, 0.99),
            samples: ns.len(),
            cpu_ns: None,
            pinned,
        }
    }
}

/// The far side of a row: a thread pinned to `core` that runs `trip` until it returns `false`,
/// then reports whether its pin held and its CPU time per trip.
fn echo(
    core: usize,
    mut trip: impl FnMut() -> bool + Send + 'static,
) -> std::thread::JoinHandle<(bool, Option<f64>)> {
    std::thread::spawn(move || {
        let pin = affinity::pin_current(core);
        let (cpu0, mut trips) = (sched::thread_cpu_ns(), 0u64);
        while trip() {
            trips += 1;
        }
        let cpu = cpu0.zip(sched::thread_cpu_ns()).map(|(a, b)| b - a);
        (pin.held, cpu.map(|ns| ns as f64 / trips.max(1) as f64))
    })
}

/// One side's timing of a row's round trips.
#[derive(Default)]
struct Timed {
    /// Each trip timed on its own (ns).
    per_trip: Vec<f64>,
    /// Each batch's time ÷ its trips (ns).
    batched: Vec<f64>,
    /// The thread's CPU time per trip over both phases (ns).
    cpu_ns: Option<f64>,
}

impl Timed {
    /// The row, with the other side's CPU time per trip added to this side's.
    fn row(
        self,
        name: &str,
        cores: (usize, usize),
        other_cpu: Option<f64>,
        pinned: bool,
    ) -> LatencyRow {
        let batched = stats::sorted(&self.batched);
        LatencyRow {
            batched_ns: (!batched.is_empty()).then(|| quantile(&batched, 0.5)),
            cpu_ns: self.cpu_ns.zip(other_cpu).map(|(a, b)| a + b),
            ..LatencyRow::from_samples(name, cores.0, cores.1, self.per_trip, pinned)
        }
    }
}

/// Runs `trip(i, deadline)` (round trip i, from 1; `false` when it failed) for a warm-up, then
/// `samples` trips timed one by one (for the quantiles), then about as many in batches of
/// [`BATCH`] with one clock read per batch (for the median); each phase within half the row's
/// budget.
fn time_trips(samples: usize, mut trip: impl FnMut(u64, Instant) -> bool) -> Timed {
    let timeout = Duration::from_secs(10);
    let mut t = Timed::default();
    let mut i = 0u64;
    let mut next = |deadline: Instant| {
        i += 1;
        trip(i, deadline)
    };
    // The first trips warm caches and the scheduler; they are not kept.
    for _ in 0..16 {
        if !next(Instant::now() + timeout) {
            return t;
        }
    }
    let cpu0 = sched::thread_cpu_ns();
    let mut trips = 0u64;
    let start = Instant::now();
    while t.per_trip.len() < samples {
        let t0 = Instant::now();
        if !next(t0 + timeout) {
            return t;
        }
        t.per_trip.push(t0.elapsed().as_nanos() as f64);
        trips += 1;
        if start.elapsed() > ROW_BUDGET / 2 {
            break;
        }
    }
    let start = Instant::now();
    let batches = (samples as u64).div_ceil(BATCH).max(1);
    for _ in 0..batches {
        let t0 = Instant::now();
        for _ in 0..BATCH {
            if !next(t0 + timeout) {
                return t;
            }
        }
        t.batched
            .push(t0.elapsed().as_nanos() as f64 / BATCH as f64);
        trips += BATCH;
        if start.elapsed() > ROW_BUDGET / 2 {
            break;
        }
    }
    t.cpu_ns = cpu0
        .zip(sched::thread_cpu_ns())
        .map(|(a, b)| (b - a) as f64 / trips.max(1) as f64);
    t
}

/// What one clock read costs on this machine (ns): `Instant::now()` called in a tight loop.
pub fn clock_read_ns() -> f64 {
    let reads = 200_000u32;
    let start = Instant::now();
    let mut last = start;
    for _ in 0..reads {
        last = std::hint::black_box(Instant::now());
    }
    (last - start).as_nanos() as f64 / f64::from(reads)
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
    let far = {
        let handoff = Arc::clone(&handoff);
        echo(helper, move || {
            let free = handoff.wait_free(Instant::now() + timeout);
            let go = free == Ok(Free::Slot);
            if go {
                handoff.publish();
            }
            go
        })
    };
    let (timed, main_held) = std::thread::scope(|s| {
        s.spawn(|| {
            let pin = affinity::pin_current(main);
            let mut timed = Timed::default();
            if handoff.wait_published(0, Instant::now() + timeout).is_ok() {
                timed = time_trips(samples, |i, deadline| {
                    handoff.release();
                    handoff.wait_published(i, deadline).is_ok()
                });
            }
            (timed, pin.held)
        })
        .join()
        .unwrap_or_default()
    });
    handoff.shutdown();
    let (helper_held, helper_cpu) = far.join().unwrap_or((false, None));
    timed.row(
        method.name(),
        (main, helper),
        helper_cpu,
        main_held && helper_held,
    )
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
    let far = echo(helper, move || {
        let v = take(&mut *from_main, 1, Instant::now() + timeout);
        if v != u64::MAX {
            *to_main.buffer() = v;
            to_main.publish();
        }
        v != u64::MAX
    });
    let (timed, main_held) = std::thread::scope(|s| {
        s.spawn(|| {
            let pin = affinity::pin_current(main);
            let timed = time_trips(samples, |i, deadline| {
                *to_helper.buffer() = i;
                to_helper.publish();
                take(&mut *from_helper, i, deadline) == i
            });
            *to_helper.buffer() = u64::MAX;
            to_helper.publish();
            (timed, pin.held)
        })
        .join()
        .unwrap_or_default()
    });
    let (helper_held, helper_cpu) = far.join().unwrap_or((false, None));
    let name = format!("{} latest", method.name());
    Some(timed.row(&name, (main, helper), helper_cpu, main_held && helper_held))
}

/// The raw floor: one cache line bounced between the two cores, in batches (the median) and
/// each trip timed (the quantiles).
pub fn ping_pong(main: usize, helper: usize, samples: usize) -> LatencyRow {
    let trips = crosscore::round_trip_samples(main, helper, samples);
    let batched = crosscore::round_trip(main, helper, (samples / 200).max(10));
    LatencyRow {
        batched_ns: Some(batched.median_ns),
        ..LatencyRow::from_samples(
            "ping-pong",
            main,
            helper,
            trips.ns,
            trips.pinned && batched.pinned,
        )
    }
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

/// The whole table `repeats` times over, one repeat's rows after another so that a drift of the
/// machine spreads over every method rather than landing on one; the run's times and machine
/// are filled in by the caller.
pub fn repeated(a: usize, b: usize, samples: usize, repeats: usize) -> Vec<MethodRepeats> {
    let mut rows: Vec<MethodRepeats> = Vec::new();
    for _ in 0..repeats {
        for (i, row) in table(a, b, samples).into_iter().enumerate() {
            match rows.get_mut(i) {
                Some(r) => r.repeats.push(row),
                None => rows.push(MethodRepeats {
                    method: row.method.clone(),
                    main_core: row.main_core,
                    helper_core: row.helper_core,
                    repeats: vec![row],
                }),
            }
        }
    }
    rows
}

/// The rows as an aligned text table: the batched median and its ratio to the same placement's
/// batched floor, the per-trip median and p99, and the CPU time per trip.
pub fn to_text(rows: &[LatencyRow]) -> String {
    let mut out = format!(
        "{:<20} {:>5} {:>6} {:>11} {:>8} {:>11} {:>11} {:>11} {:>8}\n",
        "method",
        "main",
        "helper",
        "batched ns",
        "x floor",
        "median ns",
        "p99 ns",
        "CPU ns",
        "samples"
    );
    let floor = |r: &LatencyRow| {
        rows.iter()
            .find(|f| {
                f.method == "ping-pong"
                    && (f.main_core, f.helper_core) == (r.main_core, r.helper_core)
            })
            .and_then(|f| f.batched_ns)
    };
    let or_dash =
        |v: Option<f64>, digits: usize| v.map_or("–".to_string(), |v| format!("{v:.digits$}"));
    for r in rows {
        let ratio = r.batched_ns.zip(floor(r)).map(|(b, f)| b / f);
        out.push_str(&format!(
            "{:<20} {:>5} {:>6} {:>11} {:>8} {:>11.0} {:>11.0} {:>11} {:>8}{}\n",
            r.method,
            r.main_core,
            r.helper_core,
            or_dash(r.batched_ns, 0),
            or_dash(ratio, 2),
            r.median_ns,
            r.p99_ns,
            or_dash(r.cpu_ns, 0),
            r.samples,
            if r.pinned { "" } else { "  (pin did not hold)" }
        ));
    }
    out
}

/// The cache-line round trip of every pair of a set of cores.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Matrix {
    /// The cores, in the order given.
    pub cores: Vec<usize>,
    /// Each pair's median round trip (ns), `[a, b, ns]` with `a` before `b` in `cores`.
    pub pairs: Vec<(usize, usize, f64)>,
}

/// Refuses a matrix of fewer than two cores, or one that lists a core twice.
pub fn check_matrix_cores(cores: &[usize]) -> Result<(), crate::input::InputError> {
    let mut seen = cores.to_vec();
    seen.sort_unstable();
    seen.dedup();
    if seen.len() != cores.len() {
        return Err(crate::input::InputError(format!(
            "--cores: the matrix pairs different cores; {} lists one twice",
            affinity::list(cores)
        )));
    }
    if cores.len() < 2 {
        return Err(crate::input::InputError(format!(
            "--matrix: needs at least two cores, got {}",
            affinity::list(cores)
        )));
    }
    Ok(())
}

impl Matrix {
    /// Measures every pair of `cores` once with `round_trip(a, b)` (ns), in order.
    pub fn measure(cores: &[usize], mut round_trip: impl FnMut(usize, usize) -> f64) -> Matrix {
        let mut pairs = Vec::new();
        for (i, &a) in cores.iter().enumerate() {
            for &b in &cores[i + 1..] {
                pairs.push((a, b, round_trip(a, b)));
            }
        }
        Matrix {
            cores: cores.to_vec(),
            pairs,
        }
    }

    /// The round trip between `a` and `b`, either way round.
    pub fn get(&self, a: usize, b: usize) -> Option<f64> {
        self.pairs
            .iter()
            .find(|&&(x, y, _)| (x, y) == (a, b) || (x, y) == (b, a))
            .map(|p| p.2)
    }

    /// The matrix as text: a lower triangle of round trips (ns), each marked `n` (near) or `f`
    /// (far) when the pairs split into two placements, then one line per placement naming its
    /// pairs, and which pairs the OS lists as thread siblings (`siblings(a, b)`).
    pub fn to_text(&self, siblings: impl Fn(usize, usize) -> Option<bool>) -> String {
        let split = crate::placement::Split::of(self.pairs.iter().map(|p| p.2));
        let mark = |ns: f64| match split.as_ref().and_then(|s| s.class(ns)) {
            Some(crate::placement::Class::Near) => " n",
            Some(crate::placement::Class::Far) => " f",
            _ => "  ",
        };
        let mut out = format!("{:>6}", "core");
        for &b in &self.cores[..self.cores.len().saturating_sub(1)] {
            out.push_str(&format!("{b:>9}"));
        }
        out.push('\n');
        for (i, &a) in self.cores.iter().enumerate().skip(1) {
            out.push_str(&format!("{a:>6}"));
            for &b in &self.cores[..i] {
                let cell = self
                    .get(a, b)
                    .map_or("–".into(), |ns| format!("{ns:.0}{}", mark(ns)));
                out.push_str(&format!("{cell:>9}"));
            }
            out.push('\n');
        }
        if let Some(s) = &split {
            out.push_str(&format!("{}\n", s.describe()));
        }
        let listed: Vec<String> = self
            .pairs
            .iter()
            .filter(|&&(a, b, _)| siblings(a, b) == Some(true))
            .map(|&(a, b, _)| format!("{a},{b}"))
            .collect();
        out.push_str(&if listed.is_empty() {
            "the OS lists no pair as thread siblings (in a VM, the guest's view, not where the host put the vCPUs)\n".to_string()
        } else {
            format!(
                "thread siblings by the OS: {} (in a VM, the guest's view, not where the host put the vCPUs)\n",
                listed.join(" ")
            )
        });
        out.push_str("(ns: median cache-line round trip, batched; n near, f far)\n");
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_matrix_measures_every_pair_once_and_names_near_and_far() {
        // Cores 0 and 2 are one die, 5 and 7 another: near within, far across.
        let die = |c: usize| c / 4;
        let mut asked = Vec::new();
        let m = Matrix::measure(&[0, 2, 5, 7], |a, b| {
            asked.push((a, b));
            if die(a) == die(b) {
                50.0
            } else {
                400.0
            }
        });
        assert_eq!(asked, [(0, 2), (0, 5), (0, 7), (2, 5), (2, 7), (5, 7)]);
        assert_eq!(m.get(7, 0), Some(400.0));
        assert_eq!(m.get(5, 7), Some(50.0));
        let text = m.to_text(|a, b| Some(a == 0 && b == 2));
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(
            lines[0].split_whitespace().collect::<Vec<_>>(),
            ["core", "0", "2", "5"]
        );
        assert_eq!(
            lines[3].split_whitespace().collect::<Vec<_>>(),
            ["7", "400", "f", "400", "f", "50", "n"]
        );
        assert!(text.contains("two placements: near 50 ns (2 round trips), far 400 ns (4)"));
        assert!(text.contains("thread siblings by the OS: 0,2"), "{text}");
    }

    #[test]
    fn a_matrix_needs_two_different_cores() {
        assert!(check_matrix_cores(&[0, 1, 2]).is_ok());
        let e = check_matrix_cores(&[1, 1]).unwrap_err().0;
        assert!(e.starts_with("--cores: "), "{e}");
        let e = check_matrix_cores(&[3]).unwrap_err().0;
        assert!(e.starts_with("--matrix: needs at least two cores"), "{e}");
    }
}
