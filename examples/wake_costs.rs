//! What a sleep costs the thread that sleeps and the thread that wakes it, on this machine.
//!
//! `cargo run --release --example wake_costs [wait_us] [rounds] [--out DIR]`: the sleeper
//! pinned to the second allowed core, the waker (when there is one) to the first, each round
//! makes `SLEEPS` sleeps of each kind, interleaved round by round:
//! - `timed`: a parking_lot condvar wait that only its timeout (`wait_us`) ends, the sleeper's
//!   timer slack at 1 ns, as `adaptive`'s wake-up ahead of a change sleeps;
//! - `woken`: a wait with no timeout that the waker ends `wait_us` after it began, with a store
//!   and `notify_one` (`condvar`'s and a late `adaptive` wake-up's path);
//! - `woken, timeout armed`: the same, the sleeper's timeout set far past the wake-up (what
//!   `adaptive` pays when the change comes before its wake-up ahead).
//!
//! It prints, per sleep, the sleeper's CPU time (`CLOCK_THREAD_CPUTIME_ID`), how late a timed
//! sleep ends past its timeout, and the waker's wall and CPU time inside `notify_one`. `--out
//! DIR` also writes them as a benchmark run, DIR/bench.json (docs/performance.md, "Benchmark
//! runs"): the value the median round, lower and upper the lowest and the highest.

use oceanbench::affinity;
use oceanbench::bench_run::{BenchEstimate, BenchRun, SCHEMA_VERSION};
use oceanbench::machine::Machine;
use oceanbench::sched::thread_cpu_ns;
use parking_lot::{Condvar, Mutex};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Sleeps of each kind per round.
const SLEEPS: u64 = 1_000;

/// The sleeper's and waker's shared state: `asked` counts the sleeps the sleeper has begun,
/// `woken` the wake-ups the waker has sent.
struct Pair {
    asked: AtomicU64,
    woken: Mutex<u64>,
    changed: Condvar,
}

/// One round's means per sleep, in µs.
#[derive(Default)]
struct Round {
    timed_cpu: f64,
    timed_late: f64,
    woken_cpu: f64,
    armed_cpu: f64,
    notify_wall: f64,
    notify_cpu: f64,
}

impl Round {
    const FIGURES: usize = 6;

    /// Each figure with its id, in the order the run lists them.
    fn figures(&self) -> [(&'static str, f64); Round::FIGURES] {
        [
            ("timed/sleeper cpu", self.timed_cpu),
            ("timed/late", self.timed_late),
            ("woken/sleeper cpu", self.woken_cpu),
            ("woken, timeout armed/sleeper cpu", self.armed_cpu),
            ("woken/waker notify wall", self.notify_wall),
            ("woken/waker notify cpu", self.notify_cpu),
        ]
    }
}

fn cpu_us() -> f64 {
    thread_cpu_ns().expect("this OS has no thread CPU clock") as f64 / 1e3
}

/// Timed sleeps that nothing wakes: the sleeper's CPU and lateness per sleep.
fn timed(wait: Duration) -> (f64, f64) {
    let (lock, cv) = (Mutex::new(()), Condvar::new());
    let (mut late, cpu0) = (0.0, cpu_us());
    for _ in 0..SLEEPS {
        let due = Instant::now() + wait;
        let mut guard = lock.lock();
        while !cv.wait_until(&mut guard, due).timed_out() {}
        late += due.elapsed().as_secs_f64() * 1e6;
    }
    let n = SLEEPS as f64;
    ((cpu_us() - cpu0) / n, late / n)
}

/// The waker's side of [`woken`]: `wait` after each sleep begins, one wake-up; its mean wall
/// and CPU time inside the store and `notify_one`, per wake-up.
fn waker(pair: &Pair, wait: Duration, from: u64) -> (f64, f64) {
    let (mut wall, mut cpu) = (0.0, 0.0);
    for i in from + 1..=from + SLEEPS {
        while pair.asked.load(Ordering::Acquire) < i {
            std::hint::spin_loop();
        }
        let begun = Instant::now();
        while begun.elapsed() < wait {
            std::hint::spin_loop();
        }
        let (t0, c0) = (Instant::now(), cpu_us());
        *pair.woken.lock() = i;
        pair.changed.notify_one();
        wall += t0.elapsed().as_secs_f64() * 1e6;
        cpu += cpu_us() - c0;
    }
    (wall / SLEEPS as f64, cpu / SLEEPS as f64)
}

fn round(cores: [usize; 2], wait: Duration, pair: &Arc<Pair>, from: u64) -> Round {
    let mut r = Round::default();
    (r.timed_cpu, r.timed_late) = timed(wait);
    let mut notify = [(0.0, 0.0); 2];
    for (k, armed) in [false, true].into_iter().enumerate() {
        let p = Arc::clone(pair);
        let start = from + k as u64 * SLEEPS;
        let waking = std::thread::spawn(move || {
            affinity::pin_current(cores[0]);
            waker(&p, wait, start)
        });
        *pair.woken.lock() = start;
        pair.asked.store(start, Ordering::Release);
        let cpu = woken(pair, armed, start);
        notify[k] = waking.join().expect("the waker panicked");
        if armed {
            r.armed_cpu = cpu;
        } else {
            r.woken_cpu = cpu;
        }
    }
    r.notify_wall = (notify[0].0 + notify[1].0) / 2.0;
    r.notify_cpu = (notify[0].1 + notify[1].1) / 2.0;
    r
}

/// Sleeps the waker ends, counted from `from`: the sleeper's CPU per sleep; its timeout, when
/// `armed`, far off.
fn woken(pair: &Pair, armed: bool, from: u64) -> f64 {
    let cpu0 = cpu_us();
    for i in from + 1..=from + SLEEPS {
        let mut woken = pair.woken.lock();
        pair.asked.store(i, Ordering::Release);
        while *woken < i {
            if armed {
                pair.changed
                    .wait_until(&mut woken, Instant::now() + Duration::from_millis(50));
            } else {
                pair.changed.wait(&mut woken);
            }
        }
    }
    (cpu_us() - cpu0) / SLEEPS as f64
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let started = oceanbench::sweep::utc_now();
    let (args, out) = oceanbench::bench_run::example_args();
    let wait_us: u64 = args.first().map_or(150, |a| a.parse().expect("wait_us"));
    let rounds: usize = args.get(1).map_or(5, |a| a.parse().expect("rounds"));
    let machine = Machine::current();
    let allowed = affinity::allowed_cores();
    assert!(allowed.len() >= 2, "wake_costs needs two cores");
    let cores = [allowed[0], allowed[1]];
    affinity::pin_current(cores[1]);
    // SAFETY: PR_SET_TIMERSLACK takes a value and touches only this thread; 1 ns as adaptive.
    unsafe { libc::prctl(libc::PR_SET_TIMERSLACK, 1 as libc::c_ulong) };
    let wait = Duration::from_micros(wait_us);
    let pair = Arc::new(Pair {
        asked: AtomicU64::new(0),
        woken: Mutex::new(0),
        changed: Condvar::new(),
    });
    let rs: Vec<Round> = (0..rounds)
        .map(|k| round(cores, wait, &pair, k as u64 * 2 * SLEEPS))
        .collect();
    let estimates: Vec<BenchEstimate> = (0..Round::FIGURES)
        .map(|k| {
            let mut v: Vec<f64> = rs.iter().map(|r| r.figures()[k].1).collect();
            let value = median(&mut v);
            BenchEstimate {
                id: format!("{}/{wait_us}", rs[0].figures()[k].0),
                unit: "us".into(),
                value,
                lower: v[0],
                upper: v[v.len() - 1],
                throughput: None,
            }
        })
        .collect();
    for e in &estimates {
        println!(
            "{:<40} {:>8.2} µs  [{:.2}, {:.2}]",
            e.id, e.value, e.lower, e.upper
        );
    }
    if let Some(dir) = out {
        let run = BenchRun {
            schema_version: SCHEMA_VERSION,
            name: "wake_costs".into(),
            started,
            machine,
            command: std::env::args().collect(),
            source: format!(
                "examples/wake_costs.rs, sleeper on core {} and waker on core {}, waits of \
                 {wait_us} µs: µs per sleep, value the median of {rounds} rounds of {SLEEPS} \
                 sleeps of each kind, lower and upper the lowest and the highest round",
                cores[1], cores[0]
            ),
            estimates,
        };
        run.write(&dir).expect("writing bench.json");
        println!("wrote {}", dir.join("bench.json").display());
    }
}
