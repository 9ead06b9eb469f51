//! `oceanbench latency`: every hand-off method's round trip next to the cache-line floor, or
//! with `--matrix` the cache-line round trip of every pair of allowed cores.

use super::{lock_cores, two_cores, CliError};
use crate::affinity;
use crate::cli::LatencyArgs;
use crate::config::InputError;
use crate::report;

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
    let [a, b] = two_cores(args.cores.as_deref())?;
    let _core_locks = lock_cores(&[a, b], &args.wait)?;
    let rows = crate::latency::table(a, b, args.samples);
    print!("{}", crate::latency::to_text(&rows));
    println!(
        "(batched: one clock read per {} round trips, the central figure; median and p99: each trip timed, \
         which adds about two clock reads of {:.0} ns each)",
        crate::latency::BATCH,
        crate::latency::clock_read_ns()
    );
    if let Some(path) = &args.json {
        let text = serde_json::to_string_pretty(&rows).map_err(anyhow::Error::from)?;
        report::json::write_atomic(path, text.as_bytes())
            .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    }
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
