//! A run's findings, computed from its results file alone: what the run shows, each as one
//! sentence with its numbers and conditions and as data (`findings.json`).
//!
//! Findings are computed per *slice*: one combination of values of every dimension that has
//! more than one value in the run, except size, workload level and mode (which every slice lays
//! out as its Figure 5-1 table). A ratio compares the median trials of two cells, with a
//! seeded bootstrap interval; it says so beside it when a cell's trial spread
//! ((max − min) ÷ median) exceeds [`SPREAD_PERCENT`], when a cell is marked † (noisy), ‡
//! (an unexplained slow trial) or § (mixed placements), and when a cell has no per-trial
//! records (files from before schema 3), since then no slow trial could be attributed.

pub mod placement;
pub mod provenance;

use crate::cell::Mode;
use crate::cell::{Dim, DimValue, Value};
use crate::results::{Cell, CellKey, Results};
use crate::stats;
use serde::{Deserialize, Serialize};
use std::fmt::Write;

/// A cell's trials whose (max − min) ÷ median exceeds this are called out beside any number
/// drawn from it.
pub const SPREAD_PERCENT: f64 = 5.0;

/// DP counts as flat across workload levels while its median trial stays within this percent
/// of its FPS at the lowest level.
pub const FLAT_PERCENT: f64 = 5.0;

/// Bootstrap resamples behind each ratio's interval.
const RESAMPLES: usize = 2000;

/// The layout of findings.json; bumped on every change to it.
pub const FINDINGS_SCHEMA: u32 = 1;

/// The values that set a slice apart: every dimension with more than one value in the run,
/// except size, workload level and mode.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Slice {
    /// Each varying dimension's config key and value, in dimension order.
    pub values: Vec<(String, String)>,
}

impl Slice {
    /// The slice of `key` made of `dims` (see [`slice_dims`]).
    pub fn of(dims: &[Dim], key: &CellKey) -> Slice {
        Slice {
            values: dims
                .iter()
                .filter_map(|&d| Some((d.config_key().to_string(), key.get(d)?.to_string())))
                .collect(),
        }
    }

    /// The slice as text, e.g. `sync atomic, helpers 2`; `every cell` when the run has one
    /// slice.
    pub fn label(&self) -> String {
        if self.values.is_empty() {
            return "every cell".into();
        }
        self.values
            .iter()
            .map(|(k, v)| format!("{k} {v}"))
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// Whether `key` lies in the slice. A serial cell lacks the hand-off dimensions, and lies in
    /// every slice its other values match.
    pub fn contains(&self, key: &CellKey) -> bool {
        self.values.iter().all(|(k, v)| {
            let dim = Dim::ALL.iter().find(|d| d.config_key() == k);
            match dim.and_then(|&d| key.get(d)) {
                Some(value) => value.to_string() == *v,
                None => true,
            }
        })
    }

    /// Whether the slice holds `other`'s every value (a filter such as `sync=atomic` matches
    /// the slices with that value whatever their others).
    pub fn matches(&self, filter: &[(String, String)]) -> bool {
        filter.iter().all(|f| self.values.contains(f))
    }
}

/// The dimensions a run's slices are made of: those with more than one value among its cells,
/// but size, workload and mode.
pub fn slice_dims(results: &Results) -> Vec<Dim> {
    Dim::ALL
        .iter()
        .copied()
        .filter(|d| ![Dim::Size, Dim::Workload, Dim::Mode].contains(d))
        .filter(|&d| {
            let mut seen: Vec<Value> = Vec::new();
            for v in results.cells.iter().filter_map(|c| c.key.get(d)) {
                if !seen.contains(&v) {
                    seen.push(v);
                }
            }
            seen.len() > 1
        })
        .collect()
}

/// Every slice of the run, in the order its threaded cells first show them (a serial-only run
/// has the slices of its serial cells).
pub fn slices(results: &Results) -> Vec<Slice> {
    let dims = slice_dims(results);
    let of = |key: &CellKey| Slice::of(&dims, key);
    let mut out: Vec<Slice> = Vec::new();
    let threaded = results.cells.iter().any(|c| !c.key.is_serial());
    let keys = results
        .cells
        .iter()
        .map(|c| &c.key)
        .filter(|k| !threaded || !k.is_serial())
        // A balance search's cell belongs to a slice even in a run of balance searches alone.
        .chain(results.balance.iter().map(|e| &e.key));
    for k in keys {
        let s = of(k);
        if !out.contains(&s) {
            out.push(s);
        }
    }
    out
}

/// One number of a finding, with the cell it comes from and what qualifies it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Figure {
    /// What the number is, e.g. `dp_over_up`, `dp_fps`.
    pub name: String,
    /// The number.
    pub value: f64,
    /// Its 95 % bootstrap interval, for ratios of trials.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub interval: Option<[f64; 2]>,
    /// The cell (or row) it was read from, by label.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cell: Option<String>,
    /// What a reader must know about it: a cell's marks, a wide spread, no trial records.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub caveats: Vec<String>,
}

/// One finding: a sentence and its figures.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Finding {
    /// What kind of finding: `peak-dp-over-up`, `peak-dp-over-serial`, `up-over-serial`,
    /// `dp-flat`, `balance`, `handoffs`, `marks` or `placement`.
    pub id: String,
    /// The slice it holds for (empty values for run-wide findings).
    pub slice: Slice,
    /// The mesh size it is about, when it is about one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub size: Option<usize>,
    /// What the run shows, in one sentence with its numbers and conditions.
    pub sentence: String,
    /// The numbers of the sentence.
    pub figures: Vec<Figure>,
}

/// findings.json: a run's findings and where they come from.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Findings {
    /// [`FINDINGS_SCHEMA`].
    pub schema_version: u32,
    /// The run's config name.
    pub run: String,
    /// When the run started.
    pub started: String,
    /// The machine line.
    pub machine: String,
    /// The dimensions its slices are made of, by config key.
    pub slice_dims: Vec<String>,
    /// Every finding, run-wide ones last.
    pub findings: Vec<Finding>,
}

/// A cell's median trial and what qualifies it.
#[derive(Clone, Debug)]
struct Stat<'a> {
    cell: &'a Cell,
    trials: Vec<f64>,
    median: f64,
}

impl<'a> Stat<'a> {
    fn of(cell: Option<&'a Cell>) -> Option<Stat<'a>> {
        let cell = cell?;
        let s = cell.summary.as_ref()?;
        let trials: Vec<f64> = if s.fps_trials.is_empty() {
            vec![s.fps]
        } else {
            s.fps_trials.clone()
        };
        let median = s.median_trial_fps();
        (median.is_finite() && median > 0.0).then_some(Stat {
            cell,
            trials,
            median,
        })
    }

    fn spread_percent(&self) -> f64 {
        let (lo, hi) = stats::min_max(&self.trials);
        (hi - lo) / self.median * 100.0
    }

    /// What a number read from this cell must carry beside it, in short: `DP †`, `UP's trials
    /// spread 13 %`, `no per-trial records`.
    fn caveats(&self, who: &str) -> Vec<String> {
        let mut out = Vec::new();
        let marks: String = [
            (self.cell.noisy(), "†"),
            (self.cell.unexplained_slow_trials() > 0, "‡"),
            (self.cell.mixed_placements(), "§"),
        ]
        .iter()
        .filter(|(on, _)| *on)
        .map(|(_, m)| *m)
        .collect();
        if !marks.is_empty() {
            out.push(format!("{who} {marks}"));
        }
        let spread = self.spread_percent();
        if spread > SPREAD_PERCENT {
            out.push(format!("{who}'s trials spread {spread:.0} %"));
        }
        if self.cell.trials.is_empty() {
            out.push("no per-trial records".into());
        }
        out
    }
}

/// A ratio of two cells' median trials with its bootstrap interval and caveats.
fn ratio(name: &str, num: &Stat, num_who: &str, den: &Stat, den_who: &str) -> Figure {
    let seed = num.trials.len() as u64 * 1_000_003 + den.trials.len() as u64;
    let interval = median_ratio_interval(&num.trials, &den.trials, seed);
    let mut caveats = num.caveats(num_who);
    caveats.extend(den.caveats(den_who));
    Figure {
        name: name.into(),
        value: num.median / den.median,
        interval: Some(interval),
        cell: Some(num.cell.key.label()),
        caveats,
    }
}

/// The 95 % percentile bootstrap interval of median(`num`) ÷ median(`den`), seeded so the same
/// trials always give the same interval.
pub fn median_ratio_interval(num: &[f64], den: &[f64], seed: u64) -> [f64; 2] {
    let mut rng = stats::SplitMix64(seed);
    let mut resample = |xs: &[f64]| {
        let draw: Vec<f64> = (0..xs.len()).map(|_| xs[rng.below(xs.len())]).collect();
        stats::median(&draw)
    };
    let ratios: Vec<f64> = (0..RESAMPLES)
        .map(|_| resample(num) / resample(den))
        .collect();
    let sorted = stats::sorted(&ratios);
    [
        stats::quantile(&sorted, stats::INTERVAL_TAILS.0),
        stats::quantile(&sorted, stats::INTERVAL_TAILS.1),
    ]
}

/// The cell of `key` in another mode (the serial twin drops the hand-off dimensions).
fn in_mode<'a>(results: &'a Results, key: &CellKey, mode: Mode) -> Option<&'a Cell> {
    results.cell(&key.with(Dim::Mode, mode.value())?)
}

/// A workload level as sentences name it: its index, and what it came to (µs for the synthetic
/// chain's iterations, else the amount in the kind's unit).
fn level(results: &Results, cell: &Cell) -> String {
    let w = cell.key.workload;
    let amount = cell.workload_amount();
    if amount == 0 {
        return format!("workload {w}");
    }
    if cell.workload_unit() == crate::workload::Synthetic::UNIT {
        if let Some(l) = results.calibration.levels.iter().find(|l| l.workload == w) {
            return format!("workload {w} ({:.0} µs)", l.micros);
        }
    }
    let amount = cell
        .key
        .workload_kind
        .amount_text(&amount.to_string(), cell.workload_unit());
    format!("workload {w} ({amount})")
}

/// A cell by its row: `128×128 workload 2`.
fn row_name(cell: &Cell) -> String {
    format!("{0}×{0} workload {1}", cell.key.size, cell.key.workload)
}

fn fmt_interval(f: &Figure) -> String {
    match f.interval {
        Some([lo, hi]) => format!("{:.2} [{lo:.2}, {hi:.2}]", f.value),
        None => format!("{:.2}", f.value),
    }
}

/// The sentence with what qualifies its figures after it, each said once; the legend of the
/// marks is in every output that prints findings.
fn with_caveats(sentence: String, figures: &[Figure]) -> String {
    let mut caveats: Vec<&str> = Vec::new();
    for c in figures.iter().flat_map(|f| &f.caveats) {
        if !caveats.contains(&c.as_str()) {
            caveats.push(c);
        }
    }
    if caveats.is_empty() {
        format!("{sentence}.")
    } else {
        format!("{sentence} ({}).", caveats.join("; "))
    }
}

/// The DP cells of a slice, in run order.
fn dp_cells<'a>(results: &'a Results, slice: &Slice) -> Vec<&'a Cell> {
    results
        .cells
        .iter()
        .filter(|c| c.key.mode == Mode::Dp && slice.contains(&c.key))
        .collect()
}

/// Where DP ÷ `other` peaks in the slice: the DP cell whose median trial is the largest
/// multiple of its twin's in `other`.
fn peak(results: &Results, slice: &Slice, other: Mode) -> Option<Finding> {
    let (id, name, who) = match other {
        Mode::Up => ("peak-dp-over-up", "dp_over_up", "UP"),
        _ => ("peak-dp-over-serial", "dp_over_serial", "serial"),
    };
    let best = dp_cells(results, slice)
        .into_iter()
        .filter_map(|c| {
            let dp = Stat::of(Some(c))?;
            let base = Stat::of(in_mode(results, &c.key, other))?;
            Some((dp.median / base.median, dp, base))
        })
        .max_by(|a, b| a.0.total_cmp(&b.0))?;
    let (_, dp, base) = best;
    let figure = ratio(name, &dp, "DP", &base, who);
    let sentence = format!(
        "DP ÷ {who} peaks at {} on {n}×{n} at {} (median trials: DP {:.0} FPS, {who} {:.0})",
        fmt_interval(&figure),
        level(results, dp.cell),
        dp.median,
        base.median,
        n = dp.cell.key.size,
    );
    let figures = vec![
        figure,
        fps_figure("dp_fps", &dp, "DP"),
        fps_figure(&format!("{}_fps", who.to_lowercase()), &base, who),
    ];
    Some(Finding {
        id: id.into(),
        slice: slice.clone(),
        size: Some(dp.cell.key.size),
        sentence: with_caveats(sentence, &figures[..1]),
        figures,
    })
}

fn fps_figure(name: &str, stat: &Stat, who: &str) -> Figure {
    Figure {
        name: name.into(),
        value: stat.median,
        interval: None,
        cell: Some(stat.cell.key.label()),
        caveats: stat.caveats(who),
    }
}

/// The range of UP ÷ serial over the slice's rows: one core doing both threads' work in turn.
fn up_over_serial(results: &Results, slice: &Slice) -> Option<Finding> {
    let ups: Vec<&Cell> = results
        .cells
        .iter()
        .filter(|c| c.key.mode == Mode::Up && slice.contains(&c.key))
        .collect();
    let ratios: Vec<(f64, Figure, String)> = ups
        .iter()
        .filter_map(|c| {
            let up = Stat::of(Some(c))?;
            let serial = Stat::of(in_mode(results, &c.key, Mode::Serial))?;
            let f = ratio("up_over_serial", &up, "UP", &serial, "serial");
            Some((f.value, f, row_name(c)))
        })
        .collect();
    if ratios.len() < 2 {
        return None;
    }
    let lo = ratios.iter().min_by(|a, b| a.0.total_cmp(&b.0))?;
    let hi = ratios.iter().max_by(|a, b| a.0.total_cmp(&b.0))?;
    let lo_name = Figure {
        name: "up_over_serial_min".into(),
        ..lo.1.clone()
    };
    let hi_name = Figure {
        name: "up_over_serial_max".into(),
        ..hi.1.clone()
    };
    let (lo, hi) = ((lo.0, lo.2.clone()), (hi.0, hi.2.clone()));
    let sentence = format!(
        "UP runs at {:.2}-{:.2} × serial over the {} rows with both (median trials; lowest at {}, highest at {})",
        lo.0,
        hi.0,
        ratios.len(),
        lo.1,
        hi.1,
    );
    let figures = vec![lo_name, hi_name];
    Some(Finding {
        id: "up-over-serial".into(),
        slice: slice.clone(),
        size: None,
        sentence: with_caveats(sentence, &figures),
        figures,
    })
}

/// Per size, the workload levels over which DP stays within [`FLAT_PERCENT`] of its FPS at
/// the lowest level, and where it falls after them.
fn flat(results: &Results, slice: &Slice) -> Vec<Finding> {
    let cells = dp_cells(results, slice);
    let mut sizes: Vec<usize> = cells.iter().map(|c| c.key.size).collect();
    sizes.dedup();
    sizes.sort_unstable();
    sizes.dedup();
    let mut out = Vec::new();
    for size in sizes {
        let mut row: Vec<Stat> = cells
            .iter()
            .filter(|c| c.key.size == size)
            .filter_map(|c| Stat::of(Some(c)))
            .collect();
        row.sort_by_key(|s| s.cell.key.workload);
        if row.len() < 2 {
            continue;
        }
        let base = row[0].median;
        let within = |s: &Stat| ((s.median / base - 1.0) * 100.0).abs() <= FLAT_PERCENT;
        let kept = row.iter().take_while(|s| within(s)).count();
        let flat_part = &row[..kept];
        let (lo, hi) = stats::min_max(&flat_part.iter().map(|s| s.median).collect::<Vec<_>>());
        let first = &row[0];
        let last_flat = &flat_part[kept - 1];
        let mut figures: Vec<Figure> = flat_part
            .iter()
            .map(|s| fps_figure("dp_fps", s, &format!("DP w{}", s.cell.key.workload)))
            .collect();
        let mut sentence = if kept == 1 {
            format!(
                "On {size}×{size}, DP does not stay flat: {:.0} FPS at {} and {:.0} at {}",
                first.median,
                level(results, first.cell),
                row[1].median,
                level(results, row[1].cell)
            )
        } else {
            format!(
                "On {size}×{size}, DP stays within {FLAT_PERCENT:.0} % of its {} FPS from {} to {} ({lo:.0}-{hi:.0} FPS)",
                workload_word(first.cell),
                level(results, first.cell),
                level(results, last_flat.cell),
            )
        };
        if kept == 1 {
            figures.push(fps_figure(
                "dp_fps",
                &row[1],
                &format!("DP w{}", row[1].cell.key.workload),
            ));
        } else if let Some(next) = row.get(kept) {
            let moves = if next.median < base { "falls" } else { "rises" };
            let _ = write!(
                sentence,
                ", then {moves} to {:.0} at {} ({:.2} × )",
                next.median,
                level(results, next.cell),
                next.median / base
            );
            figures.push(fps_figure(
                "dp_fps_after",
                next,
                &format!("DP w{}", next.cell.key.workload),
            ));
        }
        let sentence = sentence.replace(" × )", " ×)");
        out.push(Finding {
            id: "dp-flat".into(),
            slice: slice.clone(),
            size: Some(size),
            sentence: with_caveats(sentence, &figures),
            figures,
        });
    }
    out
}

fn workload_word(cell: &Cell) -> String {
    format!("workload-{}", cell.key.workload)
}

/// The balance points the run found in the slice, and DP ÷ serial there.
fn balance(results: &Results, slice: &Slice) -> Vec<Finding> {
    results
        .balance
        .iter()
        .filter(|e| slice.contains(&e.key))
        .map(|e| {
            let n = e.key.size;
            let placement = e
                .placement
                .map(|p| format!(", placement {p}"))
                .unwrap_or_default();
            let mut figures = Vec::new();
            let sentence = match (e.balance_us, e.dp_over_serial) {
                (Some(us), dp) => {
                    figures.push(Figure {
                        name: "balance_us".into(),
                        value: us,
                        interval: e.balance_us_low.zip(e.balance_us_high).map(|(l, h)| [l, h]),
                        cell: Some(e.key.label()),
                        caveats: Vec::new(),
                    });
                    // S as the balance compares it: timed in the probes of the headline's
                    // placement, where the search recorded one (schema 6).
                    let step = e
                        .placements
                        .iter()
                        .find(|p| Some(p.placement) == e.placement)
                        .and_then(|p| p.step_us)
                        .unwrap_or(e.step_us);
                    figures.push(Figure {
                        name: "step_us".into(),
                        value: step,
                        interval: None,
                        cell: Some(e.key.label()),
                        caveats: Vec::new(),
                    });
                    let mut s = format!(
                        "On {n}×{n}, the two threads' work is equal at {us:.0} µs of workload ({:.2} × the {step:.0} µs step){placement}",
                        us / step,
                    );
                    if let Some(r) = dp {
                        let interval = e.dp_over_serial_low.zip(e.dp_over_serial_high).map(|(l, h)| [l, h]);
                        let f = Figure {
                            name: "dp_over_serial_at_balance".into(),
                            value: r,
                            interval,
                            cell: Some(e.key.label()),
                            caveats: Vec::new(),
                        };
                        let _ = write!(s, "; DP ÷ serial there is {}", fmt_interval(&f));
                        figures.push(f);
                    }
                    if e.set_aside > 0 {
                        let _ = write!(
                            s,
                            "; {} probe(s) of another placement set aside",
                            e.set_aside
                        );
                    }
                    s
                }
                (None, _) => format!(
                    "On {n}×{n}, the search found no balance point{placement}{}",
                    e.note
                        .as_deref()
                        .map(|n| format!(": {n}"))
                        .unwrap_or_default()
                ),
            };
            Finding {
                id: "balance".into(),
                slice: slice.clone(),
                size: Some(n),
                sentence: format!("{sentence}."),
                figures,
            }
        })
        .collect()
}

/// How many of the slice's cells carry each mark, and how many have no trial records.
fn marks(results: &Results, slice: &Slice) -> Option<Finding> {
    let cells: Vec<&Cell> = results
        .cells
        .iter()
        .filter(|c| c.summary.is_some() && slice.contains(&c.key))
        .collect();
    let count = |f: fn(&Cell) -> bool| cells.iter().filter(|c| f(c)).count();
    let noisy = count(Cell::noisy);
    let unexplained = count(|c| c.unexplained_slow_trials() > 0);
    let mixed = count(Cell::mixed_placements);
    let bare = count(|c| c.trials.is_empty());
    let spread = cells
        .iter()
        .filter_map(|c| Stat::of(Some(c)))
        .filter(|s| s.spread_percent() > SPREAD_PERCENT)
        .count();
    let n = cells.len();
    if n == 0 {
        return None;
    }
    // Only the marks the run has are named, so a run without § says nothing of it.
    let named: Vec<String> = [
        (noisy, "† (noisy)"),
        (unexplained, "‡ (unexplained slow trial)"),
        (mixed, "§ (mixed placements)"),
    ]
    .iter()
    .filter(|(k, _)| *k > 0)
    .map(|(k, m)| format!("{k} {m}"))
    .collect();
    let marked = if named.is_empty() {
        "none marked".to_string()
    } else {
        named.join(", ")
    };
    let mut sentence = format!(
        "Marks over the {n} cells: {marked}; {spread} with trials spread over {SPREAD_PERCENT:.0} %"
    );
    if bare > 0 {
        let _ = write!(sentence, "; {bare} have no per-trial records");
    }
    let figure = |name: &str, value: usize| Figure {
        name: name.into(),
        value: value as f64,
        interval: None,
        cell: None,
        caveats: Vec::new(),
    };
    Some(Finding {
        id: "marks".into(),
        slice: slice.clone(),
        size: None,
        sentence: format!("{sentence}."),
        figures: vec![
            figure("cells", n),
            figure("noisy", noisy),
            figure("unexplained", unexplained),
            figure("mixed", mixed),
            figure("spread", spread),
            figure("no_trial_records", bare),
        ],
    })
}

/// The fastest and slowest hand-off per mode, over the rows where every method ran: each
/// method's geometric mean of its median trial ÷ the row's fastest.
fn handoffs(results: &Results) -> Vec<Finding> {
    if !slice_dims(results).contains(&Dim::Sync) {
        return Vec::new();
    }
    let mut out = Vec::new();
    for mode in [Mode::Up, Mode::Dp] {
        // Rows: the cell keys with the method taken out.
        let cells: Vec<&Cell> = results
            .cells
            .iter()
            .filter(|c| c.key.mode == mode && c.summary.is_some())
            .collect();
        let mut methods: Vec<String> = Vec::new();
        for c in &cells {
            let m = c
                .key
                .get(Dim::Sync)
                .map(|v| v.to_string())
                .unwrap_or_default();
            if !methods.contains(&m) {
                methods.push(m);
            }
        }
        if methods.len() < 2 {
            continue;
        }
        // A row: the cells equal but for their method, named by size, level and slice.
        let mut rows: Vec<(String, String)> = Vec::new();
        let dims = slice_dims(results);
        for c in &cells {
            let r = c.key.label_without(&[Dim::Sync]);
            if !rows.iter().any(|(k, _)| *k == r) {
                let mut slice = Slice::of(&dims, &c.key);
                slice.values.retain(|(k, _)| k != Dim::Sync.config_key());
                let name = if slice.values.is_empty() {
                    row_name(c)
                } else {
                    format!("{} ({})", row_name(c), slice.label())
                };
                rows.push((r, name));
            }
        }
        let mut shares: Vec<Vec<f64>> = vec![Vec::new(); methods.len()];
        let mut worst: Vec<(f64, String)> = vec![(f64::INFINITY, String::new()); methods.len()];
        let mut full_rows = 0;
        for (r, name) in &rows {
            let here: Vec<(usize, f64)> = cells
                .iter()
                .filter(|c| &c.key.label_without(&[Dim::Sync]) == r)
                .filter_map(|c| {
                    let m = c.key.get(Dim::Sync)?.to_string();
                    let i = methods.iter().position(|x| *x == m)?;
                    Some((i, Stat::of(Some(c))?.median))
                })
                .collect();
            if here.len() != methods.len() {
                continue;
            }
            full_rows += 1;
            let best = here.iter().map(|&(_, f)| f).fold(0.0, f64::max);
            for (i, f) in here {
                shares[i].push(f / best);
                if f / best < worst[i].0 {
                    worst[i] = (f / best, name.clone());
                }
            }
        }
        if full_rows == 0 {
            continue;
        }
        let geo: Vec<f64> = shares
            .iter()
            .map(|s| (s.iter().map(|x| x.ln()).sum::<f64>() / s.len() as f64).exp())
            .collect();
        let order = |a: &usize, b: &usize| geo[*a].total_cmp(&geo[*b]);
        let idx: Vec<usize> = (0..methods.len()).collect();
        let fastest = *idx.iter().max_by(|a, b| order(a, b)).unwrap_or(&0);
        let slowest = *idx.iter().min_by(|a, b| order(a, b)).unwrap_or(&0);
        let mode_name = mode.value().to_string().to_uppercase();
        let sentence = format!(
            "In {mode_name}, over the {full_rows} rows where all {} hand-offs ran, the fastest is {} ({:.2} × each row's fastest, geometric mean) and the slowest {} ({:.2} ×; {:.2} × at worst, in {})",
            methods.len(),
            methods[fastest],
            geo[fastest],
            methods[slowest],
            geo[slowest],
            worst[slowest].0,
            worst[slowest].1,
        );
        let figure = |name: &str, i: usize| Figure {
            name: name.into(),
            value: geo[i],
            interval: None,
            cell: Some(methods[i].clone()),
            caveats: Vec::new(),
        };
        out.push(Finding {
            id: "handoffs".into(),
            slice: Slice::default(),
            size: None,
            sentence: format!("{sentence}."),
            figures: vec![figure("fastest", fastest), figure("slowest", slowest)],
        });
    }
    out
}

/// Every finding of `results`: per slice, then the run-wide ones.
pub fn of(results: &Results) -> Findings {
    let slices = slices(results);
    let mut findings = Vec::new();
    for s in &slices {
        findings.extend(peak(results, s, Mode::Up));
        findings.extend(peak(results, s, Mode::Serial));
        findings.extend(up_over_serial(results, s));
        findings.extend(flat(results, s));
        findings.extend(balance(results, s));
        findings.extend(marks(results, s));
    }
    findings.extend(handoffs(results));
    if let Some(p) = crate::findings::placement::finding(results) {
        findings.push(Finding {
            id: "placement".into(),
            slice: Slice::default(),
            size: None,
            sentence: p.sentence.clone(),
            figures: p
                .sides
                .iter()
                .filter_map(|s| {
                    Some(Figure {
                        name: format!("dp_over_serial_{}", s.class),
                        value: s.dp_over_serial?,
                        interval: None,
                        cell: None,
                        caveats: Vec::new(),
                    })
                })
                .collect(),
        });
    }
    Findings {
        schema_version: FINDINGS_SCHEMA,
        run: results.config.name.clone(),
        started: results.started.clone(),
        machine: results.machine.line(),
        slice_dims: slice_dims(results)
            .iter()
            .map(|d| d.config_key().to_string())
            .collect(),
        findings,
    }
}

impl Findings {
    /// The findings in runs of one slice each, in order, each headed by its slice's label
    /// (`Across the run` for run-wide ones); one run with no heading when the run has one slice.
    pub fn grouped(&self) -> Vec<(Option<String>, Vec<&Finding>)> {
        let several = !self.slice_dims.is_empty();
        let mut out: Vec<(Option<String>, Vec<&Finding>)> = Vec::new();
        let mut last: Option<&Slice> = None;
        for f in &self.findings {
            if out.is_empty() || (several && last != Some(&f.slice)) {
                let heading = several.then(|| {
                    if f.slice.values.is_empty() {
                        "Across the run".to_string()
                    } else {
                        f.slice.label()
                    }
                });
                out.push((heading, Vec::new()));
                last = Some(&f.slice);
            }
            if let Some((_, group)) = out.last_mut() {
                group.push(f);
            }
        }
        out
    }

    /// The findings as a markdown section: one list per slice, run-wide ones last.
    pub fn to_markdown(&self) -> String {
        let mut out = String::from("## Findings\n\n");
        if self.findings.is_empty() {
            out.push_str("No finished cell yet.\n\n");
            return out;
        }
        for (i, (heading, group)) in self.grouped().iter().enumerate() {
            if let Some(heading) = heading {
                let _ = writeln!(out, "{}**{heading}**\n", if i > 0 { "\n" } else { "" });
            }
            for f in group {
                let _ = writeln!(out, "- {}", f.sentence);
            }
        }
        out.push('\n');
        out
    }

    /// The findings as JSON text.
    pub fn to_json(&self) -> serde_json::Result<String> {
        serde_json::to_string_pretty(self)
    }
}
