//! `oceanbench chart`: redraw the charts from results files.

use super::{draw_charts, load_results, report_drawn, results_dir, CliError};
use crate::cell::Dim;
use crate::cli::{ChartArgs, DimArgs};
use crate::config::InputError;
use crate::report::chart::{self as charts, ChartOptions};
use crate::results::latency::LatencyRun;
use std::path::Path;

pub(super) fn chart(args: ChartArgs) -> Result<(), CliError> {
    let mut select = Vec::new();
    for (dim, values) in &args.select.given {
        let flag = DimArgs::flag(*dim);
        if *dim == Dim::Mode {
            return Err(InputError(format!(
                "--{flag}: the charts draw every mode side by side; choose cells with the other dimensions"
            ))
            .into());
        }
        match values.as_slice() {
            [one] => select.push((*dim, *one)),
            _ => {
                return Err(InputError(format!(
                    "--{flag}: the charts hold a dimension at one value, got {}",
                    values.len()
                ))
                .into())
            }
        }
    }
    if let Some(run) = args.results.iter().find(|p| LatencyRun::is_latency_run(p)) {
        return latency_chart(&args, run, &select);
    }
    let runs = args
        .results
        .iter()
        .map(|p| load_results(p))
        .collect::<Result<Vec<_>, _>>()?;
    // A value no cell has would draw empty charts; name what the results do have instead.
    for &(dim, value) in &select {
        let cells = || runs.iter().flat_map(|r| &r.cells);
        if !cells().any(|c| c.key.get(dim) == Some(value)) {
            let mut present: Vec<String> = Vec::new();
            for v in cells().filter_map(|c| c.key.get(dim)) {
                let v = v.to_string();
                if !present.contains(&v) {
                    present.push(v);
                }
            }
            let present = if present.is_empty() {
                "none".to_string()
            } else {
                present.join(", ")
            };
            return Err(InputError(format!(
                "--{}: no cell in the results has `{value}`; they have {}: {present}",
                DimArgs::flag(dim),
                dim.name()
            ))
            .into());
        }
    }
    let out = args.out.unwrap_or_else(|| results_dir(&args.results[0]));
    let options = ChartOptions {
        formats: args.format,
        select,
    };
    draw_charts(&runs, &out, &options)
}

/// The round-trip chart of latency run `run`, the only results given.
fn latency_chart(
    args: &ChartArgs,
    run: &Path,
    select: &[(Dim, crate::cell::Value)],
) -> Result<(), CliError> {
    if args.results.len() > 1 {
        return Err(InputError(format!(
            "{}: a latency run is charted alone; `oceanbench compare BASE NEW` sets two side by side",
            run.display()
        ))
        .into());
    }
    if let Some((dim, _)) = select.first() {
        return Err(InputError(format!(
            "--{}: a latency run's chart shows every method on every core pair; it has no cells to choose",
            DimArgs::flag(*dim)
        ))
        .into());
    }
    let latency = LatencyRun::load(run).map_err(|e| InputError(e.to_string()))?;
    let out = args.out.clone().unwrap_or_else(|| results_dir(run));
    let drawn = charts::draw_latency(&latency, &out, &args.format).map_err(anyhow::Error::from)?;
    report_drawn(&drawn);
    Ok(())
}
