//! The balance point: the smallest main-thread workload W at which the main thread no longer
//! waits for the helper's mesh, measured instead of presumed ("presumably between workload 2 and
//! 3", section 5.3). Below it the main thread waits; above it the helper idles. Each probe runs
//! the cell and its serial (and, for DP, its UP) twins in paired, interleaved trials, and reads
//! the sign from every frame's recorded waits, which survives noise better than FPS alone.
//!
//! The search runs on a [`Testbed`] (the sweep implements it), asked by the config's
//! [`BalanceSettings`], and what it finds is plain data in [`crate::results::balance`], which
//! the results file holds; so nothing here imports the sweep.

pub use crate::config::BalanceSettings;
pub use crate::results::balance::{BalanceEntry, PlacementBalance, Probe, Ratio, UnitCost};

use crate::cell::CellKey;
use crate::frame_loop::{LoopError, Mode};
use crate::input::InputError;
use crate::measure::{FrameRecord, Trial};
use crate::placement::{Class, Split};
use crate::stats;
use crate::summary::Summary;

/// What a search needs of the run it probes on: a trial of any cell at a given workload, the
/// workload's calibration and the cross-core round trip. The sweep runs real frame loops; a
/// test can answer from a model, so the search's logic is checked apart from the scheduler.
pub trait Testbed {
    /// One trial of `key` with `amount` of main-thread work per frame, in the kind's unit.
    fn trial(&self, key: &CellKey, amount: u64) -> Result<Trial, LoopError>;
    /// The workload's calibrated speed (ns per iteration).
    fn ns_per_iteration(&self) -> f64;
    /// The median cache-line round trip between the two cores over `batches` batches (ns);
    /// `None` on one core.
    fn round_trip(&self, batches: usize) -> Option<f64>;
}

/// Batches of the round trip before and after a search.
const SEARCH_ROUND_TRIP_BATCHES: usize = 300;

/// Batches of the round trip before each round of a probe's paired trials: enough for a
/// median that tells near from far, as around a sweep's trials.
const PROBE_ROUND_TRIP_BATCHES: usize = 10;

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

/// Runs the search and the curve for `key` (a DP or UP cell) on `testbed`.
pub fn search(
    testbed: &dyn Testbed,
    key: &CellKey,
    settings: &BalanceSettings,
) -> Result<BalanceEntry, BalanceError> {
    let mut prober = Prober::new(testbed, key, settings);
    prober.unit_cost = prober.unit_cost()?;
    let before = testbed.round_trip(SEARCH_ROUND_TRIP_BATCHES);
    let step_us = prober.step_us()?;
    let mut probes: Vec<Probe> = Vec::new();
    for workload_us in curve(settings, step_us) {
        probes.push(prober.probe(workload_us)?);
    }
    let mut entry = BalanceEntry {
        unit_cost: prober.unit_cost.clone(),
        ..BalanceEntry::new(key.clone(), step_us)
    };
    let seed = stats::seed_from(&key.label());
    if key.mode == Mode::Up {
        entry.note = Some("one core runs both threads: the main thread always waits, so there is no balance point".into());
    } else {
        let (lo, hi, note) = bracket(&prober, &mut probes, step_us, settings)?;
        let at = prober.probe((lo + hi) / 2.0)?;
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
    entry.round_trip_ns = [before, testbed.round_trip(SEARCH_ROUND_TRIP_BATCHES)]
        .into_iter()
        .flatten()
        .collect();
    by_placement(&mut entry, seed);
    Ok(entry)
}

/// The curve's workloads (µs): `settings.points` of them from `range[0]` to `range[1]` times
/// the step, evenly spaced on a log scale, so each decade of the range gets as many.
fn curve(settings: &BalanceSettings, step_us: f64) -> Vec<f64> {
    let [from, to] = settings.range;
    let n = settings.points;
    (0..n)
        .map(|i| from * (to / from).powf(i as f64 / (n - 1) as f64) * step_us)
        .collect()
}

/// Places every probe against the search's own round trips and gives the figures of each
/// placement from its probes alone. When the probes mixed placements, the headline becomes the
/// figures of one placement (of those whose probes bracket a balance point, the one most probes
/// ran in), and the note says how many probes were set aside.
pub fn by_placement(entry: &mut BalanceEntry, seed: u64) {
    let trips = entry
        .probes
        .iter()
        .flat_map(|p| &p.round_trip_ns)
        .chain(&entry.round_trip_ns)
        .copied();
    let Some(split) = Split::of(trips) else {
        return;
    };
    for p in &mut entry.probes {
        p.placement = split.class_of(&p.round_trip_ns);
    }
    let count = |class: Class| {
        entry
            .probes
            .iter()
            .filter(|p| p.placement == Some(class))
            .count()
    };
    let mut classes: Vec<Class> = [Class::Near, Class::Far, Class::One]
        .into_iter()
        .filter(|&c| count(c) > 0)
        .collect();
    // Most probes first; among equals, near before far (a stable sort keeps the order).
    classes.sort_by_key(|&c| std::cmp::Reverse(count(c)));
    let threaded = entry.key.mode != Mode::Up;
    let mut placements: Vec<PlacementBalance> = classes
        .iter()
        .map(|&class| {
            let probes: Vec<&Probe> = entry
                .probes
                .iter()
                .filter(|p| p.placement == Some(class))
                .collect();
            placement_balance(class, &probes, &split, threaded, entry.step_us, seed)
        })
        .collect();
    // The headline: the placement of most probes among those that bracket a balance point,
    // or of most probes when none does.
    let Some(first) = placements
        .iter()
        .position(|p| p.balance_us.is_some())
        .or((!placements.is_empty()).then_some(0))
    else {
        return;
    };
    let head = placements.remove(first);
    placements.insert(0, head);
    let primary = placements[0].placement;
    entry.placements = placements;
    entry.placement = Some(primary);
    entry.set_aside = entry.probes.len() - count(primary);
    if entry.set_aside == 0 {
        // One placement throughout: the bisection's bracket is the placement's.
        if let Some(p) = entry.placements.first_mut() {
            p.balance_us = entry.balance_us;
            p.balance_us_low = entry.balance_us_low;
            p.balance_us_high = entry.balance_us_high;
        }
        return;
    }
    let head = entry.placements[0].clone();
    let mut others: Vec<String> = [Class::Near, Class::Far, Class::Moved]
        .into_iter()
        .filter(|&c| c != primary)
        .filter_map(|c| {
            let n = count(c);
            (n > 0).then(|| format!("{n} {c}"))
        })
        .collect();
    let unplaced = entry
        .probes
        .iter()
        .filter(|p| p.placement.is_none())
        .count();
    if unplaced > 0 {
        others.push(format!("{unplaced} unplaced"));
    }
    let mixed = format!(
        "probes mixed placements: {} of {} set aside ({}); the figures are the {primary} probes' alone",
        entry.set_aside,
        entry.probes.len(),
        others.join(", ")
    );
    if threaded {
        entry.balance_us = head.balance_us;
        entry.balance_us_low = head.balance_us_low;
        entry.balance_us_high = head.balance_us_high;
        entry.dp_over_serial = head.dp_over_serial.map(|r| r.value);
        entry.dp_over_serial_low = head.dp_over_serial.map(|r| r.low);
        entry.dp_over_serial_high = head.dp_over_serial.map(|r| r.high);
        entry.dp_over_up = head.dp_over_up;
        entry.overhead_percent = nearest(&entry.probes, primary, head.balance_us).map(|p| {
            let work = p.workload_us.max(head.step_us.unwrap_or(entry.step_us)) * 1e-3;
            100.0 * (p.frame_ms / work - 1.0)
        });
    }
    let none = if threaded && head.balance_us.is_none() {
        ", which bracket no balance point"
    } else {
        ""
    };
    entry.note = Some(match entry.note.take() {
        Some(n) => format!("{mixed}{none}; {n}"),
        None => format!("{mixed}{none}"),
    });
}

/// The probe of `class` nearest `workload_us` (the middle of them without one).
fn nearest(probes: &[Probe], class: Class, workload_us: Option<f64>) -> Option<&Probe> {
    let of: Vec<&Probe> = probes
        .iter()
        .filter(|p| p.placement == Some(class))
        .collect();
    match workload_us {
        Some(w) => of.into_iter().min_by(|a, b| {
            (a.workload_us - w)
                .abs()
                .total_cmp(&(b.workload_us - w).abs())
        }),
        None => of.get(of.len() / 2).copied(),
    }
}

/// The figures of one placement's `probes` (sorted by workload).
fn placement_balance(
    class: Class,
    probes: &[&Probe],
    split: &Split,
    threaded: bool,
    search_step_us: f64,
    seed: u64,
) -> PlacementBalance {
    let trips: Vec<f64> = probes
        .iter()
        .flat_map(|p| &p.round_trip_ns)
        .copied()
        .filter(|&ns| split.class(ns) == Some(class))
        .collect();
    let (lo, hi) = stats::min_max(&trips);
    let bracket = threaded.then(|| bracket_of(probes)).flatten();
    let balance = bracket.map(|(lo, hi)| (lo + hi) / 2.0);
    let owned: Vec<Probe> = probes.iter().map(|&p| p.clone()).collect();
    let at = threaded
        .then(|| nearest(&owned, class, balance.or(Some(search_step_us))))
        .flatten();
    let steps: Vec<f64> = probes.iter().filter_map(|p| p.step()).collect();
    let step_us = match at.and_then(Probe::step) {
        Some(s) if balance.is_some() => Some(s),
        _ => (!steps.is_empty()).then(|| stats::median(&steps)),
    };
    PlacementBalance {
        placement: class,
        probes: probes.len(),
        round_trip_ns: [lo, hi],
        step_us,
        balance_us: balance,
        balance_us_low: bracket.map(|b| b.0),
        balance_us_high: bracket.map(|b| b.1),
        dp_over_serial: at.map(|p| p.over_serial(seed)),
        dp_over_up: at.and_then(|p| p.over_up(seed)),
    }
}

/// The bracket a set of measured probes makes: the highest workload at which the main thread
/// still waits and the lowest at which the helper idles (either way round when noise crossed
/// them), narrowed by a probe within noise of the balance between them, as the bisection does.
/// `None` when every probe is on one side.
pub fn bracket_of(probes: &[&Probe]) -> Option<(f64, f64)> {
    let mut sorted: Vec<&Probe> = probes.to_vec();
    sorted.sort_by(|a, b| a.workload_us.total_cmp(&b.workload_us));
    let first_above = sorted.iter().position(|p| p.below() == Some(false))?;
    let last_below = sorted.iter().rposition(|p| p.below() == Some(true))?;
    let (a, b) = (
        sorted[last_below].workload_us,
        sorted[first_above].workload_us,
    );
    let (mut lo, mut hi) = (a.min(b), a.max(b));
    for p in sorted.iter().filter(|p| p.below().is_none()) {
        let w = p.workload_us;
        if w > lo && w < hi {
            // The window holds W (a probe within noise has |mean| ≤ noise), so it meets the
            // bracket; with no noise at all it is W alone, as in the bisection.
            let (centre, noise) = (w + stats::mean(&p.signs()), p.noise_us());
            (lo, hi) = ((centre - noise).max(lo), (centre + noise).min(hi));
        }
    }
    Some((lo, hi))
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
                // A window wider than the tolerance cannot be bisected further: every probe
                // inside it would read as noise too. A narrower one ends the loop.
                if noise > tolerance / 2.0 {
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
    testbed: &'a dyn Testbed,
    key: &'a CellKey,
    serial: CellKey,
    up: Option<CellKey>,
    settings: &'a BalanceSettings,
    /// The cost of one unit of a kind not counted in the chain's iterations.
    unit_cost: Option<UnitCost>,
}

/// The level at which a kind with its own unit has its cost per unit measured: the slides'
/// particle count.
const UNIT_COST_AT: u64 = 131_072;

/// The median over a trial's frames of one of their times, in µs.
fn median_us(trial: &Trial, f: fn(&FrameRecord) -> u64) -> f64 {
    stats::median(
        &trial
            .frames
            .iter()
            .map(|r| f(r) as f64 * 1e-3)
            .collect::<Vec<_>>(),
    )
}

impl<'a> Prober<'a> {
    fn new(
        testbed: &'a dyn Testbed,
        key: &'a CellKey,
        settings: &'a BalanceSettings,
    ) -> Prober<'a> {
        let twin = |mode: Mode| {
            key.with(crate::cell::Dim::Mode, crate::cell::DimValue::value(mode))
                .expect("a threaded cell has a serial and an UP twin")
        };
        Prober {
            testbed,
            key,
            serial: twin(Mode::Serial),
            up: (key.mode == Mode::Dp).then(|| twin(Mode::Up)),
            settings,
            unit_cost: None,
        }
    }

    /// For a kind whose unit is not the chain's iterations, the main thread's time per unit at
    /// [`UNIT_COST_AT`] units in the serial twin: the search's W converts to a level through
    /// it (linearly: the kind's fixed cost per frame is spread over the units).
    fn unit_cost(&self) -> Result<Option<UnitCost>, BalanceError> {
        let unit = self.key.workload_kind.unit();
        if unit == crate::workload::Synthetic::UNIT {
            return Ok(None);
        }
        let trial = self.run_at(&self.serial, UNIT_COST_AT)?;
        let main: Vec<f64> = trial.frames.iter().map(|f| f.workload_ns as f64).collect();
        Ok(Some(UnitCost {
            unit: unit.to_string(),
            ns: stats::mean(&main) / UNIT_COST_AT as f64,
        }))
    }

    fn trial(&self, key: &CellKey, workload_us: f64) -> Result<Trial, BalanceError> {
        let amount = match &self.unit_cost {
            Some(cost) => cost.amount(workload_us),
            None => (workload_us * 1e3 / self.testbed.ns_per_iteration()).round() as u64,
        };
        self.run_at(key, amount)
    }

    /// One trial of `key` at `amount` of the kind's unit.
    fn run_at(&self, key: &CellKey, amount: u64) -> Result<Trial, BalanceError> {
        match self.testbed.trial(key, amount) {
            Ok(trial) => Ok(trial),
            Err(LoopError::Interrupted) => Err(BalanceError::Interrupted),
            Err(source) => Err(BalanceError::Loop {
                cell: key.label(),
                source,
            }),
        }
    }

    /// The helper's step S in the cell, with no workload (µs).
    fn step_us(&self) -> Result<f64, BalanceError> {
        Ok(median_us(&self.trial(self.key, 0.0)?, |r| r.step_ns))
    }

    /// The cell and its twins at `workload_us`, trials interleaved, the round trip timed
    /// before each round and after the last.
    fn probe(&self, workload_us: f64) -> Result<Probe, BalanceError> {
        let mut probe = Probe {
            workload_us,
            fps: Vec::new(),
            serial_fps: Vec::new(),
            up_fps: Vec::new(),
            main_wait_us: Vec::new(),
            helper_wait_us: Vec::new(),
            frame_ms: 0.0,
            step_us: Vec::new(),
            round_trip_ns: Vec::new(),
            placement: None,
        };
        let mut cell_trials = Vec::new();
        for _ in 0..self.settings.trials {
            probe
                .round_trip_ns
                .extend(self.testbed.round_trip(PROBE_ROUND_TRIP_BATCHES));
            let t = self.trial(self.key, workload_us)?;
            probe.main_wait_us.push(median_us(&t, |r| r.wait_ns));
            probe
                .helper_wait_us
                .push(median_us(&t, |r| r.helper_wait_ns));
            probe.step_us.push(median_us(&t, |r| r.step_ns));
            probe.fps.push(t.fps());
            cell_trials.push(t);
            probe
                .serial_fps
                .push(self.trial(&self.serial, workload_us)?.fps());
            if let Some(up) = &self.up {
                probe.up_fps.push(self.trial(up, workload_us)?.fps());
            }
        }
        probe
            .round_trip_ns
            .extend(self.testbed.round_trip(PROBE_ROUND_TRIP_BATCHES));
        probe.frame_ms = Summary::of(&cell_trials).map_or(f64::NAN, |s| s.frame_time_ms.median);
        Ok(probe)
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
            step_us: vec![],
            round_trip_ns: vec![],
            placement: None,
        }
    }

    #[test]
    fn the_curve_spans_the_range_evenly_on_a_log_scale() {
        let settings = BalanceSettings {
            points: 5,
            range: [0.1, 1000.0],
            ..BalanceSettings::default()
        };
        let curve = curve(&settings, 20.0);
        let expected = [2.0, 20.0, 200.0, 2000.0, 20000.0];
        assert_eq!(curve.len(), expected.len());
        for (w, e) in curve.iter().zip(expected) {
            assert!((w / e - 1.0).abs() < 1e-12, "{curve:?}");
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
    fn a_kind_with_its_own_unit_reports_the_balance_in_it() {
        let cost = UnitCost {
            unit: "particles".into(),
            ns: 8.0,
        };
        assert_eq!(cost.amount(1_000.0), 125_000, "1 ms at 8 ns a particle");
        let json = serde_json::json!({
            "size": 512, "workload": 0, "workload_kind": "spray", "mode": "dp",
            "sync": "atomic", "threading": "pool", "helpers": 1, "depth": 1, "policy": "fifo",
            "normals": "analytic", "ocean": "fft", "kernel": "reference",
            "consume": "copy",
            "step_us": 8000.0, "balance_us": 6000.0, "balance_us_low": 5900.0,
            "balance_us_high": 6100.0, "dp_over_serial": 1.8, "dp_over_serial_low": 1.7,
            "dp_over_serial_high": 1.9, "dp_over_up": null, "overhead_percent": 3.0,
            "round_trip_ns": [], "probes": [],
            "unit_cost": {"unit": "particles", "ns": 8.0}
        });
        let mut entry: BalanceEntry = serde_json::from_value(json).unwrap();
        assert_eq!(entry.balance_amount(), Some((750_000, "particles")));
        entry.unit_cost = None;
        assert_eq!(entry.balance_amount(), None, "iterations are not restated");
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
