//! The Figure 5-1 table: rows mesh size × workload, columns serial / UP / DP and the ratios, one
//! table per combination of the other dimensions (hand-off method, threading, normals, kernel...).

use super::export::{Export, ExportError, Exporter};
use crate::cell::{Dim, DimValue, Mode};
use crate::findings::placement::RunPlacement;
use crate::level::{self, Calibrate};
use crate::placement::Class;
use crate::results::balance::{BalanceEntry, Ratio};
use crate::results::{Cell, CellKey, CellNoise, Results};
use crate::slow_trials::{Cause, Slow, TrialRecord};
use crate::stats;
use crate::sync::{Policy, SyncMethod};
use crate::workload::{WorkTrial, WorkloadKind};
use itertools::Itertools;
use std::fmt::Write;
use strum::VariantArray;

/// Marks a cell that kept trials disturbed beyond the noise threshold.
pub const NOISY: &str = "†";

/// Marks a cell with a slow trial that nothing recorded explains.
pub const UNEXPLAINED: &str = "‡";

/// Marks a cell whose kept trials ran in more than one placement of the two cores (or moved
/// during one).
pub const MIXED: &str = "§";

/// Worst cells a warning names before it points to the full list.
const WORST_NAMED: usize = 5;

/// A table as text cells, drawn as markdown here and as HTML by `report::html`, so both show
/// the same figures.
#[derive(Clone, Debug, PartialEq)]
pub struct Table {
    /// The heading above it.
    pub title: String,
    /// Column headers.
    pub header: Vec<String>,
    /// Which columns hold numbers (right-aligned).
    pub numeric: Vec<bool>,
    /// The rows, one text per column.
    pub rows: Vec<Vec<String>>,
    /// Lines under the table.
    pub notes: Vec<String>,
}

impl Table {
    /// The table as markdown: its heading, the rows, then its notes.
    pub fn to_markdown(&self) -> String {
        let mut out = format!("### {}\n\n| {} |\n|", self.title, self.header.join(" | "));
        for &n in &self.numeric {
            out.push_str(if n { "---:|" } else { "---|" });
        }
        out.push('\n');
        for r in &self.rows {
            let _ = writeln!(out, "| {} |", r.join(" | "));
        }
        out.push('\n');
        if !self.notes.is_empty() {
            out.push_str(&self.notes.join("\n"));
            out.push_str("\n\n");
        }
        out
    }
}

/// A cell's marks: [`NOISY`] when it kept noisy trials, [`UNEXPLAINED`] when a slow trial has
/// no recorded cause, [`MIXED`] when its trials mixed placements; empty for a clean cell.
pub fn marks(c: &Cell) -> String {
    let mut out = String::new();
    if c.noisy() {
        out.push_str(NOISY);
    }
    if c.unexplained_slow_trials() > 0 {
        out.push_str(UNEXPLAINED);
    }
    if c.mixed_placements() {
        out.push_str(MIXED);
    }
    out
}

/// The run's cells in reading order: by size, then workload, then mode (serial, UP, DP); cells
/// equal in those keep the order they ran in.
pub fn reading_order(results: &Results) -> Vec<&Cell> {
    let mut cells: Vec<&Cell> = results.cells.iter().collect();
    cells.sort_by_key(|c| (c.key.size, c.key.workload, c.key.mode));
    cells
}

/// What each part of the run's cell labels means, from the values its cells carry (`w2`:
/// workload 2, ...), and which settings labels leave out; `None` for a run with no cells.
pub fn label_legend(results: &Results) -> Option<String> {
    let mut parts = Vec::new();
    let mut quiet = Vec::new();
    for &d in Dim::ALL {
        let mut seen = Vec::new();
        for v in results.cells.iter().filter_map(|c| c.key.get(d)) {
            if !seen.contains(&v) {
                seen.push(v);
            }
        }
        for v in seen {
            if Some(v) == d.quiet() {
                quiet.push(d.title(v));
            } else {
                parts.push(format!("{} = {}", d.label(v), d.title(v)));
            }
        }
    }
    if parts.is_empty() {
        return None;
    }
    let left_out = if quiet.is_empty() {
        String::new()
    } else {
        format!(
            "; a label leaves out the paper's settings: {}",
            quiet.join(", ")
        )
    };
    Some(format!(
        "Cell labels list the cell's values in this order: {}{left_out}.",
        parts.join(", ")
    ))
}

/// A cell's FPS with its spread over trials, marked [`NOISY`] when it kept noisy trials,
/// [`UNEXPLAINED`] when a slow trial has no recorded cause and [`MIXED`] when its trials mixed
/// placements; `failed` or `–` when there is none.
pub fn fps(cell: Option<&Cell>) -> String {
    match cell {
        Some(
            c @ Cell {
                summary: Some(s), ..
            },
        ) => {
            format!("{:.0} ±{:.1}%{}", s.fps, s.fps_spread.cv_percent, marks(c))
        }
        Some(Cell { error: Some(_), .. }) => "failed".into(),
        _ => "–".into(),
    }
}

/// The ratio of two cells' median trials: one slow trial does not move it, as it moves the
/// ratio of their all-frames FPS.
fn ratio(a: Option<&Cell>, b: Option<&Cell>) -> String {
    match (
        a.and_then(|c| c.summary.as_ref()),
        b.and_then(|c| c.summary.as_ref()),
    ) {
        (Some(a), Some(b)) => format!("{:.2}", a.median_trial_fps() / b.median_trial_fps()),
        _ => "–".into(),
    }
}

/// The header lines: machine, placement and workload levels.
pub fn preamble(results: &Results) -> String {
    let mut out = String::new();
    let _ = writeln!(out, "Machine: {}  ", results.machine.line());
    let _ = writeln!(out, "Source: {}  ", results.machine.provenance_line());
    if let Some((lo, hi)) = results.round_trip.changed() {
        let _ = writeln!(
            out,
            "**Placement changed mid-run**: cross-core round trip ranged {lo:.0}-{hi:.0} ns  "
        );
    }
    if let Some(line) = round_trip(results) {
        let _ = writeln!(out, "Cross-core round trip {line}  ");
    }
    if let Some(line) = placement_line(results) {
        let _ = writeln!(out, "Placement: {line}  ");
    }
    let _ = writeln!(out, "Workload levels: {}  ", levels(results));
    let calibrated = results.cells.iter().find_map(|c| c.calibration.as_ref());
    if let Some(c) = calibrated {
        let _ = writeln!(
            out,
            "Calibration: {}  ",
            match c.calibrate {
                Calibrate::Row => "step_fraction levels re-derived from the yardstick measured before every row",
                Calibrate::Once => "levels resolved once at the start; the yardstick re-measured before every row for drift",
            }
        );
    }
    for line in noise_warnings(results) {
        let _ = writeln!(out, "**Warning**: {line}  ");
    }
    let _ = writeln!(
        out,
        "Run: {} ({} cells), started {}",
        results.config.name,
        results.cells.len(),
        results.started
    );
    out
}

/// `(cores a,b): before X ns, during lo-hi ns, after Y ns`; `None` when the round trip was
/// not measured before the run (one core, or a file from before it was recorded).
pub fn round_trip(results: &Results) -> Option<String> {
    let rt = results.round_trip.before.as_ref()?;
    let during: Vec<f64> = results
        .round_trip
        .during
        .iter()
        .map(|r| r.median_ns)
        .collect();
    let during = if during.is_empty() {
        String::new()
    } else {
        let lo = during.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = during.iter().copied().fold(0.0, f64::max);
        format!(", during {lo:.0}-{hi:.0} ns")
    };
    let after = results
        .round_trip
        .after
        .as_ref()
        .map_or(String::new(), |a| format!(", after {:.0} ns", a.median_ns));
    Some(format!(
        "(cores {},{}): before {:.0} ns{during}{after}",
        rt.cores[0], rt.cores[1], rt.median_ns
    ))
}

/// Each workload level's microseconds at the start: `0: 0 µs, 1: 83 µs, ...`.
pub fn levels(results: &Results) -> String {
    results
        .calibration
        .levels
        .iter()
        .map(|l| match l.level.amount() {
            Some((unit, amount)) if unit != crate::workload::Synthetic::UNIT => {
                format!("{}: {amount} {unit}", l.workload)
            }
            _ => format!("{}: {:.0} µs", l.workload, l.micros),
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// Rows whose kind could not come down to the µs their level asked (fog whose vertex pass
/// alone outlasts the level), naming what ran instead.
fn missed_levels(results: &Results) -> Option<String> {
    let mut rows: Vec<String> = Vec::new();
    for c in &results.cells {
        let Some(cal) = &c.calibration else { continue };
        let Some(asked) = cal.asked_micros else {
            continue;
        };
        let row = format!(
            "{} (asked {asked:.0} µs, ran {:.0} µs: {})",
            c.key.row_label(),
            cal.level_micros,
            c.key
                .workload_kind
                .amount_text(&c.workload_amount().to_string(), c.workload_unit())
        );
        if !rows.contains(&row) {
            rows.push(row);
        }
    }
    (!rows.is_empty()).then(|| {
        format!(
            "{} row(s) ran more work than their level asked, the least their workload kind does on that mesh: {}; results.json keeps both (`asked_micros`, `level_micros`)",
            rows.len(),
            rows.join(", ")
        )
    })
}

/// What makes a run's figures less trustworthy: rows whose yardstick drifted since the start
/// of the sweep, rows whose level could not be met, cells that kept trials disturbed beyond the noise threshold, slow trials, and
/// cells whose trials mixed placements.
pub fn noise_warnings(results: &Results) -> Vec<String> {
    let mut out = Vec::new();
    let mut drifted: Vec<String> = Vec::new();
    let mut calibrate = None;
    for c in &results.cells {
        let Some(cal) = &c.calibration else { continue };
        calibrate = Some(cal.calibrate);
        let row = format!(
            "{} (step {:+.0}%, workload {:+.0}%)",
            c.key.row_label(),
            100.0 * cal.step_drift(),
            100.0 * cal.workload_drift()
        );
        if cal.drifted() && !drifted.contains(&row) {
            drifted.push(row);
        }
    }
    if !drifted.is_empty() {
        let what = match calibrate {
            Some(Calibrate::Once) => {
                "their levels were resolved once, at the start (--calibrate once)"
            }
            _ => "their step_fraction levels were re-derived before the row",
        };
        out.push(format!(
            "the machine drifted more than {:.0}% from the start's calibration in {} row(s): {}; {what}",
            100.0 * level::DRIFT_WARNING,
            drifted.len(),
            drifted.join(", ")
        ));
    }
    out.extend(missed_levels(results));
    let mut noisy: Vec<(&Cell, &CellNoise)> = results
        .cells
        .iter()
        .filter(|c| c.noisy())
        .filter_map(|c| Some((c, c.noise.as_ref()?)))
        .collect();
    if let Some(&(_, first)) = noisy.first() {
        let taken = |n: &CellNoise| n.preempted_percent().max(n.steal_percent());
        noisy.sort_by(|a, b| taken(b.1).total_cmp(&taken(a.1)));
        let worst: Vec<String> = noisy
            .iter()
            .take(WORST_NAMED)
            .map(|(c, n)| {
                format!(
                    "{} (off its core {:.1}%, steal {:.1}%)",
                    c.key.label(),
                    n.preempted_percent(),
                    n.steal_percent()
                )
            })
            .collect();
        let rest = if noisy.len() > WORST_NAMED {
            "; every one is listed under \"Noisy cells\" below and in results.json"
        } else {
            ""
        };
        out.push(format!(
            "{} of {} cells kept trials in which other tasks or the hypervisor took more than {}% of the wall time ({NOISY} in the tables); the worst: {}{rest}; re-run with --retry-noisy or on a quieter machine (docs/noise.md)",
            noisy.len(),
            results.cells.len(),
            first.threshold_percent,
            worst.join(", "),
        ));
    }
    if let Some(line) = slow_trial_warning(results) {
        out.push(line);
    }
    let run = RunPlacement::of(results);
    let mixed: Vec<String> = run.mixed().map(|c| c.key.label()).collect();
    if !mixed.is_empty() {
        let named: Vec<&str> = mixed.iter().take(WORST_NAMED).map(String::as_str).collect();
        let rest = if mixed.len() > WORST_NAMED {
            ", ..."
        } else {
            ""
        };
        out.push(format!(
            "{} of {} cells kept trials from more than one placement of the two cores ({MIXED} in the tables): {}{rest}; FPS per placement under \"Placement\", and --retry-noisy re-runs such cells (docs/noise.md)",
            mixed.len(),
            run.cells.len(),
            named.join(", ")
        ));
    }
    out
}

/// One line on the slow trials: how many, and how many each cause explains.
fn slow_trial_warning(results: &Results) -> Option<String> {
    let trials: Vec<&TrialRecord> = results.cells.iter().flat_map(|c| &c.trials).collect();
    let slow: Vec<&Slow> = trials.iter().filter_map(|t| t.slow.as_ref()).collect();
    if slow.is_empty() {
        return None;
    }
    let causes: Vec<String> = Cause::VARIANTS
        .iter()
        .map(|&cause| {
            (
                slow.iter().filter(|s| s.causes.contains(&cause)).count(),
                cause,
            )
        })
        .filter(|&(n, _)| n > 0)
        .map(|(n, cause)| format!("{} {n}", cause.name().replace('-', " ")))
        .collect();
    Some(format!(
        "{} of {} trials ran more than {}% below their cell's median FPS: {} ({UNEXPLAINED} in the tables where nothing explains one; \"Slow trials\" below, docs/noise.md)",
        slow.len(),
        trials.len(),
        results.config.slow_trial_percent,
        causes.join(", ")
    ))
}

/// Every slow trial with its causes and evidence, and every noisy cell when the warning named
/// only the worst.
fn slow_and_noisy(results: &Results) -> String {
    let mut out = String::new();
    if let Some(t) = slow_trials(results) {
        out.push('\n');
        out.push_str(t.to_markdown().trim_end_matches('\n'));
        out.push('\n');
    }
    let noisy = noisy_cells(results);
    if !noisy.is_empty() {
        let _ = writeln!(out, "\n### Noisy cells\n");
        for line in noisy {
            let _ = writeln!(out, "- {line}");
        }
    }
    out
}

/// Every slow trial: its cell, FPS, how far below the cell's median, its causes and their
/// evidence; `None` when no trial was slow.
pub fn slow_trials(results: &Results) -> Option<Table> {
    let slow: Vec<(&Cell, usize, &TrialRecord, &Slow)> = results
        .cells
        .iter()
        .flat_map(|c| {
            c.trials
                .iter()
                .enumerate()
                .filter_map(move |(i, t)| Some((c, i, t, t.slow.as_ref()?)))
        })
        .collect();
    if slow.is_empty() {
        return None;
    }
    let header = [
        "cell",
        "trial",
        "FPS",
        "below median",
        "causes",
        "off core / steal",
        "step ÷ median",
        "workload ÷ calibration",
        "round trip before / after",
    ];
    let ratio = |r: Option<f64>| r.map_or("–".to_string(), |r| format!("{r:.2}"));
    let rows = slow
        .into_iter()
        .map(|(c, i, t, s)| {
            let noise = c.noise.as_ref().and_then(|n| n.trials.get(i));
            let causes: Vec<&str> = s.causes.iter().map(|c| c.name()).collect();
            let taken = noise.map_or("–".to_string(), |n| {
                format!("{:.1}% / {:.1}%", n.preempted_percent(), n.steal_percent())
            });
            let trips = t
                .round_trip_ns
                .map_or("–".to_string(), |[a, b]| format!("{a:.0} / {b:.0} ns"));
            vec![
                c.key.label(),
                (i + 1).to_string(),
                format!("{:.1}", t.fps),
                format!("{:.0}%", s.below_median_percent),
                causes.join(", "),
                taken,
                ratio(t.step_ratio),
                ratio(t.workload_ratio),
                trips,
            ]
        })
        .collect();
    Some(Table {
        title: "Slow trials".into(),
        header: header.map(String::from).to_vec(),
        numeric: header.map(|h| !matches!(h, "cell" | "causes")).to_vec(),
        rows,
        notes: Vec::new(),
    })
}

/// One line per noisy cell (its trials, the most taken from it), when there are more than the
/// noise warning names; empty otherwise.
pub fn noisy_cells(results: &Results) -> Vec<String> {
    let noisy: Vec<&Cell> = results.cells.iter().filter(|c| c.noisy()).collect();
    if noisy.len() <= WORST_NAMED {
        return Vec::new();
    }
    noisy
        .iter()
        .filter_map(|c| {
            let n = c.noise.as_ref()?;
            Some(format!(
                "{}: {} of {} trials, off its core up to {:.1}%, steal up to {:.1}%",
                c.key.label(),
                n.noisy_trials(),
                n.trials.len(),
                n.preempted_percent(),
                n.steal_percent()
            ))
        })
        .collect()
}

/// How the run's round trips split, how its trials and cells fell, and whether the OS lists the
/// two cores as thread siblings; `None` when nothing was measured across two cores.
pub fn placement_line(results: &Results) -> Option<String> {
    let run = RunPlacement::of(results);
    let mut line = run.summary()?;
    if run.mixed().next().is_some() {
        line.push_str(&format!(" ({MIXED} in the tables)"));
    }
    // In a VM the guest's topology says nothing of where the host put the vCPUs.
    line.push_str(match results.round_trip.thread_siblings {
        Some(true) => "; the OS lists the two cores as thread siblings of one core (in a VM, the guest's view)",
        Some(false) => "; the OS does not list the two cores as thread siblings (in a VM, the guest's view)",
        None => "",
    });
    Some(line)
}

/// The cells that mixed placements, set trials aside for one, or ran wholly in the run's less
/// common placement, with their trials and FPS per placement; `None` in a run of one placement
/// or without such a cell.
pub fn placement_table(results: &Results) -> Option<Table> {
    let run = RunPlacement::of(results);
    if !run.split.as_ref().is_some_and(|s| s.two()) {
        return None;
    }
    let trials = run.trials();
    let count = |c: Class| trials.iter().find(|t| t.0 == c).map_or(0, |t| t.1);
    let minority = if count(Class::Far) <= count(Class::Near) {
        Class::Far
    } else {
        Class::Near
    };
    let rows: Vec<Vec<String>> = run
        .cells
        .iter()
        .filter_map(|p| {
            let cell = results.cell(&p.key)?;
            let listed = p.mixed() || !cell.set_aside.is_empty() || p.only() == Some(minority);
            if !listed {
                return None;
            }
            let n = |c: Class| p.get(c).map_or("0".into(), |t| t.trials.to_string());
            let f = |c: Class| p.get(c).map_or("–".into(), |t| format!("{:.0}", t.fps));
            Some(vec![
                p.key.label(),
                n(Class::Near),
                n(Class::Far),
                n(Class::Moved),
                f(Class::Near),
                f(Class::Far),
                cell.set_aside.len().to_string(),
            ])
        })
        .collect();
    if rows.is_empty() {
        return None;
    }
    let header = [
        "cell",
        "near trials",
        "far trials",
        "moved",
        "FPS near",
        "FPS far",
        "set aside",
    ];
    Some(Table {
        title: format!("Placement: cells that mixed placements or ran {minority}"),
        header: header.map(String::from).to_vec(),
        numeric: header.map(|h| h != "cell").to_vec(),
        rows,
        notes: vec![format!(
            "FPS per placement: the mean of the cell's kept trials in it. {MIXED} in the tables marks a cell whose kept trials mixed placements; set-aside trials ran in the other placement and were re-run (retry_noisy); docs/noise.md says what to do."
        )],
    })
}

/// The placement section: the line, the table of [`placement_table`] and the run's finding.
pub fn placement(results: &Results) -> String {
    let Some(line) = placement_line(results) else {
        return String::new();
    };
    let mut first = line.chars();
    let line: String = first
        .next()
        .map_or(String::new(), |c| c.to_uppercase().chain(first).collect());
    let mut out = format!("### Placement\n\n{line}\n\n");
    if let Some(t) = placement_table(results) {
        out.push_str(
            t.to_markdown()
                .split_once("\n\n")
                .map_or("", |(_, rest)| rest),
        );
    }
    if let Some(f) = crate::findings::placement::finding(results) {
        let _ = writeln!(out, "{}\n", f.sentence);
    }
    out
}

/// The whole markdown report.
pub fn to_string(results: &Results) -> String {
    let mut out = String::from("# oceanbench results\n\n");
    out.push_str(&crate::findings::of(results).to_markdown());
    out.push_str(&body(results));
    out
}

/// The markdown report after its findings: the run's preamble, the tables and the sections.
pub fn body(results: &Results) -> String {
    let mut out = String::from("## The run\n\n");
    out.push_str(&preamble(results));
    out.push('\n');
    out.push_str(&tables(results));
    out.push_str(&run_ahead(results));
    out.push_str(&latest(results));
    out.push_str(&waiting(results));
    out.push_str(&placement(results));
    out.push_str(&balance(results));
    for t in work_tables(results) {
        out.push_str(&t.to_markdown());
    }
    out.push_str(&slow_and_noisy(results));
    let failed: Vec<&Cell> = results.cells.iter().filter(|c| c.error.is_some()).collect();
    if !failed.is_empty() {
        out.push_str("\n## Failed cells\n\n");
        for c in failed {
            let _ = writeln!(
                out,
                "- {}: {}",
                c.key.label(),
                c.error.as_deref().unwrap_or("")
            );
        }
    }
    out
}

/// What each run-ahead depth buys in FPS and costs in latency: one row per threaded cell but its
/// depth, one column per depth, each entry the FPS and the median input-to-consume time. Empty
/// when the run measured a single depth.
pub fn run_ahead(results: &Results) -> String {
    let mut depths: Vec<usize> = results.cells.iter().filter_map(|c| c.key.depth).collect();
    depths.sort_unstable();
    depths.dedup();
    if depths.len() < 2 {
        return String::new();
    }
    let mut rows: Vec<CellKey> = Vec::new();
    for c in results.cells.iter().filter(|c| !c.key.is_serial()) {
        let row = CellKey {
            depth: Some(depths[0]),
            ..c.key.clone()
        };
        if !rows.contains(&row) {
            rows.push(row);
        }
    }
    let mut out = String::from(
        "### Run-ahead: FPS · median input-to-consume latency (ms) by depth\n\n| cell |",
    );
    for d in &depths {
        let _ = write!(out, " depth {d} |");
    }
    let _ = write!(out, "\n|---|{}\n", "---:|".repeat(depths.len()));
    for row in rows {
        let _ = write!(out, "| {} |", row.label_without(&[Dim::Depth]));
        for &d in &depths {
            let cell = results.cell(&CellKey {
                depth: Some(d),
                ..row.clone()
            });
            let latency = cell
                .and_then(|c| c.summary.as_ref())
                .and_then(|s| s.latency.as_ref())
                .map_or(String::new(), |l| {
                    format!(" · {:.2}", l.input_to_consume_ms_median)
                });
            let _ = write!(out, " {}{latency} |", fps(cell));
        }
        out.push('\n');
    }
    out.push('\n');
    out
}

/// Per workload kind that counts something each frame (spray: its particles), one table: each
/// cell's FPS, every count per frame (the mean over the trials' means, and the fewest and most
/// any frame had), the work's main-thread time per frame and the consumed meshes' age. Then per
/// kind that keeps a record of its work (fog: its volume and the time of each part of its
/// pass), one table of those values. The keys are the kind's: any kind renders.
pub fn work_tables(results: &Results) -> Vec<Table> {
    let mut kinds: Vec<WorkloadKind> = Vec::new();
    for c in &results.cells {
        if !kinds.contains(&c.key.workload_kind) {
            kinds.push(c.key.workload_kind);
        }
    }
    let mut out = Vec::new();
    for kind in kinds {
        let cells: Vec<&Cell> = results
            .cells
            .iter()
            .filter(|c| c.key.workload_kind == kind)
            .collect();
        out.extend(counts_table(kind, &cells));
        out.extend(record_table(kind, &cells));
    }
    out
}

/// A cell's trials of a counting kind (none for another kind, or a cell that failed).
fn work_trials(c: &Cell) -> &[WorkTrial] {
    c.summary.as_ref().map_or(&[], |s| &s.work_trials)
}

fn counts_table(kind: WorkloadKind, cells: &[&Cell]) -> Option<Table> {
    let keys: Vec<String> = cells
        .iter()
        .flat_map(|c| work_trials(c).iter().flat_map(|t| &t.counts))
        .map(|c| c.key.clone())
        .unique()
        .collect();
    let rows: Vec<Vec<String>> = cells
        .iter()
        .filter(|c| !work_trials(c).is_empty())
        .map(|c| {
            let t = work_trials(c);
            let mean = |f: &dyn Fn(&WorkTrial) -> Option<f64>| {
                let v: Vec<f64> = t.iter().filter_map(f).collect();
                (!v.is_empty()).then(|| stats::mean(&v))
            };
            let mut row = vec![c.key.label(), fps(Some(c))];
            for key in &keys {
                let counts: Vec<_> = t.iter().filter_map(|t| t.count(key)).collect();
                let span = match (
                    counts.iter().filter_map(|c| c.min).min(),
                    counts.iter().filter_map(|c| c.max).max(),
                ) {
                    (Some(lo), Some(hi)) => format!(" ({lo}-{hi})"),
                    _ => String::new(),
                };
                row.push(match mean(&|t| t.count(key).map(|c| c.mean)) {
                    Some(m) => format!("{m:.0}{span}"),
                    None => "–".into(),
                });
            }
            row.push(mean(&|t| Some(t.main_ms)).map_or("–".into(), |m| format!("{m:.3}")));
            row.push(
                c.summary
                    .as_ref()
                    .and_then(|s| s.latency.as_ref())
                    .map_or("–".into(), |l| format!("{:.2}", l.age_frames_mean)),
            );
            row
        })
        .collect();
    if rows.is_empty() {
        return None;
    }
    let mut header = vec!["cell".to_string(), "FPS".into()];
    header.extend(
        keys.iter()
            .map(|k| format!("{k} per frame: mean (min-max)")),
    );
    header.push(format!("{kind} ms per frame (main thread)"));
    header.push("mesh age (frames)".into());
    Some(Table {
        title: format!("Counted per frame by `{kind}`"),
        numeric: header.iter().enumerate().map(|(i, _)| i > 0).collect(),
        header,
        rows,
        notes: vec![format!(
            "The counts are the `{kind}` kind's own, after each frame's work; a range is the fewest and most any frame had."
        )],
    })
}

fn record_table(kind: WorkloadKind, cells: &[&Cell]) -> Option<Table> {
    let keys: Vec<&str> = cells
        .iter()
        .filter_map(|c| c.work.as_ref())
        .flat_map(|r| r.iter().map(|(k, _)| k))
        .unique()
        .collect();
    let rows: Vec<Vec<String>> = cells
        .iter()
        .filter_map(|c| {
            let r = c.work.as_ref()?;
            let mut row = vec![c.key.label()];
            row.extend(keys.iter().map(|k| r.get(k).map_or("–".into(), number)));
            Some(row)
        })
        .collect();
    if rows.is_empty() {
        return None;
    }
    let mut header = vec!["cell".to_string()];
    header.extend(keys.iter().map(|k| k.to_string()));
    Some(Table {
        title: format!("Recorded by `{kind}` of its work"),
        numeric: header.iter().enumerate().map(|(i, _)| i > 0).collect(),
        header,
        rows,
        notes: vec!["Each value is the median over the cell's trials.".into()],
    })
}

/// A recorded value as text: whole numbers without decimals, times to the microsecond.
fn number(v: f64) -> String {
    if v.fract() == 0.0 && v.abs() < 1e15 {
        format!("{v:.0}")
    } else {
        format!("{v:.3}")
    }
}

/// What the `latest` policy buys and what it drops: per `latest` cell, its FPS, the consumed
/// meshes' age, the helper frames dropped and the meshes taken twice per consumed frame, and
/// beside it the FPS of the `fifo` loop at depth 1 and 2 (same method where it serves `fifo`,
/// else `atomic`). Empty when the run has no `latest` cell.
pub fn latest(results: &Results) -> String {
    let cells: Vec<&Cell> = results
        .cells
        .iter()
        .filter(|c| c.key.policy == Some(Policy::Latest))
        .collect();
    if cells.is_empty() {
        return String::new();
    }
    let mut out = String::from(
        "### Latest mesh (mailbox) beside FIFO\n\n\
         | cell | FPS | age ms p50 · p99 | dropped per frame | taken twice | FIFO depth 1 | FIFO depth 2 |\n\
         |---|---:|---:|---:|---:|---:|---:|\n",
    );
    for c in cells {
        let fifo = |depth: usize| {
            let sync = c.key.sync.filter(|s| s.serves(Policy::Fifo));
            results.cell(&CellKey {
                policy: Some(Policy::Fifo),
                sync: Some(sync.unwrap_or(SyncMethod::Atomic)),
                depth: Some(depth),
                ..c.key.clone()
            })
        };
        let s = c.summary.as_ref();
        let age = s.and_then(|s| s.latency.as_ref()).map_or("–".into(), |l| {
            format!("{:.2} · {:.2}", l.age_ms_median, l.age_ms_p99)
        });
        let (dropped, twice) = s
            .and_then(|s| s.mailbox.as_ref().map(|m| (m, s.frames.max(1) as f64)))
            .map_or(("–".into(), "–".into()), |(m, frames)| {
                (
                    format!("{:.2}", m.dropped as f64 / frames),
                    format!("{:.1}%", 100.0 * m.repeated as f64 / frames),
                )
            });
        let _ = writeln!(
            out,
            "| {} | {} | {age} | {dropped} | {twice} | {} | {} |",
            c.key.label(),
            fps(Some(c)),
            fps(fifo(1)),
            fps(fifo(2)),
        );
    }
    out.push('\n');
    out
}

/// What waiting costs: per threaded cell, each side's wait per frame on the wall clock and on
/// its CPU clock. A method that waits by burning the CPU shows equal columns; one that sleeps,
/// a CPU column near zero. Empty for results from before the CPU was recorded.
pub fn waiting(results: &Results) -> String {
    let cells: Vec<&Cell> = results
        .cells
        .iter()
        .filter(|c| !c.key.is_serial())
        .filter(|c| {
            c.summary
                .as_ref()
                .is_some_and(|s| !s.wait_cpu_ms_trials.is_empty())
        })
        .collect();
    if cells.is_empty() {
        return String::new();
    }
    let mut out = String::from(
        "### Waiting per frame, wall and CPU (ms)\n\n\
         | cell | main waits | main CPU | helper waits | helper CPU |\n\
         |---|---:|---:|---:|---:|\n",
    );
    for c in cells {
        let b = &c.summary.as_ref().expect("filtered on a summary").breakdown;
        let _ = writeln!(
            out,
            "| {} | {:.3} | {:.3} | {:.3} | {:.3} |",
            c.key.label(),
            b.wait_ms,
            b.wait_cpu_ms,
            b.helper_wait_ms,
            b.helper_wait_cpu_ms
        );
    }
    out.push('\n');
    out
}

/// The balance points: per searched cell, the helper's step S, the balance workload with its
/// bracket, DP ÷ serial and DP ÷ UP there with their 95% intervals, the overhead above
/// max(W, S), and where the run's workload levels fall against S. Empty when none was searched.
pub fn balance(results: &Results) -> String {
    balance_table(results).map_or(String::new(), |t| t.to_markdown())
}

/// The table of [`balance`]; `None` when no balance point was searched.
pub fn balance_table(results: &Results) -> Option<Table> {
    if results.balance.is_empty() && results.balance_failures.is_empty() {
        return None;
    }
    let header = [
        "cell",
        "step S (µs)",
        "balance W (µs)",
        "W ÷ S",
        "DP ÷ serial",
        "DP ÷ UP",
        "overhead",
        "levels ÷ S",
        "placement",
    ];
    let interval =
        |v: Option<f64>, lo: Option<f64>, hi: Option<f64>, digits: usize| match (v, lo, hi) {
            (Some(v), Some(lo), Some(hi)) => format!("{v:.digits$} [{lo:.digits$}, {hi:.digits$}]"),
            _ => "–".into(),
        };
    let ratio = |r: Option<Ratio>| {
        r.map_or("–".into(), |r| {
            format!("{:.2} [{:.2}, {:.2}]", r.value, r.low, r.high)
        })
    };
    let split = results.placement.as_ref();
    let mut rows = Vec::new();
    let mut notes = Vec::new();
    for e in &results.balance {
        let levels: Vec<String> = results
            .calibration
            .levels
            .iter()
            .filter(|l| l.micros > 0.0)
            .map(|l| format!("w{} {:.2}", l.workload, l.micros / e.step_us))
            .collect();
        let label = e.key.label_without(&[Dim::Workload]);
        let step = e.headline().and_then(|p| p.step_us).unwrap_or(e.step_us);
        rows.push(vec![
            label.clone(),
            format!("{step:.0}"),
            match e.balance_amount() {
                Some((amount, unit)) => format!(
                    "{} = {amount} {unit} at {:.1} ns each",
                    interval(e.balance_us, e.balance_us_low, e.balance_us_high, 0),
                    e.unit_cost.as_ref().map_or(f64::NAN, |c| c.ns)
                ),
                None => interval(e.balance_us, e.balance_us_low, e.balance_us_high, 0),
            },
            e.fraction().map_or("–".into(), |f| format!("{f:.2}")),
            interval(
                e.dp_over_serial,
                e.dp_over_serial_low,
                e.dp_over_serial_high,
                2,
            ),
            ratio(e.dp_over_up),
            e.overhead_percent
                .map_or("–".into(), |o| format!("{o:+.1}%")),
            levels.join(", "),
            balance_placement(e, split),
        ]);
        // Each other placement's own figures, from its probes alone.
        for p in e
            .placements
            .iter()
            .filter(|p| Some(p.placement) != e.placement)
        {
            rows.push(vec![
                format!("{label} ({} probes)", p.placement),
                p.step_us.map_or("–".into(), |s| format!("{s:.0}")),
                interval(p.balance_us, p.balance_us_low, p.balance_us_high, 0),
                p.fraction().map_or("–".into(), |f| format!("{f:.2}")),
                ratio(p.dp_over_serial),
                ratio(p.dp_over_up),
                "–".into(),
                String::new(),
                format!(
                    "{} {:.0}-{:.0} ns, {} probe(s)",
                    p.placement, p.round_trip_ns[0], p.round_trip_ns[1], p.probes
                ),
            ]);
        }
        if let Some(n) = &e.note {
            notes.push(format!("- {label}: {n}"));
        }
    }
    notes.extend(
        results
            .balance_failures
            .iter()
            .map(|f| format!("- no balance point: {f}")),
    );
    if results.balance.iter().any(|e| !e.placements.is_empty()) {
        notes.push("S is the helper's step timed in the probes of the same placement as W (nearest the balance point); a search whose probes mixed placements gives its headline from one placement's probes and each other placement's on its own row.".into());
    }
    Some(Table {
        title: "Balance points".into(),
        header: header.map(String::from).to_vec(),
        numeric: header
            .map(|h| !matches!(h, "cell" | "levels ÷ S" | "placement"))
            .to_vec(),
        rows,
        notes,
    })
}

/// Where a search's probes ran: its headline placement with the round trips around its probes
/// and the probes set aside; for a file from before schema 6, its round trips before and after
/// the search, each placed against the run's split.
fn balance_placement(e: &BalanceEntry, split: Option<&crate::placement::Split>) -> String {
    if let Some(head) = e.headline() {
        let aside = if e.set_aside > 0 {
            format!(", {} of {} probes set aside", e.set_aside, e.probes.len())
        } else {
            String::new()
        };
        return format!(
            "{} {:.0}-{:.0} ns{aside}",
            head.placement, head.round_trip_ns[0], head.round_trip_ns[1]
        );
    }
    e.round_trip_ns
        .iter()
        .map(|&ns| match split.and_then(|s| s.class(ns)) {
            Some(c) => format!("{c} {ns:.0} ns"),
            None => format!("{ns:.0} ns"),
        })
        .collect::<Vec<_>>()
        .join(" → ")
}

/// How the tables' FPS and ratios are computed.
const RATIO_NOTE: &str = "FPS: all frames ÷ all seconds over the trials, ± the trials' coefficient of variation; DP÷UP and DP÷serial: ratios of the cells' median trials.";

/// The dimensions every table lays out: rows are size × workload, columns the modes.
const TABLE_DIMS: [Dim; 3] = [Dim::Size, Dim::Workload, Dim::Mode];

/// One Figure 5-1 table per combination of the other dimensions found among threaded cells; the
/// serial column comes from the serial cell of the same row.
pub fn tables(results: &Results) -> String {
    fps_tables(results).iter().map(Table::to_markdown).collect()
}

/// The tables of [`tables`].
pub fn fps_tables(results: &Results) -> Vec<Table> {
    fps_tables_of(results).into_iter().map(|(_, t)| t).collect()
}

/// The tables of [`tables`], each with the slice it lays out ([`crate::findings::Slice`]).
pub fn fps_tables_of(results: &Results) -> Vec<(crate::findings::Slice, Table)> {
    let slice_dims = crate::findings::slice_dims(results);
    // A group is a key with the table's own dimensions set to placeholders.
    let group_of = |key: &CellKey| -> CellKey {
        let mut g = key.clone();
        g.size = 0;
        g.workload = 0;
        if !g.is_serial() {
            g.mode = Mode::Up;
        }
        g
    };
    let mut groups: Vec<CellKey> = Vec::new();
    for c in results.cells.iter().filter(|c| !c.key.is_serial()) {
        let g = group_of(&c.key);
        if !groups.contains(&g) {
            groups.push(g);
        }
    }
    // A serial-only run still gets one table.
    if groups.is_empty() {
        if let Some(c) = results.cells.first() {
            groups.push(group_of(&c.key));
        }
    }
    let mut rows: Vec<(usize, usize)> = Vec::new();
    for c in &results.cells {
        if !rows.contains(&(c.key.size, c.key.workload)) {
            rows.push((c.key.size, c.key.workload));
        }
    }
    let header = [
        "mesh",
        "workload",
        "serial",
        "UP",
        "DP",
        "DP÷UP",
        "DP÷serial",
    ];
    groups
        .into_iter()
        .map(|g| {
            let heading: Vec<String> = Dim::ALL
                .iter()
                .filter(|d| !TABLE_DIMS.contains(d))
                .filter_map(|&d| {
                    let v = g.get(d)?;
                    (Some(v) != d.quiet()).then(|| d.title(v))
                })
                .collect();
            let rows = rows
                .iter()
                .map(|&(size, workload)| {
                    let find = |mode: Mode| {
                        let key = CellKey {
                            size,
                            workload,
                            ..g.clone()
                        }
                        .with(Dim::Mode, mode.value())?;
                        results.cell(&key)
                    };
                    let (s, u, d) = (find(Mode::Serial), find(Mode::Up), find(Mode::Dp));
                    vec![
                        format!("{size}×{size}"),
                        workload.to_string(),
                        fps(s),
                        fps(u),
                        fps(d),
                        ratio(d, u),
                        ratio(d, s),
                    ]
                })
                .collect();
            let table = Table {
                title: format!("FPS, {}", heading.join(", ")),
                header: header.map(String::from).to_vec(),
                numeric: header.map(|h| h != "mesh").to_vec(),
                rows,
                notes: vec![RATIO_NOTE.into()],
            };
            (crate::findings::Slice::of(&slice_dims, &g), table)
        })
        .collect()
}

/// The markdown format: `results.md`, the Figure 5-1 tables and everything beside them.
pub struct Markdown;

impl Exporter for Markdown {
    fn export(&self, results: &Results) -> Result<Vec<Export>, ExportError> {
        Ok(vec![Export {
            name: "results.md",
            text: to_string(results),
        }])
    }
}
