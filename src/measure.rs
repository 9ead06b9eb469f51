//! What the loops measure of each frame, and a cell's statistics computed from it: average FPS
//! as frames ÷ elapsed time, frame-time percentiles, the 1% low, the per-frame breakdown, the
//! meshes' age and the spread over trials. The statistics' types are [`crate::summary`]'s,
//! which results files and reports read without this module.

use crate::stats::{self, quantile};
use crate::summary::work::{WorkCounts, WorkTrial};
use crate::summary::{
    Breakdown, FrameMetrics, FrameTimes, Latency, Mailbox, Quantile, Spread, Summary, QUANTILES,
};

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

impl Latency {
    pub(crate) fn of(frames: &[&FrameRecord]) -> Latency {
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
