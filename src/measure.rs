//! Frame statistics: average FPS as frames ÷ elapsed time, frame-time percentiles, the 1% low,
//! the per-frame breakdown, and the spread over trials.

use crate::stats::{self, quantile};
use serde::{Deserialize, Serialize};

/// What the main thread timed in one frame (nanoseconds).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FrameRecord {
    /// Whole frame: from the start of the workload to the release of the helper.
    pub total_ns: u64,
    /// The synthetic workload.
    pub workload_ns: u64,
    /// Waiting for the helper's mesh (zero in `serial`).
    pub wait_ns: u64,
    /// Copying the mesh into the render buffer.
    pub copy_ns: u64,
    /// The mesh step as timed by the thread that ran it.
    pub step_ns: u64,
}

/// One trial's frames.
#[derive(Clone, Debug, Default)]
pub struct Trial {
    /// Measured frames, in order (warm-up frames are not kept).
    pub frames: Vec<FrameRecord>,
}

impl Trial {
    /// Elapsed seconds over the measured frames.
    pub fn seconds(&self) -> f64 {
        self.frames.iter().map(|f| f.total_ns).sum::<u64>() as f64 * 1e-9
    }

    /// Frames ÷ elapsed seconds.
    pub fn fps(&self) -> f64 {
        self.frames.len() as f64 / self.seconds()
    }
}

/// Percentiles of frame time, in milliseconds.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FrameTimes {
    /// Mean frame time.
    pub mean: f64,
    /// Median frame time.
    pub median: f64,
    /// 99th percentile (nearest rank).
    pub p99: f64,
    /// Slowest frame.
    pub max: f64,
}

/// The quantiles of frame time every summary records, for distribution charts.
pub const QUANTILES: [f64; 10] = [0.0, 0.1, 0.25, 0.5, 0.75, 0.9, 0.95, 0.99, 0.999, 1.0];

/// One point of the frame-time distribution.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Quantile {
    /// The quantile, 0 (fastest frame) to 1 (slowest).
    pub q: f64,
    /// Frame time at that quantile, nearest rank (ms).
    pub ms: f64,
}

/// Mean time per frame of each part of the frame, in milliseconds.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Breakdown {
    /// Main thread's synthetic workload.
    pub workload_ms: f64,
    /// Main thread waiting for the mesh.
    pub wait_ms: f64,
    /// Main thread copying the mesh to its render buffer.
    pub copy_ms: f64,
    /// The mesh step (helper thread, or main in `serial`).
    pub step_ms: f64,
}

/// Spread of the per-trial FPS.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Spread {
    /// Slowest trial.
    pub min: f64,
    /// Fastest trial.
    pub max: f64,
    /// Sample standard deviation over trials (0 with one trial).
    pub stddev: f64,
    /// Standard deviation as a percentage of the mean trial FPS.
    pub cv_percent: f64,
}

/// Everything reported for one cell.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Summary {
    /// All measured frames ÷ all measured seconds, over every trial.
    pub fps: f64,
    /// Each trial's frames ÷ seconds.
    pub fps_trials: Vec<f64>,
    /// Spread of `fps_trials`.
    pub fps_spread: Spread,
    /// Frame-time percentiles over every measured frame.
    pub frame_time_ms: FrameTimes,
    /// The frame-time distribution at [`QUANTILES`] (absent in results from before it existed).
    #[serde(default)]
    pub frame_time_quantiles: Vec<Quantile>,
    /// 1% low: frames ÷ time of the slowest 1% of frames (at least one frame).
    pub one_percent_low_fps: f64,
    /// Mean per-frame breakdown.
    pub breakdown: Breakdown,
    /// Measured frames over every trial.
    pub frames: usize,
    /// Measured seconds over every trial.
    pub seconds: f64,
}

impl Summary {
    /// Summarises the trials of one cell; `None` when no frame was measured.
    pub fn of(trials: &[Trial]) -> Option<Summary> {
        let all: Vec<&FrameRecord> = trials.iter().flat_map(|t| &t.frames).collect();
        if all.is_empty() {
            return None;
        }
        let ms = |ns: u64| ns as f64 * 1e-6;
        let times = stats::sorted(&all.iter().map(|f| ms(f.total_ns)).collect::<Vec<_>>());
        let seconds: f64 = trials.iter().map(Trial::seconds).sum();
        let fps_trials: Vec<f64> = trials
            .iter()
            .filter(|t| !t.frames.is_empty())
            .map(Trial::fps)
            .collect();
        let avg = stats::mean(&fps_trials);
        let stddev = stats::stddev(&fps_trials);
        let (min, max) = stats::min_max(&fps_trials);
        let slowest = (times.len() / 100).max(1);
        let slow_ms: f64 = times[times.len() - slowest..].iter().sum();
        let part = |f: fn(&FrameRecord) -> u64| {
            stats::mean(&all.iter().map(|r| ms(f(r))).collect::<Vec<_>>())
        };
        Some(Summary {
            fps: all.len() as f64 / seconds,
            fps_spread: Spread {
                min,
                max,
                stddev,
                cv_percent: 100.0 * stddev / avg,
            },
            fps_trials,
            frame_time_ms: FrameTimes {
                mean: stats::mean(&times),
                median: quantile(&times, 0.5),
                p99: quantile(&times, 0.99),
                max: times[times.len() - 1],
            },
            frame_time_quantiles: QUANTILES
                .iter()
                .map(|&q| Quantile {
                    q,
                    ms: quantile(&times, q),
                })
                .collect(),
            one_percent_low_fps: slowest as f64 * 1e3 / slow_ms,
            breakdown: Breakdown {
                workload_ms: part(|r| r.workload_ns),
                wait_ms: part(|r| r.wait_ns),
                copy_ms: part(|r| r.copy_ns),
                step_ms: part(|r| r.step_ns),
            },
            frames: all.len(),
            seconds,
        })
    }
}
