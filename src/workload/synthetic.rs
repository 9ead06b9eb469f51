//! The synthetic main-thread work standing in for a game's AI and collision: CPU-bound, a
//! dependent chain of integer mixing the compiler can neither vectorise nor remove, and never a
//! sleep (a sleeping main thread would free the core and falsify the one-core `up` mode).

use crate::stats;
use serde::{Deserialize, Serialize};
use std::hint::black_box;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

/// Runs `iterations` steps of the mixing chain from `seed` and returns its final value.
#[inline(never)]
pub fn run(iterations: u64, seed: u64) -> u64 {
    let mut z = black_box(seed);
    for _ in 0..black_box(iterations) {
        // splitmix64's finaliser: each step depends on the last, so iterations cannot overlap.
        z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
    }
    black_box(z)
}

/// Iterations between two looks at the stop flag: about 100 µs of work on current machines,
/// far too few looks to show in the timing and often enough to stop any frame at once.
const CHUNK: u64 = 1 << 14;

/// Runs `iterations` steps as [`run`] does, looking at `stop` every `CHUNK` iterations; `None`
/// when it was raised before the work was done.
pub fn run_unless(iterations: u64, seed: u64, stop: Option<&AtomicBool>) -> Option<u64> {
    let mut z = seed;
    let mut left = iterations;
    while left > 0 {
        if stop.is_some_and(|s| s.load(Ordering::Relaxed)) {
            return None;
        }
        let n = left.min(CHUNK);
        z = run(n, z);
        left -= n;
    }
    Some(z)
}

/// The machine's speed at the workload, measured once per run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Calibration {
    /// Nanoseconds per iteration (median of the samples).
    pub ns_per_iteration: f64,
    /// Iterations per sample.
    pub sample_iterations: u64,
    /// Nanoseconds per iteration of each sample, in the order taken.
    pub samples_ns_per_iteration: Vec<f64>,
}

impl Calibration {
    /// Times `samples` runs of about 2 ms each, after a warm-up, on the calling thread.
    pub fn measure(samples: usize) -> Calibration {
        let probe = 1u64 << 16;
        let t = Instant::now();
        black_box(run(probe, 1));
        let per_iter = t.elapsed().as_secs_f64() / probe as f64;
        let sample_iterations = ((2e-3 / per_iter.max(1e-10)) as u64).clamp(probe, 1 << 26);
        black_box(run(sample_iterations, 2));
        let samples_ns_per_iteration: Vec<f64> = (0..samples.max(1))
            .map(|s| {
                let t = Instant::now();
                black_box(run(sample_iterations, s as u64));
                t.elapsed().as_nanos() as f64 / sample_iterations as f64
            })
            .collect();
        Calibration {
            ns_per_iteration: stats::median(&samples_ns_per_iteration),
            sample_iterations,
            samples_ns_per_iteration,
        }
    }

    /// Iterations that take `micros` microseconds of one core on this machine.
    pub fn iterations_for(&self, micros: f64) -> u64 {
        (micros * 1e3 / self.ns_per_iteration).round() as u64
    }
}

/// The kind's name.
pub(super) const NAME: &str = "synthetic";

/// The descriptor of the paper's game work.
pub struct SyntheticKind;

impl super::Kind for SyntheticKind {
    type Params = ();

    fn name(&self) -> &'static str {
        NAME
    }

    fn doc(&self) -> &'static str {
        "The paper's game work: a chain of integer mixing, before the wait for the mesh."
    }

    fn unit(&self) -> &'static str {
        Synthetic::UNIT
    }

    fn is_calibrated_chain(&self) -> bool {
        true
    }

    fn build(&self, spec: &super::WorkSpec, _: &()) -> super::Work {
        super::Work::before_wait(Synthetic::new(spec.amount))
    }
}

/// The synthetic workload of one loop: `iterations` of the chain per frame, seeded with the
/// frame's index.
pub struct Synthetic {
    iterations: u64,
    last: u64,
}

impl Synthetic {
    /// A synthetic level counts iterations of the chain.
    pub const UNIT: &'static str = "iterations";

    /// `iterations` of the chain per frame.
    pub fn new(iterations: u64) -> Synthetic {
        Synthetic {
            iterations,
            last: 0,
        }
    }
}

impl super::WorkOutput for Synthetic {
    fn digest(&self) -> u64 {
        self.last
    }
}

impl super::FrameWork for Synthetic {
    fn run(&mut self, k: u64, stop: Option<&AtomicBool>) -> Result<(), super::Stopped> {
        self.last = run_unless(self.iterations, k, stop).ok_or(super::Stopped)?;
        Ok(())
    }
}
