//! A benchmark run as a committed file: the estimates of one `cargo bench` (or of the
//! `kernel_ratio` example) with the machine and commit they were measured on, so the numbers
//! the docs quote are held by a file in `results/bench-<name>-<UTC>/bench.json`.
//!
//! Criterion 0.5 has no documented machine-readable output of its own (that is cargo-criterion's
//! `--message-format=json`, a separate tool), so [`BenchRun::from_criterion`] reads the files it
//! writes under `target/criterion`, which its docs call internal: `<id>/new/estimates.json` and
//! `<id>/new/benchmark.json`, right after the run that wrote them. Cargo.toml keeps criterion at
//! 0.5 for that reason.

use crate::machine::Machine;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::time::SystemTime;

/// The layout version [`BenchRun::write`] writes.
pub const SCHEMA_VERSION: u32 = 1;

/// The file a run's folder holds.
pub const FILE_NAME: &str = "bench.json";

/// A benchmark run as committed under `results/bench-<name>-<UTC>/bench.json`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BenchRun {
    /// The layout version ([`SCHEMA_VERSION`]).
    pub schema_version: u32,
    /// The bench target or example: `fft`, `kernels`, `kernel_ratio`, ...
    pub name: String,
    /// When the run started, RFC 3339 UTC.
    pub started: String,
    /// The machine and commit it ran on.
    pub machine: Machine,
    /// How it was made, e.g. `["scripts/bench-run.sh", "fft", "fft-512"]`.
    pub command: Vec<String>,
    /// One sentence: where the numbers were read from and what the interval is.
    pub source: String,
    /// The estimates, in the order they were measured.
    pub estimates: Vec<BenchEstimate>,
}

/// One benchmark's estimate.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BenchEstimate {
    /// Criterion's full id, e.g. `fft-512/model transforms` or `heights/fused/256`.
    pub id: String,
    /// `ns` for times per iteration, or e.g. `Mvertices/s`.
    pub unit: String,
    /// The point estimate (criterion: the median's).
    pub value: f64,
    /// The interval's lower bound (criterion: of the median's confidence interval).
    pub lower: f64,
    /// The interval's upper bound.
    pub upper: f64,
    /// What one iteration processes, when the bench said so.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub throughput: Option<Throughput>,
}

/// What one iteration of a benchmark processes, as criterion's `Throughput`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Throughput {
    /// Elements per iteration (vertices, flops, samples: the bench's doc says which).
    Elements(u64),
    /// Bytes per iteration (criterion's `BytesDecimal` too: it differs only in display).
    Bytes(u64),
}

/// Why a benchmark run could not be read or built; each names the file or folder.
#[derive(Debug, thiserror::Error)]
pub enum BenchRunError {
    /// A file or folder could not be read.
    #[error("{}: {source}", path.display())]
    Read {
        /// The file or folder.
        path: PathBuf,
        /// What the OS said.
        source: std::io::Error,
    },
    /// A file is not what it should be.
    #[error("{}: {what}: {source}", path.display())]
    Parse {
        /// The file.
        path: PathBuf,
        /// What it should have been.
        what: &'static str,
        /// What the parser said.
        source: serde_json::Error,
    },
    /// The file was written by a newer oceanbench.
    #[error("{}: bench run schema version {found}, newer than this build's {SCHEMA_VERSION}", path.display())]
    Newer {
        /// The file.
        path: PathBuf,
        /// Its schema version.
        found: u32,
    },
    /// No criterion estimate was written since the run started.
    #[error("no criterion estimates in {} written since {since} (did cargo bench run, and did its filter match?)", dir.display())]
    NoEstimates {
        /// The criterion folder.
        dir: PathBuf,
        /// When the run started, RFC 3339 UTC.
        since: String,
    },
}

/// Takes `--out DIR` out of an example's arguments, for the folder its [`BenchRun`] goes to;
/// `None` when it is not given. A `--out` with no folder after it is refused in one line.
pub fn take_out_arg(args: &mut Vec<String>) -> Result<Option<PathBuf>, String> {
    let Some(i) = args.iter().position(|a| a == "--out") else {
        return Ok(None);
    };
    let dir = args
        .get(i + 1)
        .cloned()
        .ok_or("--out: needs a folder after it")?;
    args.drain(i..=i + 1);
    Ok(Some(PathBuf::from(dir)))
}

/// An example's arguments after its name, with `--out DIR` taken out ([`take_out_arg`]); a
/// `--out` with no folder ends the process with its one-line reason and exit status 2.
pub fn example_args() -> (Vec<String>, Option<PathBuf>) {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    match take_out_arg(&mut args) {
        Ok(out) => (args, out),
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(2)
        }
    }
}

impl BenchRun {
    /// Reads a run from its folder or its bench.json.
    pub fn load(path: &Path) -> Result<BenchRun, BenchRunError> {
        let path = if path.is_dir() {
            path.join(FILE_NAME)
        } else {
            path.to_path_buf()
        };
        let run: BenchRun = read_json(&path, "not an oceanbench bench run")?;
        if run.schema_version > SCHEMA_VERSION {
            return Err(BenchRunError::Newer {
                path,
                found: run.schema_version,
            });
        }
        Ok(run)
    }

    /// The estimate with this id.
    pub fn estimate(&self, id: &str) -> Option<&BenchEstimate> {
        self.estimates.iter().find(|e| e.id == id)
    }

    /// Creates `dir` and writes bench.json into it, pretty-printed and atomically.
    pub fn write(&self, dir: &Path) -> std::io::Result<()> {
        std::fs::create_dir_all(dir)?;
        let text = serde_json::to_string_pretty(self).map_err(std::io::Error::other)?;
        crate::report::json::write_atomic(&dir.join(FILE_NAME), text.as_bytes())
    }

    /// The run of bench `name` whose estimates criterion wrote into `criterion_dir` at or after
    /// `since` (earlier ones are from other runs), on this machine, made by `command`.
    pub fn from_criterion(
        name: &str,
        criterion_dir: &Path,
        since: SystemTime,
        command: Vec<String>,
    ) -> Result<BenchRun, BenchRunError> {
        let started = humantime::format_rfc3339_seconds(since).to_string();
        let mut found = Vec::new();
        collect_new(criterion_dir, since, &mut found)?;
        if found.is_empty() {
            return Err(BenchRunError::NoEstimates {
                dir: criterion_dir.to_path_buf(),
                since: started,
            });
        }
        // In the order criterion measured them, as the bench's output lists them.
        found.sort();
        let mut levels = Vec::new();
        let mut estimates = Vec::new();
        for (_, new_dir) in found {
            let (estimate, level) = criterion_estimate(&new_dir)?;
            if !levels.contains(&level) {
                levels.push(level);
            }
            estimates.push(estimate);
        }
        let levels: Vec<String> = levels
            .iter()
            .map(|l| format!("{}%", (l * 1000.0).round() / 10.0))
            .collect();
        let source = format!(
            "criterion 0.5's internal files under {} written since the run started: each \
             estimate is new/estimates.json's median time per iteration in ns with its {} \
             bootstrap confidence interval, its id and throughput from new/benchmark.json",
            criterion_dir.display(),
            levels.join(" / ")
        );
        Ok(BenchRun {
            schema_version: SCHEMA_VERSION,
            name: name.to_string(),
            started,
            machine: Machine::current(),
            command,
            source,
            estimates,
        })
    }
}

/// Reads and parses a JSON file, naming it in any error.
fn read_json<T: serde::de::DeserializeOwned>(
    path: &Path,
    what: &'static str,
) -> Result<T, BenchRunError> {
    let text = std::fs::read_to_string(path).map_err(read_error(path))?;
    serde_json::from_str(&text).map_err(|source| BenchRunError::Parse {
        path: path.to_path_buf(),
        what,
        source,
    })
}

/// The error of a failed read of `path`.
fn read_error(path: &Path) -> impl FnOnce(std::io::Error) -> BenchRunError + '_ {
    move |source| BenchRunError::Read {
        path: path.to_path_buf(),
        source,
    }
}

/// Adds every criterion `new/` folder under `dir` whose estimates.json was written at or after
/// `since`, with that time.
fn collect_new(
    dir: &Path,
    since: SystemTime,
    found: &mut Vec<(SystemTime, PathBuf)>,
) -> Result<(), BenchRunError> {
    for entry in std::fs::read_dir(dir).map_err(read_error(dir))? {
        let path = entry.map_err(read_error(dir))?.path();
        if !path.is_dir() {
            continue;
        }
        let estimates = path.join("estimates.json");
        if path.file_name() == Some("new".as_ref()) && estimates.is_file() {
            let modified = std::fs::metadata(&estimates)
                .and_then(|m| m.modified())
                .map_err(read_error(&estimates))?;
            if modified >= since {
                found.push((modified, path));
            }
        } else {
            collect_new(&path, since, found)?;
        }
    }
    Ok(())
}

/// The estimate in one criterion `new/` folder, with its confidence level.
fn criterion_estimate(new_dir: &Path) -> Result<(BenchEstimate, f64), BenchRunError> {
    // Only the fields used; criterion 0.5 writes these (src/estimate.rs, src/report.rs).
    #[derive(Deserialize)]
    struct Estimates {
        median: Estimate,
    }
    #[derive(Deserialize)]
    struct Estimate {
        point_estimate: f64,
        confidence_interval: Interval,
    }
    #[derive(Deserialize)]
    struct Interval {
        confidence_level: f64,
        lower_bound: f64,
        upper_bound: f64,
    }
    #[derive(Deserialize)]
    struct Benchmark {
        full_id: String,
        throughput: Option<CriterionThroughput>,
    }
    #[derive(Deserialize)]
    enum CriterionThroughput {
        Bytes(u64),
        BytesDecimal(u64),
        Elements(u64),
    }

    let estimates: Estimates = read_json(
        &new_dir.join("estimates.json"),
        "not criterion 0.5's estimates.json",
    )?;
    let benchmark: Benchmark = read_json(
        &new_dir.join("benchmark.json"),
        "not criterion 0.5's benchmark.json",
    )?;
    let median = estimates.median;
    let estimate = BenchEstimate {
        id: benchmark.full_id,
        unit: "ns".into(),
        value: median.point_estimate,
        lower: median.confidence_interval.lower_bound,
        upper: median.confidence_interval.upper_bound,
        throughput: benchmark.throughput.map(|t| match t {
            CriterionThroughput::Bytes(n) | CriterionThroughput::BytesDecimal(n) => {
                Throughput::Bytes(n)
            }
            CriterionThroughput::Elements(n) => Throughput::Elements(n),
        }),
    };
    Ok((estimate, median.confidence_interval.confidence_level))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn out_is_taken_from_anywhere_in_the_arguments_or_refused_without_a_folder() {
        let args = |v: &[&str]| v.iter().map(|s| s.to_string()).collect::<Vec<_>>();
        let mut a = args(&["256", "--out", "results/x", "7"]);
        assert_eq!(take_out_arg(&mut a), Ok(Some(PathBuf::from("results/x"))));
        assert_eq!(a, args(&["256", "7"]));
        let mut b = args(&["256"]);
        assert_eq!(take_out_arg(&mut b), Ok(None));
        assert_eq!(b, args(&["256"]));
        let mut c = args(&["256", "--out"]);
        assert_eq!(
            take_out_arg(&mut c),
            Err("--out: needs a folder after it".to_string())
        );
    }
}
