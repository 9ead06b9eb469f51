//! Command-line definitions (clap). The commands themselves are in `commands/`.

// The doc comments here are clap's `--help` text, where `<name>` is a placeholder as the
// terminal shows it, not an HTML tag; backticks would print as backticks.
#![allow(rustdoc::invalid_html_tags)]

use crate::cell::{Dim, Value};
use crate::named::Named;
use crate::report::chart::ChartFormat;
use crate::report::compare;
use clap::builder::{PossibleValuesParser, TypedValueParser};
use clap::error::{ContextKind, ContextValue, ErrorKind};
use clap::{Arg, ArgAction, ArgMatches, Args, Parser, Subcommand};
use std::path::PathBuf;

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
    /// Measure one cell (or the few its flags list) and print its statistics.
    Run(RunArgs),
    /// Run a sweep config (default: the built-in Figure 5-1 sweep) and write results files.
    Sweep(SweepArgs),
    /// Draw the charts (Figure 5-1, relative, sync, frame-times, breakdown, latency-vs-fps,
    /// balance; round-trips for a latency run) from results files.
    Chart(ChartArgs),
    /// Compare two results files, or the alternatives within one run, with noise-aware verdicts.
    Compare(CompareArgs),
    /// Write one self-contained HTML page of a run: what ran, the charts, the tables and, with
    /// --baseline, the comparison with another run.
    Report(ReportArgs),
    /// Hand-off round trip of every sync method on one core and across two, next to the raw
    /// cache-line ping-pong (the floor).
    Latency(LatencyArgs),
    /// Write one frame of the surface as CSV (i,j,x,y,z,nx,ny,nz).
    Mesh(MeshArgs),
    /// Find the balance point: the main-thread workload at which the main thread stops waiting
    /// for the helper, with DP ÷ serial there and the speed-up curve around it.
    Balance(BalanceArgs),
    /// Check what on this machine makes measurements noisy (governor, boost, SMT, isolation,
    /// steal, load, busy threads, pinning, placement), each finding with how to fix it.
    Doctor(DoctorArgs),
    /// Say where the two cores sat during a run: its round trips as one placement or near and
    /// far, the cells that mixed placements with their FPS per placement, each balance point
    /// per placement, and whether DP behaved differently on the two (any results file; one
    /// from before placement was recorded is placed from the round trips it holds).
    Placement(PlacementArgs),
    /// What a run shows, computed from its results file alone: per slice of the run, where
    /// DP ÷ UP and DP ÷ serial peak, the levels over which DP stays flat, the balance point,
    /// the fastest and slowest hand-off and how many cells carry noise marks.
    Findings(FindingsArgs),
    /// Regenerates (or checks) the measured numbers in README.md and docs/: every block
    /// between `<!-- ob:... -->` and `<!-- /ob -->` is rewritten from the committed run it names.
    Docs(DocsArgs),
    /// Collect the estimates a `cargo bench` run just wrote into results/bench-<name>-<UTC>/.
    BenchRecord(BenchRecordArgs),
    /// Print the shell completion script for bash, zsh, fish, elvish or powershell.
    Completions(CompletionsArgs),
    /// Print the man page (roff), or write one page per command into a folder.
    Man(ManArgs),
    /// Write a run's FPS per cell for a CI benchmark tracker: Bencher (bmf) or
    /// github-action-benchmark.
    Export(ExportArgs),
    /// Chart a metric across runs in the order they were made, one line per cell, with runs
    /// on another machine marked, and find where each cell changed.
    History(HistoryArgs),
}

/// One flag per dimension of a cell (`--size`, `--mode`, `--sync`, ...), each taking a value or
/// a comma-separated list; built from the declared dimensions, so a new one gets its flag.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct DimArgs {
    /// The dimensions given on the command line, with their values in the order given.
    pub given: Vec<(Dim, Vec<Value>)>,
}

impl DimArgs {
    /// The values given for `dim`, if the flag was used.
    pub fn get(&self, dim: Dim) -> Option<&[Value]> {
        self.given
            .iter()
            .find(|(d, _)| *d == dim)
            .map(|(_, v)| v.as_slice())
    }

    /// The flag of `dim`: its name with `-` for `_`.
    pub fn flag(dim: Dim) -> String {
        dim.name().replace('_', "-")
    }

    /// The config key of each dimension given, with its flag, for
    /// [`InputError::naming_flags`](crate::config::InputError::naming_flags).
    pub fn flag_fields(&self) -> Vec<(&'static str, String)> {
        self.given
            .iter()
            .map(|(dim, _)| (dim.config_key(), format!("--{}", Self::flag(*dim))))
            .collect()
    }
}

impl clap::FromArgMatches for DimArgs {
    fn from_arg_matches(matches: &ArgMatches) -> Result<Self, clap::Error> {
        let given = Dim::ALL
            .iter()
            .filter_map(|&dim| {
                let values = matches.get_many::<Value>(dim.name())?;
                Some((dim, values.copied().collect()))
            })
            .collect();
        Ok(DimArgs { given })
    }

    fn update_from_arg_matches(&mut self, matches: &ArgMatches) -> Result<(), clap::Error> {
        *self = Self::from_arg_matches(matches)?;
        Ok(())
    }
}

impl Args for DimArgs {
    fn augment_args(cmd: clap::Command) -> clap::Command {
        Dim::ALL.iter().fold(cmd, |cmd, &dim| {
            let arg = Arg::new(dim.name())
                .long(DimArgs::flag(dim))
                .value_name(dim.name().to_uppercase())
                .action(ArgAction::Set)
                .value_delimiter(',')
                .help(format!(
                    "{} (config key `{}`)",
                    dim.doc().unwrap_or_default().trim_end_matches('.'),
                    dim.config_key()
                ));
            let arg = match dim.names() {
                Some(names) => arg.value_parser(
                    PossibleValuesParser::new(names)
                        .map(move |s: String| dim.parse_value(&s).expect("a listed name parses")),
                ),
                None => arg.value_parser(move |s: &str| dim.parse_value(s)),
            };
            cmd.arg(arg)
        })
    }

    fn augment_args_for_update(cmd: clap::Command) -> clap::Command {
        Self::augment_args(cmd)
    }
}

/// Flags of `run` and `sweep` that set how trials are kept valid on a noisy machine; each
/// overrides the config key of the same name.
#[derive(Clone, Debug, Default, PartialEq, Args)]
pub struct NoiseArgs {
    /// When `step_fraction` workload levels are resolved: before every row (row, the default)
    /// or once at the start (config key `calibrate`).
    #[arg(long, value_enum)]
    pub calibrate: Option<crate::calibrate::Calibrate>,
    /// A trial whose run delay or steal exceeds this percentage of its wall time is noisy
    /// (config key `noise_threshold_percent`, default 2).
    #[arg(long, allow_negative_numbers = true)]
    pub noise_threshold: Option<f64>,
    /// Re-run a noisy trial up to N times, 0 to 10 (config key `retry_noisy`, default 0).
    #[arg(long, value_name = "N")]
    pub retry_noisy: Option<u32>,
    /// A trial more than this percentage below its cell's median FPS is slow and explained
    /// (config key `slow_trial_percent`, default 10).
    #[arg(long, value_name = "PERCENT", allow_negative_numbers = true)]
    pub slow_trial_percent: Option<f64>,
}

impl NoiseArgs {
    /// The config key of each flag given, with the flag.
    pub fn flag_fields(&self) -> Vec<(&'static str, String)> {
        [
            (
                "noise_threshold_percent",
                "--noise-threshold",
                self.noise_threshold.is_some(),
            ),
            ("retry_noisy", "--retry-noisy", self.retry_noisy.is_some()),
            (
                "slow_trial_percent",
                "--slow-trial-percent",
                self.slow_trial_percent.is_some(),
            ),
        ]
        .into_iter()
        .filter(|&(_, _, given)| given)
        .map(|(field, flag, _)| (field, flag.to_string()))
        .collect()
    }

    /// The config with these flags applied.
    pub fn apply(&self, config: &mut crate::config::SweepConfig) {
        if let Some(c) = self.calibrate {
            config.calibrate = c;
        }
        if let Some(t) = self.noise_threshold {
            config.noise_threshold_percent = t;
        }
        if let Some(n) = self.retry_noisy {
            config.retry_noisy = n;
        }
        if let Some(p) = self.slow_trial_percent {
            config.slow_trial_percent = p;
        }
    }
}

/// Flags of `oceanbench run`.
#[derive(Debug, Args)]
#[command(
    after_help = "Every flag of a cell's dimensions takes one value or a comma-separated list; a flag left out takes run's default: a 128×128 mesh in dp at workload 0, and the sweep's first value of every other dimension.\n\nExamples:\n  oceanbench run --size 256 --workload 3 --mode up --sync mutex --trials 3\n  oceanbench run --mode up,dp --sync atomic,condvar"
)]
pub struct RunArgs {
    /// The cell's dimensions; a flag left out takes `run`'s default (128×128, workload 0, dp,
    /// atomic, pool, 1 helper, neighbors, reference).
    #[command(flatten)]
    pub cell: DimArgs,
    /// Workload as microseconds of one core's work, instead of a level index.
    #[arg(long, conflicts_with = "workload", allow_negative_numbers = true)]
    pub workload_micros: Option<f64>,
    /// The level in the workload kind's own unit (synthetic: iterations; spray: particles,
    /// by default the kind's own; fog: the volume's edge), instead of a level index.
    #[arg(
        long,
        visible_alias = "particles",
        conflicts_with_all = ["workload", "workload_micros"],
        allow_negative_numbers = true
    )]
    pub amount: Option<f64>,
    /// Waves file (JSON); default: the built-in deep-ocean set.
    #[arg(long)]
    pub waves: Option<PathBuf>,
    /// The FFT ocean's parameters file (JSON); default: the values of configs/fft-ocean.json.
    #[arg(long)]
    pub fft_params: Option<PathBuf>,
    /// Measured frames per trial, at least.
    #[arg(long, default_value_t = 200)]
    pub frames: u64,
    /// Measured seconds per trial, at least.
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
    pub seconds: f64,
    /// A trial stops after this many seconds even short of --frames (default: 10 × --seconds,
    /// at least 10); a cell that stopped short is named on stderr.
    #[arg(long, allow_negative_numbers = true)]
    pub max_seconds: Option<f64>,
    /// Trials per cell, interleaved with the other cells' trials.
    #[arg(long, default_value_t = 3)]
    pub trials: u32,
    /// Seconds a hand-off wait may take before the cell is given up; also the most work a
    /// frame's workload may be.
    #[arg(long, default_value_t = 5.0, allow_negative_numbers = true)]
    pub timeout: f64,
    /// Cores for the main and helper threads, e.g. `0,1` (default: the first allowed).
    #[arg(long, value_delimiter = ',')]
    pub cores: Option<Vec<usize>>,
    /// Also write results files into this directory.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Write each cell's last trial as a MangoHud frame-time log (CSV) into this folder.
    #[arg(long, value_name = "DIR")]
    pub frame_log: Option<PathBuf>,
    /// Calibration and noise handling.
    #[command(flatten)]
    pub noise: NoiseArgs,
    /// The camera (the `render` workload and the projected grid).
    #[command(flatten)]
    pub camera: CameraArgs,
    /// Waiting for other runs on the same cores.
    #[command(flatten)]
    pub wait: WaitArgs,
    /// Write the frame timeline of the cell's first trial to FILE, as Chrome Trace Event JSON
    /// (Perfetto, chrome://tracing, speedscope, Tracy's import-chrome; docs/trace.md).
    #[arg(long, value_name = "FILE")]
    pub trace: Option<PathBuf>,
    /// Frames the trace keeps.
    #[command(flatten)]
    pub trace_frames: TraceFramesArg,
}

/// How many frames a trace keeps.
#[derive(Clone, Debug, Default, PartialEq, Args)]
pub struct TraceFramesArg {
    /// Measured frames a trace keeps, 1 to 100000 (default 1000); the file says how many of how
    /// many it kept.
    #[arg(
        long,
        value_name = "N",
        requires = "trace",
        allow_negative_numbers = true
    )]
    pub trace_frames: Option<i64>,
}

/// Flags that set the camera (config key `camera`), which the `render` workload looks through
/// and the projected grid is cast from; each overrides the key of the same name.
#[derive(Clone, Debug, Default, PartialEq, Args)]
pub struct CameraArgs {
    /// Camera height above the still sea (`camera.height`; default: framing the patch).
    #[arg(long, allow_negative_numbers = true)]
    pub camera_height: Option<f32>,
    /// Degrees below the horizon the camera looks, above 0 and at most 90
    /// (`camera.pitch_degrees`, default 30).
    #[arg(long, allow_negative_numbers = true)]
    pub pitch: Option<f32>,
    /// Vertical field of view in degrees, above 0 and below 180 (`camera.fov_degrees`,
    /// default 60).
    #[arg(long, allow_negative_numbers = true)]
    pub fov: Option<f32>,
    /// Image width over height (`camera.aspect`, default 16/9).
    #[arg(long, allow_negative_numbers = true)]
    pub aspect: Option<f32>,
    /// How far the projected grid reaches (`camera.far`; default 10 × the patch's width).
    #[arg(long, allow_negative_numbers = true)]
    pub far: Option<f32>,
    /// Radius of the circle the camera travels (`camera.path.radius`; default: still).
    #[arg(long, allow_negative_numbers = true)]
    pub path_radius: Option<f32>,
    /// Seconds of frame time per turn of the path (`camera.path.period_seconds`, default 30).
    #[arg(long, requires = "path_radius", allow_negative_numbers = true)]
    pub path_period: Option<f32>,
}

/// Seconds per turn of a camera path given by its radius alone.
const DEFAULT_PATH_PERIOD: f32 = 30.0;

impl CameraArgs {
    /// The config key of each flag given, with the flag.
    pub fn flag_fields(&self) -> Vec<(&'static str, String)> {
        [
            (
                "camera.height",
                "--camera-height",
                self.camera_height.is_some(),
            ),
            ("camera.pitch_degrees", "--pitch", self.pitch.is_some()),
            ("camera.fov_degrees", "--fov", self.fov.is_some()),
            ("camera.aspect", "--aspect", self.aspect.is_some()),
            ("camera.far", "--far", self.far.is_some()),
            (
                "camera.path.radius",
                "--path-radius",
                self.path_radius.is_some(),
            ),
            (
                "camera.path.period_seconds",
                "--path-period",
                self.path_period.is_some(),
            ),
        ]
        .into_iter()
        .filter(|&(_, _, given)| given)
        .map(|(field, flag, _)| (field, flag.to_string()))
        .collect()
    }

    /// The camera with these flags applied (validated by the caller).
    pub fn apply(&self, camera: &mut crate::camera::Camera) {
        if let Some(h) = self.camera_height {
            camera.height = Some(h);
        }
        if let Some(p) = self.pitch {
            camera.pitch_degrees = p;
        }
        if let Some(f) = self.fov {
            camera.fov_degrees = f;
        }
        if let Some(a) = self.aspect {
            camera.aspect = a;
        }
        if let Some(f) = self.far {
            camera.far = Some(f);
        }
        if let Some(radius) = self.path_radius {
            let period_seconds = self
                .path_period
                .or(camera.path.map(|p| p.period_seconds))
                .unwrap_or(DEFAULT_PATH_PERIOD);
            camera.path = Some(crate::camera::CameraPath {
                radius,
                period_seconds,
            });
        }
    }
}

/// Whether to wait for another oceanbench run measuring on the same cores.
#[derive(Debug, Default, Args)]
pub struct WaitArgs {
    /// Refuse (exit 2) instead of waiting when another oceanbench run is measuring on any of
    /// these cores (each measuring command holds a lock per core; see docs/noise.md).
    #[arg(long)]
    pub no_wait: bool,
}

/// Flags of `oceanbench sweep`.
#[derive(Debug, Args)]
#[command(
    after_help = "Examples:\n  oceanbench sweep\n  oceanbench sweep configs/sync-primitives.json --out results/sync"
)]
pub struct SweepArgs {
    /// Sweep config (JSON); default: the built-in Figure 5-1 config.
    pub config: Option<PathBuf>,
    /// Results directory (default: results/<config name>-<UTC timestamp>).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Print no progress bar.
    #[arg(long)]
    pub quiet: bool,
    /// Do not draw the charts at the end.
    #[arg(long)]
    pub no_charts: bool,
    /// Do not write report.html at the end.
    #[arg(long)]
    pub no_report: bool,
    /// Continue the interrupted sweep in this results directory (only its missing cells).
    #[arg(long, conflicts_with = "out")]
    pub resume: Option<PathBuf>,
    /// Skip the machine checks `doctor` makes before the sweep.
    #[arg(long)]
    pub no_doctor: bool,
    /// Cores for the main and helper threads, e.g. `0,1` (config key `cores`; default: the
    /// first two allowed).
    #[arg(long, value_delimiter = ',', conflicts_with = "resume")]
    pub cores: Option<Vec<usize>>,
    /// Write each cell's last trial as a MangoHud frame-time log (CSV) into this folder.
    #[arg(long, value_name = "DIR")]
    pub frame_log: Option<PathBuf>,
    /// Calibration and noise handling (not with --resume, which keeps the recorded config).
    #[command(flatten)]
    pub noise: NoiseArgs,
    /// Waiting for other runs on the same cores.
    #[command(flatten)]
    pub wait: WaitArgs,
    /// Write the frame timeline of the first trial of each cell --trace-cells chooses into DIR,
    /// one Chrome Trace Event JSON file per cell (docs/trace.md).
    #[arg(long, value_name = "DIR", conflicts_with = "resume")]
    pub trace: Option<PathBuf>,
    /// The cells traced, as DIM=VALUE items that must all hold (a dimension named twice takes
    /// either value), e.g. `mode=dp,size=40` (default: every cell).
    #[arg(long, value_name = "FILTER", value_delimiter = ',', requires = "trace")]
    pub trace_cells: Vec<String>,
    /// Frames each trace keeps.
    #[command(flatten)]
    pub trace_frames: TraceFramesArg,
}

/// Flags of `oceanbench chart`.
#[derive(Debug, Args)]
#[command(
    after_help = "Examples:\n  oceanbench chart results/figure-5-1-20261122T020000Z\n  oceanbench chart run-a/results.json run-b/results.json --out charts --format png\n  oceanbench chart results/quick-X --normals analytic --size 40"
)]
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
    /// Which cells to draw: `--size`/`--workload` choose the cell of the frame-times and
    /// breakdown charts (default: the largest size at its highest workload); any other
    /// dimension holds every chart at that value (default: the first measured).
    #[command(flatten)]
    pub select: DimArgs,
}

/// Flags of `oceanbench report`.
#[derive(Debug, Args)]
#[command(
    after_help = "The page needs no network: charts are inline SVG, styles are in the page, there is no script.\n\nExamples:\n  oceanbench report results/figure-5-1-20261125T064618Z\n  oceanbench report results/new --baseline results/base --out new-vs-base.html"
)]
pub struct ReportArgs {
    /// The results directory (or its results.json).
    pub results: PathBuf,
    /// Another run to compare with, cell by cell, as `compare BASELINE RESULTS` does.
    #[arg(long)]
    pub baseline: Option<PathBuf>,
    /// The page to write (default: report.html in the results directory).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Also rewrite the run's results.md and findings.json with this build (results.json is
    /// left as it is): brings an older run's write-ups up to date.
    #[arg(long)]
    pub refresh: bool,
    /// With --baseline: a change counts only when its whole 95% interval clears this many
    /// percent.
    #[arg(long, default_value_t = compare::DEFAULT_THRESHOLD_PCT, allow_negative_numbers = true)]
    pub threshold: f64,
}

crate::named! {
    /// Output format of `oceanbench compare`.
    pub enum CompareFormat {
        /// Aligned columns for a terminal.
        Text,
        /// A table ready to paste into a pull-request comment.
        Markdown,
        /// Machine-readable.
        Json,
    }
}

/// Flags of `oceanbench compare`.
#[derive(Debug, Args)]
#[command(
    after_help = "Verdicts: improved or regressed when the whole 95% interval clears the threshold; below threshold when it excludes 0 but does not clear it; within noise when it includes 0; too few trials when a side has fewer than 5 (point estimate only, never a failure).\n\nExit status: 0 nothing regressed, 1 something regressed, 2 bad input, no cell compared, or (with --strict) runs that are not like for like.\n\nExamples:\n  oceanbench compare results/base results/new --threshold 5 --format markdown\n  oceanbench compare results/base results/new --strict\n  oceanbench compare results/sync-primitives-X --by sync --baseline atomic"
)]
pub struct CompareArgs {
    /// Baseline results (directory or results.json); with --by, the one run to compare within.
    pub base: PathBuf,
    /// New results to compare against BASE (omit with --by).
    pub new: Option<PathBuf>,
    /// Compare alternatives within one run along this dimension.
    #[arg(long, value_enum, requires = "baseline", conflicts_with = "new")]
    pub by: Option<Dim>,
    /// The value of --by the others are ranked against (e.g. atomic, up, neighbors, 2).
    #[arg(long, requires = "by")]
    pub baseline: Option<String>,
    /// A change counts only when its whole 95% interval clears this many percent.
    #[arg(long, default_value_t = compare::DEFAULT_THRESHOLD_PCT, allow_negative_numbers = true)]
    pub threshold: f64,
    /// What to compare: FPS (higher is better) or the CPU time per frame spent waiting
    /// (lower is better).
    #[arg(long, value_enum, default_value = "fps")]
    pub metric: compare::Metric,
    /// Output format.
    #[arg(long, value_enum, default_value = "text")]
    pub format: CompareFormat,
    /// Exit 2 when the two runs are not like for like (another CPU, core count or core
    /// placement, or workload levels more than 10% apart in microseconds) instead of warning.
    #[arg(long)]
    pub strict: bool,
    /// Compare only the trials that ran in this placement of the two cores (near or far on a
    /// VM whose vCPUs moved, `one` when they never did), on both sides.
    #[arg(long, value_enum)]
    pub placement: Option<crate::placement::Class>,
}

/// Flags of `oceanbench latency`.
#[derive(Debug, Args)]
#[command(
    after_help = "Writes results/latency-<UTC>/latency.json, which report, chart and compare read.\n\nExamples:\n  oceanbench latency\n  oceanbench latency --cores 0,1 --samples 20000 --repeats 10 --out results/latency-mine\n  oceanbench compare results/latency-a results/latency-b\n  oceanbench latency --matrix"
)]
pub struct LatencyArgs {
    /// The two cores, e.g. `0,1` (default: the first two allowed); with --matrix, the cores
    /// to pair (default: every allowed core).
    #[arg(long, value_delimiter = ',')]
    pub cores: Option<Vec<usize>>,
    /// Print the cache-line round trip of every pair of cores instead (as core-to-core-latency
    /// does), each pair named near or far against the others.
    #[arg(long)]
    pub matrix: bool,
    /// Round trips per row and repeat (each row also stops after 2 s).
    #[arg(long, default_value_t = 20_000)]
    pub samples: usize,
    /// Times the whole table is measured, for the spread compare's verdicts need (1 to 100).
    #[arg(long, default_value_t = crate::results::latency::DEFAULT_REPEATS)]
    pub repeats: usize,
    /// Results directory for latency.json and latency.txt (default: results/latency-<UTC
    /// timestamp>); not with --matrix.
    #[arg(long, conflicts_with = "matrix")]
    pub out: Option<PathBuf>,
    /// Also write the run (with --matrix, the matrix) as JSON to this file.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Waiting for other runs on the same cores.
    #[command(flatten)]
    pub wait: WaitArgs,
}

/// Flags of `oceanbench balance`.
#[derive(Debug, Args)]
#[command(
    after_help = "Each dimension flag takes one value or a list; by default the Figure 5-1 sizes in dp with atomic.\nExit status 2 when a range holds no balance point (the message says which side it fell on).\n\nExamples:\n  oceanbench balance\n  oceanbench balance --size 256 --mode dp,up --sync atomic,condvar --kernel reference,fast\n  oceanbench balance --size 40 --tolerance 1 --range 0.2,5"
)]
pub struct BalanceArgs {
    /// A config (JSON) whose dimension lists choose the cells and whose `balance` object sets
    /// the search; the flags below override it.
    pub config: Option<PathBuf>,
    /// The cells to search (not --workload: the search sets it).
    #[command(flatten)]
    pub select: DimArgs,
    /// Stop when the bracket is narrower than this percentage of the step (default 2).
    #[arg(long, allow_negative_numbers = true)]
    pub tolerance: Option<f64>,
    /// Points of the speed-up curve (default 12).
    #[arg(long)]
    pub points: Option<usize>,
    /// The range of workloads, as multiples of the step: FROM,TO (default 0.1,10).
    #[arg(long, value_delimiter = ',')]
    pub range: Option<Vec<f64>>,
    /// Paired trials at every probe (default 3).
    #[arg(long)]
    pub trials: Option<u32>,
    /// Cores for the main and helper threads, e.g. `0,1` (config key `cores`; default: the
    /// first two allowed).
    #[arg(long, value_delimiter = ',')]
    pub cores: Option<Vec<usize>>,
    /// Results directory (default: results/balance-<UTC timestamp>).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Do not draw the charts at the end.
    #[arg(long)]
    pub no_charts: bool,
    /// Waiting for other runs on the same cores.
    #[command(flatten)]
    pub wait: WaitArgs,
}

/// Flags of `oceanbench doctor`.
#[derive(Debug, Args)]
#[command(
    after_help = "Exit status 0 whatever it finds; entries missing from /proc or /sys are listed.\n\nExamples:\n  oceanbench doctor\n  oceanbench doctor --cores 2,3 --seconds 5 --json"
)]
pub struct DoctorArgs {
    /// The main and helper cores to check, e.g. `0,1` (default: the first two allowed).
    #[arg(long, value_delimiter = ',')]
    pub cores: Option<Vec<usize>>,
    /// Seconds to watch the machine for steal, load and busy threads.
    #[arg(long, default_value_t = 2.0, allow_negative_numbers = true)]
    pub seconds: f64,
    /// Print the findings as JSON.
    #[arg(long)]
    pub json: bool,
}

/// Flags of `oceanbench completions`.
#[derive(Debug, Args)]
#[command(
    after_help = "Examples:\n  oceanbench completions bash > ~/.local/share/bash-completion/completions/oceanbench\n  oceanbench completions zsh > ~/.zfunc/_oceanbench\n  oceanbench completions fish > ~/.config/fish/completions/oceanbench.fish"
)]
pub struct CompletionsArgs {
    /// The shell to complete in.
    #[arg(value_enum)]
    pub shell: clap_complete::Shell,
}

/// Flags of `oceanbench man`.
#[derive(Debug, Args)]
#[command(
    after_help = "Examples:\n  oceanbench man | man -l -\n  oceanbench man --out ~/.local/share/man/man1"
)]
pub struct ManArgs {
    /// Write oceanbench.1 and one oceanbench-<command>.1 per command into this existing folder
    /// instead of printing the top page.
    #[arg(long)]
    pub out: Option<PathBuf>,
}

/// Flags of `oceanbench placement`.
#[derive(Debug, Args)]
#[command(
    after_help = "Examples:\n  oceanbench placement results/projected-20261125T163816Z\n  oceanbench placement results/fog-20261125T163342Z --json"
)]
pub struct PlacementArgs {
    /// The results directory (or its results.json).
    pub results: PathBuf,
    /// Print the cells' placements and the finding as JSON.
    #[arg(long)]
    pub json: bool,
}

/// Flags of `oceanbench findings`.
#[derive(Debug, Args)]
#[command(
    after_help = "Examples:\n  oceanbench findings results/figure-5-1-20261125T064618Z\n  oceanbench findings results/fog-20261125T163342Z --json"
)]
pub struct FindingsArgs {
    /// The results directory (or its results.json).
    pub results: PathBuf,
    /// Print findings.json's content instead of sentences.
    #[arg(long)]
    pub json: bool,
    /// Print every cell's label instead, one per line: what `docs` blocks name a cell by.
    #[arg(long, conflicts_with = "json")]
    pub cells: bool,
}

/// Flags of `oceanbench docs`.
#[derive(Debug, Args)]
#[command(
    after_help = "Examples:\n  oceanbench docs --check\n  oceanbench docs --write\n  oceanbench docs --numbers"
)]
pub struct DocsArgs {
    /// Rewrite every generated block in place from its run.
    #[arg(long, conflicts_with_all = ["check", "numbers"])]
    pub write: bool,
    /// Exit 1 when a generated block differs from what its run gives (2 when a block is bad).
    #[arg(long, conflicts_with = "numbers")]
    pub check: bool,
    /// List the numbers left outside generated blocks, one per line (file:line: number: text).
    #[arg(long)]
    pub numbers: bool,
    /// The checkout's top folder: README.md, docs/ and the runs are read under it.
    #[arg(long, default_value = ".")]
    pub root: PathBuf,
}

/// Flags of `oceanbench bench-record`.
#[derive(Debug, Args)]
#[command(
    after_help = "scripts/bench-run.sh touches the stamp, runs cargo bench and then this.\n\nExamples:\n  oceanbench bench-record fft --since /tmp/stamp --out results/bench-fft-20261127T120000Z -- scripts/bench-run.sh fft fft-512"
)]
pub struct BenchRecordArgs {
    /// The bench's name (its `cargo bench --bench` target), in the folder name and bench.json.
    pub name: String,
    /// Criterion's output folder.
    #[arg(long, default_value = "target/criterion")]
    pub criterion_dir: PathBuf,
    /// A file touched before `cargo bench` started: only estimates written since count.
    #[arg(long, value_name = "STAMP_FILE")]
    pub since: PathBuf,
    /// The run's folder (default: results/bench-<name>-<UTC timestamp>).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// How the run was made, recorded in bench.json (default: this command line).
    #[arg(last = true, value_name = "COMMAND")]
    pub command: Vec<String>,
}

/// Flags of `oceanbench export`.
#[derive(Debug, Args)]
#[command(
    after_help = "Each cell is one benchmark, named by every dimension's value and its workload level as the config gives it; FPS with the slowest and fastest trial as its bounds (docs/ci.md).\n\nExamples:\n  oceanbench export results/figure-5-1-20261125T064618Z --format bmf --out bmf.json\n  oceanbench export results/quick/results.json --format github-action-benchmark"
)]
pub struct ExportArgs {
    /// The run: a results directory or its results.json.
    pub run: PathBuf,
    /// The tracker's format.
    #[arg(long, value_enum)]
    pub format: crate::report::ci::CiFormat,
    /// The file to write (default: standard output).
    #[arg(long)]
    pub out: Option<PathBuf>,
}

/// Flags of `oceanbench history`.
#[derive(Debug, Args)]
#[command(
    after_help = "Runs are ordered by the time they started, then by commit, whatever order they are given in. Each cell's change points are printed (docs/ci.md).\n\nExit status: 0, or 1 when a cell's newest run lies in a segment that began with a regression; 2 on bad input.\n\nExamples:\n  oceanbench history results/ci-*/ --out history\n  oceanbench history a/results.json b/results.json --metric fps,wait-cpu --size 128 --mode dp"
)]
pub struct HistoryArgs {
    /// Two or more runs: results folders or results.json files.
    #[arg(required = true, value_name = "RUN")]
    pub runs: Vec<PathBuf>,
    /// The metrics to chart, one chart each.
    #[arg(long, value_enum, value_delimiter = ',', default_value = "fps")]
    pub metric: Vec<compare::Metric>,
    /// Folder for the charts (history-<metric>.<format>).
    #[arg(long, default_value = ".")]
    pub out: PathBuf,
    /// Image formats.
    #[arg(long, value_enum, value_delimiter = ',', default_value = "png,svg")]
    pub format: Vec<ChartFormat>,
    /// Chart runs whose configs differ (by default refused: their cells are other work).
    #[arg(long)]
    pub force: bool,
    /// Which cells to draw: a dimension given keeps the cells with one of its values (default:
    /// every cell of the newest run).
    #[command(flatten)]
    pub select: DimArgs,
}

/// Flags of `oceanbench mesh`.
#[derive(Debug, Args)]
#[command(
    after_help = "Examples:\n  oceanbench mesh --size 32 --time 10 --waves my-waves.json --out frame.csv\n  oceanbench mesh --ocean fft --size 256 --time 10 --out fft.csv\n  oceanbench mesh --grid projected --size 64 --time 2 --camera-height 20 --pitch 20 --out projected.csv"
)]
pub struct MeshArgs {
    /// Mesh size N (N×N vertices).
    #[arg(long)]
    pub size: usize,
    /// Simulated time t in seconds.
    #[arg(long, allow_negative_numbers = true)]
    pub time: f32,
    /// Distance between vertices (the sines; the fft ocean's is its patch ÷ size).
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
    pub spacing: f32,
    /// Waves file (JSON); default: the built-in deep-ocean set.
    #[arg(long)]
    pub waves: Option<PathBuf>,
    /// The FFT ocean's parameters file (JSON); default: the values of configs/fft-ocean.json.
    #[arg(long)]
    pub fft_params: Option<PathBuf>,
    /// Which ocean model computes the surface (a registered model: sines, fft, ...).
    #[arg(long, value_parser = |s: &str| crate::ocean::OceanKind::parse(s), default_value = "sines")]
    pub ocean: crate::ocean::OceanKind,
    /// How vertex normals are computed.
    #[arg(long, value_enum, default_value = "analytic")]
    pub normals: crate::ocean::NormalMethod,
    /// Which kernel computes the surface.
    #[arg(long, value_enum, default_value = "reference")]
    pub kernel: crate::ocean::Kernel,
    /// Where the vertices lie: the regular patch, or projected from the camera.
    #[arg(long, value_enum, default_value = "regular")]
    pub grid: crate::ocean::GridKind,
    /// The camera the projected grid is cast from.
    #[command(flatten)]
    pub camera: CameraArgs,
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
    let suggested = get(ContextKind::SuggestedValue)
        .map(|v| format!("; did you mean `{v}`?"))
        .unwrap_or_default();
    match err.kind() {
        ErrorKind::InvalidValue | ErrorKind::ValueValidation if !arg.is_empty() => {
            let why = std::error::Error::source(err)
                .map(|m| format!(": {m}"))
                .unwrap_or_default();
            format!("{arg}: invalid value '{value}'{why}{suggested}{allowed}")
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
