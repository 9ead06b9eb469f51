//! `oceanbench export`: a run's FPS per cell in a CI benchmark tracker's format, to a file or
//! standard output.

use super::{check_out_file, load_results, CliError};
use crate::cli::ExportArgs;
use crate::config::InputError;
use crate::report::{ci, json::write_atomic};
use std::io::Write;

pub(super) fn export(args: ExportArgs) -> Result<(), CliError> {
    if let Some(out) = &args.out {
        check_out_file("--out", out)?;
    }
    let results = load_results(&args.run).map_err(|e| match e {
        CliError::Input(e) => {
            InputError(format!("RUN: {e}; give a run's folder or its results.json")).into()
        }
        e => e,
    })?;
    if results.cells.iter().all(|c| c.summary.is_none()) {
        return Err(InputError(format!(
            "RUN: {} holds no measured cell to export",
            args.run.display()
        ))
        .into());
    }
    let text = ci::to_string(&results, args.format).map_err(anyhow::Error::from)? + "\n";
    match &args.out {
        Some(path) => write_atomic(path, text.as_bytes())
            .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?,
        // A reader that stops early (`| head`) wants no more; that is no failure.
        None => match std::io::stdout().write_all(text.as_bytes()) {
            Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
                return Err(anyhow::anyhow!("standard output: {e}").into())
            }
            _ => {}
        },
    }
    Ok(())
}
