//! The balance point: the smallest main-thread workload W at which the main thread no longer
//! waits for the helper's mesh, measured instead of presumed ("presumably between workload 2 and
//! 3", section 5.3). Below it the main thread waits; above it the helper idles. Each probe runs
//! the cell and its serial (and, for DP, its UP) twins in paired, interleaved trials, and reads
//! the sign from every frame's recorded waits, which survives noise better than FPS alone.

use crate::cell::CellKey;
use crate::crosscore;
use crate::frame_loop::{self, Budget, LoopError, Mode};
use crate::input::InputError;
use crate::measure::{FrameRecord, Summary, Trial};
use crate::stats;
use crate::sweep::Sweep;
use serde::{Deserialize, Serialize};

/// How the search runs; the config key `balance` (an object) sets it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct BalanceSettings {
    /// Stop bisecting when the bracket is narrower than this percentage of the step S.
    pub tolerance_percent: f64,
    /// Points of the speed-up curve, log-spaced over `range`.
    pub points: usize,
    /// The curve's range, and the search's, as W ÷ S.
    pub range: [f64; 2],
    /// Paired trials at every probe.
    pub trials: u32,
}

impl Default for BalanceSettings {
    fn default() -> Self {
        BalanceSettings {
            tolerance_percent: 2.0,
            points: 12,
            range: [0.1, 10.0],
            trials: 3,
        }
    }
}

impl BalanceSettings {
    /// Checks every field, naming it and what is allowed.
    pub fn validate(&self, field: &str) -> Result<(), InputError> {
        let t = self.tolerance_percent;
        if !(t.is_finite() && t > 0.0 && t <= 50.0) {
            return Err(InputError(format!(
                "{field}tolerance_percent: must be above 0 and at most 50, got {t}"
            )));
        }
        if !(2..=64).contains(&self.points) {
            return Err(InputError(format!(
                "{field}points: must be 2 to 64, got {}",
                self.points
            )));
        }
        let [a, b] = self.range;
        if !(a.is_finite() && b.is_finite() && 0.0 < a && a < b && b <= 100.0) {
            return Err(InputError(format!(
                "{field}range: must be [from, to] with 0 < from < to <= 100 (times the step), got [{a}, {b}]"
            )));
        }
        if !(1..=20).contains(&self.trials) {
            return Err(InputError(format!(
                "{field}trials: must be 1 to 20, got {}",
                self.trials
            )));
        }
        Ok(())
    }
}

/// One measured workload.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Probe {
    /// The main thread's workload per frame (µs).
    pub workload_us: f64,
    /// The cell's trial FPS.
    pub fps: Vec<f64>,
    /// The serial twin's trial FPS, paired with the cell's.
    pub serial_fps: Vec<f64>,
    /// The UP twin's trial FPS (empty when the cell is UP).
    pub up_fps: Vec<f64>,
    /// Median time per frame the main thread waited for the mesh (µs), per trial.
    pub main_wait_us: Vec<f64>,
    /// Median time per frame the helper waited for a free slot (µs), per trial.
    pub helper_wait_us: Vec<f64>,
    /// The cell's median frame time over every trial (ms).
    pub frame_ms: f64,
}

impl Probe {
    /// Per trial: positive while the main thread waits (below the balance), negative while the
    /// helper idles (above it).
    fn signs(&self) -> Vec<f64> {
        self.main_wait_us
            .iter()
            .zip(&self.helper_wait_us)
            .map(|(m, h)| m - h)
            .collect()
    }

    /// Whether the main thread waits (below the balance) or the helper idles (above it), or
    /// `None` when the mean over trials lies within two standard errors of zero: the balance is
    /// then within [`Probe::noise_us`] of this probe.
    fn below(&self) -> Option<bool> {
        let signs = self.signs();
        let mean = stats::mean(&signs);
        if mean.abs() > self.noise_us() {
            Some(mean > 0.0)
        } else {
            None
        }
    }

    /// Two standard errors of the mean wait difference over the trials (µs).
    fn noise_us(&self) -> f64 {
        let signs = self.signs();
        2.0 * stats::stddev(&signs) / (signs.len() as f64).sqrt()
    }

    /// The cell's FPS over the serial twin's, with the 95% bootstrap interval `compare` uses.
    pub fn over_serial(&self, seed: u64) -> Ratio {
        Ratio::of(&self.serial_fps, &self.fps, seed)
    }

    /// The cell's FPS over the UP twin's, when there is one.
    pub fn over_up(&self, seed: u64) -> Option<Ratio> {
        (!self.up_fps.is_empty()).then(|| Ratio::of(&self.up_fps, &self.fps, seed))
    }
}

/// A ratio of mean FPS with its 95% interval.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Ratio {
    /// Mean of the new trials over mean of the base trials.
    pub value: f64,
    /// Lower end of the 95% interval.
    pub low: f64,
    /// Upper end.
    pub high: f64,
}

impl Ratio {
    fn of(base: &[f64], new: &[f64], seed: u64) -> Ratio {
        let value = stats::mean(new) / stats::mean(base);
        let (low, high) = if base.len() < 2 || new.len() < 2 {
            (value, value)
        } else {
            let (lo, hi) = stats::bootstrap_change_pct(base, new, 10_000, seed);
            (1.0 + lo / 100.0, 1.0 + hi / 100.0)
        };
        Ratio { value, low, high }
    }
}

/// What the search found for one cell.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BalanceEntry {
    /// The cell (its workload index is unused: W is set directly).
    #[serde(flatten)]
    pub key: CellKey,
    /// The helper's step S, measured in the cell with no workload (µs).
    pub step_us: f64,
    /// The balance workload (µs): the middle of the final bracket. Absent when there is none
    /// (UP, where one core runs both).
    pub balance_us: Option<f64>,
    /// The final bracket's lower end (µs).
    pub balance_us_low: Option<f64>,
    /// The final bracket's upper end (µs).
    pub balance_us_high: Option<f64>,
    /// DP ÷ serial at the balance point.
    pub dp_over_serial: Option<f64>,
    /// Its 95% interval's lower end.
    pub dp_over_serial_low: Option<f64>,
    /// Its upper end.
    pub dp_over_serial_high: Option<f64>,
    /// DP ÷ UP at the balance point, with its interval.
    pub dp_over_up: Option<Ratio>,
    /// How far the balanced frame time lies above max(W, S), in percent: the hand-off and the
    /// copy the threads cannot overlap.
    pub overhead_percent: Option<f64>,
    /// Cache-line round trip between the two cores before and after the search (ns).
    pub round_trip_ns: Vec<f64>,
    /// Why the bracket stopped wider than the tolerance, or why there is no balance point.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
    /// Every measured point: the curve's, the search's and the balance's.
    pub probes: Vec<Probe>,
}

impl BalanceEntry {
    /// The balance point as a fraction of the step.
    pub fn fraction(&self) -> Option<f64> {
        self.balance_us.map(|b| b / self.step_us)
    }
}

/// Why a search could not run.
#[derive(Debug, thiserror::Error)]
pub enum BalanceError {
    /// The cell is not one the search can run, or the range holds no balance point.
    #[error(transparent)]
    Input(#[from] InputError),
    /// A loop failed (stall, helper crash).
    #[error("{cell}: {source}")]
    Loop {
        /// The cell.
        cell: String,
        /// What failed.
        source: LoopError,
    },
    /// A stop request arrived.
    #[error("interrupted")]
    Interrupted,
}

/// Runs the search and the curve for `key` (a DP or UP cell) on `sweep`'s machine set-up.
pub fn search(
    sweep: &Sweep,
    key: &CellKey,
    settings: &BalanceSettings,
) -> Result<BalanceEntry, BalanceError> {
    let prober = Prober::new(sweep, key, settings);
    let before = prober.round_trip();
    let step_us = prober.step_us()?;
    let mut probes: Vec<Probe> = Vec::new();
    let [from, to] = settings.range;
    let n = settings.points;
    for i in 0..n {
        let ratio = from * (to / from).powf(i as f64 / (n - 1) as f64);
        probes.push(prober.probe(ratio * step_us)?);
    }
    let mut entry = BalanceEntry {
        key: key.clone(),
        step_us,
        balance_us: None,
        balance_us_low: None,
        balance_us_high: None,
        dp_over_serial: None,
        dp_over_serial_low: None,
        dp_over_serial_high: None,
        dp_over_up: None,
        overhead_percent: None,
        round_trip_ns: Vec::new(),
        note: None,
        probes: Vec::new(),
    };
    if key.mode == Mode::Up {
        entry.note = Some("one core runs both threads: the main thread always waits, so there is no balance point".into());
    } else {
        let (lo, hi, note) = bracket(&prober, &mut probes, step_us, settings)?;
        let at = prober.probe((lo + hi) / 2.0)?;
        let seed = stats::seed_from(&key.label());
        let over_serial = at.over_serial(seed);
        let max_work = (at.workload_us.max(step_us)) * 1e-3;
        entry.balance_us = Some((lo + hi) / 2.0);
        entry.balance_us_low = Some(lo);
        entry.balance_us_high = Some(hi);
        entry.dp_over_serial = Some(over_serial.value);
        entry.dp_over_serial_low = Some(over_serial.low);
        entry.dp_over_serial_high = Some(over_serial.high);
        entry.dp_over_up = at.over_up(seed);
        entry.overhead_percent = Some(100.0 * (at.frame_ms / max_work - 1.0));
        entry.note = note;
        probes.push(at);
    }
    probes.sort_by(|a, b| a.workload_us.total_cmp(&b.workload_us));
    entry.probes = probes;
    entry.round_trip_ns = [before, prober.round_trip()]
        .into_iter()
        .flatten()
        .collect();
    Ok(entry)
}

/// Brackets the sign change among the curve's probes, then bisects; returns the bracket and
/// why it stopped short of the tolerance, if it did.
fn bracket(
    prober: &Prober,
    probes: &mut Vec<Probe>,
    step_us: f64,
    settings: &BalanceSettings,
) -> Result<(f64, f64, Option<String>), BalanceError> {
    let sorted = {
        let mut p: Vec<&Probe> = probes.iter().collect();
        p.sort_by(|a, b| a.workload_us.total_cmp(&b.workload_us));
        p
    };
    let first_above = sorted.iter().position(|p| p.below() == Some(false));
    let last_below = sorted.iter().rposition(|p| p.below() == Some(true));
    let (mut lo, mut hi) = match (last_below, first_above) {
        (Some(b), Some(a)) if b < a => (sorted[b].workload_us, sorted[a].workload_us),
        (Some(b), Some(a)) => (sorted[a].workload_us, sorted[b].workload_us),
        (None, _) => {
            return Err(InputError(format!(
                "balance: {}: the helper already idles at the bottom of the range ({} × the step): try a range starting lower, e.g. \"range\": [{}, {}]",
                prober.key.label(),
                settings.range[0],
                settings.range[0] / 10.0,
                settings.range[1]
            ))
            .into())
        }
        (_, None) => {
            return Err(InputError(format!(
                "balance: {}: the main thread still waits at the top of the range ({} × the step): try a range ending higher, e.g. \"range\": [{}, {}]",
                prober.key.label(),
                settings.range[1],
                settings.range[0],
                (settings.range[1] * 10.0).min(100.0)
            ))
            .into())
        }
    };
    let tolerance = settings.tolerance_percent / 100.0 * step_us;
    while hi - lo > tolerance {
        let probe = prober.probe((lo + hi) / 2.0)?;
        let verdict = probe.below();
        let w = probe.workload_us;
        probes.push(probe);
        match verdict {
            Some(true) => lo = w,
            Some(false) => hi = w,
            None => {
                // Within noise of the balance: the difference of the waits falls by about a
                // microsecond per microsecond of workload, so the balance is W + (the mean
                // difference), give or take the noise.
                let p = probes.last().expect("just pushed");
                let (centre, noise) = (w + stats::mean(&p.signs()), p.noise_us());
                let (new_lo, new_hi) = ((centre - noise).max(lo), (centre + noise).min(hi));
                if new_hi - new_lo >= hi - lo || noise > tolerance / 2.0 {
                    return Ok((
                        new_lo,
                        new_hi,
                        Some(format!(
                            "noise (±{noise:.0} µs in the waits at {w:.0} µs) prevents a bracket narrower than {:.1}% of the step",
                            100.0 * (new_hi - new_lo) / step_us
                        )),
                    ));
                }
                (lo, hi) = (new_lo, new_hi);
            }
        }
    }
    Ok((lo, hi, None))
}

/// Runs a cell and its twins at a chosen workload.
struct Prober<'a> {
    sweep: &'a Sweep,
    key: &'a CellKey,
    serial: CellKey,
    up: Option<CellKey>,
    settings: &'a BalanceSettings,
    budget: Budget,
}

impl<'a> Prober<'a> {
    fn new(sweep: &'a Sweep, key: &'a CellKey, settings: &'a BalanceSettings) -> Prober<'a> {
        let twin = |mode: Mode| {
            key.with(crate::cell::Dim::Mode, crate::cell::DimValue::value(mode))
                .expect("a threaded cell has a serial and an UP twin")
        };
        Prober {
            sweep,
            key,
            serial: twin(Mode::Serial),
            up: (key.mode == Mode::Dp).then(|| twin(Mode::Up)),
            settings,
            budget: sweep.results.config.budget(),
        }
    }

    fn trial(&self, key: &CellKey, workload_us: f64) -> Result<Trial, BalanceError> {
        let ns_per_iteration = self.sweep.results.calibration.workload.ns_per_iteration;
        let iterations = (workload_us * 1e3 / ns_per_iteration).round() as u64;
        let spec = self.sweep.loop_spec(key, iterations);
        match frame_loop::run(&spec, &self.budget, |_, _| {}) {
            Ok(run) => Ok(run.trial),
            Err(LoopError::Interrupted) => Err(BalanceError::Interrupted),
            Err(source) => Err(BalanceError::Loop {
                cell: key.label(),
                source,
            }),
        }
    }

    /// The helper's step S in the cell, with no workload (µs).
    fn step_us(&self) -> Result<f64, BalanceError> {
        let trial = self.trial(self.key, 0.0)?;
        let steps: Vec<f64> = trial
            .frames
            .iter()
            .map(|f| f.step_ns as f64 * 1e-3)
            .collect();
        Ok(stats::median(&steps))
    }

    /// The cell and its twins at `workload_us`, trials interleaved.
    fn probe(&self, workload_us: f64) -> Result<Probe, BalanceError> {
        let mut probe = Probe {
            workload_us,
            fps: Vec::new(),
            serial_fps: Vec::new(),
            up_fps: Vec::new(),
            main_wait_us: Vec::new(),
            helper_wait_us: Vec::new(),
            frame_ms: 0.0,
        };
        let mut cell_trials = Vec::new();
        for _ in 0..self.settings.trials {
            let t = self.trial(self.key, workload_us)?;
            let median_us = |f: fn(&FrameRecord) -> u64| {
                stats::median(
                    &t.frames
                        .iter()
                        .map(|r| f(r) as f64 * 1e-3)
                        .collect::<Vec<_>>(),
                )
            };
            probe.main_wait_us.push(median_us(|r| r.wait_ns));
            probe.helper_wait_us.push(median_us(|r| r.helper_wait_ns));
            probe.fps.push(t.fps());
            cell_trials.push(t);
            probe
                .serial_fps
                .push(self.trial(&self.serial, workload_us)?.fps());
            if let Some(up) = &self.up {
                probe.up_fps.push(self.trial(up, workload_us)?.fps());
            }
        }
        probe.frame_ms = Summary::of(&cell_trials).map_or(f64::NAN, |s| s.frame_time_ms.median);
        Ok(probe)
    }

    fn round_trip(&self) -> Option<f64> {
        let [a, b] = self.sweep.cores();
        (a != b).then(|| crosscore::round_trip(a, b, 300).median_ns)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn probe(main: &[f64], helper: &[f64]) -> Probe {
        Probe {
            workload_us: 100.0,
            fps: vec![200.0, 210.0, 190.0],
            serial_fps: vec![100.0, 105.0, 95.0],
            up_fps: vec![],
            main_wait_us: main.to_vec(),
            helper_wait_us: helper.to_vec(),
            frame_ms: 5.0,
        }
    }

    #[test]
    fn who_waits_decides_the_side_unless_noise_hides_it() {
        assert_eq!(
            probe(&[50.0, 52.0, 48.0], &[0.0, 0.0, 0.0]).below(),
            Some(true)
        );
        assert_eq!(
            probe(&[0.0, 0.0, 0.0], &[30.0, 31.0, 29.0]).below(),
            Some(false)
        );
        let noisy = probe(&[40.0, 0.0, 0.0], &[0.0, 35.0, 1.0]);
        assert_eq!(noisy.below(), None, "trials that disagree say nothing");
        assert!(noisy.noise_us() > 20.0);
    }

    #[test]
    fn ratios_carry_the_bootstrap_interval() {
        let p = probe(&[1.0; 3], &[0.0; 3]);
        let r = p.over_serial(7);
        assert!((r.value - 2.0).abs() < 1e-12);
        assert!(r.low < r.value && r.value < r.high);
        assert!(p.over_up(7).is_none(), "no UP twin measured");
    }

    #[test]
    fn settings_are_checked_field_by_field() {
        assert!(BalanceSettings::default().validate("").is_ok());
        for (bad, field) in [
            (
                BalanceSettings {
                    tolerance_percent: 0.0,
                    ..Default::default()
                },
                "tolerance_percent",
            ),
            (
                BalanceSettings {
                    points: 1,
                    ..Default::default()
                },
                "points",
            ),
            (
                BalanceSettings {
                    range: [2.0, 1.0],
                    ..Default::default()
                },
                "range",
            ),
            (
                BalanceSettings {
                    trials: 0,
                    ..Default::default()
                },
                "trials",
            ),
        ] {
            let e = bad.validate("balance.").unwrap_err().to_string();
            assert!(e.starts_with(&format!("balance.{field}")), "{e}");
        }
    }
}
