//! `oceanbench report`: one self-contained HTML page of a run, optionally compared with a
//! baseline run.

use super::{check_out_file, check_threshold, load_results, results_dir, CliError};
use crate::cli::ReportArgs;
use crate::config::InputError;
use crate::report::compare::{self, Metric};
use crate::report::html::{self, Baseline};
use crate::report::json;
use crate::results::latency::LatencyRun;
use crate::results::Results;
use std::path::{Path, PathBuf};

pub(super) fn report(args: ReportArgs) -> Result<(), CliError> {
    check_threshold(args.threshold)?;
    if let Some(out) = &args.out {
        check_out_file("--out", out)?;
    }
    if LatencyRun::is_latency_run(&args.results) {
        return latency_report(&args);
    }
    let results = load_results(&args.results)?;
    let comparison = match &args.baseline {
        Some(path) => {
            let base = load_results(path)?;
            let c = compare::between(&base, &results, args.threshold, Metric::Fps);
            if let Some(why) = c.nothing_compared() {
                return Err(InputError(format!("--baseline: {why}")).into());
            }
            Some((path, c))
        }
        None => None,
    };
    let baseline_name = comparison.as_ref().map(|(p, _)| p.display().to_string());
    let baseline = comparison
        .as_ref()
        .zip(baseline_name.as_deref())
        .map(|((_, comparison), name)| Baseline { name, comparison });
    let out = args
        .out
        .unwrap_or_else(|| default_path(&results_dir(&args.results)));
    write(&results, &args.results, baseline.as_ref(), &out)?;
    if args.refresh {
        refresh(&results, &results_dir(&args.results))?;
    }
    println!("report: {}", out.display());
    Ok(())
}

/// Writes the page of `results` (read from `source`) to `out`, atomically.
pub(super) fn write(
    results: &Results,
    source: &Path,
    baseline: Option<&Baseline>,
    out: &Path,
) -> Result<(), CliError> {
    let page = html::page(results, &source.display().to_string(), baseline)
        .map_err(anyhow::Error::from)?;
    json::write_atomic(out, page.as_bytes())
        .map_err(|e| anyhow::anyhow!("writing {}: {e}", out.display()))?;
    Ok(())
}

/// The page of a latency run, against another latency run with `--baseline`.
fn latency_report(args: &ReportArgs) -> Result<(), CliError> {
    let load = |p: &Path| LatencyRun::load(p).map_err(|e| InputError(e.to_string()));
    let run = load(&args.results)?;
    if args.refresh {
        return Err(InputError(
            "--refresh: a latency run has no results.md or findings.json to rewrite".into(),
        )
        .into());
    }
    let comparison = match &args.baseline {
        Some(path) if !LatencyRun::is_latency_run(path) => {
            return Err(InputError(format!(
                "--baseline: {} is no latency run; a latency run is compared with another",
                path.display()
            ))
            .into())
        }
        Some(path) => {
            let c = compare::latency_between(&load(path)?, &run, args.threshold);
            if let Some(why) = c.nothing_compared() {
                return Err(InputError(format!("--baseline: {why}")).into());
            }
            Some((path.display().to_string(), c))
        }
        None => None,
    };
    let baseline = comparison
        .as_ref()
        .map(|(name, comparison)| Baseline { name, comparison });
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| default_path(&results_dir(&args.results)));
    let page = html::latency_page(&run, &args.results.display().to_string(), baseline.as_ref())
        .map_err(anyhow::Error::from)?;
    json::write_atomic(&out, page.as_bytes())
        .map_err(|e| anyhow::anyhow!("writing {}: {e}", out.display()))?;
    println!("report: {}", out.display());
    Ok(())
}

/// Where `sweep` writes its page.
pub(super) fn default_path(dir: &Path) -> PathBuf {
    dir.join("report.html")
}

/// Rewrites the run's results.md and findings.json from `results` (never results.json).
fn refresh(results: &Results, dir: &Path) -> Result<(), CliError> {
    let findings = crate::findings::of(results)
        .to_json()
        .map_err(anyhow::Error::from)?;
    for (name, text) in [
        ("results.md", crate::report::markdown::to_string(results)),
        ("findings.json", findings),
    ] {
        let path = dir.join(name);
        json::write_atomic(&path, text.as_bytes())
            .map_err(|e| anyhow::anyhow!("writing {}: {e}", path.display()))?;
        println!("refreshed: {}", path.display());
    }
    Ok(())
}
