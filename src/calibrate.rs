//! Workload levels measured against this machine. A `step_fraction` level is given in the
//! yardstick step of a mesh size of the cell's own ocean (each model names its yardstick: for the
//! sums of sines, the reference kernel with `neighbors` normals) and resolved to workload
//! iterations through the workload's measured speed. Both are measured at the start of a sweep
//! and again before every row, interleaved, so "1.25 × the 256² step" keeps its meaning when the
//! machine slows down mid-sweep (a shared VM's memory-bound step and ALU-bound workload do not
//! slow down alike).

pub use crate::level::Calibrate;
use crate::level::Level;
use crate::ocean::{Grid, Mesh, OceanKind, OceanParams};
use crate::stats;
use crate::workload;
use serde::{Deserialize, Serialize};
use std::time::{Duration, Instant};

pub use crate::level::DRIFT_WARNING;

/// The model whose yardstick the sweep's start record of levels (`calibration.levels`) and
/// `step_ms` use; every other model's steps are kept in `model_step_ms`.
pub const LEVEL_OCEAN: OceanKind = OceanKind::SINES;

/// One model's yardstick step at one size.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ModelStep {
    /// The model.
    pub ocean: OceanKind,
    /// Mesh size N.
    pub size: usize,
    /// Median step (ms) with the model's yardstick kernel and normals.
    pub ms: f64,
}

/// One size's yardstick: an ocean ready to step, as the model's yardstick says.
struct Stepper {
    kind: OceanKind,
    size: usize,
    ocean: Box<dyn crate::ocean::Stepper>,
    mesh: Mesh,
    frame: u32,
}

/// What one measurement found: the median yardstick step of each size and the workload's
/// speed, sampled alternately.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Yardstick {
    /// Median step (ms) of each size, with [`LEVEL_OCEAN`]'s yardstick kernel and normals.
    pub step_ms: Vec<(usize, f64)>,
    /// The same for every other model measured (absent before schema 4: only the sines were).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub model_step_ms: Vec<ModelStep>,
    /// Median nanoseconds per workload iteration.
    pub ns_per_iteration: f64,
}

impl Yardstick {
    /// Measures each model's yardstick at its sizes and the workload in rounds (one step of
    /// each, then one workload sample of `sample_iterations`), at least `min_rounds` and until
    /// `min_time` has passed, at most 31 rounds.
    pub fn measure(
        points: &[(OceanKind, usize)],
        spacing: f32,
        params: &OceanParams,
        sample_iterations: u64,
        min_rounds: usize,
        min_time: Duration,
    ) -> Yardstick {
        let mut steppers: Vec<Stepper> = points
            .iter()
            .map(|&(kind, size)| {
                let grid =
                    Grid::new(size, spacing).expect("sizes are validated before calibration");
                let model = kind.model();
                let (kernel, normals) = model.yardstick();
                let mut ocean = model
                    .prepare(grid, params, normals, kernel)
                    .expect("a model's yardstick accepts every valid size");
                let mut mesh = model.mesh(grid);
                ocean.step(0.0, &mut mesh);
                Stepper {
                    kind,
                    size,
                    ocean,
                    mesh,
                    frame: 0,
                }
            })
            .collect();
        let mut steps: Vec<Vec<f64>> = vec![Vec::new(); steppers.len()];
        let mut work = Vec::new();
        let started = Instant::now();
        for round in 1..=31 {
            for (s, times) in steppers.iter_mut().zip(&mut steps) {
                s.frame += 1;
                let t = Instant::now();
                s.ocean.step(s.frame as f32 / 60.0, &mut s.mesh);
                times.push(t.elapsed().as_secs_f64() * 1e3);
            }
            let t = Instant::now();
            std::hint::black_box(workload::run(sample_iterations, round as u64));
            work.push(t.elapsed().as_nanos() as f64 / sample_iterations.max(1) as f64);
            if round >= min_rounds && started.elapsed() >= min_time {
                break;
            }
        }
        let measured = steppers.iter().zip(&steps);
        Yardstick {
            step_ms: measured
                .clone()
                .filter(|(s, _)| s.kind == LEVEL_OCEAN)
                .map(|(s, t)| (s.size, stats::median(t)))
                .collect(),
            model_step_ms: measured
                .filter(|(s, _)| s.kind != LEVEL_OCEAN)
                .map(|(s, t)| ModelStep {
                    ocean: s.kind,
                    size: s.size,
                    ms: stats::median(t),
                })
                .collect(),
            ns_per_iteration: stats::median(&work),
        }
    }

    /// The measured yardstick step of `ocean` at `size`, if it was measured.
    pub fn step_for(&self, ocean: OceanKind, size: usize) -> Option<f64> {
        if ocean == LEVEL_OCEAN {
            return self.step_of(size);
        }
        self.model_step_ms
            .iter()
            .find(|m| m.ocean == ocean && m.size == size)
            .map(|m| m.ms)
    }

    /// The measured step of `size`, if it was measured.
    pub fn step_of(&self, size: usize) -> Option<f64> {
        self.step_ms
            .iter()
            .find(|(s, _)| *s == size)
            .map(|&(_, ms)| ms)
    }
}

/// The microseconds a level stands for and the workload iterations it comes to, with steps
/// from `step_of` and the workload's speed: a level in iterations is taken as it is, and one in
/// another kind's unit (spray's particles) too, standing for 0 µs: only the chain's iterations
/// have a measured time.
pub fn resolve(
    level: &Level,
    step_of: impl Fn(usize) -> Option<f64>,
    ns_per_iteration: f64,
) -> (f64, u64) {
    let iterations = |micros: f64| (micros * 1e3 / ns_per_iteration).round() as u64;
    match (
        level.micros,
        level.step_fraction,
        level.size,
        level.amount(),
    ) {
        (Some(us), _, _, _) => (us, iterations(us)),
        (None, Some(fraction), Some(size), _) => {
            let us = fraction * step_of(size).expect("the level's size was measured") * 1e3;
            (us, iterations(us))
        }
        (None, None, None, Some((unit, amount))) if unit == workload::Synthetic::UNIT => {
            (amount as f64 * ns_per_iteration / 1e3, amount)
        }
        (None, None, None, Some((_, amount))) => (0.0, amount),
        _ => unreachable!("levels are validated before calibration"),
    }
}

/// The sizes a sweep measures: every listed size (for drift) and every size a level refers to.
pub fn yardstick_sizes<'a>(
    sizes: &[usize],
    levels: impl IntoIterator<Item = &'a Level>,
) -> Vec<usize> {
    let mut all: Vec<usize> = sizes.to_vec();
    all.extend(levels.into_iter().filter_map(|l| l.size));
    all.sort_unstable();
    all.dedup();
    all
}

/// Every (model, size) a yardstick measures: the sizes of [`yardstick_sizes`] for each of
/// `oceans`, and always for [`LEVEL_OCEAN`], whose steps the start record of levels keeps.
pub fn yardstick_points<'a>(
    oceans: &[OceanKind],
    sizes: &[usize],
    levels: impl IntoIterator<Item = &'a Level> + Clone,
) -> Vec<(OceanKind, usize)> {
    let mut kinds = vec![LEVEL_OCEAN];
    kinds.extend(oceans.iter().copied().filter(|&o| o != LEVEL_OCEAN));
    let sizes = yardstick_sizes(sizes, levels);
    kinds
        .into_iter()
        .flat_map(|k| sizes.iter().map(move |&s| (k, s)))
        .collect()
}

/// How a cell's workload level was set and how the machine had moved when its row started.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RowCalibration {
    /// When the level was resolved.
    pub calibrate: Calibrate,
    /// The yardstick step of the cell's size at the start of the sweep (ms).
    pub step_ms_at_start: f64,
    /// The same, measured just before the cell's row (ms).
    pub step_ms_in_row: f64,
    /// Workload nanoseconds per iteration at the start of the sweep.
    pub ns_per_iteration_at_start: f64,
    /// The same, measured just before the row.
    pub ns_per_iteration_in_row: f64,
    /// The microseconds of work per frame the cell's level came to.
    pub level_micros: f64,
    /// The microseconds the level asked for, when its kind could not come within
    /// [`DRIFT_WARNING`] of them (fog on a mesh whose vertex pass alone takes longer).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub asked_micros: Option<f64>,
}

impl RowCalibration {
    /// The step's change since the start, as a fraction (0.1 = 10% slower).
    pub fn step_drift(&self) -> f64 {
        self.step_ms_in_row / self.step_ms_at_start - 1.0
    }

    /// The workload speed's change since the start, as a fraction (0.1 = 10% slower).
    pub fn workload_drift(&self) -> f64 {
        self.ns_per_iteration_in_row / self.ns_per_iteration_at_start - 1.0
    }

    /// Whether either drifted by more than [`DRIFT_WARNING`].
    pub fn drifted(&self) -> bool {
        self.step_drift().abs() > DRIFT_WARNING || self.workload_drift().abs() > DRIFT_WARNING
    }

    /// `asked` when the `ran` µs are more than [`DRIFT_WARNING`] away from it, for
    /// [`RowCalibration::asked_micros`].
    pub fn missed(asked: f64, ran: f64) -> Option<f64> {
        ((ran - asked).abs() > DRIFT_WARNING * asked.max(f64::MIN_POSITIVE)).then_some(asked)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn levels_resolve_against_the_steps_given() {
        let steps = |size: usize| (size == 256).then_some(12.0);
        assert_eq!(resolve(&Level::micros(150.0), steps, 2.0), (150.0, 75_000));
        assert_eq!(
            resolve(&Level::step_fraction(1.25, 256), steps, 3.0),
            (15_000.0, 5_000_000)
        );
        assert_eq!(
            resolve(&Level::in_unit("iterations", 4_001), steps, 0.5),
            (2.0005, 4_001)
        );
        assert_eq!(
            resolve(&Level::in_unit("particles", 131_072), steps, 0.5),
            (0.0, 131_072)
        );
    }

    #[test]
    fn the_yardstick_measures_every_size_and_the_workload() {
        let points = [
            (OceanKind::SINES, 8),
            (OceanKind::SINES, 16),
            (OceanKind::FFT, 16),
        ];
        let y = Yardstick::measure(
            &points,
            1.0,
            &OceanParams::default(),
            1000,
            3,
            Duration::ZERO,
        );
        assert_eq!(y.step_ms.len(), 2);
        assert!(y.step_of(8).unwrap() > 0.0 && y.step_of(16).unwrap() > 0.0);
        assert!(y.step_of(32).is_none());
        assert_eq!(y.model_step_ms.len(), 1);
        assert!(y.step_for(OceanKind::FFT, 16).unwrap() > 0.0);
        assert!(y.step_for(OceanKind::FFT, 8).is_none());
        assert_eq!(y.step_for(OceanKind::SINES, 8), y.step_of(8));
        assert!(y.ns_per_iteration > 0.0);
        assert_eq!(
            yardstick_points(&[OceanKind::FFT], &[16], &[Level::step_fraction(1.0, 32)]),
            [
                (OceanKind::SINES, 16),
                (OceanKind::SINES, 32),
                (OceanKind::FFT, 16),
                (OceanKind::FFT, 32)
            ]
        );
    }

    #[test]
    fn drift_is_a_signed_fraction_of_the_start() {
        let c = RowCalibration {
            calibrate: Calibrate::Row,
            step_ms_at_start: 10.0,
            step_ms_in_row: 12.5,
            ns_per_iteration_at_start: 6.0,
            ns_per_iteration_in_row: 6.0,
            level_micros: 0.0,
            asked_micros: None,
        };
        assert_eq!(c.step_drift(), 0.25);
        assert_eq!(c.workload_drift(), 0.0);
        assert!(c.drifted());
        let still = RowCalibration {
            step_ms_in_row: 10.5,
            ..c
        };
        assert!(!still.drifted());
        assert_eq!(
            yardstick_sizes(
                &[40, 128],
                &[Level::step_fraction(1.0, 256), Level::micros(3.0)]
            ),
            [40, 128, 256]
        );
    }
}
