//! A cell's frame times as a MangoHud log (`run`/`sweep --frame-log DIR`), the CSV layout that
//! MangoHud a5e7dc7's src/logging.cpp writes and FlightlessSomething, mangoplot and CapFrameX
//! read: line 1 names the system fields, line 2 gives them, line 3 names the 16 columns, then one
//! line per measured frame. Only the frame times are measured here, so the sensor columns hold 0
//! (docs/exports.md lists which).
//!
//! MangoHud's line 2 holds the machine but has no field for the commit, the config or the
//! placement, and its readers compare line 1 whole, so those travel in a `*.provenance.json`
//! beside each log (docs/exports.md).
//!
//! One file per cell, holding its last kept trial: a cell's trials are interleaved with the
//! other cells' of its row, so only one trial is a continuous stretch of time, as a MangoHud
//! capture is.

use crate::findings::provenance::{self, CellFacts, Provenance};
use crate::input::InputError;
use crate::machine::{self, Machine};
use crate::measure::Trial;
use crate::report::json::write_atomic;
use crate::results::{Cell, CellKey, Results};
use crate::sweep::Observer;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Line 1: the system fields, as MangoHud writes them and FlightlessSomething compares whole.
pub const SYSTEM_HEADER: &str = "os,cpu,gpu,ram,kernel,driver,cpuscheduler";

/// Line 3: MangoHud a5e7dc7's columns, frametime in ms and elapsed in ns.
pub const COLUMNS: [&str; 16] = [
    "fps",
    "frametime",
    "cpu_load",
    "cpu_power",
    "gpu_load",
    "cpu_temp",
    "gpu_temp",
    "gpu_core_clock",
    "gpu_mem_clock",
    "gpu_vram_used",
    "gpu_power",
    "ram_used",
    "swap_used",
    "process_rss",
    "cpu_mhz",
    "elapsed",
];

/// The machine as line 2 of a log gives it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SystemLine {
    /// The OS's pretty name.
    pub os: String,
    /// The CPU model, its parenthesised marks dropped as MangoHud's `sed 's/([^)]*)//g'` does.
    pub cpu: String,
    /// The GPU: empty, as MangoHud leaves it when no renderer names a device.
    pub gpu: String,
    /// MemTotal in kB, when /proc/meminfo gives it.
    pub ram_kib: Option<u64>,
    /// The kernel release.
    pub kernel: String,
    /// The graphics driver: empty, as MangoHud a5e7dc7 leaves it on Linux (its glxinfo probe
    /// is commented out).
    pub driver: String,
    /// cpu0's cpufreq governor (empty without cpufreq, as in most VMs).
    pub cpu_scheduler: String,
}

impl SystemLine {
    /// The line of `machine`, with this machine's memory and cpu0's governor read now.
    pub fn of(machine: &Machine) -> SystemLine {
        let governor =
            std::fs::read_to_string("/sys/devices/system/cpu/cpu0/cpufreq/scaling_governor")
                .unwrap_or_default();
        SystemLine {
            os: machine.os.clone(),
            cpu: without_parentheses(&machine.cpu_model),
            gpu: String::new(),
            ram_kib: machine::total_memory_kib(),
            kernel: machine.kernel.clone(),
            driver: String::new(),
            cpu_scheduler: governor.lines().next().unwrap_or_default().to_string(),
        }
    }

    /// The line's text: no value holds a comma (a reader splits on every one).
    fn text(&self) -> String {
        let ram = self.ram_kib.map(|k| k.to_string()).unwrap_or_default();
        [
            self.os.as_str(),
            &self.cpu,
            &self.gpu,
            &ram,
            &self.kernel,
            &self.driver,
            &self.cpu_scheduler,
        ]
        .map(|v| v.replace([',', '\n', '\r'], " ").trim().to_string())
        .join(",")
    }
}

/// `text` without its parenthesised parts, spaces collapsed: `Intel(R) Xeon(R) CPU` gives
/// `Intel Xeon CPU`.
fn without_parentheses(text: &str) -> String {
    let mut out = String::new();
    let mut rest = text;
    while let Some(open) = rest.find('(') {
        match rest[open..].find(')') {
            Some(close) => {
                out.push_str(&rest[..open]);
                rest = &rest[open + close + 1..];
            }
            None => break,
        }
    }
    out.push_str(rest);
    out.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// The log of frames timed `frames_ns` (each from its start to the next frame's start): fps is
/// 1000 ÷ frametime, elapsed the end of the frame since the first one started, every other
/// column 0.
pub fn to_csv(system: &SystemLine, frames_ns: &[u64]) -> String {
    let mut out = format!(
        "{SYSTEM_HEADER}\n{}\n{}\n",
        system.text(),
        COLUMNS.join(",")
    );
    let zeros = ",0".repeat(COLUMNS.len() - 3);
    let mut elapsed: u64 = 0;
    for &ns in frames_ns {
        elapsed += ns;
        let ms = ns as f64 * 1e-6;
        let fps = if ns > 0 { 1e3 / ms } else { 0.0 };
        // Six decimals of a millisecond keep every nanosecond, so the column adds up to elapsed.
        let _ = writeln!(out, "{fps:.3},{ms:.6}{zeros},{elapsed}");
    }
    out
}

/// The log's file name for cell `key`: its label (every value that is not a dimension's quiet
/// default, so adding a dimension renames nothing), each value kept to file-name characters.
pub fn file_name(key: &CellKey) -> String {
    let label: String = key
        .label()
        .chars()
        .map(|c| match c {
            ' ' => '_',
            c if c.is_ascii_alphanumeric() || c == '-' || c == '.' => c,
            _ => '-',
        })
        .collect();
    format!("{label}.csv")
}

/// Writes each measured cell's log into a folder as the sweep finishes the cell, and its
/// provenance beside it after every row.
pub struct FrameLogger {
    dir: PathBuf,
    system: SystemLine,
    written: Vec<(PathBuf, CellKey)>,
    error: Option<String>,
}

impl FrameLogger {
    /// A logger into `dir` (named by `flag` in errors), created if missing; refused when it is
    /// no folder or already holds the log of any of `keys`, so no earlier log is overwritten.
    pub fn prepare(
        flag: &str,
        dir: &Path,
        keys: &[CellKey],
        machine: &Machine,
    ) -> Result<FrameLogger, InputError> {
        std::fs::create_dir_all(dir).map_err(|e| {
            InputError(format!(
                "{flag}: cannot create the folder {}: {e}",
                dir.display()
            ))
        })?;
        if let Some(taken) = keys
            .iter()
            .map(|k| dir.join(file_name(k)))
            .flat_map(|p| [provenance::sidecar(&p), p])
            .find(|p| p.exists())
        {
            return Err(InputError(format!(
                "{flag}: {} already exists; choose a folder without frame logs of these cells",
                taken.display()
            )));
        }
        Ok(FrameLogger {
            dir: dir.to_path_buf(),
            system: SystemLine::of(machine),
            written: Vec::new(),
            error: None,
        })
    }

    /// The logs written, or the first write that failed.
    pub fn finish(self) -> Result<Vec<PathBuf>, String> {
        match self.error {
            Some(e) => Err(e),
            None => Ok(self.written.into_iter().map(|(path, _)| path).collect()),
        }
    }

    fn fail(&mut self, path: &Path, e: std::io::Error) {
        self.error
            .get_or_insert_with(|| format!("{}: {e}", path.display()));
    }
}

impl Observer for FrameLogger {
    fn cell_finished(&mut self, cell: &Cell, last_trial: &Trial) {
        let frames: Vec<u64> = last_trial.frames.iter().map(|f| f.total_ns).collect();
        let path = self.dir.join(file_name(&cell.key));
        match write_atomic(&path, to_csv(&self.system, &frames).as_bytes()) {
            Ok(()) => self.written.push((path, cell.key.clone())),
            Err(e) => self.fail(&path, e),
        }
    }

    // Rewritten after every row, not once: a trial's placement is a class against all the
    // run's round trips, so the last row's write holds the placement results.json ends with.
    fn row_finished(&mut self, results: &Results) {
        let mut failed = Vec::new();
        for (path, key) in &self.written {
            let Some(cell) = results.cell(key) else {
                continue;
            };
            let record = Provenance::of(results, vec![CellFacts::of(key.label(), cell)]);
            let sidecar = provenance::sidecar(path);
            let json = serde_json::to_vec_pretty(&record).map_err(std::io::Error::other);
            if let Err(e) = json.and_then(|j| write_atomic(&sidecar, &j)) {
                failed.push((sidecar, e));
            }
        }
        for (path, e) in failed {
            self.fail(&path, e);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn marks_in_parentheses_go_as_mangohud_drops_them() {
        assert_eq!(
            without_parentheses("Intel(R) Xeon(R) CPU @ 2.20GHz"),
            "Intel Xeon CPU @ 2.20GHz"
        );
        assert_eq!(without_parentheses("AMD EPYC 7B13"), "AMD EPYC 7B13");
    }

    #[test]
    fn no_system_value_holds_a_comma() {
        let line = SystemLine {
            os: "Debian, 12".into(),
            cpu: "x".into(),
            gpu: String::new(),
            ram_kib: Some(1024),
            kernel: "6.1".into(),
            driver: String::new(),
            cpu_scheduler: "performance\n".into(),
        };
        assert_eq!(line.text(), "Debian  12,x,,1024,6.1,,performance");
    }
}
