//! A run as the CI benchmark trackers take it (`oceanbench export`): Bencher Metric Format and
//! github-action-benchmark's `customBiggerIsBetter` list. Each measured cell is one benchmark
//! named by every dimension's value, defaults included, and its workload level as the config
//! gives it, so a name stays the same when a default or a level's index changes; FPS is the
//! metric, bounded by the slowest and fastest trial.

use crate::cell::Dim;
use crate::findings::provenance::{CellFacts, Provenance};
use crate::results::{Cell, Results};
use crate::summary::Summary;
use serde::Serialize;
use serde_json::{json, Map, Value};

crate::named! {
    /// A CI tracker's format.
    pub enum CiFormat {
        /// Bencher Metric Format: `{name: {measure: {value, lower_value, upper_value}}}`.
        Bmf,
        /// github-action-benchmark's `customBiggerIsBetter` list: `[{name, unit, value,
        /// range, extra}]`.
        GithubActionBenchmark,
    }
}

/// The BMF measure and github-action-benchmark unit of the one metric exported.
pub const FPS_MEASURE: &str = "fps";

/// The benchmark name of `cell`: `size=256, workload_kind=synthetic, level=20 µs, mode=dp, ...`
/// — every dimension the cell has (a serial cell has no hand-off), in declaration order, with
/// the workload level in place of its index.
pub fn name(results: &Results, cell: &Cell) -> String {
    Dim::ALL
        .iter()
        .filter_map(|&dim| match dim {
            Dim::Workload => Some(format!("level={}", level(results, cell))),
            _ => cell
                .key
                .get(dim)
                .map(|value| format!("{}={value}", dim.name())),
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// The cell's workload level as the config gives it: in µs, in the kind's unit, or as a
/// fraction of a mesh's step (whose µs this machine measured, and another would not repeat);
/// the amount the cell ran when the config does not say.
fn level(results: &Results, cell: &Cell) -> String {
    let given = results.config.workload_levels.get(cell.key.workload);
    match given.map(|l| (l.amount(), l.micros, l.step_fraction.zip(l.size))) {
        Some((Some((unit, amount)), _, _)) => format!("{amount} {unit}"),
        Some((None, Some(us), _)) => format!("{us} µs"),
        Some((None, None, Some((fraction, size)))) => {
            format!("{fraction} × the {size}×{size} step")
        }
        _ => format!("{} {}", cell.workload_amount(), cell.workload_unit()),
    }
}

/// The measured cells with their names, in the run's order.
fn measured(results: &Results) -> impl Iterator<Item = (String, &Summary)> {
    results
        .cells
        .iter()
        .filter_map(|c| c.summary.as_ref().map(|s| (name(results, c), s)))
}

/// The slowest and fastest trial's FPS, or the FPS itself when the summary kept no trials.
fn bounds(s: &Summary) -> (f64, f64) {
    if s.fps_trials.is_empty() {
        (s.fps, s.fps)
    } else {
        (s.fps_spread.min, s.fps_spread.max)
    }
}

/// Bencher Metric Format: per cell, the `fps` measure with the trials' range as its bounds.
pub fn bmf(results: &Results) -> Value {
    let mut out = Map::new();
    for (name, s) in measured(results) {
        let (lower, upper) = bounds(s);
        out.insert(
            name,
            json!({ FPS_MEASURE: { "value": s.fps, "lower_value": lower, "upper_value": upper } }),
        );
    }
    Value::Object(out)
}

/// One benchmark of github-action-benchmark's custom tools.
#[derive(Debug, Serialize)]
pub struct ActionBenchmark {
    /// The cell's name ([`name`]).
    pub name: String,
    /// `FPS`.
    pub unit: &'static str,
    /// The cell's FPS: all measured frames ÷ all measured seconds.
    pub value: f64,
    /// The slowest and fastest trial, as text.
    pub range: String,
    /// The trials, then the provenance one fact per line: machine, commit, config, the run's
    /// placement and the cell's (the chart's tooltip).
    pub extra: String,
}

/// The provenance of an export of `results`: every measured cell under its export name.
pub fn provenance(results: &Results) -> Provenance {
    let cells = results
        .cells
        .iter()
        .filter(|c| c.summary.is_some())
        .map(|c| CellFacts::of(name(results, c), c))
        .collect();
    Provenance::of(results, cells)
}

/// github-action-benchmark's `customBiggerIsBetter` list: FPS per cell, bigger is better.
pub fn github_action_benchmark(results: &Results) -> Vec<ActionBenchmark> {
    let provenance = provenance(results);
    let run = provenance.run_lines().join("\n");
    measured(results)
        .zip(&provenance.placement.cells)
        .map(|((name, s), cell)| {
            let (lower, upper) = bounds(s);
            ActionBenchmark {
                name,
                unit: "FPS",
                value: s.fps,
                range: format!("trials {lower:.2} to {upper:.2}"),
                extra: format!(
                    "{} trial(s), {} frames\n{run}\n{}",
                    s.fps_trials.len(),
                    s.frames,
                    cell.line()
                ),
            }
        })
        .collect()
}

/// The export of `results` in `format`, as pretty JSON.
pub fn to_string(results: &Results, format: CiFormat) -> serde_json::Result<String> {
    match format {
        CiFormat::Bmf => serde_json::to_string_pretty(&bmf(results)),
        CiFormat::GithubActionBenchmark => {
            serde_json::to_string_pretty(&github_action_benchmark(results))
        }
    }
}
