//! The commands, one file each; `execute` dispatches a parsed command line to them.

mod balance;
mod bench_record;
mod chart;
mod compare;
mod docs;
mod doctor;
mod export;
mod findings;
mod history;
mod interrupt;
mod latency;
mod mesh;
mod placement;
mod report;
mod run;
mod shell;
mod sweep;

use crate::affinity;
use crate::cli::{Cli, Command, WaitArgs};
use crate::config::InputError;
use crate::lock::{self, Lock, LockError};
use crate::report::chart::{self as charts, ChartOptions};
use crate::results::Results;
use std::path::{Path, PathBuf};

/// Why a command failed; each kind has its exit status.
#[derive(Debug, thiserror::Error)]
pub enum CliError {
    /// The user's input is wrong (exit 2).
    #[error(transparent)]
    Input(#[from] InputError),
    /// Something failed while running (exit 1).
    #[error(transparent)]
    Run(#[from] anyhow::Error),
    /// A comparison found a regression; its report is already printed (exit 1).
    #[error("a cell regressed beyond the threshold")]
    Regressed,
    /// A signal stopped the command; what it finished is kept and the message says where
    /// (exit 130, as shells report SIGINT).
    #[error("{0}")]
    Interrupted(String),
}

pub use crate::exit::{EXIT_BAD_INPUT, EXIT_FAILED, EXIT_INTERRUPTED};

impl CliError {
    /// The process exit status for this error.
    pub fn exit_code(&self) -> u8 {
        match self {
            CliError::Input(_) => EXIT_BAD_INPUT,
            CliError::Run(_) | CliError::Regressed => EXIT_FAILED,
            CliError::Interrupted(_) => EXIT_INTERRUPTED,
        }
    }
}

/// Runs a parsed command line.
pub fn execute(cli: Cli) -> Result<(), CliError> {
    match cli.command {
        Command::Run(args) => run::run(args),
        Command::Sweep(args) => sweep::sweep(args),
        Command::Chart(args) => chart::chart(args),
        Command::Compare(args) => compare::compare(args),
        Command::Report(args) => report::report(args),
        Command::Latency(args) => latency::latency(args),
        Command::Mesh(args) => mesh::mesh(args),
        Command::Doctor(args) => doctor::doctor(args),
        Command::Balance(args) => balance::balance(args),
        Command::Placement(args) => placement::placement(args),
        Command::Findings(args) => findings::findings(args),
        Command::Docs(args) => docs::docs(args),
        Command::BenchRecord(args) => bench_record::bench_record(args),
        Command::Completions(args) => shell::completions(args),
        Command::Man(args) => shell::man(args),
        Command::Export(args) => export::export(args),
        Command::History(args) => history::history(args),
    }
}

/// Reads a results file, its trials placed (a file from before schema 6 from whatever round
/// trips it holds).
fn load_results(path: &Path) -> Result<Results, CliError> {
    let mut results = Results::load(path).map_err(|e| InputError(e.to_string()))?;
    crate::findings::placement::label(&mut results);
    Ok(results)
}

/// The directory a results path stands for (a results.json's parent, or the directory itself).
fn results_dir(path: &Path) -> PathBuf {
    if path.is_dir() {
        path.to_path_buf()
    } else {
        path.parent()
            .map_or_else(|| PathBuf::from("."), Path::to_path_buf)
    }
}

/// `results/<name>-<UTC timestamp>`: where a run writes when `--out` is not given.
fn default_out_dir(name: &str) -> PathBuf {
    let stamp: String = crate::sweep::utc_now()
        .chars()
        .filter(|c| c.is_ascii_alphanumeric())
        .collect();
    PathBuf::from("results").join(format!("{name}-{stamp}"))
}

/// Creates the results directory and locks it, refusing one that already holds results or that
/// another run is writing.
fn prepare_out_dir(dir: &Path) -> Result<Lock, CliError> {
    std::fs::create_dir_all(dir)
        .map_err(|e| InputError(format!("--out: cannot create {}: {e}", dir.display())))?;
    let lock = lock_out_dir(dir, "--out")?;
    for file in ["results.json", crate::results::latency::FILE_NAME] {
        if dir.join(file).exists() {
            return Err(InputError(format!(
                "--out: {} already holds {file}; choose another directory",
                dir.display()
            ))
            .into());
        }
    }
    Ok(lock)
}

/// Locks the results directory `dir` (named by `flag` in the error) for this run's writes.
fn lock_out_dir(dir: &Path, flag: &str) -> Result<Lock, CliError> {
    lock::out_dir(dir).map_err(|e| match e {
        LockError::Held { holder, .. } => InputError(format!(
            "{flag}: {} is being written by another run ({holder}); wait for it or choose another directory",
            dir.display()
        ))
        .into(),
        e @ LockError::Io { .. } => anyhow::anyhow!("locking {}: {e}", dir.display()).into(),
    })
}

/// Locks the cores a command measures on, waiting (with one message) while another run holds
/// any of them, or refusing at once with `--no-wait`.
fn lock_cores(cores: &[usize], wait: &WaitArgs) -> Result<Vec<Lock>, CliError> {
    let stop = interrupt::flag();
    let stopped = || stop.load(std::sync::atomic::Ordering::SeqCst);
    let announce = |e: &LockError| {
        eprintln!(
            "oceanbench: waiting for another run to finish measuring on core(s) {}: {e}",
            affinity::list(cores)
        )
    };
    lock::cores(cores, !wait.no_wait, announce, stopped).map_err(|e| match e {
        LockError::Held { .. } if stopped() => CliError::Interrupted(format!(
            "interrupted while waiting for core(s) {}",
            affinity::list(cores)
        )),
        e @ LockError::Held { .. } => InputError(format!(
            "--no-wait: another run is measuring on core(s) {}: {e}; wait for it (drop --no-wait) or choose other cores with --cores",
            affinity::list(cores)
        ))
        .into(),
        e @ LockError::Io { .. } => anyhow::anyhow!("locking cores: {e}").into(),
    })
}

/// Draws every chart and prints where they went and which were skipped.
fn draw_charts(runs: &[Results], out: &Path, options: &ChartOptions) -> Result<(), CliError> {
    let drawn = charts::draw_with(runs, out, options).map_err(anyhow::Error::from)?;
    report_drawn(&drawn);
    Ok(())
}

/// Says which chart files were written, and why any chart was not.
fn report_drawn(drawn: &charts::Drawn) {
    for file in &drawn.files {
        println!("chart: {}", file.display());
    }
    for s in &drawn.skipped {
        eprintln!("oceanbench: chart {} skipped: {}", s.chart, s.reason);
    }
}

/// The main and helper cores a command measures on: the ones given, or the first two allowed
/// (one core alone stands for both).
fn chosen_cores(given: Option<&[usize]>) -> Result<[usize; 2], InputError> {
    let allowed = affinity::allowed_cores();
    let cores = match given {
        Some(c) => {
            affinity::check_allowed(c)?;
            c.to_vec()
        }
        None => allowed.iter().copied().take(2).collect(),
    };
    match cores.as_slice() {
        [only] => Ok([*only, *only]),
        [a, b] => Ok([*a, *b]),
        [] => Err(InputError(
            "cores: no core is allowed for this process".into(),
        )),
        _ => Err(InputError(format!(
            "--cores: give one or two core ids, got {}",
            affinity::list(&cores)
        ))),
    }
}

/// [`chosen_cores`] for a command that measures between the two cores (`latency`, `doctor`):
/// one core stands for itself, but two must differ.
fn two_cores(given: Option<&[usize]>) -> Result<[usize; 2], InputError> {
    match given {
        Some([a, b]) if a == b => Err(InputError(format!(
            "--cores: give two different cores (or one), got {a},{b}"
        ))),
        _ => chosen_cores(given),
    }
}

/// The command line this process was started with, for the results file.
fn command_line() -> Vec<String> {
    std::env::args_os()
        .map(|a| a.to_string_lossy().into_owned())
        .collect()
}

/// Refuses an output file `flag` names whose folder does not exist (or is no folder), before
/// anything is read or written: bad input (exit 2), not a failed run.
fn check_out_file(flag: &str, path: &Path) -> Result<(), InputError> {
    let folder = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    if folder.is_dir() {
        Ok(())
    } else {
        Err(InputError(format!(
            "{flag}: {} is no folder; create it first or write elsewhere",
            folder.display()
        )))
    }
}

/// Refuses a `--threshold` that is not a finite percentage >= 0.
fn check_threshold(threshold: f64) -> Result<(), InputError> {
    if threshold.is_finite() && threshold >= 0.0 {
        Ok(())
    } else {
        Err(InputError(format!(
            "--threshold: must be a finite percentage >= 0, got {threshold}"
        )))
    }
}

/// Fails (exit 1) when any cell failed; the results already say why.
fn fail_on_errors(results: &Results) -> Result<(), CliError> {
    let failed = results.cells.iter().filter(|c| c.error.is_some()).count();
    if failed > 0 {
        return Err(anyhow::anyhow!("{failed} cell(s) failed; see the results").into());
    }
    Ok(())
}
