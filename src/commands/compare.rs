//! `oceanbench compare`: two runs cell by cell, or the values of one dimension within a run.

use super::{check_threshold, load_results, CliError};
use crate::cli::{CompareArgs, CompareFormat};
use crate::config::InputError;
use crate::report::compare::{self, Metric};
use crate::results::latency::LatencyRun;

pub(super) fn compare(args: CompareArgs) -> Result<(), CliError> {
    check_threshold(args.threshold)?;
    let comparison = if LatencyRun::is_latency_run(&args.base) {
        if args.placement.is_some() {
            return Err(InputError(
                "--placement: a latency run measures each placement apart already; it takes no --placement".into(),
            )
            .into());
        }
        latency_comparison(&args)?
    } else {
        runs_comparison(&args)?
    };
    if let Some(why) = comparison.nothing_compared() {
        return Err(InputError(why).into());
    }
    if args.strict && !comparison.warnings.is_empty() {
        return Err(InputError(format!(
            "compare --strict: the runs are not like for like: {}",
            comparison.warnings.join("; ")
        ))
        .into());
    }
    match args.format {
        CompareFormat::Text => print!("{}", comparison.to_text()),
        CompareFormat::Markdown => print!("{}", comparison.to_markdown()),
        CompareFormat::Json => println!("{}", comparison.to_json()),
    }
    if comparison.regressed() {
        return Err(CliError::Regressed);
    }
    Ok(())
}

/// Two latency runs, method by method over their repeats; a latency run pairs only with
/// another, and its one metric is the round trip.
fn latency_comparison(args: &CompareArgs) -> Result<compare::Comparison, CliError> {
    let Some(new) = &args.new else {
        return Err(InputError(
            "compare: a latency run compares with another latency run (BASE NEW), not --by".into(),
        )
        .into());
    };
    if !LatencyRun::is_latency_run(new) {
        return Err(InputError(format!(
            "compare: {} is a latency run but {} is not; compare a latency run with another",
            args.base.display(),
            new.display()
        ))
        .into());
    }
    if args.metric == Metric::WaitCpu {
        return Err(InputError(
            "--metric: a latency run has only its round trip (round-trip); got wait-cpu".into(),
        )
        .into());
    }
    let load = |p: &std::path::Path| LatencyRun::load(p).map_err(|e| InputError(e.to_string()));
    Ok(compare::latency_between(
        &load(&args.base)?,
        &load(new)?,
        args.threshold,
    ))
}

/// Two sweep runs cell by cell, or the values of one dimension within a run.
fn runs_comparison(args: &CompareArgs) -> Result<compare::Comparison, CliError> {
    let base = load_results(&args.base)?;
    if args.new.as_deref().is_some_and(LatencyRun::is_latency_run) {
        return Err(InputError(format!(
            "compare: {} is a latency run but {} is not; compare a latency run with another",
            args.new.as_deref().unwrap_or(&args.base).display(),
            args.base.display()
        ))
        .into());
    }
    if args.metric == Metric::RoundTrip {
        return Err(InputError(
            "--metric: round-trip is the metric of latency runs; a sweep's is fps or wait-cpu"
                .into(),
        )
        .into());
    }
    let placed = |r: crate::results::Results| match args.placement {
        Some(class) => r.in_placement(class),
        None => r,
    };
    let base = placed(base);
    Ok(match (&args.new, args.by, &args.baseline) {
        (Some(new), None, _) => compare::between(
            &base,
            &placed(load_results(new)?),
            args.threshold,
            args.metric,
        ),
        (None, Some(by), Some(baseline)) => {
            { compare::within(&base, by, baseline, args.threshold, args.metric) }
                .map_err(|e| InputError(e.to_string()))?
        }
        _ => {
            return Err(InputError(
                "compare: give BASE NEW, or one RESULTS with --by and --baseline".into(),
            )
            .into())
        }
    })
}
