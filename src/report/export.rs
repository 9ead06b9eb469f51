//! The formats of a results folder, one exporter each behind one trait (as hyperfine's export/
//! has them): JSON (the results file and its findings), markdown and CSV. Each turns a results
//! file into its files; [`super::EXPORTERS`] lists them and [`super::write_all`] writes every
//! exporter's files, atomically.

use crate::results::Results;

/// One file of a format: its name in the run's folder and its text.
pub struct Export {
    /// The file's name.
    pub name: &'static str,
    /// What it holds.
    pub text: String,
}

/// A file a format could not build, named.
#[derive(Debug, thiserror::Error)]
#[error("{name}: {message}")]
pub struct ExportError {
    /// The file.
    pub name: &'static str,
    /// What went wrong.
    pub message: String,
}

impl ExportError {
    /// The error of file `name` from `e`.
    pub fn of(name: &'static str) -> impl Fn(String) -> ExportError {
        move |message| ExportError { name, message }
    }
}

/// A format of a results folder.
pub trait Exporter: Sync {
    /// The files of this format for `results`; none when the results hold nothing it shows.
    fn export(&self, results: &Results) -> Result<Vec<Export>, ExportError>;
}
