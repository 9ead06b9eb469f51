//! A metric across runs (`oceanbench history`): the runs in the order they were made, one line
//! per cell over them, and a run made on another machine than the run before it marked on the
//! axis and named in a note, so a step there is not read as a change of code. Each change point
//! found in a cell's line is drawn where it lies, between two runs, with its size.

use super::bars::shade;
use super::render::{Body, Chart, Frame, Legend, LinePanel, LinePlot, Marker, Series};
use super::{ChartError, ChartFormat, NothingToDraw, CHART_SIZE, PALETTE};
use crate::changepoint::{self, ChangePoint};
use crate::report::compare::Metric;
use crate::results::{CellKey, Results};
use crate::stats;
use std::path::{Path, PathBuf};

/// Orders runs as a history reads them: by the time each started (RFC 3339 UTC, so text order
/// is time order), then by commit.
pub fn order(runs: &mut [Results]) {
    runs.sort_by(|a, b| {
        (&a.started, &a.machine.git_commit).cmp(&(&b.started, &b.machine.git_commit))
    });
}

/// Each run (by index) whose machine differs from the run before it, with both machines.
pub fn machine_changes(runs: &[Results]) -> Vec<(usize, String, String)> {
    runs.windows(2)
        .enumerate()
        .filter_map(|(i, pair)| {
            let (before, after) = (pair[0].machine.line(), pair[1].machine.line());
            (before != after).then_some((i + 1, before, after))
        })
        .collect()
}

/// A cell's value of `metric` in each run: the median of its trials (as ratios between cells
/// use), `None` where the cell failed or lacks the metric.
pub fn series(runs: &[Results], key: &CellKey, metric: Metric) -> Vec<Option<f64>> {
    runs.iter()
        .map(|run| {
            let cell = run.cell(key)?;
            metric.trials(cell).ok().map(|t| stats::median(&t))
        })
        .collect()
}

/// A change point in a cell's series across runs.
#[derive(Clone, Debug, PartialEq)]
pub struct RunChange {
    /// The index of the first run after the change, among all runs.
    pub run: usize,
    /// The change, over the runs that measured the cell.
    pub change: ChangePoint,
    /// Whether the change made the metric worse.
    pub regression: bool,
}

impl RunChange {
    /// `16 w0 dp ..., FPS from run 6: -10.0% (regression)`, the change in cell `label`.
    pub fn line(&self, label: &str, metric: Metric) -> String {
        format!(
            "{label}, {} from run {}: {:+.1}% ({})",
            metric.unit(),
            self.run + 1,
            self.change.percent(),
            if self.regression {
                "regression"
            } else {
                "improvement"
            }
        )
    }
}

/// The change points of cell `key`'s `metric` across `runs`, found over the runs that measured
/// it, with shuffles seeded by the cell's label so the command and the chart find the same.
pub fn changes(runs: &[Results], key: &CellKey, metric: Metric) -> Vec<RunChange> {
    let (at, values): (Vec<usize>, Vec<f64>) = series(runs, key, metric)
        .into_iter()
        .enumerate()
        .filter_map(|(i, v)| v.map(|v| (i, v)))
        .unzip();
    changepoint::detect(&values, stats::seed_from(&key.label()))
        .into_iter()
        .map(|change| RunChange {
            run: at[change.at],
            regression: (change.after < change.before) == metric.higher_is_better(),
            change,
        })
        .collect()
}

/// How the axis names run `i`: its number, its commit's first seven digits and its day, with
/// `*` when its machine differs from the run before it.
fn category(i: usize, run: &Results, changed: bool) -> String {
    let commit: String = run
        .machine
        .git_commit
        .as_deref()
        .unwrap_or("no commit")
        .chars()
        .take(7)
        .collect();
    let day = run.started.get(..10).unwrap_or(&run.started);
    let mark = if changed { " *" } else { "" };
    format!("{} {commit} {day}{mark}", i + 1)
}

/// The chart of `metric` over `runs` (in order) for the cells `keys`, one line per cell.
fn chart(runs: &[Results], metric: Metric, keys: &[CellKey]) -> Result<Chart, NothingToDraw> {
    let machines = machine_changes(runs);
    let mut legend = Vec::new();
    let mut lines = Vec::new();
    let (mut markers, mut change_notes) = (Vec::new(), Vec::new());
    for (i, key) in keys.iter().enumerate() {
        let values = series(runs, key, metric);
        if values.iter().all(Option::is_none) {
            continue;
        }
        let color = shade(PALETTE[i % PALETTE.len()], i / PALETTE.len());
        for c in changes(runs, key, metric) {
            markers.push(Marker {
                // Between the last run before the change and the first after it.
                at: c.run as f64 - 0.5,
                color,
                label: format!("{:+.1}%", c.change.percent()),
            });
            change_notes.push(format!("change: {}", c.line(&key.label(), metric)));
        }
        legend.push(Legend::boxed(key.label(), color));
        lines.push(Series { color, values });
    }
    if lines.is_empty() {
        return Err(NothingToDraw(format!(
            "no chosen cell has {} in any run",
            metric.unit()
        )));
    }
    let categories = runs
        .iter()
        .enumerate()
        .map(|(i, r)| category(i, r, machines.iter().any(|c| c.0 == i)))
        .collect();
    let notes = machines
        .iter()
        .map(|(i, before, after)| {
            format!(
                "* run {} ran on another machine than run {i}: {after} (before: {before})",
                i + 1
            )
        })
        .chain(change_notes)
        .collect();
    Ok(Chart {
        frame: Frame {
            title: format!("{} across {} runs", metric.unit(), runs.len()),
            lines: vec![
                "Each cell's median trial, run by run in the order they started (then by commit)."
                    .into(),
            ],
            legend,
            notes,
        },
        body: Body::Lines(LinePlot {
            panels: vec![LinePanel {
                caption: String::new(),
                series: lines,
            }],
            categories,
            first_apart: false,
            x_desc: "run: number, commit, day (* another machine); dashed: a change".into(),
            y_desc: format!("{} (log scale)", metric.unit()),
            markers,
        }),
        size: CHART_SIZE,
    })
}

/// Draws each of `metrics` over `runs` into `dir` as `history-<metric>.<format>`; the files
/// written, and for a metric with nothing to draw, why.
pub fn write(
    runs: &[Results],
    metrics: &[Metric],
    keys: &[CellKey],
    dir: &Path,
    formats: &[ChartFormat],
) -> Result<Vec<Result<Vec<PathBuf>, NothingToDraw>>, ChartError> {
    super::prepare(dir)?;
    let mut out = Vec::new();
    for &metric in metrics {
        let chart = match chart(runs, metric, keys) {
            Ok(chart) => chart,
            Err(e) => {
                out.push(Err(e));
                continue;
            }
        };
        let stem = format!("history-{}", metric.name());
        out.push(Ok(super::write_formats(&chart, dir, &stem, formats)?));
    }
    Ok(out)
}
