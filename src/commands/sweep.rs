//! `oceanbench sweep`: run a config (or resume one), write results after every row, print the
//! table, draw the charts and write the HTML report.

use super::{
    command_line, default_out_dir, draw_charts, fail_on_errors, interrupt, load_results,
    lock_cores, lock_out_dir, prepare_out_dir, results_dir, CliError,
};
use crate::cli::{NoiseArgs, SweepArgs};
use crate::config::{InputError, SweepConfig};
use crate::doctor;
use crate::frame_log::FrameLogger;
use crate::lock::Lock;
use crate::machine::Machine;
use crate::measure::Trial;
use crate::report::{self, chart::ChartOptions};
use crate::results::{Cell, CellKey, Results};
use crate::sweep::{Observer, Progress, Sweep};
use crate::trace::{CellFilter, Target, TracePlan, DEFAULT_FRAMES};
use std::path::{Path, PathBuf};
use std::time::Duration;

/// Names the top-level keys where two configs differ.
pub(super) fn config_differences(a: &SweepConfig, b: &SweepConfig) -> Vec<String> {
    let (Ok(serde_json::Value::Object(a)), Ok(serde_json::Value::Object(b))) =
        (serde_json::to_value(a), serde_json::to_value(b))
    else {
        return vec!["(unreadable)".into()];
    };
    let keys: std::collections::BTreeSet<&String> = a
        .keys()
        .chain(b.keys())
        .filter(|k| a.get(*k) != b.get(*k))
        .collect();
    keys.into_iter().cloned().collect()
}

/// The progress bar, the results files rewritten after every row and, when asked for, each
/// cell's frame log.
struct Writer<'a> {
    dir: &'a Path,
    bar: indicatif::ProgressBar,
    error: Option<report::WriteError>,
    frame_log: Option<FrameLogger>,
}

impl Observer for Writer<'_> {
    fn trial_starting(&mut self, p: Progress<'_>) {
        self.bar.set_length(p.total as u64);
        self.bar.set_position(p.done as u64);
        self.bar.set_message(p.cell.label());
    }

    fn cell_finished(&mut self, cell: &Cell, last_trial: &Trial) {
        if let Some(logger) = &mut self.frame_log {
            logger.cell_finished(cell, last_trial);
        }
    }

    fn row_finished(&mut self, results: &Results) {
        if let Err(e) = report::write_all(self.dir, results) {
            self.error.get_or_insert(e);
        }
        if let Some(logger) = &mut self.frame_log {
            logger.row_finished(results);
        }
    }
}

/// The sweep to run, where its results go, the locks of its results folder and cores (held until
/// it ends) and the frame logger `--frame-log` asks for.
struct Start {
    sweep: Sweep,
    dir: PathBuf,
    _locks: Vec<Lock>,
    frame_log: Option<FrameLogger>,
}

/// The `--frame-log` logger for the cells `keys`, refused before anything is measured.
fn frame_logger(args: &SweepArgs, keys: &[CellKey]) -> Result<Option<FrameLogger>, CliError> {
    let Some(dir) = &args.frame_log else {
        return Ok(None);
    };
    Ok(Some(FrameLogger::prepare(
        "--frame-log",
        dir,
        keys,
        &Machine::current(),
    )?))
}

/// A new sweep, or the rest of an interrupted one.
fn start(args: &SweepArgs) -> Result<Option<Start>, CliError> {
    let config = match &args.config {
        Some(path) => Some(SweepConfig::load(path)?),
        None => None,
    };
    let Some(dir) = &args.resume else {
        let mut config = config.unwrap_or_default();
        args.noise.apply(&mut config);
        let mut flags = args.noise.flag_fields();
        if let Some(cores) = &args.cores {
            config.cores = Some(cores.clone());
            flags.push(("cores", "--cores".into()));
        }
        config.validate().map_err(|e| e.naming_flags(&flags))?;
        let frame_log = frame_logger(args, &crate::sweep::cells(&config))?;
        for note in config
            .notes
            .iter()
            .cloned()
            .chain(crate::sweep::kind_skips(&config))
        {
            eprintln!("oceanbench: {note}");
        }
        let trace = args
            .trace
            .as_ref()
            .map(|dir| trace_plan(dir, args, &config))
            .transpose()?;
        let dir = args
            .out
            .clone()
            .unwrap_or_else(|| default_out_dir(&config.name));
        let mut locks = vec![prepare_out_dir(&dir)?];
        locks.extend(lock_cores(&config.placement()?, &args.wait)?);
        let doctor = (!args.no_doctor).then(|| {
            let [main, helper] = config.placement().expect("the config was validated");
            let cores: Vec<usize> = if main == helper {
                vec![main]
            } else {
                vec![main, helper]
            };
            let report = doctor::examine(&cores, Duration::from_secs(1));
            eprintln!("oceanbench: {}", report.summary());
            report
        });
        eprintln!("oceanbench: calibrating; results go to {}", dir.display());
        let mut sweep = Sweep::prepare(config)?;
        if let Some(plan) = trace {
            sweep = sweep.tracing(plan);
        }
        sweep.results.doctor = doctor;
        sweep.results.command = Some(command_line());
        return Ok(Some(Start {
            sweep,
            dir,
            _locks: locks,
            frame_log,
        }));
    };
    if args.noise != NoiseArgs::default() {
        return Err(InputError(
            "--resume: keeps the recorded config; --calibrate, --noise-threshold and --retry-noisy cannot change it".into(),
        )
        .into());
    }
    let out = results_dir(dir);
    let mut locks = Vec::new();
    if out.is_dir() {
        locks.push(lock_out_dir(&out, "--resume")?);
    }
    let previous = load_results(dir)?;
    if let Some(config) = &config {
        let differ = config_differences(config, &previous.config);
        if !differ.is_empty() {
            return Err(InputError(format!(
                "--resume: the config differs from the one recorded in {} (fields: {}); \
                 resume without a config, or start a new sweep",
                dir.display(),
                differ.join(", ")
            ))
            .into());
        }
    }
    let sweep = Sweep::resume(previous)?;
    if sweep.keys().is_empty() {
        println!(
            "Nothing to resume: every cell of the config is in {}",
            dir.display()
        );
        return Ok(None);
    }
    locks.extend(lock_cores(&sweep.results.config.placement()?, &args.wait)?);
    eprintln!(
        "oceanbench: resuming {}: {} cells to run",
        dir.display(),
        sweep.keys().len()
    );
    let frame_log = frame_logger(args, sweep.keys())?;
    Ok(Some(Start {
        sweep,
        dir: out,
        _locks: locks,
        frame_log,
    }))
}

/// `--trace DIR`: the folder, the cells `--trace-cells` chooses (at least one of the config's)
/// and the frames each trace keeps.
fn trace_plan(dir: &Path, args: &SweepArgs, config: &SweepConfig) -> Result<TracePlan, InputError> {
    let cells = CellFilter::parse(&args.trace_cells)?;
    let all = crate::sweep::cells(config);
    if !all.iter().any(|k| cells.chooses(k)) {
        return Err(InputError(format!(
            "--trace-cells: `{}` chooses none of the config's {} cells",
            args.trace_cells.join(","),
            all.len()
        )));
    }
    TracePlan::new(
        Target::Dir(dir.to_path_buf()),
        cells,
        args.trace_frames
            .trace_frames
            .unwrap_or(DEFAULT_FRAMES as i64),
    )
}

pub(super) fn sweep(args: SweepArgs) -> Result<(), CliError> {
    let stop = interrupt::flag();
    let Some(Start {
        sweep,
        dir,
        _locks,
        frame_log,
    }) = start(&args)?
    else {
        return Ok(());
    };
    let sweep = sweep.stopping_on(stop);
    let bar = if args.quiet {
        indicatif::ProgressBar::hidden()
    } else {
        indicatif::ProgressBar::new(0)
    };
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{elapsed_precise} [{bar:30}] {pos}/{len} trials, eta {eta} {msg}",
        )
        .expect("the template is valid")
        .progress_chars("=> "),
    );
    let mut writer = Writer {
        dir: &dir,
        bar,
        error: None,
        frame_log,
    };
    let results = sweep.run(&mut writer);
    writer.bar.finish_and_clear();
    if let Some(e) = writer.error {
        return Err(anyhow::anyhow!("writing results: {e}").into());
    }
    if let Some(logger) = writer.frame_log {
        let written = logger
            .finish()
            .map_err(|e| anyhow::anyhow!("frame log {e}"))?;
        eprintln!(
            "oceanbench: {} frame log(s) in {}",
            written.len(),
            args.frame_log
                .as_deref()
                .unwrap_or(Path::new("."))
                .display()
        );
    }
    if results.finished.is_none() {
        return Err(CliError::Interrupted(format!(
            "interrupted; {} finished cells kept in {}. Resume with:\n  oceanbench sweep --resume {}",
            results.cells.len(),
            dir.display(),
            dir.display()
        )));
    }
    println!("{}", report::markdown::body(&results));
    warn_about_placement(&results);
    warn_about_noise(&results);
    if !args.no_charts {
        draw_charts(
            std::slice::from_ref(&results),
            &dir,
            &ChartOptions::default(),
        )?;
    }
    if !args.no_report {
        let page = super::report::default_path(&dir);
        super::report::write(&results, &dir, None, &page)?;
        println!("report: {}", page.display());
    }
    // The findings close the output, where a terminal leaves them in view.
    print!("{}", crate::findings::of(&results).to_markdown());
    println!("Results: {}", dir.display());
    fail_on_errors(&results)
}

/// Warns about rows whose yardstick drifted since the start and about cells that kept noisy
/// trials, naming them.
fn warn_about_noise(results: &Results) {
    for line in report::markdown::noise_warnings(results) {
        eprintln!("oceanbench: warning: {line}");
    }
}

/// Warns about pins that did not hold and about the two cores moving mid-run.
fn warn_about_placement(results: &Results) {
    let unpinned = results
        .cells
        .iter()
        .filter(|c| !c.pinned && c.error.is_none())
        .count();
    if unpinned > 0 {
        eprintln!("oceanbench: warning: {unpinned} cell(s) ran with a pin the OS did not hold; see `pinned` in results.json");
    }
    if let Some((lo, hi)) = results.round_trip.changed() {
        eprintln!(
            "oceanbench: warning: the cross-core round trip ranged from {lo:.0} to {hi:.0} ns during the run: \
             the two cores moved between near and far placements, so DP figures from different parts of the run differ"
        );
    }
}
