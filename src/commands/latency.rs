//! `oceanbench latency`: every hand-off method's round trip next to the cache-line floor.

use super::{chosen_cores, lock_cores, CliError};
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
    let [a, b] = chosen_cores(args.cores.as_deref())?;
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
