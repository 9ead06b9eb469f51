//! `oceanbench export`: a run's FPS per cell in a CI benchmark tracker's format, to a file or
//! standard output, with the run's provenance beside it.

use super::{check_out_file, load_results, CliError};
use crate::cli::ExportArgs;
use crate::config::InputError;
use crate::findings::provenance;
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
    let provenance = ci::provenance(&results);
    match &args.out {
        Some(path) => {
            // Every file export gets the sidecar, even github-action-benchmark whose `extra`
            // holds the same facts as text, so a CI step reads provenance one way for both.
            let sidecar = provenance::sidecar(path);
            let json =
                serde_json::to_string_pretty(&provenance).map_err(anyhow::Error::from)? + "\n";
            for (file, bytes) in [(&sidecar, json.as_bytes()), (path, text.as_bytes())] {
                write_atomic(file, bytes)
                    .map_err(|e| anyhow::anyhow!("{}: {e}", file.display()))?;
            }
        }
        None => {
            // BMF has no field for provenance and standard output no file beside it: it goes to
            // standard error, one line, so a pipe into Bencher still reads pure BMF.
            if args.format == ci::CiFormat::Bmf {
                let json = serde_json::to_string(&provenance).map_err(anyhow::Error::from)?;
                eprintln!(
                    "oceanbench: provenance (give --out FILE for FILE's .provenance.json): {json}"
                );
            }
            // A reader that stops early (`| head`) wants no more; that is no failure.
            match std::io::stdout().write_all(text.as_bytes()) {
                Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
                    return Err(anyhow::anyhow!("standard output: {e}").into())
                }
                _ => {}
            }
        }
    }
    Ok(())
}
