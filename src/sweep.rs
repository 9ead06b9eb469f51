//! Expands a config into cells, calibrates the workload levels, runs each row's trials
//! interleaved, and hands the results to an [`Observer`] after every row (the sweep command
//! rewrites the results files there), so an interrupted sweep keeps every finished row.

use crate::balance::{self, BalanceError, BalanceSettings, Testbed};
use crate::calibrate::{self, Calibrate, RowCalibration, Yardstick};
use crate::cell::{Dim, Value};
use crate::config::{self, InputError, SweepConfig};
use crate::crosscore;
use crate::findings::placement::{label, round_trips};
use crate::findings::provenance::Provenance;
use crate::frame_loop::{self, Budget, LoopError, LoopSpec, Mode, Threading};
use crate::machine::Machine;
use crate::measure::Trial;
use crate::ocean::{Grid, OceanKind, OceanParams};
use crate::placement::{self, Class, Split};
use crate::results::{
    CalibrationRecord, Cell, CellKey, CellNoise, LevelRecord, Pins, Placement, Results, StepTime,
};
use crate::sched::TrialNoise;
use crate::slow_trials::{self, TrialFacts};
use crate::summary::{Breakdown, Mailbox, Summary};
use crate::sync::{Policy, SyncMethod};
use crate::trace::TracePlan;
use crate::workload::{Calibration, KindParams, LevelAt, WorkRecord, WorkloadKind};
use itertools::Itertools;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, SystemTime};

/// Every cell of the config in the order they run (see [`crate::cell::Axes::cells`]).
pub fn cells(config: &SweepConfig) -> Vec<CellKey> {
    config.axes.cells()
}

/// The line saying which cells a sweep leaves out because a workload kind cannot run on their
/// ocean or grid (spray on the sines), when it lists such a surface beside one it can.
pub fn kind_skips(config: &SweepConfig) -> Option<String> {
    let mut lines = Vec::new();
    for &kind in &config.axes.workload_kind {
        let mut reasons = Vec::new();
        for &ocean in &config.axes.ocean {
            for &grid in &config.axes.grid {
                if let Err(e) = kind.check_surface(ocean, grid) {
                    if !reasons.contains(&e.0) {
                        reasons.push(e.0);
                    }
                }
            }
        }
        if !reasons.is_empty() {
            lines.push(format!("{kind} cells skipped: {}", reasons.join("; ")));
        }
    }
    (!lines.is_empty()).then(|| lines.join("; "))
}

/// Each listed workload kind's parameters, in the order of the list.
fn work_params(config: &SweepConfig) -> Result<Vec<KindParams>, InputError> {
    config
        .axes
        .workload_kind
        .iter()
        .map(|&k| config.kind_params(k))
        .collect()
}

/// Measures the workload speed and the yardstick (every listed size and every size a level
/// refers to), and resolves every level to iterations.
pub fn calibrate(config: &SweepConfig, params: &OceanParams) -> CalibrationRecord {
    let workload = Calibration::measure(9);
    let points = calibrate::yardstick_points(
        &config.axes.ocean,
        &config.axes.sizes,
        &config.workload_levels,
    );
    let start = Yardstick::measure(
        &points,
        config.spacing,
        params,
        workload.sample_iterations,
        7,
        Duration::from_millis(500),
    );
    let step_times = config
        .workload_levels
        .iter()
        .filter_map(|l| l.step_fraction.and(l.size))
        .fold(Vec::<StepTime>::new(), |mut v, size| {
            if !v.iter().any(|s| s.size == size) {
                let median_ms = start.step_of(size).expect("level sizes are measured");
                v.push(StepTime { size, median_ms });
            }
            v
        });
    let levels = config
        .workload_levels
        .iter()
        .enumerate()
        .map(|(index, level)| {
            let (micros, iterations) =
                calibrate::resolve(level, |s| start.step_of(s), workload.ns_per_iteration);
            LevelRecord {
                workload: index,
                level: level.clone(),
                micros,
                iterations,
            }
        })
        .collect();
    CalibrationRecord {
        workload,
        step_times,
        levels,
        start: Some(start),
    }
}

/// Each listed kind's own account of the start record's levels, on the sweep's largest mesh:
/// a kind with its own calibration (fog) times a level given in its unit, and refuses one in µs
/// it cannot reach.
fn kind_levels(
    config: &SweepConfig,
    params: &[KindParams],
    calibration: &mut CalibrationRecord,
) -> Result<(), InputError> {
    let size = config.axes.sizes.iter().copied().max().expect("validated");
    let grid = Grid::new(size, config.spacing).expect("validated");
    for p in params {
        let kind = p.kind().kind()?;
        for l in &mut calibration.levels {
            let at = LevelAt {
                grid,
                camera: config.camera,
                given: l.level.amount().map(|(_, a)| a),
            };
            l.micros = kind
                .start_level(p, &at, l.micros)
                .map_err(|e| InputError(format!("workload_levels[{}]: {e}", l.workload)))?;
        }
    }
    Ok(())
}

/// UTC now in RFC 3339, seconds precision.
pub fn utc_now() -> String {
    humantime::format_rfc3339_seconds(SystemTime::now()).to_string()
}

/// Batches per cross-core measurement: about 50 ms on a far placement.
const ROUND_TRIP_BATCHES: usize = 500;

/// Batches per round trip around a trial: enough for a median that tells near from far.
pub const TRIAL_ROUND_TRIP_BATCHES: usize = 10;

/// Rounds of the yardstick measured before every row, at least (step and workload alternately).
pub const ROW_YARDSTICK_ROUNDS: usize = 5;

/// Time the yardstick before every row takes, at least.
pub const ROW_YARDSTICK_MIN: Duration = Duration::from_millis(50);

/// What a running sweep reports to whoever runs it; every method does nothing unless
/// overridden (as criterion's `Report`).
pub trait Observer {
    /// A trial is about to start.
    fn trial_starting(&mut self, _progress: Progress<'_>) {}

    /// A cell's trials are over: the cell as results keep it, and its last kept trial's frames
    /// (told for measured cells only, once the row's trials are all done, so nothing it does
    /// runs inside a timed loop).
    fn cell_finished(&mut self, _cell: &Cell, _last_trial: &Trial) {}

    /// A row of cells finished, or the whole sweep (then `results.finished` is set): the
    /// results so far, ready to be written.
    fn row_finished(&mut self, _results: &Results) {}
}

/// An observer that wants to know nothing.
impl Observer for () {}

/// Progress of a sweep, for a progress bar.
#[derive(Clone, Debug)]
pub struct Progress<'a> {
    /// Trials finished so far.
    pub done: usize,
    /// Trials in the whole sweep.
    pub total: usize,
    /// The cell about to run.
    pub cell: &'a CellKey,
}

/// A sweep ready to run: validated config, ocean parameters, placement and calibration.
pub struct Sweep {
    /// The results so far (cells grow as groups finish).
    pub results: Results,
    params: OceanParams,
    work_params: Vec<KindParams>,
    cores: [usize; 2],
    keys: Vec<CellKey>,
    stop: Arc<AtomicBool>,
    trace: Option<TracePlan>,
}

impl Sweep {
    /// Validates the config, describes the machine, measures the cross-core round trip and
    /// calibrates the workload.
    pub fn prepare(mut config: SweepConfig) -> Result<Sweep, InputError> {
        config.validate()?;
        config.record_kind_defaults();
        let params = config.ocean_params()?;
        let work_params = work_params(&config)?;
        let cores = config.placement()?;
        let before = (cores[0] != cores[1])
            .then(|| crosscore::round_trip(cores[0], cores[1], ROUND_TRIP_BATCHES));
        let mut calibration = calibrate(&config, &params);
        kind_levels(&config, &work_params, &mut calibration)?;
        for l in &calibration.levels {
            if l.micros > config.max_workload_micros() {
                return Err(InputError(config::too_much_work(
                    &format!("workload_levels[{}]", l.workload),
                    l.micros.round(),
                    config.max_workload_micros(),
                )));
            }
        }
        let keys = cells(&config);
        Ok(Sweep {
            results: Results {
                schema_version: crate::results::SCHEMA_VERSION,
                machine: Machine::current(),
                command: None,
                config,
                calibration,
                round_trip: Placement {
                    before,
                    during: Vec::new(),
                    after: None,
                    thread_siblings: (cores[0] != cores[1])
                        .then(|| crate::doctor::thread_siblings(cores[0], cores[1]))
                        .flatten(),
                },
                started: utc_now(),
                finished: None,
                cells: Vec::new(),
                doctor: None,
                balance: Vec::new(),
                balance_failures: Vec::new(),
                placement: None,
            },
            params,
            work_params,
            cores,
            keys,
            stop: Arc::new(AtomicBool::new(false)),
            trace: None,
        })
    }

    /// Continues an interrupted sweep: same config, same calibration (so the workload levels are
    /// the same iterations), only the cells `previous` lacks.
    pub fn resume(previous: Results) -> Result<Sweep, InputError> {
        let config = previous.config.clone();
        config.validate()?;
        let params = config.ocean_params()?;
        let work_params = work_params(&config)?;
        let cores = config.placement()?;
        let keys = cells(&config)
            .into_iter()
            .filter(|k| previous.cell(k).is_none())
            .collect();
        Ok(Sweep {
            results: Results {
                schema_version: crate::results::SCHEMA_VERSION,
                finished: None,
                ..previous
            },
            params,
            work_params,
            cores,
            keys,
            stop: Arc::new(AtomicBool::new(false)),
            trace: None,
        })
    }

    /// Finds each size's (and grid's) balance point for the sweep's first DP cell of that size (the first
    /// listed value of every other dimension), reporting after each; a search that cannot
    /// bracket a balance point is recorded as a failure, not the end of the sweep.
    fn find_balance_points(
        &mut self,
        settings: &BalanceSettings,
        observer: &mut impl Observer,
    ) -> Result<(), LoopError> {
        let axes = &self.results.config.axes;
        let mut keys: Vec<CellKey> = Vec::new();
        // Each grid its own search: the projected grid's balance is the figure its study is
        // for (one grid listed: one search per size, as before).
        for (&size, &grid) in axes.sizes.iter().cartesian_product(&axes.grid) {
            let first = axes
                .cells()
                .into_iter()
                .find(|k| k.size == size && k.grid == grid && k.mode == Mode::Dp);
            if let Some(k) = first.and_then(|k| k.with(Dim::Workload, Value::Count(0))) {
                keys.push(k);
            }
        }
        for key in keys {
            match balance::search(self, &key, settings) {
                Ok(entry) => self.results.balance.push(entry),
                Err(BalanceError::Interrupted) => return Err(LoopError::Interrupted),
                Err(e) => self
                    .results
                    .balance_failures
                    .push(format!("{}: {e}", key.label())),
            }
            observer.row_finished(&self.results);
        }
        Ok(())
    }

    /// The main and helper cores.
    pub fn cores(&self) -> [usize; 2] {
        self.cores
    }

    /// The cells still to run.
    pub fn keys(&self) -> &[CellKey] {
        &self.keys
    }

    /// The flag that stops the sweep after the current frame when raised.
    pub fn stop_flag(&self) -> Arc<AtomicBool> {
        Arc::clone(&self.stop)
    }

    /// The same sweep, stopped by `stop` instead of its own flag (a process-wide interrupt).
    pub fn stopping_on(self, stop: Arc<AtomicBool>) -> Sweep {
        Sweep { stop, ..self }
    }

    /// The same sweep, writing the trace of the first trial of each cell `plan` chooses.
    pub fn tracing(self, plan: TracePlan) -> Sweep {
        Sweep {
            trace: Some(plan),
            ..self
        }
    }

    /// Runs the cells group by group, telling `observer` before every trial and after every
    /// group.
    ///
    /// A group is one row of Figure 5-1 (the same value of every row dimension): its cells'
    /// trials run in rotation (A B C A B C ...) so slow drift, such as the vCPUs moving between
    /// near and far placements, hits every cell of the row alike. The cross-core round trip is
    /// measured around every trial, and again after every group. With `retry_noisy` above 0, a
    /// cell whose trials mixed placements runs extra rounds (at most that many) until one
    /// placement holds `trials` of its trials; the others are set aside.
    pub fn run(mut self, observer: &mut impl Observer) -> Results {
        let keys = std::mem::take(&mut self.keys);
        let trials = self.results.config.trials as usize;
        let mut total = keys.len() * trials;
        let mut done = 0;
        for group in keys.chunk_by(|a, b| a.row() == b.row()) {
            let (iterations, calibration) = self.calibrate_row(&group[0]);
            let mut runs: Vec<CellRun> = group
                .iter()
                .map(|k| self.start_cell(k, iterations, calibration.clone()))
                .collect();
            for _ in 0..trials {
                let live = runs.iter_mut().filter(|r| r.error.is_none());
                if self.round(live, observer, &mut done, total).is_err() {
                    return self.results;
                }
            }
            for _ in 0..self.results.config.retry_noisy {
                let split = self.split_with(&runs);
                let mixed: Vec<&mut CellRun> = runs
                    .iter_mut()
                    .filter(|r| r.error.is_none() && r.needs_round(split.as_ref(), trials))
                    .collect();
                if mixed.is_empty() {
                    break;
                }
                total += mixed.len();
                if self.round(mixed, observer, &mut done, total).is_err() {
                    return self.results;
                }
            }
            let split = self.split_with(&runs);
            let config = &self.results.config;
            let (noise, slow) = (config.noise_threshold_percent, config.slow_trial_percent);
            for run in runs {
                let (cell, last_trial) = run.finish(noise, slow, split.as_ref(), trials);
                if let Some(trial) = &last_trial {
                    observer.cell_finished(&cell, trial);
                }
                self.results.cells.push(cell);
            }
            if self.cores[0] != self.cores[1] {
                let rt = crosscore::round_trip(self.cores[0], self.cores[1], ROUND_TRIP_BATCHES);
                self.results.round_trip.during.push(rt);
            }
            label(&mut self.results);
            observer.row_finished(&self.results);
            if self.stop.load(Ordering::Relaxed) {
                return self.results;
            }
        }
        if let Some(settings) = self.results.config.balance.clone() {
            if let Err(LoopError::Interrupted) = self.find_balance_points(&settings, observer) {
                return self.results;
            }
        }
        if self.cores[0] != self.cores[1] {
            self.results.round_trip.after = Some(crosscore::round_trip(
                self.cores[0],
                self.cores[1],
                ROUND_TRIP_BATCHES,
            ));
        }
        label(&mut self.results);
        self.results.finished = Some(utc_now());
        observer.row_finished(&self.results);
        self.results
    }

    /// One round: a kept trial of each of `runs` in turn, telling `observer` before each.
    /// `Err` when a stop request arrived.
    fn round<'r>(
        &self,
        runs: impl IntoIterator<Item = &'r mut CellRun>,
        observer: &mut impl Observer,
        done: &mut usize,
        total: usize,
    ) -> Result<(), LoopError> {
        for run in runs {
            observer.trial_starting(Progress {
                done: *done,
                total,
                cell: &run.key,
            });
            self.run_trial(run)?;
            *done += 1;
        }
        Ok(())
    }

    /// One kept trial of `run`, with the round trips around it: a noisy trial is re-run up to
    /// `retry_noisy` times. `Err` when a stop request arrived.
    fn run_trial(&self, run: &mut CellRun) -> Result<(), LoopError> {
        let config = &self.results.config;
        let mut retries_left = config.retry_noisy;
        // Only a cell's first attempt is traced: one file per cell.
        let trace = self
            .trace
            .as_ref()
            .filter(|p| run.trials.is_empty() && run.retries == 0 && p.chooses(&run.key));
        loop {
            let before = self.trial_round_trip();
            let cap = trace.filter(|_| run.retries == 0).map(|p| p.frames);
            let outcome = frame_loop::run_traced(&run.spec, &budget(config), cap, |_, _| {});
            let around = before.zip(self.trial_round_trip());
            if let (Some(plan), Ok(lr)) = (trace, &outcome) {
                if let Some(timeline) = &lr.timeline {
                    let provenance = Provenance::of_trial(
                        &self.results,
                        run.key.label(),
                        around.map(|(a, b)| [a, b]),
                    );
                    if let Err(e) = plan.write(&run.key, run.spec.consume, timeline, &provenance) {
                        eprintln!(
                            "oceanbench: --trace: {}: {e}",
                            plan.path_for(&run.key).display()
                        );
                    }
                }
            }
            match outcome {
                Ok(lr) if retries_left > 0 && lr.noise.is_noisy(config.noise_threshold_percent) => {
                    retries_left -= 1;
                    run.retries += 1;
                }
                Ok(lr) => {
                    run.record(lr, config.noise_threshold_percent, around);
                    return Ok(());
                }
                Err(LoopError::Interrupted) => return Err(LoopError::Interrupted),
                Err(e) => {
                    run.error = Some(e.to_string());
                    return Ok(());
                }
            }
        }
    }

    /// The split of every round trip so far: the finished cells' and the row's under way.
    fn split_with(&self, runs: &[CellRun]) -> Option<Split> {
        let row = runs
            .iter()
            .flat_map(|r| &r.facts)
            .filter_map(|f| f.round_trip_ns)
            .flatten();
        Split::of(round_trips(&self.results).into_iter().chain(row))
    }

    /// The workload iterations of a row's cells and how they were set: the yardstick is
    /// measured again (step of the row's size and of the level's size, interleaved with the
    /// workload), and a `step_fraction` level is re-derived from it unless the config says
    /// `once`. `None` for results that predate the start yardstick (a resumed old sweep).
    fn calibrate_row(&self, key: &CellKey) -> (u64, Option<RowCalibration>) {
        let config = &self.results.config;
        let at_start = &self.results.calibration.levels[key.workload];
        let Some(start) = &self.results.calibration.start else {
            return (at_start.iterations, None);
        };
        let level = &config.workload_levels[key.workload];
        let points: Vec<(OceanKind, usize)> = calibrate::yardstick_sizes(&[key.size], [level])
            .into_iter()
            .map(|s| (key.ocean, s))
            .collect();
        let row = Yardstick::measure(
            &points,
            config.spacing,
            &self.params,
            self.results.calibration.workload.sample_iterations,
            ROW_YARDSTICK_ROUNDS,
            ROW_YARDSTICK_MIN,
        );
        // A step_fraction level is a fraction of the row's own ocean's step: the row's yardstick,
        // or with `once` the start's (whose record of levels is the sines').
        let (micros, iterations) = match (config.calibrate, level.step_fraction) {
            (Calibrate::Row, Some(_)) => {
                calibrate::resolve(level, |s| row.step_for(key.ocean, s), row.ns_per_iteration)
            }
            (Calibrate::Once, Some(_)) if key.ocean != calibrate::LEVEL_OCEAN => {
                calibrate::resolve(
                    level,
                    |s| start.step_for(key.ocean, s),
                    start.ns_per_iteration,
                )
            }
            _ => (at_start.micros, at_start.iterations),
        };
        let params = self.params_of(key.workload_kind);
        let at = LevelAt {
            grid: Grid::new(key.size, config.spacing).expect("validated"),
            camera: config.camera,
            given: level.amount().map(|(_, a)| a),
        };
        let asked = micros;
        let (micros, iterations) = match key.workload_kind.kind() {
            Ok(kind) => kind.row_level(params, &at, micros, iterations),
            Err(_) => (micros, iterations),
        };
        let calibration = RowCalibration {
            calibrate: config.calibrate,
            step_ms_at_start: start.step_for(key.ocean, key.size).unwrap_or(f64::NAN),
            step_ms_in_row: row.step_for(key.ocean, key.size).unwrap_or(f64::NAN),
            ns_per_iteration_at_start: start.ns_per_iteration,
            ns_per_iteration_in_row: row.ns_per_iteration,
            level_micros: micros,
            asked_micros: at
                .given
                .is_none()
                .then(|| RowCalibration::missed(asked, micros))
                .flatten(),
        };
        (iterations, Some(calibration))
    }

    /// The median cross-core round trip around a trial (ns): about 2,200 cache-line trips and
    /// two thread starts, 0.5 ms on near cores and a few ms on far ones, to place every trial,
    /// serial and UP ones too (whose own threads share one core, but whose speed the host's
    /// placement of the vCPUs still sets). `None` when the sweep has one core.
    fn trial_round_trip(&self) -> Option<f64> {
        (self.cores[0] != self.cores[1]).then(|| {
            crosscore::round_trip(self.cores[0], self.cores[1], TRIAL_ROUND_TRIP_BATCHES).median_ns
        })
    }

    /// The core of the helper (helper 0, with several) in `mode`.
    fn helper_core(&self, mode: Mode) -> usize {
        match mode {
            Mode::Dp => self.cores[1],
            _ => self.cores[0],
        }
    }

    /// Workload kind `kind`'s parameters (every kind of the sweep's cells has them).
    fn params_of(&self, kind: WorkloadKind) -> &KindParams {
        self.work_params
            .iter()
            .find(|p| p.kind() == kind)
            .expect("every listed kind's parameters are parsed when the sweep is made")
    }

    /// The loop of cell `key` with `iterations` of workload per frame, on this sweep's cores.
    pub fn loop_spec(&self, key: &CellKey, iterations: u64) -> LoopSpec {
        let config = &self.results.config;
        LoopSpec {
            grid: Grid::new(key.size, config.spacing).expect("validated"),
            grid_kind: key.grid,
            ocean: key.ocean,
            params: self.params.clone(),
            normals: key.normals,
            kernel: key.kernel,
            mode: key.mode,
            policy: key.policy.unwrap_or(Policy::Fifo),
            sync: key.sync.unwrap_or(SyncMethod::Atomic),
            threading: key.threading.unwrap_or(Threading::Pool),
            workload_kind: key.workload_kind,
            workload_amount: iterations,
            camera: config.camera,
            work_params: self.params_of(key.workload_kind).clone(),
            depth: key.depth.unwrap_or(1),
            consume: key.consume,
            main_core: self.cores[0],
            helper_cores: frame_loop::helper_cores(
                key.mode,
                self.cores[0],
                self.helper_core(key.mode),
                key.helpers.unwrap_or(1),
            ),
            time_step: config.time_step,
            timeout: Duration::from_secs_f64(config.timeout_seconds),
            stop: Some(Arc::clone(&self.stop)),
            stall_at_frame: config.inject_stall_at_frame,
        }
    }

    fn start_cell(
        &self,
        key: &CellKey,
        iterations: u64,
        calibration: Option<RowCalibration>,
    ) -> CellRun {
        let spec = self.loop_spec(key, iterations);
        let helper_core = self.helper_core(key.mode);
        CellRun {
            key: key.clone(),
            pins: Pins {
                main_core: spec.main_core,
                helper_core: (key.mode != Mode::Serial).then_some(helper_core),
                main_held: false,
                helper_held: None,
            },
            spec,
            trials: Vec::new(),
            facts: Vec::new(),
            noise: Vec::new(),
            records: Vec::new(),
            retries: 0,
            calibration,
            pinned: true,
            error: None,
        }
    }
}

/// A cell whose trials are under way.
struct CellRun {
    key: CellKey,
    spec: LoopSpec,
    trials: Vec<Trial>,
    facts: Vec<TrialFacts>,
    noise: Vec<TrialNoise>,
    records: Vec<WorkRecord>,
    retries: usize,
    calibration: Option<RowCalibration>,
    pinned: bool,
    pins: Pins,
    error: Option<String>,
}

impl CellRun {
    /// Keeps a finished trial, with what was measured around it: whether it was noisy under
    /// `noise_percent`, its workload canary and the round trips `around` it.
    fn record(&mut self, run: frame_loop::LoopRun, noise_percent: f64, around: Option<(f64, f64)>) {
        let frames = &run.trial.frames;
        let breakdown = (!frames.is_empty()).then(|| Breakdown::of(frames));
        let ns_per_iteration = self.calibration.as_ref().map(|c| c.ns_per_iteration_in_row);
        let per_iteration = |b: &Breakdown| {
            (self
                .spec
                .workload_kind
                .kind()
                .is_ok_and(|k| k.is_calibrated_chain())
                && self.spec.workload_amount > 0)
                .then(|| b.workload_ms * 1e6 / self.spec.workload_amount as f64)
        };
        self.facts.push(TrialFacts {
            fps: run.trial.fps(),
            workload_ratio: breakdown
                .as_ref()
                .and_then(per_iteration)
                .zip(ns_per_iteration)
                .map(|(ns, cal)| ns / cal),
            breakdown,
            taken_away: run.noise.is_noisy(noise_percent),
            round_trip_ns: around.map(|(a, b)| [a, b]),
        });
        self.pins.main_held = run.main_pin.held;
        self.pins.helper_held =
            (!run.helper_pins.is_empty()).then(|| run.helper_pins.iter().all(|p| p.held));
        self.pinned &= run.pinned();
        self.trials.push(run.trial);
        self.noise.push(run.noise);
        self.records.extend(run.work_record);
    }

    /// Each trial's class against `split`.
    fn classes(&self, split: Option<&Split>) -> Vec<Option<Class>> {
        self.facts
            .iter()
            .map(|f| split.and_then(|s| s.class_of(&f.round_trip_ns.unwrap_or_default())))
            .collect()
    }

    /// Whether the trials mixed placements and no placement holds `trials` of them yet.
    fn needs_round(&self, split: Option<&Split>, trials: usize) -> bool {
        placement::needs_round(&self.classes(split), trials)
    }

    /// The cell: when its trials mixed placements and one placement holds `trials` of them,
    /// those alone, the others set aside. With it, the last kept trial of a cell that did not
    /// fail.
    fn finish(
        self,
        threshold_percent: f64,
        slow_percent: f64,
        split: Option<&Split>,
        trials: usize,
    ) -> (Cell, Option<Trial>) {
        let failed = self.error.is_some();
        let keep = placement::kept(&self.classes(split), trials);
        let (mut trials_kept, _) = partition(self.trials, &keep);
        let (facts, set_aside) = partition(self.facts, &keep);
        let (noise, _) = partition(self.noise, &keep);
        let cell = Cell {
            trials: if failed {
                Vec::new()
            } else {
                slow_trials::attribute(&facts, slow_percent)
            },
            set_aside: if failed {
                Vec::new()
            } else {
                slow_trials::attribute(&set_aside, slow_percent)
            },
            workload_iterations: self.spec.workload_amount,
            workload_unit: Some(self.spec.workload_kind.unit().to_string()),
            workload_amount: Some(self.spec.workload_amount),
            summary: if failed {
                None
            } else {
                Summary::of(&trials_kept).map(|s| Summary {
                    mailbox: (self.key.policy == Some(Policy::Latest))
                        .then(|| Mailbox::of(&trials_kept)),
                    ..s
                })
            },
            pinned: self.pinned && !failed,
            pins: self.pins,
            error: self.error,
            key: self.key,
            calibration: self.calibration,
            work: WorkRecord::of_trials(&self.records),
            noise: (!noise.is_empty()).then_some(CellNoise {
                trials: noise,
                threshold_percent,
                retries: self.retries,
            }),
        };
        let last = trials_kept
            .pop()
            .filter(|t| !failed && !t.frames.is_empty());
        (cell, last)
    }
}

/// The items whose `keep` is true, and the others, each in order.
fn partition<T>(items: Vec<T>, keep: &[bool]) -> (Vec<T>, Vec<T>) {
    let (kept, other): (Vec<_>, Vec<_>) = items.into_iter().zip(keep).partition(|&(_, &k)| k);
    (
        kept.into_iter().map(|(t, _)| t).collect(),
        other.into_iter().map(|(t, _)| t).collect(),
    )
}

/// A balance search probes on the sweep's own set-up: its loops, budget, calibration and cores.
impl Testbed for Sweep {
    fn trial(&self, key: &CellKey, amount: u64) -> Result<Trial, LoopError> {
        let spec = self.loop_spec(key, amount);
        frame_loop::run(&spec, &budget(&self.results.config), |_, _| {}).map(|run| run.trial)
    }

    fn ns_per_iteration(&self) -> f64 {
        self.results.calibration.workload.ns_per_iteration
    }

    fn round_trip(&self, batches: usize) -> Option<f64> {
        let [a, b] = self.cores;
        (a != b).then(|| crosscore::round_trip(a, b, batches).median_ns)
    }
}

/// A trial's frame budget, as the config sets it.
fn budget(config: &SweepConfig) -> Budget {
    Budget {
        warmup_frames: config.warmup_frames,
        min_frames: config.min_frames,
        min_seconds: config.min_seconds,
        max_seconds: config.max_seconds,
    }
}
