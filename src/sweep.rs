//! Expands a config into cells, calibrates the workload levels, runs every cell's trials and
//! hands each finished cell to a sink (which persists it) before starting the next.

use crate::config::{InputError, SweepConfig};
use crate::crosscore;
use crate::frame_loop::{self, LoopSpec, Mode};
use crate::machine::Machine;
use crate::measure::{Summary, Trial};
use crate::ocean::{Grid, Kernel, Mesh, NormalMethod, Ocean, WaveSet};
use crate::results::{
    CalibrationRecord, Cell, CellKey, LevelRecord, Pins, Placement, Results, StepTime,
};
use crate::workload::Calibration;
use std::time::{Duration, Instant, SystemTime};

/// Every cell of the config in the order they run: size, workload, then normals, kernel, and
/// per mode the methods; `serial` does not hand off, so it is one cell per size × workload.
pub fn cells(config: &SweepConfig) -> Vec<CellKey> {
    let mut out = Vec::new();
    for &size in &config.sizes {
        for &workload in &config.workloads {
            for &normals in &config.normals {
                for &kernel in &config.kernel {
                    for &mode in &config.modes {
                        let key = |sync, threading| CellKey {
                            size,
                            workload,
                            mode,
                            sync,
                            threading,
                            normals,
                            kernel,
                        };
                        if mode == Mode::Serial {
                            out.push(key(None, None));
                            continue;
                        }
                        for &threading in &config.threading {
                            for &sync in &config.sync {
                                out.push(key(Some(sync), Some(threading)));
                            }
                        }
                    }
                }
            }
        }
    }
    out
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
    times.sort_by(f64::total_cmp);
    times[times.len() / 2]
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

/// A sweep ready to run: validated config, waves, placement and calibration.
pub struct Sweep {
    /// The results so far (cells grow as they finish).
    pub results: Results,
    waves: WaveSet,
    cores: [usize; 2],
    keys: Vec<CellKey>,
}

impl Sweep {
    /// Validates the config, describes the machine, measures the cross-core round trip and
    /// calibrates the workload.
    pub fn prepare(config: SweepConfig) -> Result<Sweep, InputError> {
        config.validate()?;
        let waves = config.wave_set()?;
        let cores = config.placement()?;
        let round_trip_before = (cores[0] != cores[1])
            .then(|| crosscore::round_trip(cores[0], cores[1], ROUND_TRIP_BATCHES));
        let calibration = calibrate(&config, &waves);
        let keys = cells(&config);
        Ok(Sweep {
            results: Results {
                machine: Machine::current(),
                config,
                calibration,
                round_trip: Placement {
                    before: round_trip_before,
                    after: None,
                },
                started: utc_now(),
                finished: None,
                cells: Vec::new(),
            },
            waves,
            cores,
            keys,
        })
    }

    /// The cells still to run.
    pub fn keys(&self) -> &[CellKey] {
        &self.keys
    }

    /// Runs every cell, calling `on_cell` with the results after each one finishes (measured or
    /// failed) and `on_start` before each starts.
    pub fn run(
        mut self,
        mut on_start: impl FnMut(usize, &CellKey),
        mut on_cell: impl FnMut(&Results),
    ) -> Results {
        let keys = std::mem::take(&mut self.keys);
        for (i, key) in keys.iter().enumerate() {
            on_start(i, key);
            let cell = self.run_cell(key);
            self.results.cells.push(cell);
            on_cell(&self.results);
        }
        if self.cores[0] != self.cores[1] {
            self.results.round_trip.after = Some(crosscore::round_trip(
                self.cores[0],
                self.cores[1],
                ROUND_TRIP_BATCHES,
            ));
        }
        self.results.finished = Some(utc_now());
        on_cell(&self.results);
        self.results
    }

    fn run_cell(&self, key: &CellKey) -> Cell {
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
            sync: key.sync.unwrap_or(crate::sync::SyncMethod::Atomic),
            threading: key.threading.unwrap_or(frame_loop::Threading::Pool),
            workload_iterations: iterations,
            main_core: self.cores[0],
            helper_core,
            time_step: config.time_step,
            timeout: Duration::from_secs_f64(config.timeout_seconds),
        };
        let budget = config.budget();
        let mut trials: Vec<Trial> = Vec::new();
        let mut pinned = true;
        let mut pins = Pins {
            main_core: spec.main_core,
            helper_core: (key.mode != Mode::Serial).then_some(helper_core),
            main_held: false,
            helper_held: None,
        };
        let mut error = None;
        for _ in 0..config.trials {
            match frame_loop::run(&spec, &budget, |_, _| {}) {
                Ok(run) => {
                    pins.main_held = run.main_pin.held;
                    pins.helper_held = run.helper_pin.map(|p| p.held);
                    pinned &= run.main_pin.held && run.helper_pin.is_none_or(|p| p.held);
                    trials.push(run.trial);
                }
                Err(e) => {
                    error = Some(e.to_string());
                    break;
                }
            }
        }
        Cell {
            key: key.clone(),
            workload_iterations: iterations,
            summary: if error.is_none() {
                Summary::of(&trials)
            } else {
                None
            },
            pinned: pinned && error.is_none(),
            pins,
            error,
        }
    }
}
