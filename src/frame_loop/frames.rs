//! Counting frames against the trial budget: warm-up frames are dropped, measured ones kept,
//! and after each frame the loop learns whether to go on, stop, or give up on a stop request.

use super::{Budget, LoopError, LoopSpec};
use crate::measure::{FrameRecord, Trial};

/// The frames of one loop so far.
pub(super) struct FrameCounter<'a> {
    budget: &'a Budget,
    /// The next frame's index (warm-up frames included).
    pub frame: u64,
    measured_ns: u64,
    records: Vec<FrameRecord>,
}

impl<'a> FrameCounter<'a> {
    pub fn new(budget: &'a Budget) -> Self {
        FrameCounter {
            budget,
            frame: 0,
            measured_ns: 0,
            records: Vec::with_capacity(budget.min_frames.min(1 << 20) as usize),
        }
    }

    /// Records a finished frame. `Ok(true)` when the budget is met, `Ok(false)` to go on, and
    /// `Interrupted` when the stop flag was raised first.
    pub fn finish(&mut self, record: FrameRecord, spec: &LoopSpec) -> Result<bool, LoopError> {
        self.frame += 1;
        if self.frame > self.budget.warmup_frames {
            self.measured_ns += record.total_ns;
            self.records.push(record);
            if self
                .budget
                .met(self.records.len() as u64, self.measured_ns as f64 * 1e-9)
            {
                return Ok(true);
            }
        }
        if spec.stopped() {
            return Err(LoopError::Interrupted);
        }
        Ok(false)
    }

    /// The measured frames.
    pub fn trial(self) -> Trial {
        Trial {
            frames: self.records,
        }
    }
}
