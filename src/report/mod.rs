//! Outputs drawn from results files alone: JSON (the file itself), a tidy CSV, the Figure 5-1
//! markdown table, the charts and the comparisons. The three tables are rewritten whole,
//! atomically, after every finished cell.

pub mod chart;
pub mod compare;
pub mod csv;
pub mod json;
pub mod markdown;

use crate::results::Results;
use std::path::Path;

/// Writes `results.json`, `results.csv` and `results.md` into `dir`, each atomically.
pub fn write_all(dir: &Path, results: &Results) -> std::io::Result<()> {
    json::write_atomic(
        &dir.join("results.json"),
        json::to_string(results)?.as_bytes(),
    )?;
    json::write_atomic(&dir.join("results.csv"), csv::to_string(results).as_bytes())?;
    json::write_atomic(
        &dir.join("results.md"),
        markdown::to_string(results).as_bytes(),
    )?;
    Ok(())
}
