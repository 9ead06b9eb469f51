//! The sweep configuration: what to sweep, how long to measure, the workload levels, with
//! defaults that reproduce Figure 5-1 and validation that names the field and what is allowed.

use crate::affinity;
use crate::camera::Camera;
use crate::cell::Mode;
use crate::cell::{Axes, CellKey};
pub use crate::machine::available_memory;
use crate::ocean::{self, mesh, FftParams, Grid, Mesh, OceanParams, Wave, WaveSet};
use crate::suggest;
use crate::workload::{self, KindParams, WorkloadKind};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

pub use crate::input::InputError;
pub use crate::level::{too_much_work, Calibrate, Level};

/// Most times a noisy trial may be re-run (`retry_noisy`).
pub const MAX_RETRY_NOISY: u32 = 10;

/// A sweep: the lists of [`Axes`] are crossed into cells; every other key sets how the cells
/// are measured. A key left out takes the Figure 5-1 default.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct SweepConfig {
    /// Names the results directory.
    pub name: String,
    /// Free text recorded with the results.
    pub description: String,
    /// The swept lists, one per dimension of a cell, under their own keys.
    #[serde(flatten)]
    pub axes: Axes,
    /// What reading the config chose that the user did not name (normals fitted to the cells),
    /// for the command to say once; not part of the file.
    #[serde(skip)]
    pub notes: Vec<String>,
    /// Trials per cell.
    pub trials: u32,
    /// Frames thrown away before each trial.
    pub warmup_frames: u64,
    /// Measured frames per trial, at least.
    pub min_frames: u64,
    /// Measured seconds per trial, at least.
    pub min_seconds: f64,
    /// A trial stops after this many seconds even short of `min_frames`.
    pub max_seconds: f64,
    /// The workload levels, indexed by `workloads`.
    pub workload_levels: Vec<Level>,
    /// Distance between grid vertices.
    pub spacing: f32,
    /// Simulated seconds per frame.
    pub time_step: f64,
    /// The waves (default: the built-in deep-ocean set).
    pub waves: Option<Vec<Wave>>,
    /// A waves file, instead of `waves`.
    pub waves_file: Option<PathBuf>,
    /// The FFT ocean's parameters file (default: the values of `configs/fft-ocean.json`).
    pub fft_params: Option<PathBuf>,
    /// Cores for main and helper: `[main]` or `[main, helper]` (default: the first allowed).
    pub cores: Option<Vec<usize>>,
    /// Seconds a hand-off wait may take before the cell is aborted.
    pub timeout_seconds: f64,
    /// Fault injection for testing timeouts: every helper stops producing at this frame.
    pub inject_stall_at_frame: Option<u64>,
    /// When `step_fraction` levels are resolved: before every row (`row`) or once (`once`).
    pub calibrate: Calibrate,
    /// A trial whose run delay or steal exceeds this percentage of its wall time is noisy.
    pub noise_threshold_percent: f64,
    /// Times a noisy trial is re-run before it is kept anyway (0 to 10).
    pub retry_noisy: u32,
    /// A trial more than this percentage below its cell's median FPS is slow, and is explained.
    pub slow_trial_percent: f64,
    /// When present, the sweep also finds each size's balance point (see `oceanbench balance`).
    pub balance: Option<BalanceSettings>,
    /// The camera the `render` and `fog` workloads look through.
    pub camera: Camera,
    /// Each workload kind's and registered ocean model's config object under its name
    /// (`spray`, `fog`), as given: the kind or model parses and checks it
    /// ([`SweepConfig::kind_params`], [`SweepConfig::ocean_params`]).
    #[serde(flatten)]
    pub kinds: serde_json::Map<String, serde_json::Value>,
}

impl Default for SweepConfig {
    fn default() -> Self {
        SweepConfig {
            notes: Vec::new(),
            name: "figure-5-1".into(),
            description: String::new(),
            axes: Axes::default(),
            trials: 5,
            warmup_frames: 20,
            min_frames: 60,
            min_seconds: 0.5,
            max_seconds: 10.0,
            workload_levels: default_levels(),
            spacing: 1.0,
            time_step: 1.0 / 60.0,
            waves: None,
            waves_file: None,
            fft_params: None,
            cores: None,
            timeout_seconds: 5.0,
            inject_stall_at_frame: None,
            calibrate: Calibrate::Row,
            noise_threshold_percent: 2.0,
            retry_noisy: 0,
            slow_trial_percent: crate::slow_trials::DEFAULT_THRESHOLD_PERCENT,
            balance: None,
            camera: Camera::default(),
            kinds: serde_json::Map::new(),
        }
    }
}

/// Workloads 0-3 placed around the step times of the default sizes, as Figure 5-1 has them:
/// 1 below the 40×40 step, 2 between the 40×40 and the 128×128 step, 3 above the 256×256 step.
pub fn default_levels() -> Vec<Level> {
    vec![
        Level::micros(0.0),
        Level::step_fraction(0.7, 40),
        Level::step_fraction(0.7, 128),
        Level::step_fraction(1.25, 256),
    ]
}

/// Parses a config object. Unknown keys are refused with the closest known one (the keys are
/// those a default config writes), each dimension's list is parsed alone so that an error names
/// its place (`modes[1]: ...`), and other fields' errors carry their path. Every unknown key and
/// bad list is reported, one line each, before the other fields are read.
fn parse_config(text: &str) -> Result<SweepConfig, InputError> {
    let value: serde_json::Value =
        serde_json::from_str(text).map_err(|e| InputError(format!("not valid JSON: {e}")))?;
    let Some(object) = value.as_object() else {
        return Err(InputError(
            "must be a JSON object such as {\"sizes\": [40, 128]}".into(),
        ));
    };
    let known = SweepConfig::keys();
    let mut found = Vec::new();
    for (key, list) in object {
        if !known.iter().any(|k| k == key) {
            let known: Vec<&str> = known.iter().map(String::as_str).collect();
            found.push(InputError(suggest::unknown("field", key, &known)));
        } else if let Some(Err(e)) = Axes::parse_key(key, list.clone()) {
            found.push(e);
        }
    }
    InputError::all(found)?;
    let names_normals = object.contains_key("normals");
    let mut config: SweepConfig = serde_path_to_error::deserialize(value).map_err(|e| {
        let path = e.path().to_string();
        let msg = suggest::with_suggestion(&e.into_inner().to_string());
        if path == "." || path.is_empty() {
            InputError(msg)
        } else {
            InputError(format!("{path}: {msg}"))
        }
    })?;
    if !names_normals {
        config.notes.extend(config.axes.fit_default_normals());
    }
    Ok(config)
}

impl SweepConfig {
    /// Parses a config file's text and validates it.
    pub fn from_json(text: &str) -> Result<Self, InputError> {
        let config = parse_config(text).map_err(|e| e.prefixed("config: "))?;
        config.validate()?;
        Ok(config)
    }

    /// Reads and validates a config file; `name` defaults to the file's stem, and a relative
    /// `waves_file` or `fft_params` is found next to the config.
    pub fn load(path: &Path) -> Result<Self, InputError> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| InputError(format!("config {}: {e}", path.display())))?;
        let prefix = format!("{}: ", path.display());
        let in_file = |e: InputError| e.prefixed(&prefix);
        let mut config = parse_config(&text).map_err(in_file)?;
        if let Some(dir) = path.parent() {
            for file in [&mut config.waves_file, &mut config.fft_params]
                .into_iter()
                .flatten()
            {
                if file.is_relative() {
                    *file = dir.join(&*file);
                }
            }
        }
        let named =
            serde_json::from_str::<serde_json::Value>(&text).is_ok_and(|v| v.get("name").is_some());
        if !named {
            if let Some(stem) = path.file_stem() {
                config.name = stem.to_string_lossy().into_owned();
            }
        }
        config.validate().map_err(in_file)?;
        Ok(config)
    }

    /// The most work a frame's workload may be, in microseconds: `timeout_seconds`, after which
    /// a helper waiting for its slot gives the cell up.
    pub fn max_workload_micros(&self) -> f64 {
        self.timeout_seconds * 1e6
    }

    /// Every key a config may have, in the order a config is written: the config's own, then
    /// each registered workload kind's object.
    pub fn keys() -> Vec<String> {
        let mut config = SweepConfig::default();
        config.record_kind_defaults();
        match serde_json::to_value(config) {
            Ok(serde_json::Value::Object(map)) => map.keys().cloned().collect(),
            _ => unreachable!("a config serialises as an object"),
        }
    }

    /// The wave set the config asks for.
    pub fn wave_set(&self) -> Result<WaveSet, InputError> {
        match (&self.waves, &self.waves_file) {
            (Some(_), Some(_)) => Err(InputError(
                "waves, waves_file: give one of them, not both".into(),
            )),
            (Some(waves), None) => {
                WaveSet::new(waves.clone()).map_err(|e| InputError(e.to_string()))
            }
            (None, Some(path)) => WaveSet::load(path).map_err(|e| InputError(e.to_string())),
            (None, None) => Ok(WaveSet::default()),
        }
    }

    /// Every model's parameters the config asks for: the sines' waves, the FFT ocean's
    /// parameters file, and each registered model's own object.
    pub fn ocean_params(&self) -> Result<OceanParams, InputError> {
        let fft = match &self.fft_params {
            Some(path) => FftParams::load(path)?,
            None => FftParams::default(),
        };
        let mut params = OceanParams::default().with(self.wave_set()?).with(fft);
        for model in ocean::models() {
            if let Some(raw) = self.kinds.get(model.name()) {
                model.parse_params(raw, &mut params)?;
            }
        }
        Ok(params)
    }

    /// Workload kind `kind`'s parameters: its object in the config, or its defaults.
    pub fn kind_params(&self, kind: WorkloadKind) -> Result<KindParams, InputError> {
        kind.kind()?.params(self.kinds.get(kind.name()))
    }

    /// Writes every registered kind's and model's default parameters the config leaves out,
    /// so that a results file records what each ran with.
    pub fn record_kind_defaults(&mut self) {
        let kinds = workload::kinds()
            .into_iter()
            .map(|k| (k.name(), k.default_params()));
        let models = ocean::models()
            .into_iter()
            .map(|m| (m.name(), m.default_params()));
        for (name, params) in kinds.chain(models) {
            if let Some(params) = params {
                self.kinds.entry(name).or_insert(params);
            }
        }
    }

    /// Cores for [main, helper] in DP (main alone in serial and UP), checked against the
    /// allowed cores.
    pub fn placement(&self) -> Result<[usize; 2], InputError> {
        let allowed = affinity::allowed_cores();
        let needs_two = self.axes.modes.contains(&Mode::Dp);
        let cores = match &self.cores {
            Some(c) => {
                affinity::check_allowed(c)?;
                c.clone()
            }
            None => allowed.iter().copied().take(2).collect(),
        };
        match cores.as_slice() {
            [] => Err(InputError(
                "cores: no core is allowed for this process".into(),
            )),
            [only] if needs_two => Err(InputError(format!(
                "modes: dp needs two cores but {}; allowed cores: {}",
                if self.cores.is_some() {
                    format!("cores gives only {only}")
                } else {
                    "this machine (or cgroup) allows only one".to_string()
                },
                affinity::list(allowed)
            ))),
            [only] => Ok([*only, *only]),
            [a, b] if needs_two && a == b => Err(InputError(format!(
                "cores: dp needs two different cores, got {a},{b}"
            ))),
            [a, b] => Ok([*a, *b]),
            _ => Err(InputError(format!(
                "cores: give one or two core ids, got {}",
                affinity::list(&cores)
            ))),
        }
    }

    /// Checks every field before anything runs, and reports every field that fails, one line
    /// each; the cells are crossed only when every field passed, since a cross of bad lists
    /// would repeat their errors.
    pub fn validate(&self) -> Result<(), InputError> {
        let mut found = Vec::new();
        let mut check = |result: Result<(), InputError>| {
            if let Err(e) = result {
                found.push(e);
            }
        };
        check(require(
            !self.name.is_empty()
                && self
                    .name
                    .chars()
                    .all(|c| c.is_ascii_alphanumeric() || "-_.".contains(c)),
            || {
                format!(
                    "name: must be non-empty letters, digits, '-', '_' or '.', got {:?}",
                    self.name
                )
            },
        ));
        check(self.axes.check().and_then(|()| self.axes.check_coverage()));
        check(require(!self.workload_levels.is_empty(), || {
            "workload_levels: must list at least one value".into()
        }));
        check(require(
            self.spacing.is_finite() && self.spacing > 0.0,
            || format!("spacing: must be a finite number > 0, got {}", self.spacing),
        ));
        // A check that reads another field runs only when that field passed, so one mistake
        // gives one line rather than its consequences too.
        let timeout_ok = self.timeout_seconds.is_finite()
            && self.timeout_seconds > 0.0
            && self.timeout_seconds <= 86_400.0;
        let most_micros = if timeout_ok {
            self.max_workload_micros()
        } else {
            f64::INFINITY
        };
        for (i, level) in self.workload_levels.iter().enumerate() {
            check(level.validate(i, most_micros, &self.axes.workload_kind));
            check(self.check_level_size(i, level));
        }
        let levels = self.workload_levels.len();
        if let Some(&w) = self.axes.workloads.iter().find(|&&w| w >= levels) {
            check(require(levels == 0, || {
                format!(
                    "workloads: {w} has no level; allowed 0 to {} (workload_levels has {levels})",
                    levels - 1
                )
            }));
        }
        check(require((1..=1000).contains(&self.trials), || {
            format!("trials: must be 1 to 1000, got {}", self.trials)
        }));
        check(require(self.min_frames > 0, || {
            "min_frames: must be at least 1, got 0".into()
        }));
        let seconds_ok = |v: f64| v.is_finite() && v >= 0.0;
        check(require(seconds_ok(self.min_seconds), || {
            format!(
                "min_seconds: must be a finite number >= 0, got {}",
                self.min_seconds
            )
        }));
        check(require(
            !seconds_ok(self.min_seconds)
                || (self.max_seconds >= self.min_seconds && self.max_seconds > 0.0),
            || {
                format!(
                    "max_seconds: must be > 0 and >= min_seconds ({}), got {}",
                    self.min_seconds, self.max_seconds
                )
            },
        ));
        check(require(
            self.time_step.is_finite() && self.time_step >= 0.0,
            || {
                format!(
                    "time_step: must be a finite number >= 0, got {}",
                    self.time_step
                )
            },
        ));
        check(require(timeout_ok, || {
            format!(
                "timeout_seconds: must be > 0 and at most 86400, got {}",
                self.timeout_seconds
            )
        }));
        check(require(
            self.noise_threshold_percent > 0.0 && self.noise_threshold_percent < 100.0,
            || {
                format!(
                    "noise_threshold_percent: must be above 0 and below 100, got {}",
                    self.noise_threshold_percent
                )
            },
        ));
        check(crate::slow_trials::check_threshold(self.slow_trial_percent));
        check(require(self.retry_noisy <= MAX_RETRY_NOISY, || {
            format!(
                "retry_noisy: must be 0 to {MAX_RETRY_NOISY}, got {}",
                self.retry_noisy
            )
        }));
        if let Some(b) = &self.balance {
            check(b.validate("balance."));
        }
        check(self.camera.validate());
        for name in self.kinds.keys() {
            check(if let Some(kind) = workload::lookup(name) {
                self.kind_params(WorkloadKind::named(kind.name())).map(drop)
            } else if ocean::lookup(name).is_none() {
                Err(InputError(format!(
                    "{name}: no registered workload kind or ocean model has this key \
                     (registered: {}; {})",
                    workload::names().join(", "),
                    ocean::names().join(", ")
                )))
            } else {
                Ok(())
            });
        }
        check(self.ocean_params().map(drop));
        check(self.placement().map(drop));
        InputError::all(found)?;
        for key in self.axes.cells() {
            // The lists are crossed, so one bad pair would otherwise fail cells mid-sweep.
            key.runnable().values()?;
            check_memory(&key, Grid::new(key.size, self.spacing)?)?;
        }
        Ok(())
    }

    /// A step_fraction level is a fraction of each listed ocean's own yardstick step at its
    /// size, so every listed model must run that size.
    fn check_level_size(&self, i: usize, level: &Level) -> Result<(), InputError> {
        let (Some(_), Some(size)) = (level.step_fraction, level.size) else {
            return Ok(());
        };
        for &ocean in &self.axes.ocean {
            let model = ocean.model();
            model.check(size, model.yardstick().1).map_err(|e| {
                InputError(format!(
                    "workload_levels[{i}].size: {size} is no size of ocean `{ocean}`'s yardstick: {e}"
                ))
            })?;
        }
        Ok(())
    }
}

/// `Ok` when `ok` holds, else the error `message` describes.
fn require(ok: bool, message: impl FnOnce() -> String) -> Result<(), InputError> {
    if ok {
        Ok(())
    } else {
        Err(InputError(message()))
    }
}

/// Refuses a cell whose meshes (the ring's slots and the main thread's render buffer, with one
/// to spare) would not fit in the machine's available memory.
fn check_memory(key: &CellKey, grid: Grid) -> Result<(), InputError> {
    let need = (key.depth.unwrap_or(1) + 2) as u64 * Mesh::bytes(grid) as u64;
    if let Some(avail) = available_memory() {
        if need > avail {
            return Err(InputError(format!(
                "sizes: {n}×{n} needs about {} MiB but only {} MiB is available; max size {}",
                need >> 20,
                avail >> 20,
                mesh::MAX_SIZE,
                n = grid.n
            )));
        }
    }
    Ok(())
}

/// How the search runs; the config key `balance` (an object) sets it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct BalanceSettings {
    /// Stop bisecting when the bracket is narrower than this percentage of the step S.
    pub tolerance_percent: f64,
    /// Points of the speed-up curve, log-spaced over `range`.
    pub points: usize,
    /// The curve's range, and the search's, as W ÷ S.
    pub range: [f64; 2],
    /// Paired trials at every probe.
    pub trials: u32,
}

impl Default for BalanceSettings {
    fn default() -> Self {
        BalanceSettings {
            tolerance_percent: 2.0,
            points: 12,
            range: [0.1, 10.0],
            trials: 3,
        }
    }
}

impl BalanceSettings {
    /// Checks every field, naming it and what is allowed.
    pub fn validate(&self, field: &str) -> Result<(), InputError> {
        let t = self.tolerance_percent;
        if !(t.is_finite() && t > 0.0 && t <= 50.0) {
            return Err(InputError(format!(
                "{field}tolerance_percent: must be above 0 and at most 50, got {t}"
            )));
        }
        if !(2..=64).contains(&self.points) {
            return Err(InputError(format!(
                "{field}points: must be 2 to 64, got {}",
                self.points
            )));
        }
        let [a, b] = self.range;
        if !(a.is_finite() && b.is_finite() && 0.0 < a && a < b && b <= 100.0) {
            return Err(InputError(format!(
                "{field}range: must be [from, to] with 0 < from < to <= 100 (times the step), got [{a}, {b}]"
            )));
        }
        if !(1..=20).contains(&self.trials) {
            return Err(InputError(format!(
                "{field}trials: must be 1 to 20, got {}",
                self.trials
            )));
        }
        Ok(())
    }
}
