//! `bench` blocks: a benchmark run's estimates (`results/bench-<name>-<UTC>/bench.json`) as a
//! table, one estimate, or the ratio of two.

use super::{qualified, Block, BlockError};
use crate::bench_run::{BenchEstimate, BenchRun, Throughput};
use crate::machine::Tree;
use std::fmt::Write;
use std::path::Path;

/// A time in ns as docs write it: ms, µs or ns with three significant figures.
fn time(ns: f64) -> String {
    let (v, unit) = if ns >= 1e6 {
        (ns / 1e6, "ms")
    } else if ns >= 1e3 {
        (ns / 1e3, "µs")
    } else {
        (ns, "ns")
    };
    let digits = if v >= 100.0 {
        0
    } else if v >= 10.0 {
        1
    } else {
        2
    };
    format!("{v:.digits$} {unit}")
}

fn number(e: &BenchEstimate, v: f64) -> String {
    if e.unit == "ns" {
        time(v)
    } else {
        format!("{v:.1} {}", e.unit)
    }
}

/// Elements or bytes per second at the estimate's median, in millions.
fn rate(e: &BenchEstimate) -> String {
    if e.unit != "ns" {
        return String::new();
    }
    match e.throughput {
        Some(Throughput::Elements(n)) => {
            let m = n as f64 / e.value * 1e3;
            // Three significant figures, so a slow step's rate is not rounded to nothing.
            let digits = if m >= 100.0 {
                0
            } else if m >= 10.0 {
                1
            } else if m >= 1.0 {
                2
            } else {
                3
            };
            format!("{m:.digits$} M/s")
        }
        Some(Throughput::Bytes(n)) => format!("{:.2} GB/s", n as f64 / e.value),
        None => String::new(),
    }
}

/// Renders a `bench` block: `run=bench-...` with `id=ID` (one estimate), `id=ID per=element`
/// (its time per element of its throughput), `id=ID over=ID` (their ratio), or
/// `ids=PREFIX,...` (a table of the estimates whose ids start with a prefix; all when absent).
pub fn render(root: &Path, block: &Block, link: &str) -> Result<String, BlockError> {
    let name = super::run_name(block)?;
    let path = root.join("results").join(name);
    if !path.join(crate::bench_run::FILE_NAME).is_file() {
        return Err(format!(
            "run `{name}` does not exist (no results/{name}/{})",
            crate::bench_run::FILE_NAME
        ));
    }
    let run = BenchRun::load(&path).map_err(|e| e.to_string())?;
    let unknown = match run.machine.tree() {
        Tree::Dirty { diff_hash } => {
            return Err(format!(
                "run `{name}` was made from a dirty tree (uncommitted changes, diff {diff_hash}): re-run it from a commit"
            ))
        }
        Tree::Unknown => Some("tree unknown"),
        Tree::Clean => None,
    };
    let find = |id: &str| -> Result<&BenchEstimate, BlockError> {
        run.estimate(id).ok_or_else(|| {
            format!(
                "bench run `{name}` has no estimate `{id}` (its ids look like `{}`)",
                run.estimates.first().map(|e| e.id.as_str()).unwrap_or("")
            )
        })
    };
    if let Some(id) = block.attr("id") {
        let e = find(id)?;
        let text = match (block.attr("over"), block.attr("per")) {
            (Some(_), Some(_)) => return Err("per= and over= do not go together".into()),
            (None, Some("element")) => match e.throughput {
                Some(Throughput::Elements(n)) if e.unit == "ns" && n > 0 => {
                    time(e.value / n as f64)
                }
                _ => {
                    return Err(format!(
                        "per=element: `{id}` is no time with a throughput in elements"
                    ))
                }
            },
            (None, Some(other)) => {
                return Err(format!("per={other}: the allowed value is `element`"))
            }
            (Some(other), None) => {
                let o = find(other)?;
                if o.unit != e.unit {
                    return Err(format!(
                        "`{id}` is in {} and `{other}` in {}",
                        e.unit, o.unit
                    ));
                }
                format!("{:.2}", e.value / o.value)
            }
            (None, None) => number(e, e.value),
        };
        return Ok(qualified(text, &[unknown]));
    }
    for needs_id in ["over", "per"] {
        if block.attr(needs_id).is_some() {
            return Err(format!("{needs_id}= needs id="));
        }
    }
    let prefixes: Vec<&str> = block
        .attr("ids")
        .map_or(vec![""], |p| p.split(',').map(str::trim).collect());
    let chosen: Vec<&BenchEstimate> = run
        .estimates
        .iter()
        .filter(|e| prefixes.iter().any(|p| e.id.starts_with(p)))
        .collect();
    if chosen.is_empty() {
        return Err(format!(
            "ids: no estimate of `{name}` starts with {prefixes:?}"
        ));
    }
    let m = &run.machine;
    let mut out = format!(
        "Bench run [`{name}`]({link}) (`{}`): {}, {} logical cores, {}; {}. {}\n\n",
        run.command.join(" "),
        m.cpu_model,
        m.logical_cores,
        m.os,
        m.provenance_line(),
        run.source
    );
    out.push_str("| benchmark | estimate | interval | rate |\n|---|---:|---:|---:|\n");
    for e in chosen {
        let _ = writeln!(
            out,
            "| {} | {} | {}-{} | {} |",
            e.id,
            number(e, e.value),
            number(e, e.lower),
            number(e, e.upper),
            rate(e)
        );
    }
    Ok(out)
}
