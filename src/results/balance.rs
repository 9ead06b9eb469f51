//! What a balance search found: plain data, held by the results file, below the search
//! ([`crate::balance`]) that fills it.

use crate::cell::CellKey;
use crate::placement::Class;
use crate::stats;
use serde::{Deserialize, Serialize};

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
    /// The helper's median step in each of the cell's trials (µs): S timed in every probe,
    /// beside the workload it is compared with (absent before schema 6).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub step_us: Vec<f64>,
    /// The cross-core round trip before each round of paired trials and after the last (ns;
    /// absent before schema 6 and on one core).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub round_trip_ns: Vec<f64>,
    /// Where the two cores sat during the probe, against the search's round trips.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub placement: Option<Class>,
}

impl Probe {
    /// Per trial: positive while the main thread waits (below the balance), negative while the
    /// helper idles (above it).
    pub(crate) fn signs(&self) -> Vec<f64> {
        self.main_wait_us
            .iter()
            .zip(&self.helper_wait_us)
            .map(|(m, h)| m - h)
            .collect()
    }

    /// Whether the main thread waits (below the balance) or the helper idles (above it), or
    /// `None` when the mean over trials lies within two standard errors of zero: the balance is
    /// then within [`Probe::noise_us`] of this probe.
    pub(crate) fn below(&self) -> Option<bool> {
        let signs = self.signs();
        let mean = stats::mean(&signs);
        if mean.abs() > self.noise_us() {
            Some(mean > 0.0)
        } else {
            None
        }
    }

    /// The helper's step in the probe: the median over its trials (µs); `None` before schema 6.
    pub fn step(&self) -> Option<f64> {
        (!self.step_us.is_empty()).then(|| stats::median(&self.step_us))
    }

    /// Two standard errors of the mean wait difference over the trials (µs).
    pub(crate) fn noise_us(&self) -> f64 {
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
    pub(crate) fn of(base: &[f64], new: &[f64], seed: u64) -> Ratio {
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
    /// The helper's step S, measured in the cell with no workload before the search (µs): the
    /// unit of its range.
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
    /// The placement the headline figures are in: every probe's, or when the probes mixed
    /// placements the one most of them ran in (absent before schema 6 and on one core).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub placement: Option<Class>,
    /// Probes left out of the headline because they ran in another placement or moved.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub set_aside: usize,
    /// The balance point in each placement the probes ran in.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub placements: Vec<PlacementBalance>,
    /// Why the bracket stopped wider than the tolerance, or why there is no balance point.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
    /// Every measured point: the curve's, the search's and the balance's.
    pub probes: Vec<Probe>,
    /// For a kind whose level is not the chain's iterations (spray: `particles`), its unit and
    /// the main-thread nanoseconds one unit cost, measured before the search: every probe's W
    /// ran as W ÷ that many units.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub unit_cost: Option<UnitCost>,
}

fn is_zero(n: &usize) -> bool {
    *n == 0
}

/// A search's figures from the probes of one placement alone.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PlacementBalance {
    /// The placement.
    pub placement: Class,
    /// Its probes.
    pub probes: usize,
    /// Fastest and slowest round trip around them (ns).
    pub round_trip_ns: [f64; 2],
    /// The helper's step S in them (µs): at the probe nearest the balance point, or the median
    /// over them without one.
    pub step_us: Option<f64>,
    /// The balance workload (µs), the middle of the bracket its probes make; absent when they
    /// make none.
    pub balance_us: Option<f64>,
    /// The bracket's lower end (µs).
    pub balance_us_low: Option<f64>,
    /// Its upper end (µs).
    pub balance_us_high: Option<f64>,
    /// DP ÷ serial at its probe nearest the balance point.
    pub dp_over_serial: Option<Ratio>,
    /// DP ÷ UP there.
    pub dp_over_up: Option<Ratio>,
}

impl PlacementBalance {
    /// The balance point over the step measured in the same placement.
    pub fn fraction(&self) -> Option<f64> {
        Some(self.balance_us? / self.step_us?)
    }
}

/// What one unit of a kind's level cost on the main thread.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct UnitCost {
    /// The unit's name.
    pub unit: String,
    /// Main-thread nanoseconds per unit.
    pub ns: f64,
}

impl UnitCost {
    /// The level in units that `micros` of work comes to.
    pub fn amount(&self, micros: f64) -> u64 {
        (micros * 1e3 / self.ns).round() as u64
    }
}

impl BalanceEntry {
    /// The entry of a search of `key` against a step of `step_us` that has found nothing yet.
    pub fn new(key: CellKey, step_us: f64) -> BalanceEntry {
        BalanceEntry {
            key,
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
            placement: None,
            set_aside: 0,
            placements: Vec::new(),
            note: None,
            probes: Vec::new(),
            unit_cost: None,
        }
    }

    /// The balance point as a fraction of the step: the step its own placement's probes
    /// timed, or (files before schema 6) the step measured before the search.
    pub fn fraction(&self) -> Option<f64> {
        let step = self
            .headline()
            .and_then(|p| p.step_us)
            .unwrap_or(self.step_us);
        self.balance_us.map(|b| b / step)
    }

    /// The figures of the headline's placement.
    pub fn headline(&self) -> Option<&PlacementBalance> {
        let class = self.placement?;
        self.placements.iter().find(|p| p.placement == class)
    }

    /// The balance point in the kind's own unit, when the level has one (spray's particles).
    pub fn balance_amount(&self) -> Option<(u64, &str)> {
        let cost = self.unit_cost.as_ref()?;
        Some((cost.amount(self.balance_us?), cost.unit.as_str()))
    }
}
