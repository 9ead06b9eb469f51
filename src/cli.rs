//! Command-line definitions (clap) and the commands they run.

use crate::config::{InputError, Level, SweepConfig};
use crate::frame_loop::{Mode, Threading};
use crate::ocean::{Grid, Kernel, Mesh, NormalMethod, Ocean, WaveSet};
use crate::report::chart::{self, ChartFormat, ChartOptions};
use crate::report::{self, compare, compare::CompareBy};
use crate::results::Results;
use crate::sweep::Sweep;
use crate::sync::SyncMethod;
use clap::error::{ContextKind, ContextValue, ErrorKind};
use clap::{Args, Parser, Subcommand};
use std::io::Write;
use std::path::{Path, PathBuf};

/// Why a command failed: bad input (exit 2) or a failure while running (exit 1).
#[derive(Debug, thiserror::Error)]
pub enum CliError {
    /// The user's input is wrong.
    #[error(transparent)]
    Input(#[from] InputError),
    /// Something failed while running.
    #[error(transparent)]
    Run(#[from] anyhow::Error),
    /// A comparison found a regression (its report is already printed).
    #[error("a cell regressed beyond the threshold")]
    Regressed,
}

impl CliError {
    /// The process exit status for this error.
    pub fn exit_code(&self) -> i32 {
        match self {
            CliError::Input(_) => 2,
            CliError::Run(_) | CliError::Regressed => 1,
        }
    }
}

const EXAMPLES: &str = "\
Examples:
  oceanbench sweep                              # the built-in Figure 5-1 sweep into results/
  oceanbench sweep configs/quick.json --out /tmp/quick
  oceanbench run --size 128 --workload 2 --mode dp --sync condvar
  oceanbench mesh --size 64 --time 1.5 --normals analytic --out frame.csv";

/// oceanbench: the uniprocessor vs dual-processor deep-ocean study, measured on this machine.
#[derive(Debug, Parser)]
#[command(name = "oceanbench", version, after_help = EXAMPLES)]
pub struct Cli {
    /// The command to run.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Measure one cell (mesh size × workload × mode × method) and print its statistics.
    #[command(
        after_help = "Example:\n  oceanbench run --size 256 --workload 3 --mode up --sync mutex --trials 3"
    )]
    Run(RunArgs),
    /// Run a sweep config (default: the built-in Figure 5-1 sweep) and write results files.
    #[command(
        after_help = "Examples:\n  oceanbench sweep\n  oceanbench sweep configs/sync-primitives.json --out results/sync"
    )]
    Sweep(SweepArgs),
    /// Draw the charts (Figure 5-1, relative, sync, frame-times, breakdown) from results files.
    #[command(
        after_help = "Examples:\n  oceanbench chart results/figure-5-1-20261122T020000Z\n  oceanbench chart run-a/results.json run-b/results.json --out charts --format png"
    )]
    Chart(ChartArgs),
    /// Compare two results files, or the alternatives within one run, with noise-aware verdicts.
    #[command(
        after_help = "Exit status: 0 nothing regressed, 1 something regressed, 2 bad input.\n\nExamples:\n  oceanbench compare results/base results/new --threshold 5 --format markdown\n  oceanbench compare results/sync-primitives-X --by sync --baseline atomic"
    )]
    Compare(CompareArgs),
    /// Hand-off round trip of every sync method on one core and across two, next to the raw
    /// cache-line ping-pong (the floor).
    #[command(
        after_help = "Example:\n  oceanbench latency --cores 0,1 --samples 20000 --json latency.json"
    )]
    Latency(LatencyArgs),
    /// Write one frame of the surface as CSV (i,j,x,y,z,nx,ny,nz).
    #[command(
        after_help = "Example:\n  oceanbench mesh --size 32 --time 10 --waves my-waves.json --out frame.csv"
    )]
    Mesh(MeshArgs),
}

/// Flags of `oceanbench run`.
#[derive(Debug, Args)]
pub struct RunArgs {
    /// Mesh size N (N×N vertices).
    #[arg(long, default_value_t = 128)]
    pub size: usize,
    /// Workload level index (0-3 with the default levels).
    #[arg(long, default_value_t = 0)]
    pub workload: usize,
    /// Workload as microseconds of one core's work, instead of a level index.
    #[arg(long, conflicts_with = "workload")]
    pub workload_micros: Option<f64>,
    /// Where the threads run.
    #[arg(long, value_enum, default_value = "dp")]
    pub mode: Mode,
    /// Hand-off method.
    #[arg(long, value_enum, default_value = "atomic")]
    pub sync: SyncMethod,
    /// Helper threading model.
    #[arg(long, value_enum, default_value = "pool")]
    pub threading: Threading,
    /// Normal method.
    #[arg(long, value_enum, default_value = "neighbors")]
    pub normals: NormalMethod,
    /// Kernel.
    #[arg(long, value_enum, default_value = "reference")]
    pub kernel: Kernel,
    /// Helper threads the mesh's rows are split among (more than 1 needs threading `pool` and
    /// normals `analytic`).
    #[arg(long, default_value_t = 1)]
    pub helpers: usize,
    /// Waves file (JSON); default: the built-in deep-ocean set.
    #[arg(long)]
    pub waves: Option<PathBuf>,
    /// Measured frames per trial, at least.
    #[arg(long, default_value_t = 200)]
    pub frames: u64,
    /// Measured seconds per trial, at least.
    #[arg(long, default_value_t = 1.0)]
    pub seconds: f64,
    /// Trials.
    #[arg(long, default_value_t = 3)]
    pub trials: u32,
    /// Cores for the main and helper threads, e.g. `0,1` (default: the first allowed).
    #[arg(long, value_delimiter = ',')]
    pub cores: Option<Vec<usize>>,
    /// Also write results files into this directory.
    #[arg(long)]
    pub out: Option<PathBuf>,
}

/// Flags of `oceanbench sweep`.
#[derive(Debug, Args)]
pub struct SweepArgs {
    /// Sweep config (JSON); default: the built-in Figure 5-1 config.
    pub config: Option<PathBuf>,
    /// Results directory (default: results/<config name>-<UTC timestamp>).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
    /// Do not draw the charts at the end.
    #[arg(long)]
    pub no_charts: bool,
    /// Continue the interrupted sweep in this results directory (only its missing cells).
    #[arg(long, conflicts_with = "out")]
    pub resume: Option<PathBuf>,
}

/// Flags of `oceanbench chart`.
#[derive(Debug, Args)]
pub struct ChartArgs {
    /// Results directories or results.json files (several put runs side by side).
    #[arg(required = true)]
    pub results: Vec<PathBuf>,
    /// Directory for the charts (default: the first results directory).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Image formats.
    #[arg(long, value_enum, value_delimiter = ',', default_value = "png,svg")]
    pub format: Vec<ChartFormat>,
    /// Mesh size of the cell the frame-times and breakdown charts show (default: the largest).
    #[arg(long)]
    pub size: Option<usize>,
    /// Workload of that cell (default: the highest).
    #[arg(long)]
    pub workload: Option<usize>,
}

/// Output format of `oceanbench compare`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum CompareFormat {
    /// Aligned columns for a terminal.
    Text,
    /// A table ready to paste into a pull-request comment.
    Markdown,
    /// Machine-readable.
    Json,
}

/// Flags of `oceanbench compare`.
#[derive(Debug, Args)]
pub struct CompareArgs {
    /// Baseline results (directory or results.json); with --by, the one run to compare within.
    pub base: PathBuf,
    /// New results to compare against BASE (omit with --by).
    pub new: Option<PathBuf>,
    /// Compare alternatives within one run along this parameter.
    #[arg(long, value_enum, requires = "baseline", conflicts_with = "new")]
    pub by: Option<CompareBy>,
    /// The value of --by the others are ranked against (e.g. atomic, up, neighbors, reference).
    #[arg(long, requires = "by")]
    pub baseline: Option<String>,
    /// A change counts only when its whole 95% interval clears this many percent.
    #[arg(long, default_value_t = compare::DEFAULT_THRESHOLD_PCT)]
    pub threshold: f64,
    /// Output format.
    #[arg(long, value_enum, default_value = "text")]
    pub format: CompareFormat,
}

/// Flags of `oceanbench latency`.
#[derive(Debug, Args)]
pub struct LatencyArgs {
    /// The two cores, e.g. `0,1` (default: the first two allowed).
    #[arg(long, value_delimiter = ',')]
    pub cores: Option<Vec<usize>>,
    /// Round trips per row (each row also stops after 2 s).
    #[arg(long, default_value_t = 20_000)]
    pub samples: usize,
    /// Also write the rows as JSON to this file.
    #[arg(long)]
    pub json: Option<PathBuf>,
}

/// Flags of `oceanbench mesh`.
#[derive(Debug, Args)]
pub struct MeshArgs {
    /// Mesh size N (N×N vertices).
    #[arg(long)]
    pub size: usize,
    /// Simulated time t in seconds.
    #[arg(long)]
    pub time: f32,
    /// Distance between vertices.
    #[arg(long, default_value_t = 1.0)]
    pub spacing: f32,
    /// Waves file (JSON); default: the built-in deep-ocean set.
    #[arg(long)]
    pub waves: Option<PathBuf>,
    /// Normal method.
    #[arg(long, value_enum, default_value = "analytic")]
    pub normals: NormalMethod,
    /// Kernel.
    #[arg(long, value_enum, default_value = "reference")]
    pub kernel: Kernel,
    /// Output CSV file.
    #[arg(long)]
    pub out: PathBuf,
}

/// One line for a clap error: what was wrong, and the allowed values when clap knows them.
pub fn clap_line(err: &clap::Error) -> String {
    let get = |kind| match err.get(kind) {
        Some(ContextValue::String(s)) => Some(s.clone()),
        Some(ContextValue::Strings(v)) => Some(v.join(", ")),
        _ => None,
    };
    let arg = get(ContextKind::InvalidArg).unwrap_or_default();
    let value = get(ContextKind::InvalidValue).unwrap_or_default();
    let allowed = get(ContextKind::ValidValue)
        .map(|v| format!(" (allowed: {v})"))
        .unwrap_or_default();
    match err.kind() {
        ErrorKind::InvalidValue | ErrorKind::ValueValidation if !arg.is_empty() => {
            let why = err
                .source_message()
                .map(|m| format!(": {m}"))
                .unwrap_or_default();
            format!("{arg}: invalid value '{value}'{why}{allowed}")
        }
        ErrorKind::MissingRequiredArgument if !arg.is_empty() => {
            format!("missing required arguments: {arg}")
        }
        _ => {
            let first = err.render().to_string();
            let line = first.lines().next().unwrap_or("invalid arguments");
            line.trim_start_matches("error: ").to_string()
        }
    }
}

trait SourceMessage {
    fn source_message(&self) -> Option<String>;
}

impl SourceMessage for clap::Error {
    fn source_message(&self) -> Option<String> {
        std::error::Error::source(self).map(|s| s.to_string())
    }
}

/// Runs a parsed command line.
pub fn execute(cli: Cli) -> Result<(), CliError> {
    match cli.command {
        Command::Run(args) => run(args),
        Command::Sweep(args) => sweep(args),
        Command::Chart(args) => chart_cmd(args),
        Command::Compare(args) => compare_cmd(args),
        Command::Latency(args) => latency_cmd(args),
        Command::Mesh(args) => mesh(args),
    }
}

fn latency_cmd(args: LatencyArgs) -> Result<(), CliError> {
    if !(1..=10_000_000).contains(&args.samples) {
        return Err(InputError(format!(
            "--samples: must be 1 to 10000000, got {}",
            args.samples
        ))
        .into());
    }
    let two = match &args.cores {
        Some(c) => c.len() > 1,
        None => crate::affinity::allowed_cores().len() > 1,
    };
    let config = SweepConfig {
        modes: vec![if two { Mode::Dp } else { Mode::Up }],
        cores: args.cores,
        ..SweepConfig::default()
    };
    let [a, b] = config.placement()?;
    let rows = crate::latency::table(a, b, args.samples);
    print!("{}", crate::latency::to_text(&rows));
    if let Some(path) = &args.json {
        let text = serde_json::to_string_pretty(&rows).map_err(anyhow::Error::from)?;
        report::json::write_atomic(path, text.as_bytes())
            .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    }
    Ok(())
}

fn load_results(path: &Path) -> Result<Results, CliError> {
    Ok(Results::load(path).map_err(InputError)?)
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

fn chart_cmd(args: ChartArgs) -> Result<(), CliError> {
    let runs = args
        .results
        .iter()
        .map(|p| load_results(p))
        .collect::<Result<Vec<_>, _>>()?;
    let out = args.out.unwrap_or_else(|| results_dir(&args.results[0]));
    let options = ChartOptions {
        formats: args.format,
        size: args.size,
        workload: args.workload,
    };
    draw_charts(&runs, &out, &options)
}

/// Draws every chart and prints where they went and which were skipped.
fn draw_charts(runs: &[Results], out: &Path, options: &ChartOptions) -> Result<(), CliError> {
    let drawn = chart::draw_with(runs, out, options).map_err(|e| anyhow::anyhow!("{e}"))?;
    for file in &drawn.files {
        println!("chart: {}", file.display());
    }
    for s in &drawn.skipped {
        eprintln!("oceanbench: chart {} skipped: {}", s.chart, s.reason);
    }
    Ok(())
}

fn compare_cmd(args: CompareArgs) -> Result<(), CliError> {
    if !(args.threshold.is_finite() && args.threshold >= 0.0) {
        return Err(InputError(format!(
            "--threshold: must be a finite percentage >= 0, got {}",
            args.threshold
        ))
        .into());
    }
    let base = load_results(&args.base)?;
    let comparison = match (&args.new, args.by, &args.baseline) {
        (Some(new), None, _) => compare::between(&base, &load_results(new)?, args.threshold),
        (None, Some(by), Some(baseline)) => compare::within(&base, by, baseline, args.threshold)
            .map_err(|e| InputError(e.to_string()))?,
        _ => {
            return Err(InputError(
                "compare: give BASE NEW, or one RESULTS with --by and --baseline".into(),
            )
            .into())
        }
    };
    match args.format {
        CompareFormat::Text => print!("{}", comparison.to_text()),
        CompareFormat::Markdown => print!("{}", comparison.to_markdown()),
        CompareFormat::Json => println!("{}", comparison.to_json()),
    }
    if comparison.regressed() {
        return Err(CliError::Regressed);
    }
    Ok(())
}

fn run(args: RunArgs) -> Result<(), CliError> {
    let mut config = SweepConfig {
        name: "run".into(),
        sizes: vec![args.size],
        modes: vec![args.mode],
        sync: vec![args.sync],
        threading: vec![args.threading],
        normals: vec![args.normals],
        kernel: vec![args.kernel],
        helpers: vec![args.helpers],
        trials: args.trials,
        min_frames: args.frames,
        min_seconds: args.seconds,
        max_seconds: (args.seconds * 10.0).max(10.0),
        waves_file: args.waves,
        cores: args.cores,
        ..SweepConfig::default()
    };
    config.workloads = vec![args.workload];
    if let Some(us) = args.workload_micros {
        config.workload_levels = vec![Level::micros(us)];
        config.workloads = vec![0];
    }
    if let Some(dir) = &args.out {
        prepare_out_dir(dir)?;
    }
    let sweep = Sweep::prepare(config)?;
    let results = sweep.run(|_| {}, |_| {});
    if let Some(dir) = &args.out {
        report::write_all(dir, &results).map_err(|e| anyhow::anyhow!("{}: {e}", dir.display()))?;
    }
    print_cells(&results);
    fail_on_errors(&results)
}

fn print_cells(results: &Results) {
    println!("{}", report::markdown::preamble(results));
    for cell in &results.cells {
        println!("{}", cell.key.label());
        match &cell.summary {
            Some(s) => println!(
                "  {:.1} FPS (trials {}; cv {:.1}%), frame median {:.3} ms, p99 {:.3} ms, 1% low {:.1} FPS\n  per frame: workload {:.3} ms, wait {:.3} ms, copy {:.3} ms, step {:.3} ms; pinned: {}",
                s.fps,
                s.fps_trials
                    .iter()
                    .map(|f| format!("{f:.1}"))
                    .collect::<Vec<_>>()
                    .join(", "),
                s.fps_spread.cv_percent,
                s.frame_time_ms.median,
                s.frame_time_ms.p99,
                s.one_percent_low_fps,
                s.breakdown.workload_ms,
                s.breakdown.wait_ms,
                s.breakdown.copy_ms,
                s.breakdown.step_ms,
                cell.pinned
            ),
            None => println!("  failed: {}", cell.error.as_deref().unwrap_or("no frames")),
        }
    }
}

fn fail_on_errors(results: &Results) -> Result<(), CliError> {
    let failed = results.cells.iter().filter(|c| c.error.is_some()).count();
    if failed > 0 {
        return Err(anyhow::anyhow!("{failed} cell(s) failed; see the results").into());
    }
    Ok(())
}

/// Creates the results directory, refusing one that already holds results.
fn prepare_out_dir(dir: &Path) -> Result<(), CliError> {
    if dir.join("results.json").exists() {
        return Err(InputError(format!(
            "--out: {} already holds results.json; choose another directory",
            dir.display()
        ))
        .into());
    }
    std::fs::create_dir_all(dir)
        .map_err(|e| InputError(format!("--out: cannot create {}: {e}", dir.display())))?;
    Ok(())
}

/// Names the top-level keys where two configs differ.
fn config_differences(a: &SweepConfig, b: &SweepConfig) -> Vec<String> {
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

fn sweep(args: SweepArgs) -> Result<(), CliError> {
    let config = match &args.config {
        Some(path) => Some(SweepConfig::load(path)?),
        None => None,
    };
    let (sweep, dir) = match &args.resume {
        Some(dir) => {
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
                return Ok(());
            }
            eprintln!(
                "oceanbench: resuming {}: {} cells to run",
                dir.display(),
                sweep.keys().len()
            );
            (sweep, results_dir(dir))
        }
        None => {
            let config = config.unwrap_or_default();
            config.validate()?;
            let dir = args.out.clone().unwrap_or_else(|| {
                let stamp: String = crate::sweep::utc_now()
                    .chars()
                    .filter(|c| c.is_ascii_alphanumeric())
                    .collect();
                PathBuf::from("results").join(format!("{}-{stamp}", config.name))
            });
            prepare_out_dir(&dir)?;
            eprintln!("oceanbench: calibrating; results go to {}", dir.display());
            (Sweep::prepare(config)?, dir)
        }
    };
    let stop = sweep.stop_flag();
    // A second signal exits at once: every file on disk is whole, since each is renamed into place.
    let _ = ctrlc::set_handler(move || {
        if stop.swap(true, std::sync::atomic::Ordering::SeqCst) {
            std::process::exit(130);
        }
        eprintln!("\noceanbench: stopping after the current frame (again to quit now)");
    });
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
    let mut write_error = None;
    let results = sweep.run(
        |p| {
            bar.set_length(p.total as u64);
            bar.set_position(p.done as u64);
            bar.set_message(p.cell.label());
        },
        |results| {
            if let Err(e) = report::write_all(&dir, results) {
                write_error.get_or_insert(e);
            }
        },
    );
    bar.finish_and_clear();
    if let Some(e) = write_error {
        return Err(anyhow::anyhow!("writing results into {}: {e}", dir.display()).into());
    }
    if results.finished.is_none() {
        eprintln!(
            "oceanbench: interrupted; {} finished cells kept in {}. Resume with:\n  oceanbench sweep --resume {}",
            results.cells.len(),
            dir.display(),
            dir.display()
        );
        std::process::exit(130);
    }
    println!("{}", report::markdown::to_string(&results));
    warn_about_placement(&results);
    if !args.no_charts {
        draw_charts(
            std::slice::from_ref(&results),
            &dir,
            &ChartOptions::default(),
        )?;
    }
    println!("Results: {}", dir.display());
    fail_on_errors(&results)
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

fn mesh(args: MeshArgs) -> Result<(), CliError> {
    let grid = Grid::new(args.size, args.spacing).map_err(InputError)?;
    if !args.time.is_finite() {
        return Err(InputError(format!(
            "--time: must be a finite number, got {}",
            args.time
        ))
        .into());
    }
    let waves = match &args.waves {
        Some(path) => WaveSet::load(path).map_err(|e| InputError(e.to_string()))?,
        None => WaveSet::default(),
    };
    let mut ocean = Ocean::new(grid, waves, args.normals, args.kernel).map_err(InputError)?;
    let mut mesh = Mesh::new(grid);
    ocean.step(args.time, &mut mesh);
    let file = std::fs::File::create(&args.out)
        .map_err(|e| InputError(format!("--out: cannot create {}: {e}", args.out.display())))?;
    let mut w = std::io::BufWriter::new(file);
    let io = |e: std::io::Error| anyhow::anyhow!("{}: {e}", args.out.display());
    writeln!(w, "i,j,x,y,z,nx,ny,nz").map_err(io)?;
    for i in 0..grid.n {
        for j in 0..grid.n {
            let v = grid.index(i, j);
            writeln!(
                w,
                "{i},{j},{},{},{},{},{},{}",
                mesh.x[v], mesh.y[v], mesh.z[v], mesh.nx[v], mesh.ny[v], mesh.nz[v]
            )
            .map_err(io)?;
        }
    }
    w.flush().map_err(io)?;
    Ok(())
}
