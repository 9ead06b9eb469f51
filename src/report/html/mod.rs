//! One self-contained HTML page per run: what was run and on what, the charts inline as SVG,
//! the tables, and optionally the comparison with a baseline run. Drawn from results files
//! alone; the page loads nothing (no script, font or image from elsewhere).
//!
//! The page is a maud template compiled with the crate: every value spliced into it is
//! escaped, and the charts' SVG, which the chart module drew and escaped itself, is the only
//! text inserted as it is.

use super::chart::{self, ChartError, ChartOptions, NothingToDraw};
use super::compare::{Comparison, Verdict};
use super::markdown::{self, Table, MIXED, NOISY, UNEXPLAINED};
use crate::cell::{Dim, Value};
use crate::machine::{Machine, Tree};
use crate::results::{Cell, Results};
use maud::{html, Markup, PreEscaped, DOCTYPE};

mod latency;
pub use latency::latency_page;

const STYLE: &str = include_str!("report.css");

/// What an older results file lacks.
const NOT_RECORDED: &str = "not recorded";

/// A run to compare with, and the comparison `compare BASELINE RESULTS` makes.
pub struct Baseline<'a> {
    /// How the page names the baseline (its path as given).
    pub name: &'a str,
    /// The comparison of the report's run against it.
    pub comparison: &'a Comparison,
}

/// The page of `results`; `source` names the results as the user gave them.
pub fn page(
    results: &Results,
    source: &str,
    baseline: Option<&Baseline>,
) -> Result<String, ChartError> {
    let charts = chart::svgs(std::slice::from_ref(results), &ChartOptions::default())?;
    // A chart drawn per slice appears once per slice, each under its own file stem.
    let chart = |chart: &str| -> Markup {
        html! {
            @for svg in charts.iter().filter(|s| s.chart == chart) { (figure(svg)) }
        }
    };
    let title = format!("oceanbench: {}", results.config.name);
    let has_balance = !results.balance.is_empty() || !results.balance_failures.is_empty();
    let body = html! {
        h1 { (title) }
        p.subtitle {
            "Started " (results.started) ", "
            @match &results.finished {
                Some(f) => { "finished " (f) },
                None => { "not finished (interrupted, or still running)" },
            }
            "; " (results.cells.len()) " cells from " code { (source) } "."
        }
        (verdict(results, baseline))
        nav id="contents" {
            "Contents: "
            @for (i, (id, name)) in sections(has_balance, baseline.is_some()).iter().enumerate() {
                @if i > 0 { " · " }
                a href={ "#" (id) } { (name) }
            }
        }
        h2 id="figure-5-1" { "Figure 5-1" }
        (chart("figure-5-1"))
        (chart("relative"))
        h2 id="fps" { "Frames per second" }
        p.note {
            "FPS = frames ÷ seconds over every trial; ± is the spread (coefficient of variation) over trials; "
            (NOISY) " marks a cell that kept a trial in which other tasks or the hypervisor took more than "
            (results.config.noise_threshold_percent) " % of the time, " (UNEXPLAINED)
            " a cell with a slow trial that nothing recorded explains, " (MIXED)
            " a cell whose trials ran in more than one placement of the two cores; "
            "DP÷UP and DP÷serial are ratios of FPS."
        }
        @for t in markdown::fps_tables(results) { (table(&t)) }
        @if let Some(line) = markdown::placement_line(results) {
            h3 id="placement" { "Placement" }
            p { (line) }
            @if let Some(t) = markdown::placement_table(results) { (table(&t)) }
            @if let Some(f) = crate::findings::placement::finding(results) {
                p id="placement-finding" { (f.sentence) }
            }
        }
        @if let Some(t) = markdown::slow_trials(results) { (table(&t)) }
        @let noisy = markdown::noisy_cells(results);
        @if !noisy.is_empty() {
            h3 { "Noisy cells" }
            ul id="noisy-cells" { @for line in &noisy { li { (line) } } }
        }
        @for t in markdown::work_tables(results) { (table(&t)) }
        h2 id="frame-times" { "Frame times" }
        (table(&frame_metrics(results)))
        (chart("frame-times"))
        (chart("breakdown"))
        @if has_balance {
            h2 id="balance" { "Balance point" }
            @if let Some(t) = markdown::balance_table(results) { (table(&t)) }
            (chart("balance"))
        }
        h2 id="handoffs" { "Hand-offs and latency" }
        (chart("sync"))
        (chart("latency-vs-fps"))
        @if let Some(b) = baseline { (comparison(b)) }
        (what_was_run(results))
        footer {
            "Written by oceanbench " (env!("CARGO_PKG_VERSION"))
            " from the results file alone; the charts are the ones "
            code { "oceanbench chart" } " draws."
        }
    };
    Ok(document(&title, body))
}

/// A chart inline, under an id of its file stem; or why it was not drawn.
fn figure(svg: &chart::Svg) -> Markup {
    html! {
        @match &svg.drawn {
            Ok(text) => figure id={ "chart-" (svg.name) } { (PreEscaped(text.as_str())) },
            Err(NothingToDraw(why)) => p.note id={ "chart-" (svg.name) } {
                "Chart " code { (svg.name) } " not drawn: " (why)
            },
        }
    }
}

/// A whole page: its title, the style sheet inline and `body`.
fn document(title: &str, body: Markup) -> String {
    html! {
        (DOCTYPE)
        html lang="en" {
            head {
                meta charset="utf-8";
                meta name="viewport" content="width=device-width, initial-scale=1";
                title { (title) }
                style { (PreEscaped(STYLE)) }
            }
            body { (body) }
        }
    }
    .into_string()
}

/// The page's sections, each its anchor and heading, in page order.
fn sections(balance: bool, baseline: bool) -> Vec<(&'static str, &'static str)> {
    let mut out = vec![
        ("figure-5-1", "Figure 5-1"),
        ("fps", "Frames per second"),
        ("frame-times", "Frame times"),
    ];
    if balance {
        out.push(("balance", "Balance point"));
    }
    out.push(("handoffs", "Hand-offs and latency"));
    if baseline {
        out.push(("comparison", "Against the baseline"));
    }
    out.push(("what-ran", "What was run"));
    out
}

/// What the run shows, first: with a baseline, how many cells improved or regressed against
/// it; then the run's findings, each one sentence with its numbers and conditions.
fn verdict(results: &Results, baseline: Option<&Baseline>) -> Markup {
    let findings = crate::findings::of(results);
    let machine = &results.machine;
    html! {
        section id="verdict" {
            h2 { "Verdict" }
            p id="verdict-machine" {
                (machine.cpu_model) ", " (machine.logical_cores) " logical cores; "
                (or_missing(markdown::placement_line(results))) "; " (machine.provenance_line()) "."
            }
            @if let Some(b) = baseline {
                p id="verdict-baseline" {
                    (b.comparison.summary_line()) " "
                    a href="#comparison" { "(against " code { (b.name) } ")" }
                }
            }
            @let warned = warnings(results).len();
            @if warned > 0 {
                p.note id="verdict-warnings" {
                    (warned) " noise warning(s) on this run: "
                    a href="#noise-warnings" { "read them" } " before trusting its numbers."
                }
            }
            @if findings.findings.is_empty() {
                p.note { "No finding: the run holds no cell a finding compares." }
            } @else {
                div id="findings" {
                    @for (heading, group) in findings.grouped() {
                        @if let Some(h) = heading { h3.slice { (h) } }
                        ul { @for f in group { li { (f.sentence) } } }
                    }
                }
            }
        }
    }
}

/// The config, the command line, the machine and what may have disturbed the run.
fn what_was_run(results: &Results) -> Markup {
    let config = &results.config;
    let machine = &results.machine;
    let json = serde_json::to_string_pretty(config).unwrap_or_default();
    let governor: Vec<&str> = results
        .doctor
        .iter()
        .flat_map(|d| &d.findings)
        .filter(|f| f.check == "governor")
        .map(|f| f.finding.as_str())
        .collect();
    let dims: Vec<(Dim, String)> = Dim::ALL
        .iter()
        .map(|&d| {
            let values = config.axes.values(d);
            let shown: Vec<String> = values.iter().map(ToString::to_string).collect();
            (d, shown.join(", "))
        })
        .filter(|(_, v)| !v.is_empty())
        .collect();
    html! {
        h2 id="what-ran" { "What was run" }
        details id="what-ran-list" {
            summary {
                "Config " code { (config.name) } ", " (results.cells.len()) " cells, "
                (config.trials) " trial(s) per cell: its lists and levels"
            }
            dl.facts {
                dt { "config" } dd { code { (config.name) } }
                dt { "description" } dd {
                    @if config.description.is_empty() { span.missing { "none given" } }
                    @else { (config.description) }
                }
                dt { "command line" } dd { (or_missing(results.command.as_deref().map(command_line).as_deref().map(|c| html! { code { (c) } }))) }
                @for (d, values) in &dims {
                    dt { (d.config_key()) } dd { (values) }
                }
                dt { "workload levels" } dd { (markdown::levels(results)) }
                dt { "trials per cell" } dd { (config.trials) }
            }
        }
        details {
            summary { "The whole config as recorded" }
            pre { (json) }
        }
        h3 { "Machine" }
        dl.facts {
            (machine_facts(machine))
            dt { "governor" } dd { (or_missing((!governor.is_empty()).then(|| governor.join("; ")))) }
            dt { "cross-core round trip" } dd { (or_missing(markdown::round_trip(results))) }
            dt { "placement" } dd { (or_missing(markdown::placement_line(results))) }
        }
        h3 id="noise-warnings" { "Noise warnings" }
        @let warnings = warnings(results);
        @if warnings.is_empty() {
            p { "None: no trial was disturbed beyond the threshold, the levels did not drift and "
                @if results.doctor.is_some() { "doctor found nothing to warn about." }
                @else { "doctor's checks were " span.missing { (NOT_RECORDED) } "." } }
        } @else {
            ul.warnings { @for w in &warnings { li { (w) } } }
        }
    }
}

/// What every run records of its machine: CPU, cores, OS, build and source, as `dt`/`dd` pairs.
fn machine_facts(machine: &Machine) -> Markup {
    html! {
        dt { "CPU" } dd { (machine.cpu_model) }
        dt { "cores" } dd {
            (machine.logical_cores) " logical, allowed "
            (crate::affinity::list(&machine.allowed_cores))
        }
        dt { "OS, kernel" } dd { (machine.os) ", kernel " (machine.kernel) }
        dt { "build" } dd {
            "oceanbench " (machine.oceanbench_version) ", " (machine.build_profile) ", "
            (machine.rustc)
        }
        dt { "source" } dd {
            @if let Tree::Dirty { .. } = machine.tree() { strong { (machine.provenance_line()) } }
            @else { (machine.provenance_line()) }
        }
    }
}

/// The value, or "not recorded" in grey.
fn or_missing(value: Option<impl maud::Render>) -> Markup {
    match value {
        Some(v) => html! { (v) },
        None => html! { span.missing { (NOT_RECORDED) } },
    }
}

/// The words as a shell would take them back: a word with anything but safe characters is
/// single-quoted.
fn command_line(words: &[String]) -> String {
    let safe = |c: char| c.is_ascii_alphanumeric() || "-_./=,:@+".contains(c);
    words
        .iter()
        .map(|w| {
            if !w.is_empty() && w.chars().all(safe) {
                w.clone()
            } else {
                format!("'{}'", w.replace('\'', r"'\''"))
            }
        })
        .collect::<Vec<_>>()
        .join(" ")
}

/// The markdown's warnings, a placement change, and doctor's warnings with their fixes.
fn warnings(results: &Results) -> Vec<String> {
    let mut out = markdown::noise_warnings(results);
    if let Some((lo, hi)) = results.round_trip.changed() {
        out.push(format!(
            "placement changed mid-run: the cross-core round trip ranged {lo:.0}-{hi:.0} ns"
        ));
    }
    for f in results.doctor.iter().flat_map(|d| d.warnings()) {
        let fix = f
            .fix
            .as_ref()
            .map_or(String::new(), |x| format!("; fix: {x}"));
        out.push(format!("doctor, {}: {}{fix}", f.check, f.finding));
    }
    out
}

/// The dimensions besides size, workload and mode at one value in every cell that has them: a
/// long table names them once in its title instead of in every row.
pub fn held_dims(results: &Results) -> Vec<(Dim, Value)> {
    Dim::ALL
        .iter()
        .filter(|d| ![Dim::Size, Dim::Workload, Dim::Mode].contains(d))
        .filter_map(|&d| {
            let mut values = results.cells.iter().filter_map(|c| c.key.get(d));
            let first = values.next()?;
            values.all(|v| v == first).then_some((d, first))
        })
        .collect()
}

/// Per cell: median and p99 frame time and the three 1 % lows.
fn frame_metrics(results: &Results) -> Table {
    let held = held_dims(results);
    let skip: Vec<Dim> = held.iter().map(|&(d, _)| d).collect();
    let named: Vec<String> = held
        .iter()
        .filter(|&&(d, v)| Some(v) != d.quiet())
        .map(|&(d, v)| d.title(v))
        .collect();
    let header = [
        "cell",
        "median frame time (ms)",
        "p99 frame time (ms)",
        "P1 (FPS)",
        "1 % low average (FPS)",
        "1 % low integral (FPS)",
    ];
    let row = |c: &Cell| -> Vec<String> {
        let mut row = vec![format!(
            "{}{}",
            c.key.label_without(&skip),
            markdown::marks(c)
        )];
        let Some(s) = &c.summary else {
            row.push(format!(
                "failed: {}",
                c.error.as_deref().unwrap_or("no frames")
            ));
            row.extend(std::iter::repeat_n(String::new(), header.len() - 2));
            return row;
        };
        row.push(format!("{:.3}", s.frame_time_ms.median));
        row.push(format!("{:.3}", s.frame_time_ms.p99));
        match &s.frame_metrics {
            Some(m) => row.extend(
                [
                    m.p1_fps,
                    m.one_percent_low_average_fps,
                    m.one_percent_low_integral_fps,
                ]
                .map(|v| format!("{v:.0}")),
            ),
            None => row.extend(std::iter::repeat_n(NOT_RECORDED.to_string(), 3)),
        }
        row
    };
    Table {
        title: if named.is_empty() {
            "Frame-time metrics per cell".into()
        } else {
            format!("Frame-time metrics per cell, {}", named.join(", "))
        },
        header: header.map(String::from).to_vec(),
        numeric: header.map(|h| h != "cell").to_vec(),
        rows: markdown::reading_order(results).into_iter().map(row).collect(),
        notes: [
            "Rows by size, workload, then mode; a cell's marks as in the FPS tables.".to_string(),
        ]
        .into_iter()
        .chain(markdown::label_legend(results))
        .chain(["P1: 1000 ÷ the 99th percentile frame time; 1 % low average: 1000 ÷ the mean of the frames at or above it; 1 % low integral: the frame time at which the slowest frames reach 1 % of the total time (docs/methodology.md).".to_string()])
        .collect(),
    }
}

/// Rows above which a table starts collapsed: a reader opens it, rather than scrolling past it
/// to the sections after it.
const COLLAPSED_ROWS: usize = 40;

/// A table with its heading as caption, numbers right-aligned, notes under it; one of more than
/// [`COLLAPSED_ROWS`] rows is collapsed under its title.
fn table(t: &Table) -> Markup {
    let grid = table_grid(t);
    html! {
        @if t.rows.len() > COLLAPSED_ROWS {
            details.long-table {
                summary { (t.title) " (" (t.rows.len()) " rows)" }
                (grid)
            }
        } @else {
            (grid)
        }
        @for n in &t.notes { p.note { (n) } }
    }
}

/// The table itself, in a box that scrolls sideways on a narrow screen.
fn table_grid(t: &Table) -> Markup {
    let class = |i: usize| t.numeric.get(i).copied().unwrap_or(false);
    html! {
        div.scroll {
            table {
                caption { (t.title) }
                thead { tr { @for (i, h) in t.header.iter().enumerate() { th.num[class(i)] scope="col" { (h) } } } }
                tbody {
                    @for r in &t.rows {
                        tr { @for (i, v) in r.iter().enumerate() { td.num[class(i)] { (v) } } }
                    }
                }
            }
        }
    }
}

/// The comparison with the baseline: its summary, warnings, every verdict with its interval,
/// and the cells that could not be compared.
fn comparison(b: &Baseline) -> Markup {
    let c = b.comparison;
    let header = c.header();
    let rows = c.table_rows();
    html! {
        h2 id="comparison" { "Against the baseline" }
        p { "This run against " code { (b.name) } ", cell by cell: " (c.summary_line()) "." }
        p.note {
            "Each change is the change of the mean " (c.metric.unit()) " over trials (or repeats) with its 95 % interval (bootstrap); "
            "a change counts only when its whole interval clears the threshold."
        }
        @if !c.warnings.is_empty() {
            ul.warnings { @for w in &c.warnings { li { "Not like for like: " (w) } } }
        }
        div.scroll {
            table {
                caption { "Verdicts per cell" }
                thead { tr { @for (i, h) in header.iter().enumerate() { th.num[(1..5).contains(&i)] scope="col" { (h) } } } }
                tbody {
                    @for (r, change) in rows.iter().zip(&c.changes) {
                        tr.regressed[change.verdict == Verdict::Regressed]
                          .improved[change.verdict == Verdict::Improved] {
                            @for (i, v) in r.iter().enumerate() { td.num[(1..5).contains(&i)] { (v) } }
                        }
                    }
                }
            }
        }
        @for n in c.footnotes() { p.note { (n) } }
        @for (title, cells) in c.unmatched() {
            h3 { (title) " (" (cells.len()) ")" }
            ul { @for cell in cells { li { code { (cell) } } } }
        }
        @if !c.balance.is_empty() {
            h3 { "Balance points, this run against the baseline" }
            ul { @for s in &c.balance { li { (s.line()) } } }
        }
    }
}
