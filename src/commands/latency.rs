//! `oceanbench latency`: every hand-off method's round trip next to the cache-line floor.

use super::CliError;
use crate::affinity;
use crate::cli::LatencyArgs;
use crate::config::InputError;
use crate::report;

/// The two cores to measure on: the ones given, or the first two allowed (one core alone
/// measures the one-core placement only).
fn cores(given: Option<&[usize]>) -> Result<[usize; 2], InputError> {
    let allowed = affinity::allowed_cores();
    let cores = match given {
        Some(c) => {
            affinity::check_allowed(c)?;
            c.to_vec()
        }
        None => allowed.iter().copied().take(2).collect(),
    };
    match cores.as_slice() {
        [only] => Ok([*only, *only]),
        [a, b] => Ok([*a, *b]),
        [] => Err(InputError(
            "cores: no core is allowed for this process".into(),
        )),
        _ => Err(InputError(format!(
            "--cores: give one or two core ids, got {}",
            affinity::list(&cores)
        ))),
    }
}

pub(super) fn latency(args: LatencyArgs) -> Result<(), CliError> {
    if !(1..=10_000_000).contains(&args.samples) {
        return Err(InputError(format!(
            "--samples: must be 1 to 10000000, got {}",
            args.samples
        ))
        .into());
    }
    let [a, b] = cores(args.cores.as_deref())?;
    let rows = crate::latency::table(a, b, args.samples);
    print!("{}", crate::latency::to_text(&rows));
    if let Some(path) = &args.json {
        let text = serde_json::to_string_pretty(&rows).map_err(anyhow::Error::from)?;
        report::json::write_atomic(path, text.as_bytes())
            .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    }
    Ok(())
}
