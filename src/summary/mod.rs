//! What a cell's measured frames and its work came to, as results files keep it: the frame-time
//! statistics ([`Summary`] and its parts, computed in [`crate::measure`]) and the workload
//! kind's keyed counts and records ([`work`]). Plain data at the bottom of the crate, so that
//! results, findings and reports read them without importing the engine that measures them.

pub mod work;

use crate::stats::{self, quantile};
use serde::{Deserialize, Serialize};
pub use work::{CountStats, WorkCounts, WorkRecord, WorkTrial, MAX_COUNTS};

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
    /// CPU time the main thread burnt in that wait (absent in results from before).
    #[serde(default)]
    pub wait_cpu_ms: f64,
    /// Main thread consuming the mesh (copying it to its render buffer, reading it, or handing
    /// it on) and releasing the helper.
    pub copy_ms: f64,
    /// The mesh step (helper thread, or main in `serial`).
    pub step_ms: f64,
    /// The rest of the frame, so the parts add up to it (absent in results from before).
    #[serde(default)]
    pub other_ms: f64,
    /// The helpers waiting for a free slot (absent in results from before).
    #[serde(default)]
    pub helper_wait_ms: f64,
    /// CPU time the helpers burnt in that wait (absent in results from before).
    #[serde(default)]
    pub helper_wait_cpu_ms: f64,
}

impl Breakdown {
    /// CPU time per frame that every thread together spent waiting, in ms.
    pub fn wait_cpu_ms(&self) -> f64 {
        self.wait_cpu_ms + self.helper_wait_cpu_ms
    }
}

/// How old the consumed meshes were: what run-ahead costs.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Latency {
    /// Mean frames the helper had finished beyond the consumed one.
    pub age_frames_mean: f64,
    /// Median time from the helper publishing a mesh to the main thread taking it (ms).
    pub age_ms_median: f64,
    /// 99th percentile of the same (ms).
    pub age_ms_p99: f64,
    /// Median time from the helper starting a mesh (its input) to the main thread taking it (ms).
    pub input_to_consume_ms_median: f64,
    /// 99th percentile of the same (ms).
    pub input_to_consume_ms_p99: f64,
}

/// What the `latest` policy did with the helper's frames: which ones the main thread took,
/// which it never saw, which it took twice.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Mailbox {
    /// Helper frames published between two consumed ones and never taken, over every trial.
    pub dropped: u64,
    /// Frames that consumed the same mesh as the frame before, over every trial.
    pub repeated: u64,
    /// Each trial's consumed frame indices in order, as `[index, times]` runs: a mesh taken in
    /// `times` frames running.
    pub consumed: Vec<Vec<[u64; 2]>>,
}

/// Frame-time metrics under the names CapFrameX gives them (its
/// `FrametimeStatisticProvider`), each computed from every measured frame of a cell. The
/// "1 % low" of other tools is one of three different things; each has its own field here.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FrameMetrics {
    /// P1: the 1st percentile of per-frame FPS, i.e. 1000 ÷ the 99th percentile frame time
    /// (nearest rank).
    pub p1_fps: f64,
    /// 1 % low average: 1000 ÷ the mean of the frame times at or above the 99th percentile.
    pub one_percent_low_average_fps: f64,
    /// 1 % low integral (MSI Afterburner's): frame times sorted slowest first are summed until
    /// they reach 1 % of the total time; 1000 ÷ the frame time that gets there.
    pub one_percent_low_integral_fps: f64,
    /// P0.1: the same as P1 at 0.1 %.
    pub p0_1_fps: f64,
    /// 0.1 % low average.
    pub point_one_percent_low_average_fps: f64,
    /// 0.1 % low integral.
    pub point_one_percent_low_integral_fps: f64,
    /// Stutter: the share of the total time spent in frames longer than 2.5 × the average
    /// frame time (CapFrameX's `GetStutteringTimePercentage`, factor 2.5).
    pub stutter_time_percent: f64,
}

/// CapFrameX's default stuttering factor.
pub const STUTTER_FACTOR: f64 = 2.5;

impl FrameMetrics {
    /// The metrics of frame times `ms` (milliseconds, in any order); `None` when empty.
    pub fn of(ms: &[f64]) -> Option<FrameMetrics> {
        if ms.is_empty() {
            return None;
        }
        let sorted = stats::sorted(ms);
        let total: f64 = sorted.iter().sum();
        let percentile = |share: f64| quantile(&sorted, 1.0 - share);
        let low_average = |share: f64| {
            let at = percentile(share);
            let slow: Vec<f64> = sorted.iter().copied().filter(|&t| t >= at).collect();
            1000.0 / stats::mean(&slow)
        };
        let low_integral = |share: f64| {
            let mut sum = 0.0;
            for &t in sorted.iter().rev() {
                sum += t;
                if sum >= total * share {
                    return 1000.0 / t;
                }
            }
            1000.0 / sorted[0]
        };
        let average = total / sorted.len() as f64;
        // A fold from +0.0: an empty f64 sum is -0.0, which prints as "-0.00 %".
        let stutter = sorted
            .iter()
            .filter(|&&t| t > STUTTER_FACTOR * average)
            .fold(0.0, |sum, t| sum + t);
        Some(FrameMetrics {
            p1_fps: 1000.0 / percentile(0.01),
            one_percent_low_average_fps: low_average(0.01),
            one_percent_low_integral_fps: low_integral(0.01),
            p0_1_fps: 1000.0 / percentile(0.001),
            point_one_percent_low_average_fps: low_average(0.001),
            point_one_percent_low_integral_fps: low_integral(0.001),
            stutter_time_percent: 100.0 * stutter / total,
        })
    }
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
    /// Each trial's mean CPU time per frame spent waiting, every thread together (ms; absent
    /// in results from before).
    #[serde(default)]
    pub wait_cpu_ms_trials: Vec<f64>,
    /// Spread of `fps_trials`.
    pub fps_spread: Spread,
    /// Frame-time percentiles over every measured frame.
    pub frame_time_ms: FrameTimes,
    /// The frame-time distribution at [`QUANTILES`] (absent in results from before it existed).
    #[serde(default)]
    pub frame_time_quantiles: Vec<Quantile>,
    /// 1% low: frames ÷ time of the slowest 1% of frames (at least one frame), the headline;
    /// see [`FrameMetrics`] for the figures other tools call "1 % low".
    pub one_percent_low_fps: f64,
    /// P1, 1 % low average and integral, their 0.1 % versions, and stutter (absent in results
    /// from before they were recorded).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub frame_metrics: Option<FrameMetrics>,
    /// Mean per-frame breakdown.
    pub breakdown: Breakdown,
    /// The consumed meshes' age (absent in results from before it was recorded).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub latency: Option<Latency>,
    /// Under the `latest` policy, what happened to the helper's frames (absent under `fifo`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mailbox: Option<Mailbox>,
    /// With `read` consumption, the trials' checksums of the meshes read, folded.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub read_checksum: Option<u64>,
    /// Each trial's counts per frame, for a workload kind that counts (spray: its particles).
    /// Results from before counts were keyed hold spray's under `particles`.
    #[serde(default, alias = "particles", skip_serializing_if = "Vec::is_empty")]
    pub work_trials: Vec<WorkTrial>,
    /// Measured frames over every trial.
    pub frames: usize,
    /// Measured seconds over every trial.
    pub seconds: f64,
}

impl Summary {
    /// The median trial's FPS (all frames ÷ all seconds when no trial FPS was kept): the
    /// figure ratios between cells use, which one slow trial does not move.
    pub fn median_trial_fps(&self) -> f64 {
        if self.fps_trials.is_empty() {
            self.fps
        } else {
            stats::median(&self.fps_trials)
        }
    }
}
