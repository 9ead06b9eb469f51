//! Outputs drawn from results files alone: JSON (the file itself), a tidy CSV, the Figure 5-1
//! markdown table, the charts, the comparisons and the HTML page. The three tables are rewritten whole,
//! atomically, after every finished row of cells.

pub mod analysis;
pub mod chart;
pub mod ci;
pub mod csv;
pub mod export;
pub mod html;
pub mod json;
pub mod markdown;
pub mod verdicts;

pub use analysis::{compare, shift};

use crate::results::Results;
use std::path::{Path, PathBuf};

/// Every format a run's folder holds, in the order its files are written.
pub const EXPORTERS: [&dyn export::Exporter; 3] = [&json::Json, &markdown::Markdown, &csv::Csv];

/// A results file that could not be written, named.
#[derive(Debug, thiserror::Error)]
#[error("{}: {source}", path.display())]
pub struct WriteError {
    /// The file.
    pub path: PathBuf,
    /// What went wrong.
    pub source: std::io::Error,
}

/// Writes every format's files ([`EXPORTERS`]) into `dir`, each atomically: today
/// `results.json`, `findings.json`, `results.md`, `results.csv`, `trials.csv`, and with balance
/// points `balance.csv`, `balance-probes.csv` and `balance-placements.csv`. Every file is built
/// before the first is written, so a format that fails leaves the folder as it was.
pub fn write_all(dir: &Path, results: &Results) -> Result<(), WriteError> {
    let mut files = Vec::new();
    for exporter in EXPORTERS {
        files.extend(exporter.export(results).map_err(|e| WriteError {
            path: dir.join(e.name),
            source: std::io::Error::other(e.message),
        })?);
    }
    for file in files {
        let path = dir.join(file.name);
        json::write_atomic(&path, file.text.as_bytes())
            .map_err(|source| WriteError { path, source })?;
    }
    Ok(())
}
