//! Noise-aware comparisons of FPS (or of the CPU time spent waiting): two runs cell by cell, or
//! the values of one dimension against
//! a baseline value inside one run.
//!
//! Each comparison is the change of the mean trial FPS, with a 95% percentile interval from a
//! seeded bootstrap of the ratio of means (criterion's approach). A change counts only when its
//! whole interval clears the threshold, so two noisy runs of the same code compare as "within
//! noise" rather than as a coin flip. An interval that excludes zero without clearing the
//! threshold is said to be real but small; a side with fewer than [`MIN_TRIALS`] trials gets no
//! verdict at all, since a bootstrap of three values says little about the interval.

use crate::cell::{Dim, Value};
use crate::machine::Machine;
use crate::report::shift::{self, BalanceShift};
use crate::results::latency::{LatencyRun, FLOOR};
use crate::results::{Cell, CellKey, Results, PLACEMENT_CHANGE_RATIO};
use crate::stats;
use itertools::Itertools;
use serde::{Deserialize, Serialize};
use std::collections::HashMap;
use strum::EnumMessage;

crate::named! {
    /// What a comparison compares, trial by trial.
    pub enum Metric {
        /// Frames per second; higher is better.
        Fps,
        /// CPU time per frame every thread spent waiting, in ms; lower is better.
        WaitCpu,
        /// A latency run's hand-off round trip, in ns, one value per repeat; lower is better.
        RoundTrip,
    }
}

impl Metric {
    /// The metric's per-trial values of a cell, or why it has none.
    pub(crate) fn trials(self, cell: &Cell) -> Result<Vec<f64>, String> {
        let Some(s) = &cell.summary else {
            return Err(match &cell.error {
                Some(e) => format!("{}: {e}", cell.key.label()),
                None => format!("{}: no measurements", cell.key.label()),
            });
        };
        let (values, ok): (Vec<f64>, fn(f64) -> bool) = match self {
            // Older files may lack per-trial values; the headline FPS then stands as one trial.
            Metric::Fps if s.fps_trials.is_empty() => (vec![s.fps], |f| f > 0.0),
            Metric::Fps => (s.fps_trials.clone(), |f| f > 0.0),
            Metric::WaitCpu => (s.wait_cpu_ms_trials.clone(), |c| c >= 0.0),
            Metric::RoundTrip => {
                return Err(format!(
                    "{}: round trips are measured by `oceanbench latency`, not by a sweep's cells",
                    cell.key.label()
                ))
            }
        };
        if !values.is_empty() && values.iter().all(|&v| v.is_finite() && ok(v)) {
            Ok(values)
        } else {
            Err(format!("{}: no {} measured", cell.key.label(), self.unit()))
        }
    }

    pub(crate) fn higher_is_better(self) -> bool {
        self == Metric::Fps
    }

    /// What the metric counts, as the tables' titles name it.
    pub fn unit(self) -> &'static str {
        match self {
            Metric::Fps => "FPS",
            Metric::WaitCpu => "waiting CPU ms",
            Metric::RoundTrip => "round trip ns",
        }
    }
}

/// The threshold the CLI uses when none is given, in percent.
pub const DEFAULT_THRESHOLD_PCT: f64 = 5.0;

/// The fewest trials on each side for a verdict that can fail CI: a bootstrap interval from fewer
/// is too narrow to trust (three trials give only ten distinct resampled means).
pub const MIN_TRIALS: usize = 5;

/// Relative difference of a workload level's microseconds between two runs above which the
/// levels are not the same game work: the calibration drift the sweep itself warns about.
pub const LEVEL_MISMATCH: f64 = crate::level::DRIFT_WARNING;

/// Resamples per bootstrap: enough for stable 2.5%/97.5% percentiles, cheap for a few hundred cells.
const RESAMPLES: usize = 10_000;

crate::named! {
    /// What a comparison concluded about one pair of cells.
    pub enum Verdict {
        /// The whole interval lies above +threshold.
        #[strum(message = "improved")]
        Improved,
        /// The whole interval lies below -threshold.
        #[strum(message = "regressed")]
        Regressed,
        /// The interval excludes zero but does not clear the threshold: a real change, too
        /// small to count.
        #[strum(message = "below threshold")]
        BelowThreshold,
        /// The interval includes zero.
        #[strum(message = "within noise")]
        WithinNoise,
        /// A side has fewer than [`MIN_TRIALS`] trials: the point estimate only, never a
        /// failure.
        #[strum(message = "too few trials")]
        TooFewTrials,
    }
}

impl Verdict {
    /// The verdict in words, for tables.
    pub fn words(self) -> &'static str {
        self.get_message().unwrap_or(self.name())
    }
}

/// One compared pair: NEW (or the alternative) against BASE (or the baseline).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Change {
    /// Between runs the cell's label; within a run the group's label (the key without the varied parameter).
    pub label: String,
    /// Within a run, e.g. `spin vs atomic`; absent between runs.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub versus: Option<String>,
    /// Mean over the trials of the base (or baseline) cell, in the metric's unit.
    pub base: f64,
    /// Mean over the trials of the new (or alternative) cell.
    pub new: f64,
    /// Change of NEW against BASE, in percent.
    pub change_pct: f64,
    /// Lower end of the 95% interval of the change, in percent.
    pub ci_low_pct: f64,
    /// Upper end of the 95% interval of the change, in percent.
    pub ci_high_pct: f64,
    /// A side had a single trial: the interval is the point estimate alone.
    pub single_trial: bool,
    /// Trials on the base (or baseline) side.
    #[serde(default)]
    pub base_trials: usize,
    /// Trials on the new (or alternative) side.
    #[serde(default)]
    pub new_trials: usize,
    /// A side kept trials whose run delay or steal exceeded its noise threshold.
    #[serde(default)]
    pub noisy: bool,
    /// A side's trials mixed placements, or the two sides ran in different placements.
    #[serde(default)]
    pub placement: bool,
    /// The two cells' workload came to microseconds over [`LEVEL_MISMATCH`] apart: each row
    /// resolves its levels from its own yardstick, so the pair compares other game work.
    #[serde(default)]
    pub level: bool,
    /// The classification against the threshold.
    pub verdict: Verdict,
}

/// The outcome of a comparison, ready to render.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Comparison {
    /// A change counts only when its whole interval clears this many percent.
    pub threshold_pct: f64,
    /// What was compared.
    pub metric: Metric,
    /// Within a run: the varied parameter; absent between runs.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub by: Option<Dim>,
    /// Within a run: the baseline value; absent between runs.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub baseline: Option<String>,
    /// Compared pairs: regressions first (worst first), then improvements, then the rest.
    pub changes: Vec<Change>,
    /// Cells only in BASE (within a run: baseline cells with nothing to compare against).
    pub only_in_base: Vec<String>,
    /// Cells only in NEW (within a run: cells whose baseline cell is missing).
    pub only_in_new: Vec<String>,
    /// Cells that failed or measured no FPS, so their pairs could not be compared.
    pub failed: Vec<String>,
    /// Between two runs with balance searches: how each balance point moved.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub balance: Vec<BalanceShift>,
    /// Between two runs: why their cells may not be like for like (another machine, another
    /// placement of the two cores, workload levels of other microseconds).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub warnings: Vec<String>,
}

/// Why a within-run comparison could not be made.
#[derive(Debug, PartialEq, thiserror::Error)]
pub enum CompareError {
    /// The baseline is not a value of the parameter at all.
    #[error("'{baseline}' is not a value of {by}; this run has {by}: {present}")]
    UnknownBaseline {
        /// The varied parameter.
        by: &'static str,
        /// The value asked for.
        baseline: String,
        /// The values the run has, comma separated.
        present: String,
    },
    /// The baseline is a valid value that the run did not measure.
    #[error("no {by} '{baseline}' cells in this run; it has {by}: {present}")]
    AbsentBaseline {
        /// The varied parameter.
        by: &'static str,
        /// The value asked for.
        baseline: String,
        /// The values the run has, comma separated.
        present: String,
    },
    /// The run measured only the baseline value, so there is nothing to rank.
    #[error("this run has only {by} '{baseline}'; nothing to compare it with")]
    NoAlternative {
        /// The varied parameter.
        by: &'static str,
        /// The baseline value.
        baseline: String,
    },
}

/// Compares two latency runs method by method on the same cores, over their repeats (a lower
/// round trip is better); a run from before repeats were kept gets "too few trials".
pub fn latency_between(base: &LatencyRun, new: &LatencyRun, threshold_pct: f64) -> Comparison {
    let metric = Metric::RoundTrip;
    let mut out = Comparison::empty(threshold_pct, metric, None, None);
    for b in &base.rows {
        let Some(n) = new.rows.iter().find(|n| n.label() == b.label()) else {
            out.only_in_base.push(b.label());
            continue;
        };
        let label = b.label();
        let seed = stats::seed_from(&label);
        let unpinned = b.repeats.iter().chain(&n.repeats).any(|r| !r.pinned);
        out.changes.push(Change {
            noisy: unpinned,
            ..change(
                label,
                None,
                &b.round_trips(),
                &n.round_trips(),
                threshold_pct.abs(),
                seed,
                metric,
            )
        });
    }
    for n in &new.rows {
        if !base.rows.iter().any(|b| b.label() == n.label()) {
            out.only_in_new.push(n.label());
        }
    }
    out.sort_changes();
    out.warnings = machine_mismatch(base.machine.as_ref(), new.machine.as_ref());
    let floor = |run: &LatencyRun| {
        let trips: Vec<f64> = run
            .rows
            .iter()
            .filter(|r| r.method == FLOOR)
            .flat_map(|r| r.round_trips())
            .collect();
        (!trips.is_empty()).then(|| stats::median(&trips))
    };
    out.warnings
        .extend(placement_mismatch(floor(base), floor(new)));
    out
}

/// Compares every cell of `new` with the cell of `base` that has the same key.
pub fn between(base: &Results, new: &Results, threshold_pct: f64, metric: Metric) -> Comparison {
    let new_by_key = first_by_key(&new.cells);
    let base_by_key = first_by_key(&base.cells);
    let mut out = Comparison::empty(threshold_pct, metric, None, None);
    let mut pairs = Vec::new();
    for b in unique(&base.cells) {
        match new_by_key.get(&b.key) {
            Some(n) => pairs.push(Pair {
                base: b,
                new: n,
                label: b.key.label(),
                versus: None,
            }),
            None => out.only_in_base.push(b.key.label()),
        }
    }
    for n in unique(&new.cells) {
        if !base_by_key.contains_key(&n.key) {
            out.only_in_new.push(n.key.label());
        }
    }
    out.fill(pairs);
    out.balance = shift::between(base, new);
    out.warnings = mismatches(base, new);
    out
}

/// Why two runs' cells may not be like for like: each line names both values. The CPU model and
/// core count must agree; the median cross-core round trips must be within
/// [`PLACEMENT_CHANGE_RATIO`] of each other (the two cores sit in the same placement); and each
/// workload level both runs have must come to microseconds within [`LEVEL_MISMATCH`].
pub fn mismatches(base: &Results, new: &Results) -> Vec<String> {
    let mut out = machine_mismatch(Some(&base.machine), Some(&new.machine));
    let median_trip = |r: &Results| {
        let v: Vec<f64> = r.round_trip.all().map(|t| t.median_ns).collect();
        (!v.is_empty()).then(|| stats::median(&v))
    };
    out.extend(placement_mismatch(median_trip(base), median_trip(new)));
    for l in &base.calibration.levels {
        let Some(m) = new
            .calibration
            .levels
            .iter()
            .find(|m| m.workload == l.workload)
        else {
            continue;
        };
        let (x, y) = (l.micros, m.micros);
        if (x - y).abs() > LEVEL_MISMATCH * x.max(y) {
            out.push(format!(
                "workload {} is other game work: {x:.0} us against {y:.0} us (over {:.0}% apart)",
                l.workload,
                LEVEL_MISMATCH * 100.0
            ));
        }
    }
    out
}

/// Why two runs' machines are not like for like: another CPU or core count, or a run that
/// recorded no machine.
fn machine_mismatch(a: Option<&Machine>, b: Option<&Machine>) -> Vec<String> {
    let (Some(a), Some(b)) = (a, b) else {
        return vec!["a run records no machine: it may have run on another one".into()];
    };
    let mut out = Vec::new();
    if a.cpu_model != b.cpu_model {
        out.push(format!(
            "different CPUs: `{}` against `{}`",
            a.cpu_model, b.cpu_model
        ));
    }
    if a.logical_cores != b.logical_cores {
        out.push(format!(
            "different core counts: {} against {}",
            a.logical_cores, b.logical_cores
        ));
    }
    out
}

/// Why two runs' cores sat in different places: their cross-core round trips (ns) over
/// [`PLACEMENT_CHANGE_RATIO`] apart.
fn placement_mismatch(x: Option<f64>, y: Option<f64>) -> Option<String> {
    let (x, y) = (x?, y?);
    (x.max(y) > x.min(y) * PLACEMENT_CHANGE_RATIO).then(|| {
        format!(
            "different core placement: cross-core round trip {x:.0} ns against {y:.0} ns (over {PLACEMENT_CHANGE_RATIO}x apart)"
        )
    })
}

/// Ranks every other value of `by` against `baseline`, cell group by cell group, in one run.
///
/// A group is every dimension but `by`. Serial cells have no value of the hand-off dimensions,
/// so for `by = mode` a serial cell pairs with every up/dp cell that matches it in the
/// dimensions serial cells do have, while up and dp pair by the full key but mode: that is the
/// comparison Figure 5-1 makes. For `by` a hand-off dimension, serial cells are left out.
pub fn within(
    results: &Results,
    by: Dim,
    baseline: &str,
    threshold_pct: f64,
    metric: Metric,
) -> Result<Comparison, CompareError> {
    let cells = unique(&results.cells);
    let mut present: Vec<Value> = Vec::new();
    for c in &cells {
        if let Some(v) = c.key.get(by) {
            if !present.contains(&v) {
                present.push(v);
            }
        }
    }
    let listed = if present.is_empty() {
        "none".to_string()
    } else {
        present.iter().join(", ")
    };
    let base_value = by
        .parse_value(baseline)
        .map_err(|_| CompareError::UnknownBaseline {
            by: by.name(),
            baseline: baseline.into(),
            present: listed.clone(),
        })?;
    if !present.contains(&base_value) {
        return Err(CompareError::AbsentBaseline {
            by: by.name(),
            baseline: baseline.into(),
            present: listed,
        });
    }
    if present.len() == 1 {
        return Err(CompareError::NoAlternative {
            by: by.name(),
            baseline: baseline.into(),
        });
    }

    let (bases, others): (Vec<&Cell>, Vec<&Cell>) = cells
        .into_iter()
        .filter(|c| c.key.get(by).is_some())
        .partition(|c| c.key.get(by) == Some(base_value));
    let mut out = Comparison::empty(threshold_pct, metric, Some(by), Some(baseline.into()));
    let mut pairs = Vec::new();
    let mut partnered = vec![false; others.len()];
    for b in &bases {
        let mut any = false;
        for (i, o) in others.iter().enumerate() {
            if partners(by, &b.key, &o.key) {
                any = true;
                partnered[i] = true;
                let shown = if o.key.is_serial() { &b.key } else { &o.key };
                let other = o.key.get(by).map_or_else(|| "?".into(), |v| v.to_string());
                pairs.push(Pair {
                    base: b,
                    new: o,
                    label: shown.label_without(&[by]),
                    versus: Some(format!("{other} vs {baseline}")),
                });
            }
        }
        if !any {
            out.only_in_base.push(b.key.label());
        }
    }
    for (o, done) in others.iter().zip(partnered) {
        if !done {
            out.only_in_new.push(o.key.label());
        }
    }
    out.fill(pairs);
    Ok(out)
}

/// Whether a baseline cell and another cell belong to the same group: equal in every dimension
/// but `by`, where a serial cell matches any value of the dimensions it does not have.
fn partners(by: Dim, base: &CellKey, other: &CellKey) -> bool {
    let serial = base.is_serial() || other.is_serial();
    Dim::ALL
        .iter()
        .filter(|&&d| d != by)
        .all(|&d| base.get(d) == other.get(d) || (serial && !d.in_serial_cells()))
}

/// The first cell of each key: a rerun cell appended to a file must not be compared twice.
fn unique(cells: &[Cell]) -> Vec<&Cell> {
    let mut seen = std::collections::HashSet::new();
    cells.iter().filter(|c| seen.insert(&c.key)).collect()
}

fn first_by_key(cells: &[Cell]) -> HashMap<&CellKey, &Cell> {
    let mut map = HashMap::new();
    for c in cells {
        map.entry(&c.key).or_insert(c);
    }
    map
}

struct Pair<'a> {
    base: &'a Cell,
    new: &'a Cell,
    label: String,
    versus: Option<String>,
}

impl Comparison {
    fn empty(
        threshold_pct: f64,
        metric: Metric,
        by: Option<Dim>,
        baseline: Option<String>,
    ) -> Comparison {
        Comparison {
            threshold_pct,
            metric,
            by,
            baseline,
            changes: Vec::new(),
            only_in_base: Vec::new(),
            only_in_new: Vec::new(),
            failed: Vec::new(),
            balance: Vec::new(),
            warnings: Vec::new(),
        }
    }

    fn fill(&mut self, pairs: Vec<Pair>) {
        let threshold = self.threshold_pct.abs();
        for p in pairs {
            let (b, n) = match (self.metric.trials(p.base), self.metric.trials(p.new)) {
                (Ok(b), Ok(n)) => (b, n),
                (b, n) => {
                    for why in [b.err(), n.err()].into_iter().flatten() {
                        if !self.failed.contains(&why) {
                            self.failed.push(why);
                        }
                    }
                    continue;
                }
            };
            let seed = stats::seed_from(&format!("{} {:?}", p.label, p.versus));
            let noisy = [p.base, p.new]
                .iter()
                .any(|c| c.noisy() || c.unexplained_slow_trials() > 0);
            let placement = p.base.mixed_placements()
                || p.new.mixed_placements()
                || placements_differ(p.base, p.new);
            self.changes.push(Change {
                noisy,
                placement,
                level: levels_differ(p.base, p.new),
                ..change(p.label, p.versus, &b, &n, threshold, seed, self.metric)
            });
        }
        self.sort_changes();
    }

    /// Regressions first (worst first), then improvements, then the rest. Stable: within-noise
    /// rows keep the run's order, so groups stay together.
    fn sort_changes(&mut self) {
        self.changes.sort_by(|a, b| {
            let rank = |c: &Change| match c.verdict {
                Verdict::Regressed => (0, c.change_pct),
                Verdict::Improved => (1, -c.change_pct),
                Verdict::BelowThreshold => (2, 0.0),
                Verdict::WithinNoise => (3, 0.0),
                Verdict::TooFewTrials => (4, 0.0),
            };
            let (ra, ka) = rank(a);
            let (rb, kb) = rank(b);
            ra.cmp(&rb).then(ka.total_cmp(&kb))
        });
    }

    /// True when any compared cell regressed beyond the noise.
    pub fn regressed(&self) -> bool {
        self.count(Verdict::Regressed) > 0
    }

    /// How many changes have `verdict`.
    pub fn count(&self, verdict: Verdict) -> usize {
        self.changes.iter().filter(|c| c.verdict == verdict).count()
    }

    /// The non-empty lists of cells that were not compared, each with its title.
    pub fn unmatched(&self) -> Vec<(&'static str, &[String])> {
        let [only_base, only_new] = if self.by.is_some() {
            [
                "Baseline cells with nothing to compare",
                "Cells without a baseline cell",
            ]
        } else {
            ["Only in base", "Only in new"]
        };
        [
            (only_base, &self.only_in_base),
            (only_new, &self.only_in_new),
            ("Failed", &self.failed),
        ]
        .into_iter()
        .filter(|(_, list)| !list.is_empty())
        .map(|(title, list)| (title, list.as_slice()))
        .collect()
    }
}

/// Whether two cells' workload levels came to microseconds over [`LEVEL_MISMATCH`] apart, as
/// their rows resolved them (cells without a row calibration, from before it, never differ).
fn levels_differ(a: &Cell, b: &Cell) -> bool {
    match (&a.calibration, &b.calibration) {
        (Some(x), Some(y)) => {
            let (x, y) = (x.level_micros, y.level_micros);
            (x - y).abs() > LEVEL_MISMATCH * x.max(y)
        }
        _ => false,
    }
}

/// Whether two cells ran in different placements: the medians of their trials' round trips
/// over [`PLACEMENT_CHANGE_RATIO`] apart (between runs, or within one).
fn placements_differ(a: &Cell, b: &Cell) -> bool {
    let median = |c: &Cell| {
        let ns: Vec<f64> = c
            .trials
            .iter()
            .filter_map(|t| t.round_trip_ns)
            .flatten()
            .filter(|&ns| ns > 0.0)
            .collect();
        (!ns.is_empty()).then(|| stats::median(&ns))
    };
    median(a)
        .zip(median(b))
        .is_some_and(|(a, b)| a.max(b) > a.min(b) * PLACEMENT_CHANGE_RATIO)
}

fn change(
    label: String,
    versus: Option<String>,
    base: &[f64],
    new: &[f64],
    threshold: f64,
    seed: u64,
    metric: Metric,
) -> Change {
    let (base_mean, new_mean) = (stats::mean(base), stats::mean(new));
    let change_pct = (new_mean / base_mean - 1.0) * 100.0;
    // One trial has no spread to resample; pretending otherwise would invent certainty.
    let single_trial = base.len() < 2 || new.len() < 2;
    let (ci_low_pct, ci_high_pct) = if single_trial {
        (change_pct, change_pct)
    } else {
        stats::bootstrap_change_pct(base, new, RESAMPLES, seed)
    };
    let (up, down) = if metric.higher_is_better() {
        (Verdict::Improved, Verdict::Regressed)
    } else {
        (Verdict::Regressed, Verdict::Improved)
    };
    let verdict = if base.len() < MIN_TRIALS || new.len() < MIN_TRIALS {
        Verdict::TooFewTrials
    } else if ci_low_pct > threshold {
        up
    } else if ci_high_pct < -threshold {
        down
    } else if ci_low_pct > 0.0 || ci_high_pct < 0.0 {
        Verdict::BelowThreshold
    } else {
        Verdict::WithinNoise
    };
    Change {
        label,
        versus,
        base: base_mean,
        new: new_mean,
        change_pct,
        ci_low_pct,
        ci_high_pct,
        single_trial,
        base_trials: base.len(),
        new_trials: new.len(),
        noisy: false,
        placement: false,
        level: false,
        verdict,
    }
}
