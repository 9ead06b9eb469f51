//! Outputs drawn from results files alone: JSON (the file itself), a tidy CSV, the Figure 5-1
//! markdown table, the charts and the comparisons. The three tables are rewritten whole,
//! atomically, after every finished row of cells.

pub mod chart;
pub mod compare;
pub mod csv;
pub mod json;
pub mod markdown;

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

/// Writes `results.json`, `results.csv` and `results.md` into `dir`, each atomically.
pub fn write_all(dir: &Path, results: &Results) -> Result<(), WriteError> {
    let at = |name: &str| dir.join(name);
    let failed = |name: &str| {
        let path = at(name);
        move |source| WriteError { path, source }
    };
    let json = json::to_string(results).map_err(failed("results.json"))?;
    let csv = csv::to_string(results).map_err(|e| WriteError {
        path: at("results.csv"),
        source: std::io::Error::other(e),
    })?;
    let md = markdown::to_string(results);
    for (name, text) in [
        ("results.json", json),
        ("results.csv", csv),
        ("results.md", md),
    ] {
        json::write_atomic(&at(name), text.as_bytes()).map_err(failed(name))?;
    }
    Ok(())
}
