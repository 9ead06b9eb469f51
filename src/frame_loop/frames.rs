//! Counting frames against the trial budget and timing them so they tile the timeline: frame k
//! runs from its start to frame k+1's start (PresentMon's MsBetweenPresents), so a trial's frame
//! times add up to its wall time and nothing between frames goes unmeasured.

use super::timeline::{Capture, FrameMarks, Timeline};
use super::{Budget, LoopError, LoopSpec};
use crate::measure::{FrameRecord, Trial};
use std::time::Instant;

/// The frames of one loop so far.
pub(super) struct FrameCounter<'a> {
    budget: &'a Budget,
    /// The next frame's index (warm-up frames included).
    pub frame: u64,
    /// When the current frame started: the previous one's end.
    started: Instant,
    /// When the first measured frame started.
    measuring_since: Option<Instant>,
    measured_ns: u64,
    records: Vec<FrameRecord>,
    checksum: Option<u64>,
    /// The first measured frames' instants, only when a trace was asked for.
    capture: Option<Capture>,
}

impl<'a> FrameCounter<'a> {
    /// Starts the first frame now; with `trace`, keeps the instants of that many measured
    /// frames of a loop with `helpers` helper threads.
    pub fn new(budget: &'a Budget, trace: Option<usize>, helpers: usize) -> Self {
        let capture = trace.map(|cap| Capture::new(cap, helpers));
        FrameCounter {
            budget,
            frame: 0,
            started: Instant::now(),
            measuring_since: None,
            measured_ns: 0,
            records: Vec::with_capacity(budget.min_frames.min(1 << 20) as usize),
            checksum: None,
            capture,
        }
    }

    /// The current frame's trace marks, when it is traced.
    pub fn marks(&mut self) -> Option<FrameMarks<'_>> {
        if self.frame < self.budget.warmup_frames {
            return None;
        }
        self.capture.as_mut()?.marks()
    }

    /// When the current frame started.
    pub fn start(&self) -> Instant {
        self.started
    }

    /// Folds a read pass's checksum into the trial's (measured frames only).
    pub fn read(&mut self, checksum: u64) {
        if self.frame >= self.budget.warmup_frames {
            let so_far = self.checksum.unwrap_or(0);
            self.checksum = Some(so_far.rotate_left(5) ^ checksum);
        }
    }

    /// Ends the current frame now. `record` holds its parts, with `total_ns` the time they
    /// cover; the frame's total becomes the time since its start, and what the parts do not
    /// cover goes to `other_ns`. `Ok(true)` when the budget is met, `Ok(false)` to go on, and
    /// `Interrupted` when the stop flag was raised first.
    pub fn finish(&mut self, mut record: FrameRecord, spec: &LoopSpec) -> Result<bool, LoopError> {
        let end = Instant::now();
        let total = (end - self.started).as_nanos() as u64;
        record.other_ns = total.saturating_sub(record.total_ns);
        record.total_ns = total;
        if self.frame >= self.budget.warmup_frames {
            self.measuring_since.get_or_insert(self.started);
            self.measured_ns += total;
            if let Some(capture) = &mut self.capture {
                capture.finish(self.frame, self.started, end, &record);
            }
            self.records.push(record);
        }
        self.frame += 1;
        self.started = end;
        if self
            .budget
            .met(self.records.len() as u64, self.measured_ns as f64 * 1e-9)
        {
            return Ok(true);
        }
        if spec.stopped() {
            return Err(LoopError::Interrupted);
        }
        Ok(false)
    }

    /// The measured frames, and the timeline of the traced ones.
    pub fn trial(self) -> (Trial, Option<Timeline>) {
        let wall_ns = self
            .measuring_since
            .map_or(0, |since| (self.started - since).as_nanos() as u64);
        let trial = Trial {
            frames: self.records,
            wall_ns,
            checksum: self.checksum,
        };
        (trial, self.capture.map(Capture::timeline))
    }
}
