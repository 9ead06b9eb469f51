//! Outputs drawn from results files alone: JSON (the file itself), a tidy CSV, the Figure 5-1
//! markdown table, the charts, the comparisons and the HTML page. The three tables are rewritten whole,
//! atomically, after every finished row of cells.

pub mod chart;
pub mod compare;
pub mod csv;
pub mod html;
pub mod json;
pub mod markdown;
pub mod shift;

use crate::results::Results;
use std::path::{Path, PathBuf};

/// A results file that could not be written, named.
#[derive(Debug, thiserror::Error)]
#[error("{}: {source}", path.display())]
pub struct WriteError {
    /// The file.
    pub path: PathBuf,
    /// What went wrong.
    pub source: std::io::Error,
}

/// Writes `results.json`, `findings.json`, `results.csv`, `trials.csv` and `results.md` into `dir` (and
/// `balance.csv` and `balance-probes.csv` when there are balance points, and
/// `balance-placements.csv` when their probes were placed), each atomically.
pub fn write_all(dir: &Path, results: &Results) -> Result<(), WriteError> {
    let failed = |name: &str| {
        let path = dir.join(name);
        move |source| WriteError { path, source }
    };
    let from_csv = |name: &str, text: Result<String, csv::CsvError>| {
        text.map_err(|e| failed(name)(std::io::Error::other(e)))
    };
    let mut files = vec![
        (
            "results.json",
            json::to_string(results).map_err(failed("results.json"))?,
        ),
        ("results.md", markdown::to_string(results)),
        (
            "findings.json",
            crate::findings::of(results)
                .to_json()
                .map_err(|e| failed("findings.json")(e.into()))?,
        ),
    ];
    if !results.cells.is_empty() {
        files.push((
            "results.csv",
            from_csv("results.csv", csv::to_string(results))?,
        ));
    }
    if results.cells.iter().any(|c| !c.trials.is_empty()) {
        files.push(("trials.csv", from_csv("trials.csv", csv::trials(results))?));
    }
    if !results.balance.is_empty() {
        files.push((
            "balance.csv",
            from_csv("balance.csv", csv::balance(results))?,
        ));
        let probes = csv::balance_probes(results);
        files.push((
            "balance-probes.csv",
            from_csv("balance-probes.csv", probes)?,
        ));
        if results.balance.iter().any(|e| !e.placements.is_empty()) {
            let placements = csv::balance_placements(results);
            files.push((
                "balance-placements.csv",
                from_csv("balance-placements.csv", placements)?,
            ));
        }
    }
    for (name, text) in files {
        json::write_atomic(&dir.join(name), text.as_bytes()).map_err(failed(name))?;
    }
    Ok(())
}
