//! Expands a config into cells, calibrates the workload levels, runs each row's trials
//! interleaved, and hands the results to an [`Observer`] after every row (the sweep command
//! rewrites the results files there), so an interrupted sweep keeps every finished row.

use crate::config::{InputError, SweepConfig};
use crate::crosscore;
use crate::frame_loop::{self, LoopError, LoopSpec, Mode, Threading};
use crate::machine::Machine;
use crate::measure::{Summary, Trial};
use crate::ocean::{Grid, Kernel, Mesh, NormalMethod, Ocean, WaveSet};
use crate::results::{
    CalibrationRecord, Cell, CellKey, LevelRecord, Pins, Placement, Results, StepTime,
};
use crate::stats;
use crate::sync::SyncMethod;
use crate::workload::Calibration;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant, SystemTime};

/// Every cell of the config in the order they run (see [`crate::cell::Axes::cells`]).
pub fn cells(config: &SweepConfig) -> Vec<CellKey> {
    config.axes.cells()
}

/// Median single-thread step time of an N = `size` mesh with the reference kernel and
/// `neighbors` normals: the yardstick `step_fraction` levels are given in.
pub fn step_time_ms(size: usize, spacing: f32, waves: &WaveSet) -> f64 {
    let grid = Grid::new(size, spacing).expect("sizes are validated before calibration");
    let mut ocean = Ocean::new(
        grid,
        waves.clone(),
        NormalMethod::Neighbors,
        Kernel::Reference,
    )
    .expect("neighbors accepts every valid size");
    let mut mesh = Mesh::new(grid);
    ocean.step(0.0, &mut mesh);
    let mut times = Vec::new();
    let start = Instant::now();
    for k in 1..=31u32 {
        let t = Instant::now();
        ocean.step(k as f32 / 60.0, &mut mesh);
        times.push(t.elapsed().as_secs_f64() * 1e3);
        if k >= 7 && start.elapsed() > Duration::from_millis(500) {
            break;
        }
    }
    stats::median(&times)
}

/// Measures the workload speed and the step times the levels refer to, and resolves every level
/// to iterations.
pub fn calibrate(config: &SweepConfig, waves: &WaveSet) -> CalibrationRecord {
    let workload = Calibration::measure(9);
    let mut step_times: Vec<StepTime> = Vec::new();
    let levels = config
        .workload_levels
        .iter()
        .enumerate()
        .map(|(index, level)| {
            let micros = match (level.micros, level.step_fraction, level.size) {
                (Some(us), _, _) => us,
                (None, Some(fraction), Some(size)) => {
                    let ms = match step_times.iter().find(|s| s.size == size) {
                        Some(s) => s.median_ms,
                        None => {
                            let median_ms = step_time_ms(size, config.spacing, waves);
                            step_times.push(StepTime { size, median_ms });
                            median_ms
                        }
                    };
                    fraction * ms * 1e3
                }
                _ => unreachable!("levels are validated before calibration"),
            };
            LevelRecord {
                workload: index,
                level: level.clone(),
                micros,
                iterations: workload.iterations_for(micros),
            }
        })
        .collect();
    CalibrationRecord {
        workload,
        step_times,
        levels,
    }
}

/// UTC now in RFC 3339, seconds precision.
pub fn utc_now() -> String {
    humantime::format_rfc3339_seconds(SystemTime::now()).to_string()
}

/// Batches per cross-core measurement: about 50 ms on a far placement.
const ROUND_TRIP_BATCHES: usize = 500;

/// What a running sweep reports to whoever runs it; every method does nothing unless
/// overridden (as criterion's `Report`).
pub trait Observer {
    /// A trial is about to start.
    fn trial_starting(&mut self, _progress: Progress<'_>) {}

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

/// A sweep ready to run: validated config, waves, placement and calibration.
pub struct Sweep {
    /// The results so far (cells grow as groups finish).
    pub results: Results,
    waves: WaveSet,
    cores: [usize; 2],
    keys: Vec<CellKey>,
    stop: Arc<AtomicBool>,
}

impl Sweep {
    /// Validates the config, describes the machine, measures the cross-core round trip and
    /// calibrates the workload.
    pub fn prepare(config: SweepConfig) -> Result<Sweep, InputError> {
        config.validate()?;
        let waves = config.wave_set()?;
        let cores = config.placement()?;
        let before = (cores[0] != cores[1])
            .then(|| crosscore::round_trip(cores[0], cores[1], ROUND_TRIP_BATCHES));
        let calibration = calibrate(&config, &waves);
        let keys = cells(&config);
        Ok(Sweep {
            results: Results {
                machine: Machine::current(),
                config,
                calibration,
                round_trip: Placement {
                    before,
                    during: Vec::new(),
                    after: None,
                },
                started: utc_now(),
                finished: None,
                cells: Vec::new(),
            },
            waves,
            cores,
            keys,
            stop: Arc::new(AtomicBool::new(false)),
        })
    }

    /// Continues an interrupted sweep: same config, same calibration (so the workload levels are
    /// the same iterations), only the cells `previous` lacks.
    pub fn resume(previous: Results) -> Result<Sweep, InputError> {
        let config = previous.config.clone();
        config.validate()?;
        let waves = config.wave_set()?;
        let cores = config.placement()?;
        let keys = cells(&config)
            .into_iter()
            .filter(|k| previous.cell(k).is_none())
            .collect();
        Ok(Sweep {
            results: Results {
                finished: None,
                ..previous
            },
            waves,
            cores,
            keys,
            stop: Arc::new(AtomicBool::new(false)),
        })
    }

    /// The cells still to run.
    pub fn keys(&self) -> &[CellKey] {
        &self.keys
    }

    /// The flag that stops the sweep after the current frame when raised.
    pub fn stop_flag(&self) -> Arc<AtomicBool> {
        Arc::clone(&self.stop)
    }

    /// Runs the cells group by group, telling `observer` before every trial and after every
    /// group.
    ///
    /// A group is one row of Figure 5-1 (the same value of every row dimension): its cells'
    /// trials run in rotation (A B C A B C ...) so slow drift, such as the vCPUs moving between
    /// near and far placements, hits every cell of the row alike. The cross-core round trip is
    /// measured again after every group.
    pub fn run(mut self, observer: &mut impl Observer) -> Results {
        let keys = std::mem::take(&mut self.keys);
        let trials = self.results.config.trials as usize;
        let total = keys.len() * trials;
        let mut done = 0;
        for group in keys.chunk_by(|a, b| a.row() == b.row()) {
            let mut runs: Vec<CellRun> = group.iter().map(|k| self.start_cell(k)).collect();
            for _ in 0..trials {
                for run in runs.iter_mut().filter(|r| r.error.is_none()) {
                    observer.trial_starting(Progress {
                        done,
                        total,
                        cell: &run.key,
                    });
                    match frame_loop::run(&run.spec, &self.results.config.budget(), |_, _| {}) {
                        Ok(lr) => run.record(lr),
                        Err(LoopError::Interrupted) => return self.results,
                        Err(e) => run.error = Some(e.to_string()),
                    }
                    done += 1;
                }
            }
            self.results
                .cells
                .extend(runs.into_iter().map(CellRun::finish));
            if self.cores[0] != self.cores[1] {
                let rt = crosscore::round_trip(self.cores[0], self.cores[1], ROUND_TRIP_BATCHES);
                self.results.round_trip.during.push(rt);
            }
            observer.row_finished(&self.results);
            if self.stop.load(Ordering::Relaxed) {
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
        self.results.finished = Some(utc_now());
        observer.row_finished(&self.results);
        self.results
    }

    fn start_cell(&self, key: &CellKey) -> CellRun {
        let config = &self.results.config;
        let iterations = self.results.calibration.levels[key.workload].iterations;
        let helper_core = match key.mode {
            Mode::Dp => self.cores[1],
            _ => self.cores[0],
        };
        let spec = LoopSpec {
            grid: Grid::new(key.size, config.spacing).expect("validated"),
            waves: self.waves.clone(),
            normals: key.normals,
            kernel: key.kernel,
            mode: key.mode,
            sync: key.sync.unwrap_or(SyncMethod::Atomic),
            threading: key.threading.unwrap_or(Threading::Pool),
            workload_iterations: iterations,
            main_core: self.cores[0],
            helper_cores: frame_loop::helper_cores(
                key.mode,
                self.cores[0],
                helper_core,
                key.helpers.unwrap_or(1),
            ),
            time_step: config.time_step,
            timeout: Duration::from_secs_f64(config.timeout_seconds),
            stop: Some(Arc::clone(&self.stop)),
            stall_at_frame: config.inject_stall_at_frame,
        };
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
    pinned: bool,
    pins: Pins,
    error: Option<String>,
}

impl CellRun {
    fn record(&mut self, run: frame_loop::LoopRun) {
        self.pins.main_held = run.main_pin.held;
        self.pins.helper_held =
            (!run.helper_pins.is_empty()).then(|| run.helper_pins.iter().all(|p| p.held));
        self.pinned &= run.pinned();
        self.trials.push(run.trial);
    }

    fn finish(self) -> Cell {
        let failed = self.error.is_some();
        Cell {
            workload_iterations: self.spec.workload_iterations,
            summary: if failed {
                None
            } else {
                Summary::of(&self.trials)
            },
            pinned: self.pinned && !failed,
            pins: self.pins,
            error: self.error,
            key: self.key,
        }
    }
}
