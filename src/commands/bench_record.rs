//! `oceanbench bench-record`: the estimates a `cargo bench` run just wrote, as a committed
//! `results/bench-<name>-<UTC>/bench.json`.

use super::{command_line, default_out_dir, CliError};
use crate::bench_run::{BenchRun, FILE_NAME};
use crate::cli::BenchRecordArgs;
use crate::config::InputError;

pub(super) fn bench_record(args: BenchRecordArgs) -> Result<(), CliError> {
    let name = &args.name;
    // The name becomes part of a folder name.
    if name.is_empty()
        || !name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_')
    {
        return Err(InputError(format!(
            "NAME: {name:?} must be letters, digits, - or _ (the bench target's name)"
        ))
        .into());
    }
    if !args.criterion_dir.is_dir() {
        return Err(InputError(format!(
            "--criterion-dir: {} is not a folder (run cargo bench first)",
            args.criterion_dir.display()
        ))
        .into());
    }
    let since = std::fs::metadata(&args.since)
        .and_then(|m| m.modified())
        .map_err(|e| InputError(format!("--since: {}: {e}", args.since.display())))?;
    let out = args
        .out
        .unwrap_or_else(|| default_out_dir(&format!("bench-{name}")));
    if out.join(FILE_NAME).exists() {
        return Err(InputError(format!(
            "--out: {} already holds {FILE_NAME}; choose another directory",
            out.display()
        ))
        .into());
    }
    let command = if args.command.is_empty() {
        command_line()
    } else {
        args.command
    };
    let run = BenchRun::from_criterion(name, &args.criterion_dir, since, command)
        .map_err(|e| InputError(e.to_string()))?;
    run.write(&out)
        .map_err(|e| anyhow::anyhow!("writing {}: {e}", out.join(FILE_NAME).display()))?;
    println!("{}", out.display());
    Ok(())
}
