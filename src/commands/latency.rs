//! `oceanbench latency`: every hand-off method's round trip next to the cache-line floor,
//! repeated and written as a results folder, or with `--matrix` the cache-line round trip of
//! every pair of allowed cores.

use super::{
    check_out_file, command_line, default_out_dir, lock_cores, prepare_out_dir, two_cores, CliError,
};
use crate::affinity;
use crate::cli::LatencyArgs;
use crate::config::InputError;
use crate::machine::Machine;
use crate::report;
use crate::results::latency::{LatencyRun, FILE_NAME, REPEATS, SCHEMA_VERSION};

pub(super) fn latency(args: LatencyArgs) -> Result<(), CliError> {
    if !(1..=10_000_000).contains(&args.samples) {
        return Err(InputError(format!(
            "--samples: must be 1 to 10000000, got {}",
            args.samples
        ))
        .into());
    }
    if args.matrix {
        return matrix(&args);
    }
    if !REPEATS.contains(&args.repeats) {
        return Err(InputError(format!(
            "--repeats: must be {} to {}, got {}",
            REPEATS.start(),
            REPEATS.end(),
            args.repeats
        ))
        .into());
    }
    if let Some(json) = &args.json {
        check_out_file("--json", json)?;
    }
    let [a, b] = two_cores(args.cores.as_deref())?;
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| default_out_dir("latency"));
    let _out_lock = prepare_out_dir(&out)?;
    let _core_locks = lock_cores(&[a, b], &args.wait)?;
    let started = crate::sweep::utc_now();
    let rows = crate::latency::repeated(a, b, args.samples, args.repeats);
    let run = LatencyRun {
        schema_version: SCHEMA_VERSION,
        machine: Some(Machine::current()),
        command: Some(command_line()),
        started,
        finished: Some(crate::sweep::utc_now()),
        samples: args.samples,
        repeats: args.repeats,
        rows,
    };
    let text = crate::latency::to_text(&run.summary_rows());
    print!("{text}");
    println!(
        "(the median of {} repeats; batched: one clock read per {} round trips, the central figure; median and p99: each trip timed, \
         which adds about two clock reads of {:.0} ns each)",
        args.repeats,
        crate::latency::BATCH,
        crate::latency::clock_read_ns()
    );
    let written = |path: &std::path::Path, e: std::io::Error| {
        anyhow::anyhow!("writing {}: {e}", path.display())
    };
    let json = serde_json::to_string_pretty(&run).map_err(anyhow::Error::from)?;
    let file = out.join(FILE_NAME);
    report::json::write_atomic(&file, json.as_bytes()).map_err(|e| written(&file, e))?;
    let file = out.join("latency.txt");
    report::json::write_atomic(&file, text.as_bytes()).map_err(|e| written(&file, e))?;
    if let Some(path) = &args.json {
        report::json::write_atomic(path, json.as_bytes()).map_err(|e| written(path, e))?;
    }
    println!("results: {}", out.display());
    Ok(())
}

/// `--matrix`: the round trip of every pair of the given cores, or of every allowed core.
fn matrix(args: &LatencyArgs) -> Result<(), CliError> {
    let cores: Vec<usize> = match &args.cores {
        Some(c) => {
            affinity::check_allowed(c)?;
            c.clone()
        }
        None => affinity::allowed_cores().to_vec(),
    };
    crate::latency::check_matrix_cores(&cores)?;
    let _core_locks = lock_cores(&cores, &args.wait)?;
    let batches = (args.samples / 200).max(10);
    let m = crate::latency::Matrix::measure(&cores, |a, b| {
        crate::crosscore::round_trip(a, b, batches).median_ns
    });
    print!("{}", m.to_text(crate::doctor::thread_siblings));
    if let Some(path) = &args.json {
        let text = serde_json::to_string_pretty(&m).map_err(anyhow::Error::from)?;
        report::json::write_atomic(path, text.as_bytes())
            .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    }
    Ok(())
}
