//! The JSON results file and the atomic write every output uses.

use super::export::{Export, ExportError, Exporter};
use crate::results::Results;
use std::io::Write;
use std::path::Path;

/// Pretty JSON of a results file.
pub fn to_string(results: &Results) -> std::io::Result<String> {
    serde_json::to_string_pretty(results).map_err(std::io::Error::other)
}

/// Writes `bytes` to a temporary file beside `path`, syncs it, then renames it over `path`, so
/// a reader (or an interrupted run) only ever sees the old or the new file whole.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let name = path
        .file_name()
        .ok_or_else(|| std::io::Error::other("write_atomic needs a file path"))?;
    let tmp = path.with_file_name(format!(".{}.tmp", name.to_string_lossy()));
    let written = write_synced(&tmp, bytes).and_then(|()| std::fs::rename(&tmp, path));
    if written.is_err() {
        // A full disk must not also keep a half-written copy; the caller reports the first error.
        let _ = std::fs::remove_file(&tmp);
    }
    written
}

fn write_synced(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let mut file = std::fs::File::create(path)?;
    file.write_all(bytes)?;
    file.sync_all()
}

/// The JSON format: the results file itself and its findings.
pub struct Json;

impl Exporter for Json {
    fn export(&self, results: &Results) -> Result<Vec<Export>, ExportError> {
        Ok(vec![
            Export {
                name: "results.json",
                text: to_string(results)
                    .map_err(|e| ExportError::of("results.json")(e.to_string()))?,
            },
            Export {
                name: "findings.json",
                text: crate::findings::of(results)
                    .to_json()
                    .map_err(|e| ExportError::of("findings.json")(e.to_string()))?,
            },
        ])
    }
}
