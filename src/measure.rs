//! Frame statistics: average FPS as frames ÷ elapsed time, frame-time percentiles, the 1% low,
//! the per-frame breakdown, and the spread over trials.

use crate::stats::{self, quantile};
use crate::workload::{WorkCounts, WorkTrial};
use serde::{Deserialize, Serialize};

/// What the main thread timed in one frame (nanoseconds).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FrameRecord {
    /// Whole frame: from its start to the next frame's start, so frames tile the timeline.
    pub total_ns: u64,
    /// The synthetic workload.
    pub workload_ns: u64,
    /// Waiting for the helper's mesh (zero in `serial`).
    pub wait_ns: u64,
    /// CPU time the main thread spent in that wait (the thread CPU clock).
    pub wait_cpu_ns: u64,
    /// Consuming the mesh (copy, read or hand on) and releasing the helper.
    pub copy_ns: u64,
    /// The mesh step as timed by the thread that ran it (in threaded modes it overlaps the
    /// main thread's parts).
    pub step_ns: u64,
    /// The helpers' wait for a free slot before computing this frame (the longest band's).
    pub helper_wait_ns: u64,
    /// CPU time the helpers spent in that wait, together.
    pub helper_wait_cpu_ns: u64,
    /// The rest of the frame: the loop's own bookkeeping, and in `up` whatever the helper ran
    /// between the release and the next frame.
    pub other_ns: u64,
    /// Frames the helper had finished beyond the consumed one when it was consumed.
    pub age_frames: u32,
    /// From the helper publishing the consumed mesh to the main thread taking it.
    pub age_ns: u64,
    /// From the helper starting the consumed mesh (its input) to the main thread taking it.
    pub latency_ns: u64,
    /// The frame index the consumed mesh was computed for: the frame's own under `fifo`, the
    /// newest finished one under `latest`.
    pub mesh_frame: u64,
    /// What the main thread's work counted in the frame (spray's particles), if it counts.
    pub work_counts: Option<WorkCounts>,
}

/// One trial's frames.
#[derive(Clone, Debug, Default)]
pub struct Trial {
    /// Measured frames, in order (warm-up frames are not kept).
    pub frames: Vec<FrameRecord>,
    /// Wall time from the first measured frame's start to the last one's end, timed apart
    /// from the frames: the frames' times add up to it.
    pub wall_ns: u64,
    /// With `read` consumption, the per-frame checksums of the meshes read, folded: the proof
    /// that the read pass happened (and that every mode read the same meshes).
    pub checksum: Option<u64>,
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

    /// What the work counted over the trial's frames, with its mean main-thread time per
    /// frame; `None` when its frames counted nothing.
    pub fn work(&self) -> Option<WorkTrial> {
        let counts: Vec<WorkCounts> = self.frames.iter().filter_map(|f| f.work_counts).collect();
        let main: Vec<f64> = self
            .frames
            .iter()
            .map(|f| f.workload_ns as f64 * 1e-6)
            .collect();
        WorkTrial::of(&counts, stats::mean(&main))
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
    /// The mean of each part over `frames`.
    pub fn of<'a>(frames: impl IntoIterator<Item = &'a FrameRecord>) -> Breakdown {
        let all: Vec<&FrameRecord> = frames.into_iter().collect();
        let part = |f: fn(&FrameRecord) -> u64| {
            stats::mean(&all.iter().map(|r| f(r) as f64 * 1e-6).collect::<Vec<_>>())
        };
        Breakdown {
            workload_ms: part(|r| r.workload_ns),
            wait_ms: part(|r| r.wait_ns),
            copy_ms: part(|r| r.copy_ns),
            step_ms: part(|r| r.step_ns),
            other_ms: part(|r| r.other_ns),
            wait_cpu_ms: part(|r| r.wait_cpu_ns),
            helper_wait_ms: part(|r| r.helper_wait_ns),
            helper_wait_cpu_ms: part(|r| r.helper_wait_cpu_ns),
        }
    }

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

impl Mailbox {
    /// The statistics of the trials' consumed indices ([`FrameRecord::mesh_frame`]).
    pub fn of(trials: &[Trial]) -> Mailbox {
        let mut out = Mailbox {
            dropped: 0,
            repeated: 0,
            consumed: Vec::new(),
        };
        for t in trials {
            let mut runs: Vec<[u64; 2]> = Vec::new();
            for r in &t.frames {
                match runs.last_mut() {
                    Some([index, times]) if *index == r.mesh_frame => {
                        *times += 1;
                        out.repeated += 1;
                    }
                    last => {
                        if let Some([index, _]) = last {
                            out.dropped += r.mesh_frame.saturating_sub(*index + 1);
                        }
                        runs.push([r.mesh_frame, 1]);
                    }
                }
            }
            out.consumed.push(runs);
        }
        out
    }
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

impl Latency {
    fn of(frames: &[&FrameRecord]) -> Latency {
        let ms = |f: fn(&FrameRecord) -> u64| {
            stats::sorted(
                &frames
                    .iter()
                    .map(|r| f(r) as f64 * 1e-6)
                    .collect::<Vec<_>>(),
            )
        };
        let (age, input) = (ms(|r| r.age_ns), ms(|r| r.latency_ns));
        let ages: Vec<f64> = frames.iter().map(|r| f64::from(r.age_frames)).collect();
        Latency {
            age_frames_mean: stats::mean(&ages),
            age_ms_median: quantile(&age, 0.5),
            age_ms_p99: quantile(&age, 0.99),
            input_to_consume_ms_median: quantile(&input, 0.5),
            input_to_consume_ms_p99: quantile(&input, 0.99),
        }
    }
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
            frame_metrics: FrameMetrics::of(&times),
            breakdown: Breakdown::of(all.iter().copied()),
            wait_cpu_ms_trials: trials
                .iter()
                .filter(|t| !t.frames.is_empty())
                .map(|t| {
                    let cpu = |r: &FrameRecord| ms(r.wait_cpu_ns + r.helper_wait_cpu_ns);
                    stats::mean(&t.frames.iter().map(cpu).collect::<Vec<_>>())
                })
                .collect(),
            latency: Some(Latency::of(&all)),
            mailbox: None,
            read_checksum: trials
                .iter()
                .filter_map(|t| t.checksum)
                .reduce(|a, b| a ^ b.rotate_left(17)),
            work_trials: trials.iter().filter_map(Trial::work).collect(),
            frames: all.len(),
            seconds,
        })
    }
}
