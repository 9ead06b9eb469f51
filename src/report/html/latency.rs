//! The page of a latency run: the verdict against a baseline when there is one, every method's
//! round trip over its repeats next to the floor on the same cores, and what it ran on.

use super::{
    command_line, comparison, document, figure, machine_facts, or_missing, table, Baseline,
};
use crate::report::chart::{self, ChartError};
use crate::report::markdown::Table;
use crate::results::latency::{LatencyRun, FLOOR};
use crate::stats;
use maud::html;

/// The page of latency run `run`; `source` names it as the user gave it.
pub fn latency_page(
    run: &LatencyRun,
    source: &str,
    baseline: Option<&Baseline>,
) -> Result<String, ChartError> {
    let chart = chart::latency_svg(run)?;
    let title = "oceanbench: hand-off round trips";
    let body = html! {
        h1 { (title) }
        p.subtitle {
            @if run.started.is_empty() { "Start " span.missing { "not recorded" } }
            @else { "Started " (run.started) }
            "; " (run.rows.len()) " rows, each measured " (run.repeats)
            " time(s), from " code { (source) } "."
        }
        section id="verdict" {
            h2 { "Verdict" }
            @if let Some(b) = baseline {
                p id="verdict-baseline" {
                    (b.comparison.summary_line()) " "
                    a href="#comparison" { "(against " code { (b.name) } ")" }
                }
            }
            @if run.repeats < crate::report::compare::MIN_TRIALS {
                p.note {
                    "Only " (run.repeats) " repeat(s) per row: compare gives this run no verdict "
                    "(it needs " (crate::report::compare::MIN_TRIALS) ")."
                }
            }
            @if let Some(line) = floor_line(run) { p { (line) } }
        }
        nav id="contents" {
            "Contents: " a href="#round-trips" { "Round trips" }
            @if baseline.is_some() { " · " a href="#comparison" { "Against the baseline" } }
            " · " a href="#what-ran" { "What was run" }
        }
        h2 id="round-trips" { "Round trips" }
        (figure(&chart))
        (table(&round_trip_table(run)))
        @if let Some(b) = baseline { (comparison(b)) }
        h2 id="what-ran" { "What was run" }
        dl.facts {
            dt { "command line" } dd { (or_missing(run.command.as_deref().map(command_line).as_deref().map(|c| html! { code { (c) } }))) }
            dt { "round trips per row and repeat" } dd { (run.samples) }
            dt { "repeats" } dd { (run.repeats) }
            @match &run.machine {
                Some(m) => { (machine_facts(m)) },
                None => { dt { "machine" } dd { span.missing { "not recorded (a file from before runs kept it)" } } },
            }
        }
        footer {
            "Written by oceanbench " (env!("CARGO_PKG_VERSION")) " from the latency run alone."
        }
    };
    Ok(document(title, body))
}

/// The floor between the two cores, the line a reader checks the placement by.
fn floor_line(run: &LatencyRun) -> Option<String> {
    let floor = run.rows.iter().find(|r| r.method == FLOOR)?;
    let trips = floor.round_trips();
    Some(format!(
        "The cache line between cores {} and {} makes its round trip in {:.0} ns (median of {} repeat(s)); every hand-off on those cores pays at least that.",
        floor.main_core,
        floor.helper_core,
        stats::median(&trips),
        trips.len()
    ))
}

/// A row per method and placement: the median over repeats, their range, × the floor, per-trip
/// median and p99 and the CPU time.
fn round_trip_table(run: &LatencyRun) -> Table {
    let rows = run
        .rows
        .iter()
        .map(|r| {
            let trips = r.round_trips();
            let summary = r.summary();
            let central = stats::median(&trips);
            let lo = trips.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = trips.iter().copied().fold(0.0, f64::max);
            let x_floor = run
                .floor_of(r)
                .map(|f| central / stats::median(&f.round_trips()));
            let unpinned = if summary.pinned {
                ""
            } else {
                " (pin did not hold)"
            };
            vec![
                format!("{}{unpinned}", r.method),
                format!("{},{}", r.main_core, r.helper_core),
                format!("{central:.0}"),
                format!("{lo:.0}-{hi:.0}"),
                x_floor.map_or("-".into(), |x| format!("{x:.2}")),
                format!("{:.0}", summary.median_ns),
                format!("{:.0}", summary.p99_ns),
                summary.cpu_ns.map_or("-".into(), |c| format!("{c:.0}")),
            ]
        })
        .collect();
    Table {
        title: "Round trip per method and placement (ns)".into(),
        header: [
            "method",
            "cores",
            "round trip",
            "repeats' range",
            "× floor",
            "per-trip median",
            "p99",
            "CPU per trip",
        ]
        .map(String::from)
        .to_vec(),
        numeric: vec![false, false, true, true, true, true, true, true],
        rows,
        notes: vec![format!(
            "Round trip: the median over repeats of each repeat's batched median (one clock read per {} round trips); per-trip median, p99 and CPU: medians over repeats of each trip timed alone, which adds the clock's own cost; × floor: against the ping-pong on the same cores.",
            crate::results::latency::BATCH
        )],
    }
}
