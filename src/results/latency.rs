//! A latency run as a results file: every method's round trip on each placement, measured
//! several times over, with the machine, commit and cores it ran on, so `report`, `chart` and
//! `compare` read it as they read a sweep's results. Files written before the layout was
//! versioned hold a bare list of rows, one measurement each, and no machine; they still load.

use crate::machine::Machine;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The layout version [`LatencyRun`] is written with.
pub const SCHEMA_VERSION: u32 = 1;

/// The file a latency run's folder holds.
pub const FILE_NAME: &str = "latency.json";

/// Round trips per batch in the batched timing: one clock read per batch.
pub const BATCH: u64 = 64;

/// The row every other is measured against: the raw cache line between the two cores.
pub const FLOOR: &str = "ping-pong";

/// The fewest and most repeats a run may measure.
pub const REPEATS: std::ops::RangeInclusive<usize> = 1..=100;

/// The repeats `oceanbench latency` measures when not told: enough for compare's verdicts.
pub const DEFAULT_REPEATS: usize = 5;

/// One measured row: a method on one placement.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LatencyRow {
    /// `ping-pong` for the raw cache line, else the hand-off method's name.
    pub method: String,
    /// Main thread's core.
    pub main_core: usize,
    /// Helper's core (equal to `main_core` on one core).
    pub helper_core: usize,
    /// Median round trip (ns) over batches of round trips timed with one clock read per batch:
    /// the central figure, free of the clock's own cost (absent in files from before).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub batched_ns: Option<f64>,
    /// Median round trip (ns), each trip timed on its own (clock reads included).
    pub median_ns: f64,
    /// 99th percentile round trip (ns), each trip timed on its own.
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

/// One method on one placement, measured [`LatencyRun::repeats`] times.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MethodRepeats {
    /// `ping-pong` for the raw cache line, else the hand-off method's name.
    pub method: String,
    /// Main thread's core.
    pub main_core: usize,
    /// Helper's core (equal to `main_core` on one core).
    pub helper_core: usize,
    /// Each repeat's row, in the order measured.
    pub repeats: Vec<LatencyRow>,
}

impl MethodRepeats {
    /// `atomic on 0,1`: the method and its two cores, unique within a run.
    pub fn label(&self) -> String {
        format!("{} on {},{}", self.method, self.main_core, self.helper_core)
    }

    /// Each repeat's central round trip in ns: batched where it was, else timed trip by trip.
    pub fn round_trips(&self) -> Vec<f64> {
        self.repeats
            .iter()
            .map(|r| r.batched_ns.unwrap_or(r.median_ns))
            .collect()
    }

    /// One row standing for the repeats: the median over them of each figure, the samples
    /// added up, pinned only when every repeat's pins held.
    pub fn summary(&self) -> LatencyRow {
        let median = |f: &dyn Fn(&LatencyRow) -> Option<f64>| {
            let values: Vec<f64> = self.repeats.iter().filter_map(f).collect();
            (!values.is_empty()).then(|| crate::stats::median(&values))
        };
        LatencyRow {
            method: self.method.clone(),
            main_core: self.main_core,
            helper_core: self.helper_core,
            batched_ns: median(&|r| r.batched_ns),
            median_ns: median(&|r| Some(r.median_ns)).unwrap_or(f64::NAN),
            p99_ns: median(&|r| Some(r.p99_ns)).unwrap_or(f64::NAN),
            samples: self.repeats.iter().map(|r| r.samples).sum(),
            cpu_ns: median(&|r| r.cpu_ns),
            pinned: self.repeats.iter().all(|r| r.pinned),
        }
    }
}

/// A latency run as written to `results/latency-<UTC>/latency.json`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LatencyRun {
    /// The layout version ([`SCHEMA_VERSION`]); 0 for a bare list of rows from before.
    pub schema_version: u32,
    /// The machine and commit measured on (absent in a bare list).
    pub machine: Option<Machine>,
    /// The command line that made the run, program first (absent in a bare list).
    pub command: Option<Vec<String>>,
    /// UTC time the run started, RFC 3339 (empty in a bare list).
    pub started: String,
    /// UTC time the run finished.
    pub finished: Option<String>,
    /// Round trips asked per repeat of each row (each row also stops at its time budget).
    pub samples: usize,
    /// Times each row was measured, the rows of one repeat one after another.
    pub repeats: usize,
    /// Every method on every placement, in the order of the table.
    pub rows: Vec<MethodRepeats>,
}

/// Why a latency run could not be read; each names the file.
#[derive(Debug, thiserror::Error)]
pub enum LatencyRunError {
    /// The file could not be read.
    #[error("{path}: {source}")]
    Read {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// The file is not a latency run.
    #[error("{path}: not an oceanbench latency run: {why}")]
    Parse {
        /// The file.
        path: PathBuf,
        /// What serde said.
        why: String,
    },
    /// Written by a newer build.
    #[error("{path}: latency layout version {found} is newer than this build reads ({SCHEMA_VERSION}); update oceanbench")]
    Newer {
        /// The file.
        path: PathBuf,
        /// Its version.
        found: u32,
    },
}

impl LatencyRun {
    /// Whether `path` is a latency run: a folder holding latency.json and no results.json, or a
    /// latency.json itself.
    pub fn is_latency_run(path: &Path) -> bool {
        if path.is_dir() {
            path.join(FILE_NAME).is_file() && !path.join("results.json").exists()
        } else {
            path.file_name().is_some_and(|n| n == FILE_NAME)
        }
    }

    /// Reads a run from its folder or its latency.json, either layout.
    pub fn load(path: &Path) -> Result<LatencyRun, LatencyRunError> {
        let path = if path.is_dir() {
            path.join(FILE_NAME)
        } else {
            path.to_path_buf()
        };
        let text = std::fs::read_to_string(&path).map_err(|source| LatencyRunError::Read {
            path: path.clone(),
            source,
        })?;
        let parse = |why: serde_json::Error| LatencyRunError::Parse {
            path: path.clone(),
            why: why.to_string(),
        };
        let value: serde_json::Value = serde_json::from_str(&text).map_err(parse)?;
        let run = if value.is_array() {
            let rows: Vec<LatencyRow> = serde_json::from_value(value).map_err(parse)?;
            LatencyRun::from_bare_rows(rows)
        } else {
            serde_json::from_value(value).map_err(parse)?
        };
        if run.schema_version > SCHEMA_VERSION {
            return Err(LatencyRunError::Newer {
                path,
                found: run.schema_version,
            });
        }
        if run.rows.is_empty() {
            return Err(LatencyRunError::Parse {
                path,
                why: "it has no rows".into(),
            });
        }
        Ok(run)
    }

    /// A bare list from before the layout was versioned: one repeat per row, nothing recorded.
    fn from_bare_rows(rows: Vec<LatencyRow>) -> LatencyRun {
        LatencyRun {
            schema_version: 0,
            machine: None,
            command: None,
            started: String::new(),
            finished: None,
            samples: rows.iter().map(|r| r.samples).max().unwrap_or(0),
            repeats: 1,
            rows: rows
                .into_iter()
                .map(|r| MethodRepeats {
                    method: r.method.clone(),
                    main_core: r.main_core,
                    helper_core: r.helper_core,
                    repeats: vec![r],
                })
                .collect(),
        }
    }

    /// One row per method and placement, each standing for its repeats.
    pub fn summary_rows(&self) -> Vec<LatencyRow> {
        self.rows.iter().map(MethodRepeats::summary).collect()
    }

    /// The floor on the same two cores as `row`.
    pub fn floor_of(&self, row: &MethodRepeats) -> Option<&MethodRepeats> {
        self.rows.iter().find(|f| {
            f.method == FLOOR && (f.main_core, f.helper_core) == (row.main_core, row.helper_core)
        })
    }
}
