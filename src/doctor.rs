//! `doctor`: what on this machine makes a measurement noisy, each finding with how to fix it
//! (after pyperf's `system show`). It reads `/proc`, `/sys` and the core locks only, changes nothing, and says
//! which entries were missing instead of failing.

use crate::affinity;
use crate::lock;
use serde::{Deserialize, Serialize};
use std::collections::HashMap;
use std::path::Path;
use std::time::{Duration, Instant};

/// How much a finding matters.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Severity {
    /// Nothing to do.
    Ok,
    /// Worth knowing; measurements can still be trusted.
    Info,
    /// Likely to make measurements noisy or misleading.
    Warn,
}

/// One check's result.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Finding {
    /// The check, e.g. `governor`.
    pub check: String,
    /// How much it matters.
    pub severity: Severity,
    /// What was found.
    pub finding: String,
    /// How to fix it, when there is something to fix.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fix: Option<String>,
}

/// Everything `doctor` found.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Report {
    /// The cores checked: the main thread's and the helper's.
    pub cores: Vec<usize>,
    /// Seconds of sampling behind the steal, load and busy-thread checks.
    pub window_seconds: f64,
    /// One finding per check (some checks give one per core).
    pub findings: Vec<Finding>,
    /// `/proc` and `/sys` entries that were not there to read.
    pub missing: Vec<String>,
    /// The cross-core round trips timed before and after the window (ns; two cores only,
    /// absent in reports from before they were).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub round_trip_ns: Vec<f64>,
}

impl Report {
    /// The warnings.
    pub fn warnings(&self) -> impl Iterator<Item = &Finding> {
        self.findings
            .iter()
            .filter(|f| f.severity == Severity::Warn)
    }

    /// One line per finding, then the missing entries.
    pub fn to_text(&self) -> String {
        let mut out = String::new();
        for f in &self.findings {
            let tag = match f.severity {
                Severity::Ok => "ok  ",
                Severity::Info => "info",
                Severity::Warn => "WARN",
            };
            out.push_str(&format!("{tag} {}: {}", f.check, f.finding));
            if let Some(fix) = &f.fix {
                out.push_str(&format!("; fix: {fix}"));
            }
            out.push('\n');
        }
        if !self.missing.is_empty() {
            out.push_str(&format!(
                "not available here: {}\n",
                self.missing.join(", ")
            ));
        }
        out
    }

    /// The one line `sweep` prints before it starts.
    pub fn summary(&self) -> String {
        let mut warnings: Vec<String> = Vec::new();
        for f in self.warnings() {
            let n = self.warnings().filter(|g| g.check == f.check).count();
            let name = if n > 1 {
                format!("{} ×{n}", f.check)
            } else {
                f.check.clone()
            };
            if !warnings.contains(&name) {
                warnings.push(name);
            }
        }
        if warnings.is_empty() {
            format!(
                "doctor: no warnings for cores {}",
                affinity::list(&self.cores)
            )
        } else {
            format!(
                "doctor: {} warning(s) for cores {} ({}); `oceanbench doctor` says how to fix them",
                self.warnings().count(),
                affinity::list(&self.cores),
                warnings.join(", ")
            )
        }
    }
}

/// Reads `/proc` and `/sys`, remembering what was missing.
struct Reader {
    missing: Vec<String>,
}

impl Reader {
    fn read(&mut self, path: &str) -> Option<String> {
        match std::fs::read_to_string(path) {
            Ok(text) => Some(text.trim().to_string()),
            Err(_) => {
                if !self.missing.iter().any(|m| m == path) {
                    self.missing.push(path.to_string());
                }
                None
            }
        }
    }
}

/// Runs every check for `cores`, sampling the machine for `window`.
pub fn examine(cores: &[usize], window: Duration) -> Report {
    let mut r = Reader {
        missing: Vec::new(),
    };
    let mut findings = Vec::new();
    let mut round_trip_ns = round_trips(cores, PLACEMENT_TRIPS);
    findings.extend(governor(&mut r, cores));
    findings.extend(boost(&mut r));
    findings.extend(smt(&mut r, cores));
    findings.push(isolation(&mut r, cores));
    findings.push(virtualization(&mut r));
    findings.push(power(&mut r));
    findings.push(irqbalance());
    findings.push(transparent_hugepages(&mut r));
    findings.extend(sampled(&mut r, cores, window));
    round_trip_ns.extend(round_trips(cores, PLACEMENT_TRIPS));
    findings.extend(placement(cores, &round_trip_ns));
    findings.extend(pinning(cores));
    findings.extend(core_locks(cores));
    Report {
        cores: cores.to_vec(),
        window_seconds: window.as_secs_f64(),
        findings,
        missing: r.missing,
        round_trip_ns,
    }
}

fn finding(check: &str, severity: Severity, finding: String, fix: Option<&str>) -> Finding {
    Finding {
        check: check.to_string(),
        severity,
        finding,
        fix: fix.map(str::to_string),
    }
}

/// A check that found nothing to fix: every OK finding goes without a fix.
fn ok(check: &str, text: String) -> Finding {
    finding(check, Severity::Ok, text, None)
}

fn governor(r: &mut Reader, cores: &[usize]) -> Vec<Finding> {
    let mut out = Vec::new();
    for &c in cores {
        let path = format!("/sys/devices/system/cpu/cpu{c}/cpufreq/scaling_governor");
        let Some(gov) = r.read(&path) else {
            out.push(finding(
                "governor",
                Severity::Info,
                format!("core {c} has no cpufreq (usual in a VM: the host sets the clock)"),
                None,
            ));
            continue;
        };
        out.push(if gov == "performance" {
            ok("governor", format!("core {c}: performance"))
        } else {
            finding(
                "governor",
                Severity::Warn,
                format!("core {c}: {gov}, so its clock follows the load and the first frames of a trial run slower"),
                Some("sudo cpupower frequency-set -g performance"),
            )
        });
    }
    out
}

fn boost(r: &mut Reader) -> Option<Finding> {
    let intel = "/sys/devices/system/cpu/intel_pstate/no_turbo";
    let generic = "/sys/devices/system/cpu/cpufreq/boost";
    let on = if Path::new(intel).exists() {
        r.read(intel)? == "0"
    } else if Path::new(generic).exists() {
        r.read(generic)? == "1"
    } else {
        r.missing.push(format!("{intel} or {generic}"));
        return None;
    };
    Some(if on {
        finding(
            "boost",
            Severity::Warn,
            "turbo boost is on: the clock depends on temperature and on how many cores are busy, so UP and DP run at different clocks".into(),
            Some("echo 1 | sudo tee /sys/devices/system/cpu/intel_pstate/no_turbo (or echo 0 to cpufreq/boost)"),
        )
    } else {
        ok("boost", "turbo boost is off".into())
    })
}

/// Parses a CPU list such as `0-3,8,10-11`.
pub fn parse_cpu_list(text: &str) -> Vec<usize> {
    text.trim()
        .split(',')
        .filter(|p| !p.is_empty())
        .flat_map(|part| match part.split_once('-') {
            Some((a, b)) => match (a.parse::<usize>(), b.parse::<usize>()) {
                (Ok(a), Ok(b)) => (a..=b).collect(),
                _ => vec![],
            },
            None => part.parse().into_iter().collect(),
        })
        .collect()
}

/// Whether the OS lists cores `a` and `b` as thread siblings of one physical core (in a VM, the
/// guest's topology, which says nothing of where the host put the vCPUs); `None` when sysfs
/// does not say.
pub fn thread_siblings(a: usize, b: usize) -> Option<bool> {
    let path = format!("/sys/devices/system/cpu/cpu{a}/topology/thread_siblings_list");
    let list = std::fs::read_to_string(path).ok()?;
    Some(a != b && parse_cpu_list(&list).contains(&b))
}

fn smt(r: &mut Reader, cores: &[usize]) -> Vec<Finding> {
    let mut out = Vec::new();
    let mut siblings = HashMap::new();
    for &c in cores {
        let path = format!("/sys/devices/system/cpu/cpu{c}/topology/thread_siblings_list");
        if let Some(list) = r.read(&path) {
            siblings.insert(c, parse_cpu_list(&list));
        }
    }
    if let [main, helper] = cores {
        if main != helper && siblings.get(main).is_some_and(|s| s.contains(helper)) {
            out.push(finding(
                "smt",
                Severity::Warn,
                format!("cores {main} and {helper} are SMT siblings of one physical core: dp then measures hyper-threading, not two processors"),
                Some("choose cores on different physical cores with --cores (see lscpu -e)"),
            ));
        }
    }
    for &c in cores {
        let others: Vec<usize> = siblings
            .get(&c)
            .map(|s| s.iter().copied().filter(|x| !cores.contains(x)).collect())
            .unwrap_or_default();
        if !others.is_empty() {
            out.push(finding(
                "smt",
                Severity::Info,
                format!("core {c} shares its physical core with {}: whatever runs there shares its pipeline and caches", affinity::list(&others)),
                Some("keep the sibling idle, or take it offline: echo 0 | sudo tee /sys/devices/system/cpu/cpuN/online"),
            ));
        }
    }
    if out.is_empty() && !siblings.is_empty() {
        out.push(ok("smt", "no chosen core shares a physical core".into()));
    }
    out
}

/// Round trips timed before the window and again after it.
pub const PLACEMENT_TRIPS: usize = 3;

/// `n` median cross-core round trips between the two cores (ns); none on one core. Each is 300
/// batches: a few ms near, some tens far.
fn round_trips(cores: &[usize], n: usize) -> Vec<f64> {
    match cores {
        [a, b] if a != b => (0..n)
            .map(|_| crate::crosscore::round_trip(*a, *b, 300).median_ns)
            .collect(),
        _ => Vec::new(),
    }
}

/// Where the two cores sat: their round trips over the window as one placement or near and
/// far, and whether the OS lists them as thread siblings.
fn placement(cores: &[usize], trips: &[f64]) -> Option<Finding> {
    let [a, b] = cores else { return None };
    let split = crate::placement::Split::of(trips.iter().copied())?;
    let siblings = match thread_siblings(*a, *b) {
        Some(true) => "; the OS lists them as thread siblings of one core",
        Some(false) => "; the OS does not list them as thread siblings",
        None => "",
    };
    let vm = if siblings.is_empty() {
        ""
    } else {
        " (in a VM, the guest's topology: it says nothing of where the host put the vCPUs)"
    };
    let what = format!(
        "cores {a},{b}: {} over {} round trips before and after the window{siblings}{vm}",
        split.describe(),
        trips.len()
    );
    Some(if split.two() {
        finding(
            "placement",
            Severity::Warn,
            format!("{what}: the host moved the two vCPUs between near and far cores while doctor watched"),
            Some("every trial is placed (results.md's Placement section); compare within one placement, and prefer a VM with dedicated cores (docs/noise.md)"),
        )
    } else {
        finding("placement", Severity::Info, what, None)
    })
}

fn isolation(r: &mut Reader, cores: &[usize]) -> Finding {
    let isolated = r
        .read("/sys/devices/system/cpu/isolated")
        .map(|t| parse_cpu_list(&t))
        .unwrap_or_default();
    let nohz = std::fs::read_to_string("/sys/devices/system/cpu/nohz_full")
        .map(|t| parse_cpu_list(&t))
        .unwrap_or_default();
    let loose: Vec<usize> = cores
        .iter()
        .copied()
        .filter(|c| !isolated.contains(c))
        .collect();
    if loose.is_empty() {
        let tick = if cores.iter().all(|c| nohz.contains(c)) {
            ", and tickless (nohz_full)"
        } else {
            ""
        };
        ok(
            "isolation",
            format!("cores {} are isolated{tick}", affinity::list(cores)),
        )
    } else {
        finding(
            "isolation",
            Severity::Info,
            format!(
                "core(s) {} are not isolated: the scheduler may run other tasks on them",
                affinity::list(&loose)
            ),
            Some("boot with isolcpus=N nohz_full=N rcu_nocbs=N for the measured cores and pass them with --cores (docs/noise.md)"),
        )
    }
}

fn virtualization(r: &mut Reader) -> Finding {
    let cpuinfo = r.read("/proc/cpuinfo").unwrap_or_default();
    let hypervisor = cpuinfo
        .lines()
        .filter(|l| l.starts_with("flags"))
        .any(|l| l.split_whitespace().any(|f| f == "hypervisor"));
    if hypervisor {
        finding(
            "virtualization",
            Severity::Info,
            "running under a hypervisor: vCPUs move between physical cores (the cross-core round trip shows where they sit) and can lose time to steal".into(),
            Some("compare within one run (compare --by), and prefer a VM with dedicated cores"),
        )
    } else {
        ok("virtualization", "no hypervisor flag".into())
    }
}

fn power(r: &mut Reader) -> Finding {
    let dir = Path::new("/sys/class/power_supply");
    let Ok(entries) = std::fs::read_dir(dir) else {
        r.missing.push(dir.display().to_string());
        return ok(
            "power",
            "no power supply information (a desktop or a VM)".into(),
        );
    };
    let on_battery = entries.flatten().any(|e| {
        let kind = std::fs::read_to_string(e.path().join("type")).unwrap_or_default();
        let online = std::fs::read_to_string(e.path().join("online")).unwrap_or_default();
        kind.trim() == "Mains" && online.trim() == "0"
    });
    if on_battery {
        finding(
            "power",
            Severity::Warn,
            "on battery: power saving lowers and varies the clock".into(),
            Some("plug the laptop in"),
        )
    } else {
        ok("power", "on mains power".into())
    }
}

/// The names of every running process.
fn process_names() -> Vec<(u32, String)> {
    let Ok(dir) = std::fs::read_dir("/proc") else {
        return Vec::new();
    };
    dir.flatten()
        .filter_map(|e| {
            let pid: u32 = e.file_name().to_str()?.parse().ok()?;
            let comm = std::fs::read_to_string(e.path().join("comm")).ok()?;
            Some((pid, comm.trim().to_string()))
        })
        .collect()
}

fn irqbalance() -> Finding {
    if process_names().iter().any(|(_, n)| n == "irqbalance") {
        finding(
            "irqbalance",
            Severity::Info,
            "irqbalance is running: it moves interrupts onto any core, the measured ones too".into(),
            Some("sudo systemctl stop irqbalance, or list the measured cores in IRQBALANCE_BANNED_CPUS"),
        )
    } else {
        ok("irqbalance", "not running".into())
    }
}

fn transparent_hugepages(r: &mut Reader) -> Finding {
    let Some(text) = r.read("/sys/kernel/mm/transparent_hugepage/enabled") else {
        return ok("hugepages", "no transparent huge pages setting".into());
    };
    if text.contains("[always]") {
        finding(
            "hugepages",
            Severity::Info,
            "transparent huge pages are always on: khugepaged can compact the mesh's memory in the middle of a trial".into(),
            Some("echo madvise | sudo tee /sys/kernel/mm/transparent_hugepage/enabled"),
        )
    } else {
        ok("hugepages", "transparent huge pages only on request".into())
    }
}

/// Per-core busy and steal ticks from `/proc/stat`, as (busy, steal, total).
fn core_ticks(stat: &str, core: usize) -> Option<(u64, u64, u64)> {
    let name = format!("cpu{core}");
    let line = stat
        .lines()
        .find(|l| l.split_whitespace().next() == Some(name.as_str()))?;
    let v: Vec<u64> = line
        .split_whitespace()
        .skip(1)
        .filter_map(|x| x.parse().ok())
        .collect();
    let total: u64 = v.iter().take(8).sum();
    let idle = v.get(3)? + v.get(4).unwrap_or(&0);
    let steal = *v.get(7).unwrap_or(&0);
    Some((total - idle - steal, steal, total))
}

/// CPU ticks and last core of every thread on the machine, by (pid, tid).
fn thread_ticks() -> HashMap<(u32, u32), (u64, usize, String)> {
    let mut out = HashMap::new();
    let Ok(procs) = std::fs::read_dir("/proc") else {
        return out;
    };
    for p in procs.flatten() {
        let Some(pid) = p.file_name().to_str().and_then(|s| s.parse::<u32>().ok()) else {
            continue;
        };
        let Ok(tasks) = std::fs::read_dir(p.path().join("task")) else {
            continue;
        };
        for t in tasks.flatten() {
            let Some(tid) = t.file_name().to_str().and_then(|s| s.parse::<u32>().ok()) else {
                continue;
            };
            let Ok(stat) = std::fs::read_to_string(t.path().join("stat")) else {
                continue;
            };
            if let Some((ticks, cpu, name)) = parse_task_stat(&stat) {
                out.insert((pid, tid), (ticks, cpu, name));
            }
        }
    }
    out
}

/// A task's user + system ticks, the core it last ran on, and its name, from its `stat` line.
pub fn parse_task_stat(stat: &str) -> Option<(u64, usize, String)> {
    let open = stat.find('(')?;
    let close = stat.rfind(')')?;
    let name = stat[open + 1..close].to_string();
    let fields: Vec<&str> = stat[close + 1..].split_whitespace().collect();
    // Fields after the name start at field 3 (state); utime is 14, stime 15, processor 39.
    let utime: u64 = fields.get(11)?.parse().ok()?;
    let stime: u64 = fields.get(12)?.parse().ok()?;
    let cpu: usize = fields.get(36)?.parse().ok()?;
    Some((utime + stime, cpu, name))
}

fn sampled(r: &mut Reader, cores: &[usize], window: Duration) -> Vec<Finding> {
    let before_stat = r.read("/proc/stat");
    let before_threads = thread_ticks();
    let started = Instant::now();
    std::thread::sleep(window);
    let seconds = started.elapsed().as_secs_f64();
    let after_stat = r.read("/proc/stat");
    let after_threads = thread_ticks();
    let mut out = Vec::new();
    if let (Some(a), Some(b)) = (before_stat, after_stat) {
        for &c in cores {
            let (Some((busy0, steal0, total0)), Some((busy1, steal1, total1))) =
                (core_ticks(&a, c), core_ticks(&b, c))
            else {
                continue;
            };
            let total = (total1 - total0).max(1) as f64;
            let steal = 100.0 * (steal1 - steal0) as f64 / total;
            let busy = 100.0 * (busy1 - busy0) as f64 / total;
            out.push(if steal > 1.0 {
                finding(
                    "steal",
                    Severity::Warn,
                    format!("core {c} lost {steal:.1}% of the last {seconds:.0} s to the hypervisor"),
                    Some("the host is busy: re-run later, use --retry-noisy, or a VM with dedicated cores"),
                )
            } else {
                ok("steal", format!("core {c}: {steal:.1}% stolen over {seconds:.0} s"))
            });
            out.push(if busy > 10.0 {
                finding(
                    "load",
                    Severity::Warn,
                    format!("core {c} was {busy:.0}% busy over the last {seconds:.0} s before anything of ours ran"),
                    Some("stop what runs there, or choose idle cores with --cores"),
                )
            } else {
                ok("load", format!("core {c}: {busy:.0}% busy over {seconds:.0} s"))
            });
        }
    }
    if let Some(load) = r.read("/proc/loadavg") {
        let one_minute: f64 = load
            .split_whitespace()
            .next()
            .and_then(|v| v.parse().ok())
            .unwrap_or(0.0);
        if one_minute > affinity::allowed_cores().len() as f64 * 0.5 {
            out.push(finding(
                "load",
                Severity::Warn,
                format!(
                    "load average {one_minute:.2} over the last minute on {} allowed cores",
                    affinity::allowed_cores().len()
                ),
                Some("wait for other jobs to finish"),
            ));
        }
    }
    out.extend(busy_threads(
        cores,
        &before_threads,
        &after_threads,
        seconds,
    ));
    out
}

fn busy_threads(
    cores: &[usize],
    before: &HashMap<(u32, u32), (u64, usize, String)>,
    after: &HashMap<(u32, u32), (u64, usize, String)>,
    seconds: f64,
) -> Vec<Finding> {
    let own = std::process::id();
    let tick = crate::sched::clock_ticks_per_second() as f64;
    let mut busy: Vec<(f64, u32, String, usize)> = after
        .iter()
        .filter(|((pid, _), _)| *pid != own)
        .filter_map(|(id, (ticks, cpu, name))| {
            let start = before.get(id).map_or(0, |b| b.0);
            let share = 100.0 * ticks.saturating_sub(start) as f64 / tick / seconds;
            (share >= 5.0 && cores.contains(cpu)).then(|| (share, id.0, name.clone(), *cpu))
        })
        .collect();
    busy.sort_by(|a, b| b.0.total_cmp(&a.0));
    if busy.is_empty() {
        return vec![ok(
            "threads",
            "no other thread used 5% of a chosen core".into(),
        )];
    }
    let list: Vec<String> = busy
        .iter()
        .take(5)
        .map(|(share, pid, name, cpu)| format!("{name} (pid {pid}) {share:.0}% on core {cpu}"))
        .collect();
    vec![finding(
        "threads",
        Severity::Warn,
        format!("busy on the chosen cores: {}", list.join(", ")),
        Some("stop them, or move them off: taskset -acp OTHER_CORES PID"),
    )]
}

/// Another oceanbench run holding a core's lock is measuring there right now.
fn core_locks(cores: &[usize]) -> Vec<Finding> {
    cores
        .iter()
        .map(|&c| match lock::holder(&lock::core_file(c)) {
            Some(holder) => finding(
                "locks",
                Severity::Warn,
                format!("core {c} is being measured on by another oceanbench run ({holder})"),
                Some("wait for that run to finish, or choose other cores with --cores"),
            ),
            None => ok(
                "locks",
                format!("no other oceanbench run is measuring on core {c}"),
            ),
        })
        .collect()
}

fn pinning(cores: &[usize]) -> Vec<Finding> {
    cores
        .iter()
        .map(|&c| {
            let pin = std::thread::spawn(move || affinity::pin_current(c))
                .join()
                .unwrap_or(affinity::Pin {
                    core: c,
                    held: false,
                });
            if pin.held {
                ok("pinning", format!("a thread pinned to core {c} stays there"))
            } else {
                finding(
                    "pinning",
                    Severity::Warn,
                    format!("a pin to core {c} did not hold (a cgroup cpuset or a container may forbid it)"),
                    Some("run where the process may set its affinity, or choose allowed cores with --cores"),
                )
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cpu_lists_parse() {
        assert_eq!(parse_cpu_list("0-3,8,10-11\n"), [0, 1, 2, 3, 8, 10, 11]);
        assert_eq!(parse_cpu_list(""), Vec::<usize>::new());
        assert_eq!(parse_cpu_list("2"), [2]);
    }

    #[test]
    fn task_stat_lines_parse_even_with_spaces_in_the_name() {
        let line = "1234 (my (odd) name) R 1 1234 1234 0 -1 4194560 100 0 0 0 250 50 0 0 20 0 1 0 100 1000 100 18446744073709551615 1 1 0 0 0 0 0 0 0 0 0 0 17 1 0 0 0 0 0";
        assert_eq!(
            parse_task_stat(line),
            Some((300, 1, "my (odd) name".to_string()))
        );
    }

    #[test]
    fn core_ticks_split_busy_steal_and_total() {
        let stat = "cpu0 100 0 50 800 10 0 5 35 0 0\n";
        assert_eq!(core_ticks(stat, 0), Some((155, 35, 1000)));
        assert_eq!(core_ticks(stat, 1), None);
    }

    #[test]
    fn the_report_names_every_check_and_never_fails() {
        let cores = affinity::allowed_cores()
            .iter()
            .copied()
            .take(2)
            .collect::<Vec<_>>();
        let report = examine(&cores, Duration::from_millis(50));
        for check in [
            "governor",
            "isolation",
            "virtualization",
            "power",
            "threads",
            "pinning",
        ] {
            let present = report.findings.iter().any(|f| f.check == check);
            assert!(present, "{check}: {}", report.to_text());
        }
        let lines = report.to_text().lines().count();
        assert_eq!(
            lines,
            report.findings.len() + usize::from(!report.missing.is_empty())
        );
        assert!(report.summary().starts_with("doctor: "));
    }
}
