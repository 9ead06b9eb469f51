//! `grid` blocks: a table of one stat of many cells, a row per value of what varies (a hand-off
//! method, a kind) and a column per cell template, under the run's source line.
//!
//! `<!-- ob:grid run=R head=method rows="atomic;adaptive (old)=adaptive" cols="40×40 UP=40 w0 up {} pool@frame_us;..." -->`
//! - `rows`: `;`-separated row values, each `LABEL=VALUE` or just `VALUE`;
//! - `cols`: `;`-separated `HEADER=TEMPLATE@STAT`, where `{}` in the cell label template is the
//!   row's value and STAT any `value` stat (`@STAT/DIGITS` sets the digits);
//! - `gaps=yes` writes `–` where a row has no such cell or the stat does not apply to it
//!   (otherwise that is a bad block); a column with no number at all is still one.

use super::blocks::Block;
use super::{source, tree_unknown, value_text, BlockError};
use crate::results::Results;
use std::fmt::Write;

/// The grid's markdown: its source line, then the table.
pub fn render(results: &Results, block: &Block, link: &str) -> Result<String, BlockError> {
    let rows = block.attr("rows").ok_or("`grid` needs rows=\"A;B;...\"")?;
    let cols = block
        .attr("cols")
        .ok_or("`grid` needs cols=\"HEADER=TEMPLATE@STAT;...\"")?;
    let gaps = match block.attr("gaps") {
        None | Some("no") => false,
        Some("yes") => true,
        Some(other) => return Err(format!("gaps: `{other}` is not yes or no")),
    };
    let rows: Vec<(&str, &str)> = rows
        .split(';')
        .map(str::trim)
        .map(|r| r.rsplit_once('=').unwrap_or((r, r)))
        .collect();
    let cols = cols
        .split(';')
        .map(|c| column(c.trim()))
        .collect::<Result<Vec<_>, _>>()?;
    let mut out = source(results, link);
    out.push('\n');
    let _ = write!(out, "| {} |", block.attr("head").unwrap_or(""));
    for c in &cols {
        let _ = write!(out, " {} |", c.header);
    }
    out.push_str("\n|---|");
    out.push_str(&"---:|".repeat(cols.len()));
    out.push('\n');
    let mut bare = false;
    let mut filled = vec![false; cols.len()];
    for (label, value) in &rows {
        let _ = write!(out, "| {label} |");
        for (c, filled) in cols.iter().zip(filled.iter_mut()) {
            let mut attrs = vec![
                ("cell".to_string(), c.template.replace("{}", value)),
                ("stat".to_string(), c.stat.to_string()),
            ];
            if let Some(d) = c.digits {
                attrs.push(("digits".into(), d.to_string()));
            }
            let cell = Block {
                attrs,
                ..block.clone()
            };
            match value_text(results, &cell) {
                Ok((text, no_trials)) => {
                    bare |= no_trials;
                    *filled = true;
                    let _ = write!(out, " {text} |");
                }
                Err(_) if gaps => out.push_str(" – |"),
                Err(e) => return Err(format!("row `{label}`, column `{}`: {e}", c.header)),
            }
        }
        out.push('\n');
    }
    // A column of gaps is a template that matches nothing: a typo, not a gap.
    if let Some(c) = cols.iter().zip(&filled).find(|(_, f)| !**f).map(|(c, _)| c) {
        return Err(format!(
            "column `{}`: no row has a cell `{}` with stat {}",
            c.header, c.template, c.stat
        ));
    }
    let notes: Vec<&str> = [tree_unknown(results), bare.then_some("no trial records")]
        .into_iter()
        .flatten()
        .collect();
    if !notes.is_empty() {
        let _ = writeln!(out, "\nEvery number in this table: {}.", notes.join("; "));
    }
    Ok(out)
}

struct Column<'a> {
    header: &'a str,
    template: &'a str,
    stat: &'a str,
    digits: Option<&'a str>,
}

fn column(text: &str) -> Result<Column<'_>, BlockError> {
    let (header, rest) = text
        .split_once('=')
        .ok_or_else(|| format!("cols: `{text}` is not HEADER=TEMPLATE@STAT"))?;
    let (template, stat) = rest
        .rsplit_once('@')
        .ok_or_else(|| format!("cols: `{text}` names no @STAT"))?;
    if !template.contains("{}") {
        return Err(format!(
            "cols: `{template}` has no {{}} for the row's value"
        ));
    }
    let (stat, digits) = match stat.split_once('/') {
        Some((s, d)) => (s, Some(d)),
        None => (stat, None),
    };
    Ok(Column {
        header: header.trim(),
        template: template.trim(),
        stat: stat.trim(),
        digits,
    })
}
