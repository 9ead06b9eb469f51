//! `oceanbench chart`: redraw the charts from results files.

use super::{draw_charts, load_results, results_dir, CliError};
use crate::cell::Dim;
use crate::cli::{ChartArgs, DimArgs};
use crate::config::InputError;
use crate::report::chart::ChartOptions;

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
    if let Some(run) = args
        .results
        .iter()
        .find(|p| crate::results::latency::LatencyRun::is_latency_run(p))
    {
        return Err(InputError(format!(
            "{}: a latency run has no charts; `oceanbench report {}` shows its round trips and `compare` its changes",
            run.display(),
            run.display()
        ))
        .into());
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
