//! What the OS scheduler recorded of a thread and of a core: how long the thread was runnable
//! but not running (run delay) and how often it was preempted (involuntary context switches),
//! and how much time a virtual machine's core was stolen by the hypervisor. On a shared VM these
//! are the finest evidence that a measurement was disturbed.

use serde::{Deserialize, Serialize};

/// The calling thread's scheduler counters so far.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ThreadCounters {
    /// Nanoseconds spent running on a CPU (the thread CPU clock, exact to the call; schedstat's
    /// own figure lags by up to a scheduler tick).
    pub cpu_ns: u64,
    /// Nanoseconds spent runnable on a run queue but not running (schedstat's run delay).
    pub run_delay_ns: u64,
    /// Times the thread was switched out against its will.
    pub involuntary_switches: u64,
}

impl ThreadCounters {
    /// The calling thread's counters; `None` where the OS does not keep them (no
    /// `/proc/thread-self/schedstat`, or `getrusage(RUSAGE_THREAD)` failed).
    pub fn now() -> Option<ThreadCounters> {
        let text = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
        let (_, run_delay_ns) = parse_schedstat(&text)?;
        Some(ThreadCounters {
            cpu_ns: thread_cpu_ns()?,
            run_delay_ns,
            involuntary_switches: involuntary_switches()?,
        })
    }

    /// What happened between `earlier` and `self`.
    pub fn since(self, earlier: ThreadCounters) -> ThreadCounters {
        ThreadCounters {
            cpu_ns: self.cpu_ns.saturating_sub(earlier.cpu_ns),
            run_delay_ns: self.run_delay_ns.saturating_sub(earlier.run_delay_ns),
            involuntary_switches: self
                .involuntary_switches
                .saturating_sub(earlier.involuntary_switches),
        }
    }
}

/// The CPU time and run delay of a schedstat line: "cpu_ns run_delay_ns timeslices".
pub fn parse_schedstat(text: &str) -> Option<(u64, u64)> {
    let mut fields = text.split_whitespace().map(|f| f.parse::<u64>().ok());
    Some((fields.next()??, fields.next()??))
}

/// The calling thread's CPU time (`CLOCK_THREAD_CPUTIME_ID`), in nanoseconds.
pub fn thread_cpu_ns() -> Option<u64> {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: clock_gettime writes one timespec into the valid pointer it is given.
    let ok = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) } == 0;
    ok.then(|| ts.tv_sec as u64 * 1_000_000_000 + ts.tv_nsec as u64)
}

#[cfg(target_os = "linux")]
fn involuntary_switches() -> Option<u64> {
    let mut usage = std::mem::MaybeUninit::<libc::rusage>::zeroed();
    // SAFETY: getrusage writes a whole rusage into the pointer it is given, which is valid and
    // large enough; RUSAGE_THREAD asks for the calling thread alone.
    let ok = unsafe { libc::getrusage(libc::RUSAGE_THREAD, usage.as_mut_ptr()) } == 0;
    // SAFETY: on success the struct is initialised (and zeroed memory is a valid rusage anyway).
    ok.then(|| unsafe { usage.assume_init() }.ru_nivcsw as u64)
}

#[cfg(not(target_os = "linux"))]
fn involuntary_switches() -> Option<u64> {
    None
}

/// Nanoseconds each core has had stolen by the hypervisor since boot, from `/proc/stat`;
/// `None` where the file or a core's line is missing.
pub fn steal_ns(cores: &[usize]) -> Option<Vec<u64>> {
    let text = std::fs::read_to_string("/proc/stat").ok()?;
    let tick_ns = 1e9 / clock_ticks_per_second() as f64;
    cores
        .iter()
        .map(|&c| parse_steal_ticks(&text, c).map(|t| (t as f64 * tick_ns) as u64))
        .collect()
}

/// The steal column (the eighth number) of core `core`'s line in `/proc/stat`, in clock ticks.
pub fn parse_steal_ticks(stat: &str, core: usize) -> Option<u64> {
    let name = format!("cpu{core}");
    let line = stat
        .lines()
        .find(|l| l.split_whitespace().next() == Some(name.as_str()))?;
    line.split_whitespace().nth(8)?.parse().ok()
}

/// The kernel's clock tick rate (USER_HZ), the unit of `/proc/stat` and task `stat` times.
pub fn clock_ticks_per_second() -> i64 {
    // SAFETY: sysconf only reads a configuration value.
    let ticks = unsafe { libc::sysconf(libc::_SC_CLK_TCK) };
    if ticks > 0 {
        ticks
    } else {
        100
    }
}

/// What disturbed one thread during a trial.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ThreadNoise {
    /// The thread: `main`, or `helper k`.
    pub thread: String,
    /// Its core.
    pub core: usize,
    /// CPU time during the trial (ns).
    #[serde(default)]
    pub cpu_ns: u64,
    /// Run delay during the trial (ns): runnable but not running, whoever ran instead.
    pub run_delay_ns: u64,
    /// Involuntary context switches during the trial.
    pub involuntary_switches: u64,
}

/// What disturbed a trial: each pinned thread's run delay and preemptions, each pinned core's
/// steal, all against the trial's wall time.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct TrialNoise {
    /// Wall time of the trial, warm-up included (ns).
    pub wall_ns: u64,
    /// Each pinned thread.
    pub threads: Vec<ThreadNoise>,
    /// Steal of each pinned core during the trial (ns), as (core, ns).
    pub steal_ns: Vec<(usize, u64)>,
}

impl TrialNoise {
    /// Each thread's run delay that our own threads do not explain: its run delay less the CPU
    /// time of our other threads pinned to the same core (in `up`, main and helper are runnable
    /// while the other runs, which is the mode, not noise). A lower bound of the time other
    /// tasks kept the thread off its core.
    pub fn foreign_delay_ns(&self) -> Vec<u64> {
        self.threads
            .iter()
            .enumerate()
            .map(|(i, t)| {
                let partners: u64 = self
                    .threads
                    .iter()
                    .enumerate()
                    .filter(|&(j, u)| j != i && u.core == t.core)
                    .map(|(_, u)| u.cpu_ns)
                    .sum();
                t.run_delay_ns.saturating_sub(partners)
            })
            .collect()
    }

    /// The largest share of the wall time a thread was kept off its core by other tasks, in
    /// percent.
    pub fn preempted_percent(&self) -> f64 {
        self.percent(self.foreign_delay_ns().into_iter().max().unwrap_or(0))
    }

    /// The largest steal of any pinned core, as a percentage of the wall time.
    pub fn steal_percent(&self) -> f64 {
        self.percent(self.steal_ns.iter().map(|&(_, ns)| ns).max().unwrap_or(0))
    }

    /// Involuntary context switches of every thread together.
    pub fn involuntary_switches(&self) -> u64 {
        self.threads.iter().map(|t| t.involuntary_switches).sum()
    }

    /// Whether other tasks or the hypervisor took more than `threshold_percent` of the wall
    /// time from a thread or a core.
    pub fn is_noisy(&self, threshold_percent: f64) -> bool {
        self.preempted_percent() > threshold_percent || self.steal_percent() > threshold_percent
    }

    fn percent(&self, ns: u64) -> f64 {
        if self.wall_ns == 0 {
            0.0
        } else {
            100.0 * ns as f64 / self.wall_ns as f64
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn schedstat_and_proc_stat_parse() {
        assert_eq!(parse_schedstat("738265 1500 3\n"), Some((738265, 1500)));
        assert_eq!(parse_schedstat("garbage"), None);
        let stat = "cpu  263314 0 35605 734414 4036 0 258 385 0 0\n\
                    cpu0 132275 0 16185 369671 720 0 33 194 0 0\n\
                    cpu1 131039 0 19419 364743 3315 0 224 190 0 0\n\
                    cpu10 1 0 1 1 1 0 1 7 0 0\n";
        assert_eq!(parse_steal_ticks(stat, 0), Some(194));
        assert_eq!(parse_steal_ticks(stat, 1), Some(190));
        assert_eq!(parse_steal_ticks(stat, 10), Some(7));
        assert_eq!(parse_steal_ticks(stat, 2), None);
    }

    fn thread(core: usize, cpu_ns: u64, run_delay_ns: u64) -> ThreadNoise {
        ThreadNoise {
            thread: format!("on {core}"),
            core,
            cpu_ns,
            run_delay_ns,
            involuntary_switches: 2,
        }
    }

    #[test]
    fn shares_of_the_wall_time_on_two_cores() {
        let noise = TrialNoise {
            wall_ns: 1_000_000,
            threads: vec![thread(0, 900_000, 10_000), thread(1, 500_000, 30_000)],
            steal_ns: vec![(0, 5_000), (1, 0)],
        };
        assert_eq!(noise.foreign_delay_ns(), [10_000, 30_000]);
        assert_eq!(noise.preempted_percent(), 3.0);
        assert_eq!(noise.steal_percent(), 0.5);
        assert_eq!(noise.involuntary_switches(), 4);
        assert!(noise.is_noisy(2.0) && !noise.is_noisy(3.0));
        assert_eq!(TrialNoise::default().preempted_percent(), 0.0);
    }

    #[test]
    fn threads_sharing_a_core_do_not_count_each_other() {
        // up: main waited 600 µs while its helper ran 550 µs; the helper waited 400 µs while
        // main ran 450 µs. Only 50 µs of main's wait is someone else's doing.
        let noise = TrialNoise {
            wall_ns: 1_000_000,
            threads: vec![thread(0, 450_000, 600_000), thread(0, 550_000, 400_000)],
            steal_ns: vec![(0, 0)],
        };
        assert_eq!(noise.foreign_delay_ns(), [50_000, 0]);
        assert_eq!(noise.preempted_percent(), 5.0);
    }

    #[test]
    fn this_thread_has_counters_that_only_grow() {
        let Some(a) = ThreadCounters::now() else {
            return; // not Linux, or schedstats are off: nothing to read
        };
        std::thread::yield_now();
        let b = ThreadCounters::now().expect("read once, read again");
        let d = b.since(a);
        assert_eq!(d.since(d), ThreadCounters::default());
        assert!(b.run_delay_ns >= a.run_delay_ns);
    }
}
