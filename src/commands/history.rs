//! `oceanbench history`: a metric across runs in the order they were made, a chart per metric,
//! with runs on another machine marked.

use super::sweep::config_differences;
use super::{load_results, CliError};
use crate::cli::{DimArgs, HistoryArgs};
use crate::config::InputError;
use crate::report::chart::history;
use crate::report::compare::Metric;
use crate::results::{CellKey, Results};

pub(super) fn history(args: HistoryArgs) -> Result<(), CliError> {
    if args.runs.len() < 2 {
        return Err(InputError(format!(
            "RUN: give at least 2 runs to draw a history, got {}",
            args.runs.len()
        ))
        .into());
    }
    let mut runs = args
        .runs
        .iter()
        .map(|p| load_results(p))
        .collect::<Result<Vec<_>, _>>()?;
    history::order(&mut runs);
    if !args.force {
        for run in &runs[1..] {
            let differ = config_differences(&runs[0].config, &run.config);
            if !differ.is_empty() {
                return Err(InputError(format!(
                    "RUN: runs of different configs (started {} and {}; fields: {}); give runs of one config, or --force",
                    runs[0].started,
                    run.started,
                    differ.join(", ")
                ))
                .into());
            }
        }
    }
    let newest = runs.last().expect("at least two runs");
    let keys: Vec<CellKey> = newest
        .cells
        .iter()
        .map(|c| c.key.clone())
        .filter(|k| {
            args.select
                .given
                .iter()
                .all(|(dim, values)| k.get(*dim).is_some_and(|v| values.contains(&v)))
        })
        .collect();
    if keys.is_empty() {
        let flags: Vec<String> = args
            .select
            .given
            .iter()
            .map(|(dim, _)| format!("--{}", DimArgs::flag(*dim)))
            .collect();
        return Err(InputError(format!(
            "{}: no cell of the newest run has the values given; see `oceanbench findings --cells` for its cells",
            flags.join(", ")
        ))
        .into());
    }
    let changes = history::machine_changes(&runs);
    for (i, run) in runs.iter().enumerate() {
        let mark = if changes.iter().any(|c| c.0 == i) {
            " * another machine"
        } else {
            ""
        };
        println!(
            "{}. {}: {}; {}{mark}",
            i + 1,
            run.started,
            run.machine.provenance_line(),
            run.machine.line()
        );
    }
    let regressed = report_changes(&runs, &args.metric, &keys);
    let drawn = history::write(&runs, &args.metric, &keys, &args.out, &args.format)
        .map_err(anyhow::Error::from)?;
    for (metric, files) in args.metric.iter().zip(drawn) {
        match files {
            Ok(files) => files
                .iter()
                .for_each(|f| println!("chart: {}", f.display())),
            Err(e) => eprintln!("oceanbench: history of {metric}: {}", e.0),
        }
    }
    if regressed {
        return Err(anyhow::anyhow!(
            "a cell's newest run lies in a segment that began with a regression (the change lines above)"
        )
        .into());
    }
    Ok(())
}

/// Prints each cell's change points over the runs, per metric; true when a cell's newest run
/// lies in a segment that began with a regression.
fn report_changes(runs: &[Results], metrics: &[Metric], keys: &[CellKey]) -> bool {
    let mut regressed = false;
    for &metric in metrics {
        for key in keys {
            let changes = history::changes(runs, key, metric);
            for c in &changes {
                println!("change: {}", c.line(&key.label(), metric));
            }
            // The newest run is in the last segment, begun by the last change; a cell the
            // newest run did not measure says nothing of it.
            let newest_measured = history::series(runs, key, metric)
                .last()
                .is_some_and(Option::is_some);
            regressed |= newest_measured && changes.last().is_some_and(|c| c.regression);
        }
    }
    regressed
}
