//! A comparison's verdicts as users read them: the terminal's text, markdown (CI job summaries,
//! pull-request comments) and JSON, each a table of verdict, change, interval and both means
//! with the notes under it. What the verdicts are is [`super::analysis::compare`]'s.

use super::analysis::compare::{Change, Comparison, Metric, Verdict, LEVEL_MISMATCH, MIN_TRIALS};
use super::markdown::MIXED;
use std::fmt::Write;

/// Marks a verdict that rests on trials disturbed beyond their noise threshold, or on a slow
/// trial nothing recorded explains.
const NOISY: &str = "†";

/// The footnote of [`NOISY`].
const NOISY_NOTE: &str = "† rests on trials in which other tasks or the hypervisor took more than the noise threshold, or on a slow trial nothing recorded explains: re-run before trusting it";

/// Marks a verdict whose two cells' workload came to other microseconds.
const OTHER_LEVEL: &str = "¶";

/// The footnote of [`MIXED`].
const MIXED_NOTE: &str = "§ rests on a cell whose trials ran in more than one placement of the two cores, or compares cells that ran in different placements (round trips over 2× apart): compare within one placement (`compare --placement near`, docs/noise.md)";

impl Comparison {
    /// "N improved, M regressed, K within noise (threshold T%)", then the below-threshold and
    /// too-few-trials counts when there are any.
    pub fn summary_line(&self) -> String {
        let mut line = format!(
            "{} improved, {} regressed, {} within noise",
            self.count(Verdict::Improved),
            self.count(Verdict::Regressed),
            self.count(Verdict::WithinNoise),
        );
        for v in [Verdict::BelowThreshold, Verdict::TooFewTrials] {
            let n = self.count(v);
            if n > 0 {
                let _ = write!(line, ", {n} {}", v.words());
            }
        }
        let _ = write!(line, " (threshold {}%)", self.threshold_pct.abs());
        line
    }

    /// Why the comparison compared nothing, when it did not: a verdict of "nothing regressed"
    /// over no pairs would pass CI vacuously.
    pub fn nothing_compared(&self) -> Option<String> {
        if !self.changes.is_empty() {
            return None;
        }
        let base = self.only_in_base.len();
        let new = self.only_in_new.len();
        Some(if self.failed.is_empty() {
            format!(
                "compare: no cell matched between the two runs ({base} only in the first, {new} only in the second): they measured different cells"
            )
        } else {
            format!(
                "compare: no pair of cells could be compared ({} failed or unmeasured, e.g. {})",
                self.failed.len(),
                self.failed[0]
            )
        })
    }

    fn headers(&self) -> [String; 2] {
        let unit = self.metric.unit();
        if self.by.is_some() {
            [format!("Baseline {unit}"), format!("Other {unit}")]
        } else {
            [format!("Base {unit}"), format!("New {unit}")]
        }
    }

    /// The note under a table with too-few-trials rows: why they have no verdict.
    fn too_few_note(&self) -> Option<String> {
        let few: Vec<&Change> = self
            .changes
            .iter()
            .filter(|c| c.verdict == Verdict::TooFewTrials)
            .collect();
        let first = few.first()?;
        Some(format!(
            "too few trials: {} pair(s) with fewer than {MIN_TRIALS} trials on a side (e.g. n = {} vs {}) show the point estimate and its interval but get no verdict and never fail",
            few.len(),
            first.base_trials,
            first.new_trials
        ))
    }

    /// The column headers of every format's table: verdict, change, interval, both means, cell.
    pub fn header(&self) -> [String; 6] {
        let [base, new] = self.headers();
        [
            "Verdict".to_string(),
            "Change".into(),
            "95% CI".into(),
            base,
            new,
            "Cell".into(),
        ]
    }

    /// Every change as a row under [`Comparison::header`], in the comparison's order.
    pub fn table_rows(&self) -> Vec<[String; 6]> {
        let all: Vec<&Change> = self.changes.iter().collect();
        self.rows(&all, "")
    }

    /// The notes under a table: what the marks `*`, `†` and `§` mean and why some rows have no
    /// verdict, each only when a row needs it.
    pub fn footnotes(&self) -> Vec<String> {
        let mut out = Vec::new();
        if self.changes.iter().any(|c| c.single_trial) {
            out.push("* one trial on a side: no interval, point estimate only".to_string());
        }
        out.extend(self.too_few_note());
        if self.changes.iter().any(|c| c.noisy) {
            out.push(NOISY_NOTE.to_string());
        }
        if self.changes.iter().any(|c| c.placement) {
            out.push(MIXED_NOTE.to_string());
        }
        if self.changes.iter().any(|c| c.level) {
            out.push(format!(
                "{OTHER_LEVEL} compares cells whose workload came to microseconds over {:.0}% apart (each row resolves its level from its own yardstick): the change is the level's as much as the code's; compare with `calibrate: once`, or levels in µs",
                LEVEL_MISMATCH * 100.0
            ));
        }
        out
    }

    /// `blank` pads unmarked intervals so that right-aligned text columns stay aligned.
    fn rows(&self, changes: &[&Change], blank: &str) -> Vec<[String; 6]> {
        changes
            .iter()
            .map(|c| {
                let mark = if c.single_trial { "*" } else { blank };
                let label = match &c.versus {
                    Some(v) => format!("{}: {v}", c.label),
                    None => c.label.clone(),
                };
                let noisy = if c.noisy { NOISY } else { "" };
                let mixed = if c.placement { MIXED } else { "" };
                let level = if c.level { OTHER_LEVEL } else { "" };
                [
                    format!("{}{noisy}{mixed}{level}", c.verdict.words()),
                    pct(c.change_pct),
                    format!("[{}, {}]{mark}", pct(c.ci_low_pct), pct(c.ci_high_pct)),
                    value(self.metric, c.base),
                    value(self.metric, c.new),
                    label,
                ]
            })
            .collect()
    }

    fn title(&self) -> String {
        match (&self.by, &self.baseline) {
            (Some(by), Some(b)) => format!("{} by {by} against {b}", self.metric.unit()),
            _ => format!("{}, new against base", self.metric.unit()),
        }
    }

    /// Aligned columns for a terminal.
    pub fn to_text(&self) -> String {
        let mut out = String::new();
        let _ = writeln!(out, "{}: {}", self.title(), self.summary_line());
        for w in &self.warnings {
            let _ = writeln!(out, "warning: {w}");
        }
        let header = self.header();
        let all: Vec<&Change> = self.changes.iter().collect();
        let rows = self.rows(&all, " ");
        if !rows.is_empty() {
            let mut widths = header.clone().map(|h| h.chars().count());
            for r in &rows {
                for (w, v) in widths.iter_mut().zip(r) {
                    *w = (*w).max(v.chars().count());
                }
            }
            // Numbers right-aligned so magnitudes line up; words left-aligned.
            let right = [false, true, true, true, true, false];
            for r in std::iter::once(&header).chain(&rows) {
                let cols: Vec<String> = r
                    .iter()
                    .zip(widths)
                    .zip(right)
                    .map(|((v, w), right)| {
                        let pad = " ".repeat(w - v.chars().count());
                        if right {
                            format!("{pad}{v}")
                        } else {
                            format!("{v}{pad}")
                        }
                    })
                    .collect();
                let _ = writeln!(out, "{}", cols.join("  ").trim_end());
            }
        }
        for note in self.footnotes() {
            let _ = writeln!(out, "{note}");
        }
        for (title, list) in self.unmatched() {
            let _ = writeln!(out, "{title} ({}):", list.len());
            for l in list {
                let _ = writeln!(out, "  {l}");
            }
        }
        if !self.balance.is_empty() {
            let _ = writeln!(out, "Balance points (new against base):");
            for b in &self.balance {
                let _ = writeln!(out, "  {}", b.line());
            }
        }
        out
    }

    /// A table to paste into a pull-request comment; within-noise rows folded away.
    pub fn to_markdown(&self) -> String {
        let mut out = String::new();
        let _ = writeln!(out, "**{}**: {}\n", self.title(), self.summary_line());
        for w in &self.warnings {
            let _ = writeln!(out, "**Warning**: {w}\n");
        }
        let (notable, quiet): (Vec<&Change>, Vec<&Change>) = self.changes.iter().partition(|c| {
            matches!(
                c.verdict,
                Verdict::Improved | Verdict::Regressed | Verdict::BelowThreshold
            )
        });
        let [base, new] = self.headers();
        let table = |out: &mut String, changes: &[&Change]| {
            let _ = writeln!(
                out,
                "| Verdict | Change | 95% CI | {base} | {new} | Cell |\n|---|--:|--:|--:|--:|---|"
            );
            for r in self.rows(changes, "") {
                let r = r.map(|v| v.replace('|', "\\|"));
                let _ = writeln!(out, "| {} |", r.join(" | "));
            }
        };
        if !notable.is_empty() {
            table(&mut out, &notable);
            out.push('\n');
        }
        if !quiet.is_empty() {
            let _ = writeln!(
                out,
                "<details><summary>{} within noise or with too few trials</summary>\n",
                quiet.len()
            );
            table(&mut out, &quiet);
            let _ = writeln!(out, "\n</details>\n");
        }
        for note in self.footnotes() {
            // A leading `*` would start a markdown list.
            let note = note
                .strip_prefix('*')
                .map_or(note.clone(), |n| format!("\\*{n}"));
            let _ = writeln!(out, "{note}\n");
        }
        for (title, list) in self.unmatched() {
            let items: String = list.iter().map(|l| format!("- `{l}`\n")).collect();
            let _ = writeln!(out, "**{title}** ({}):\n\n{items}", list.len());
        }
        if !self.balance.is_empty() {
            let items: String = self
                .balance
                .iter()
                .map(|b| format!("- {}\n", b.line()))
                .collect();
            let _ = writeln!(out, "**Balance points** (new against base):\n\n{items}");
        }
        out
    }

    /// The comparison as pretty JSON.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("a comparison always serialises")
    }
}

/// A signed percentage; what rounds to zero shows as +0.0%, since "-0.0%" reads as a loss.
fn pct(v: f64) -> String {
    let v = if (v * 10.0).round() == 0.0 { 0.0 } else { v };
    format!("{v:+.1}%")
}

/// A value of `metric` as the tables show it.
fn value(metric: Metric, v: f64) -> String {
    match metric {
        Metric::Fps => format!("{v:.1}"),
        Metric::WaitCpu => format!("{v:.4}"),
        Metric::RoundTrip => format!("{v:.0}"),
    }
}
