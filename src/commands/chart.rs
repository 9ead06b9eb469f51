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
    let runs = args
        .results
        .iter()
        .map(|p| load_results(p))
        .collect::<Result<Vec<_>, _>>()?;
    let out = args.out.unwrap_or_else(|| results_dir(&args.results[0]));
    let options = ChartOptions {
        formats: args.format,
        select,
    };
    draw_charts(&runs, &out, &options)
}
