//! The results file: the interface between measuring and reporting. Tables, charts and
//! comparisons are drawn from it alone.

pub mod balance;
pub mod latency;

use crate::calibrate::{RowCalibration, Yardstick};
pub use crate::cell::CellKey;
use crate::config::{Level, SweepConfig};
use crate::crosscore::RoundTrip;
use crate::machine::Machine;
use crate::sched::TrialNoise;
use crate::slow_trials::TrialRecord;
use crate::summary::Summary;
use crate::workload::Calibration;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The cores a cell ran on and whether the pins held.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Pins {
    /// Main thread's core.
    pub main_core: usize,
    /// Helper's core (`null` in serial).
    pub helper_core: Option<usize>,
    /// Main thread's pin held.
    pub main_held: bool,
    /// Helper's pin held (`null` in serial).
    pub helper_held: Option<bool>,
}

/// One measured (or failed) cell.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Cell {
    /// The cell's parameters.
    #[serde(flatten)]
    pub key: CellKey,
    /// Workload iterations per frame (the synthetic chain's; `render`'s submit cost).
    pub workload_iterations: u64,
    /// The unit of the cell's workload kind (absent before schema 2: `iterations`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub workload_unit: Option<String>,
    /// The cell's workload level in that unit (absent before schema 2: the iterations).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub workload_amount: Option<u64>,
    /// The measurements; absent when the cell failed.
    #[serde(flatten)]
    pub summary: Option<Summary>,
    /// Every pin of every trial held.
    pub pinned: bool,
    /// Cores and pins of the last trial.
    pub pins: Pins,
    /// Why the cell failed, if it did.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
    /// How the cell's workload level was set, and how far the machine had drifted when its
    /// row started (absent in results from before per-row calibration).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub calibration: Option<RowCalibration>,
    /// Each trial's FPS, breakdown, speed canaries and round trips, and why a slow one was slow
    /// (absent before schema 3).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub trials: Vec<TrialRecord>,
    /// What disturbed the cell's trials (absent in results from before it was recorded).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub noise: Option<CellNoise>,
    /// What the cell's workload kind recorded of its own work, the median over trials (the
    /// fog's volume, octaves and time per part of its pass; absent for other kinds).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub work: Option<crate::workload::WorkRecord>,
    /// Trials re-run because the cell mixed placements, and set aside because another
    /// placement reached the cell's trial count first (absent when none was).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub set_aside: Vec<TrialRecord>,
}

impl Cell {
    /// The unit of the cell's workload level (files before schema 2: iterations).
    pub fn workload_unit(&self) -> &str {
        self.workload_unit.as_deref().unwrap_or("iterations")
    }

    /// Whether a kept trial was disturbed beyond the noise threshold (the tables' †).
    pub fn noisy(&self) -> bool {
        self.noise.as_ref().is_some_and(|n| n.noisy_trials() > 0)
    }

    /// Trials more than the slow-trial threshold below the cell's median that nothing recorded
    /// explains (the tables' ‡).
    pub fn unexplained_slow_trials(&self) -> usize {
        self.trials.iter().filter(|t| t.unexplained()).count()
    }

    /// Whether its kept trials ran in more than one placement, or moved during one (the tables'
    /// §), by their labels ([`crate::findings::placement::label`]).
    pub fn mixed_placements(&self) -> bool {
        let classes: Vec<_> = self.trials.iter().map(|t| t.placement).collect();
        crate::placement::mixed(&classes)
    }

    /// The cell as if only its trials in placement `class` had been kept, for comparing runs
    /// within one placement: those trials' records, FPS and waiting CPU; no summary (and an
    /// error naming the placement) when none ran there. The summary's frame times and breakdown
    /// stay those of every trial: only the per-trial values are split.
    pub fn in_placement(&self, class: crate::placement::Class) -> Cell {
        let keep: Vec<bool> = self
            .trials
            .iter()
            .map(|t| t.placement == Some(class))
            .collect();
        let mut cell = self.clone();
        cell.trials.retain(|t| t.placement == Some(class));
        if cell.trials.is_empty() {
            cell.summary = None;
            cell.error = Some(format!("no trial ran in placement {class}"));
            return cell;
        }
        if let Some(s) = &mut cell.summary {
            s.fps_trials = cell.trials.iter().map(|t| t.fps).collect();
            s.wait_cpu_ms_trials = if s.wait_cpu_ms_trials.len() == keep.len() {
                let pairs = s.wait_cpu_ms_trials.iter().zip(&keep);
                pairs.filter(|(_, &k)| k).map(|(&w, _)| w).collect()
            } else {
                Vec::new()
            };
        }
        cell
    }

    /// The cell's workload level in [`Cell::workload_unit`].
    pub fn workload_amount(&self) -> u64 {
        self.workload_amount.unwrap_or(self.workload_iterations)
    }
}

/// What disturbed a cell's trials, and what was done about it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CellNoise {
    /// Each kept trial's run delay, preemptions and steal.
    pub trials: Vec<TrialNoise>,
    /// A trial whose run delay or steal took more than this share of its wall time is noisy.
    pub threshold_percent: f64,
    /// Noisy trials re-run and thrown away.
    pub retries: usize,
}

impl CellNoise {
    /// Kept trials that are still noisy (their retries ran out).
    pub fn noisy_trials(&self) -> usize {
        self.trials
            .iter()
            .filter(|t| t.is_noisy(self.threshold_percent))
            .count()
    }

    /// The worst trial's largest share of the wall time a thread was kept off its core by
    /// other tasks, in percent.
    pub fn preempted_percent(&self) -> f64 {
        self.worst(TrialNoise::preempted_percent)
    }

    /// The worst trial's largest steal of a pinned core, in percent of its wall time.
    pub fn steal_percent(&self) -> f64 {
        self.worst(TrialNoise::steal_percent)
    }

    /// Involuntary context switches of every thread over the kept trials.
    pub fn involuntary_switches(&self) -> u64 {
        self.trials
            .iter()
            .map(TrialNoise::involuntary_switches)
            .sum()
    }

    fn worst(&self, share: fn(&TrialNoise) -> f64) -> f64 {
        self.trials.iter().map(share).fold(0.0, f64::max)
    }
}

/// A resolved workload level.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LevelRecord {
    /// Workload index.
    pub workload: usize,
    /// The level as configured.
    pub level: Level,
    /// Microseconds of one core's work it came to.
    pub micros: f64,
    /// Workload iterations per frame.
    pub iterations: u64,
}

/// A mesh step time measured to resolve `step_fraction` levels.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StepTime {
    /// Mesh size N.
    pub size: usize,
    /// Median single-thread step time (ms), reference kernel and `neighbors` normals.
    pub median_ms: f64,
}

/// What was measured before the cells to turn levels into iterations.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CalibrationRecord {
    /// The workload's speed on this machine.
    pub workload: Calibration,
    /// Step times of the sizes that levels refer to.
    pub step_times: Vec<StepTime>,
    /// Each level's microseconds and iterations at the start.
    pub levels: Vec<LevelRecord>,
    /// The yardstick at the start: every size's step and the workload's speed, measured the
    /// way each row measures them again (absent in results from before per-row calibration).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub start: Option<Yardstick>,
}

/// The cross-core round trip at the start, between groups of cells, and at the end of a run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Placement {
    /// Measured before the first cell.
    pub before: Option<RoundTrip>,
    /// Measured after each group of interleaved cells.
    #[serde(default)]
    pub during: Vec<RoundTrip>,
    /// Measured after the last cell.
    pub after: Option<RoundTrip>,
    /// Whether the OS lists the two cores as thread siblings of one physical core
    /// (`thread_siblings_list`; in a VM, the guest's view, not where the host put the vCPUs).
    /// Absent when not read.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub thread_siblings: Option<bool>,
}

pub use crate::crosscore::PLACEMENT_CHANGE_RATIO;

impl Placement {
    /// Every measurement in time order.
    pub fn all(&self) -> impl Iterator<Item = &RoundTrip> {
        self.before.iter().chain(&self.during).chain(&self.after)
    }

    /// (fastest, slowest) median round trip when they differ by more than
    /// [`PLACEMENT_CHANGE_RATIO`]: the two cores moved between near and far placements mid-run.
    pub fn changed(&self) -> Option<(f64, f64)> {
        let medians: Vec<f64> = self.all().map(|r| r.median_ns).collect();
        let lo = medians.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = medians.iter().copied().fold(0.0, f64::max);
        (medians.len() > 1 && hi > lo * PLACEMENT_CHANGE_RATIO).then_some((lo, hi))
    }
}

/// The layout of results.json this build writes. Every change to the layout bumps it; files
/// of every earlier version still load, and a file of a later one is refused rather than
/// misread. 2: cells carry `ocean`, `workload_kind`, `workload_unit` and `workload_amount`, and
/// the config `camera`; absent, they mean the sums of sines, the synthetic workload in iterations
/// and the default camera. 3: cells carry `trials` (each trial's breakdown, canaries, round
/// trips and slow-trial causes) and the config `slow_trial_percent`; absent, a cell has no
/// per-trial records and the threshold is 10. 4: the run records its `command` line, and the
/// config may carry `fft_params` (the FFT ocean's), and the yardsticks `model_step_ms` (every
/// model's step but the sines'); absent, the command was not recorded, the FFT ocean takes its
/// defaults and only the sines were measured. 5: cells carry `grid`, spray's per-trial
/// `particles` and a kind's own `work` record (the fog's), the config `spray`, `fog` and the
/// camera's `far` and `path`, and a balance entry its `unit_cost`; absent, the regular grid, no
/// particle or work records, the defaults, a still camera and a balance in microseconds. 6: every
/// trial (serial and UP too) carries its round trips and `placement`, a cell the trials it
/// `set_aside` for another placement, the run its `placement` split and whether the OS lists
/// the two cores as `thread_siblings`, a balance probe its `round_trip_ns`, `step_us` and
/// `placement`, and a balance entry its headline `placement`, the probes it `set_aside` and
/// the balance `placements` one by one; absent, placements are inferred from whatever round
/// trips the file holds (DP trials only, before schema 6). 7: a counting kind's trials are
/// `work_trials`, each count under the kind's key with its mean, fewest and most per frame,
/// and a kind's `work` record is a flat object of named numbers; files before it hold spray's
/// counts under `particles` and the fog's record under `{"fog": {...}}`, and read back into the
/// same keys.
pub const SCHEMA_VERSION: u32 = 7;

/// Files written before the field existed have today's layout, version 1.
fn version_1() -> u32 {
    1
}

/// A whole results file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Results {
    /// The layout's version ([`SCHEMA_VERSION`] when written by this build).
    #[serde(default = "version_1")]
    pub schema_version: u32,
    /// The machine measured on.
    pub machine: Machine,
    /// The command line that started the run, program first (absent before schema 3).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub command: Option<Vec<String>>,
    /// The config as run.
    pub config: SweepConfig,
    /// Workload and step calibration.
    pub calibration: CalibrationRecord,
    /// Cache-line round trip between the two cores: before the first row, after every row and
    /// after the last.
    pub round_trip: Placement,
    /// UTC time the run started (RFC 3339).
    pub started: String,
    /// UTC time the run finished; absent while it runs or if it was interrupted.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub finished: Option<String>,
    /// Every finished cell, in the order run.
    pub cells: Vec<Cell>,
    /// What `doctor` found before the run (absent when it was not run).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub doctor: Option<crate::doctor::Report>,
    /// Balance points found (`oceanbench balance`, or a sweep with a `balance` key).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub balance: Vec<balance::BalanceEntry>,
    /// Balance searches a sweep could not complete, and why.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub balance_failures: Vec<String>,
    /// Every round trip of the run as one cluster or two (near and far), against which each
    /// trial is placed (absent before schema 6, and when nothing was measured across two cores).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub placement: Option<crate::placement::Split>,
}

/// Why a results file could not be read; each names the file.
#[derive(Debug, thiserror::Error)]
pub enum LoadError {
    /// The file could not be read.
    #[error("results {}: {source}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// What the OS said.
        source: std::io::Error,
    },
    /// The file was written by a newer oceanbench, in a layout this build does not know.
    #[error("{}: results schema version {found}, newer than this build's {SCHEMA_VERSION}; read it with a newer oceanbench", path.display())]
    Newer {
        /// The file.
        path: PathBuf,
        /// Its schema version.
        found: u32,
    },
    /// The file is not a results file.
    #[error("{}: not an oceanbench results file: {source}", path.display())]
    Parse {
        /// The file.
        path: PathBuf,
        /// What the parser said.
        source: serde_json::Error,
    },
}

impl Results {
    /// The run with every cell cut to its trials in placement `class` ([`Cell::in_placement`]).
    pub fn in_placement(&self, class: crate::placement::Class) -> Results {
        Results {
            cells: self.cells.iter().map(|c| c.in_placement(class)).collect(),
            ..self.clone()
        }
    }

    /// Reads a results file, or the `results.json` inside a results directory.
    pub fn load(path: &Path) -> Result<Results, LoadError> {
        let path = if path.is_dir() {
            path.join("results.json")
        } else {
            path.to_path_buf()
        };
        let text = match std::fs::read_to_string(&path) {
            Ok(text) => text,
            Err(source) => return Err(LoadError::Read { path, source }),
        };
        // The version is read first, so a newer layout is named as such rather than reported
        // as whatever field it changed.
        #[derive(Deserialize)]
        struct Version {
            #[serde(default = "version_1")]
            schema_version: u32,
        }
        if let Ok(Version { schema_version }) = serde_json::from_str::<Version>(&text) {
            if schema_version > SCHEMA_VERSION {
                return Err(LoadError::Newer {
                    path,
                    found: schema_version,
                });
            }
        }
        serde_json::from_str(&text).map_err(|source| LoadError::Parse { path, source })
    }

    /// The cell with `key`, if it was measured.
    pub fn cell(&self, key: &CellKey) -> Option<&Cell> {
        self.cells.iter().find(|c| &c.key == key)
    }
}
