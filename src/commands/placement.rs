//! `oceanbench placement`: where the two cores sat during a run, read from its results file.

use super::{load_results, CliError};
use crate::cli::PlacementArgs;
use crate::findings::placement::{self, RunPlacement};
use crate::report::markdown;
use serde::Serialize;

/// What `--json` prints.
#[derive(Serialize)]
struct Json {
    cells: RunPlacement,
    finding: Option<placement::Finding>,
    balance: Vec<Balance>,
}

/// A balance search's placement.
#[derive(Serialize)]
struct Balance {
    cell: String,
    placement: Option<crate::placement::Class>,
    set_aside: usize,
    placements: Vec<crate::balance::PlacementBalance>,
}

pub(super) fn placement(args: PlacementArgs) -> Result<(), CliError> {
    let results = load_results(&args.results)?;
    if args.json {
        let json = Json {
            cells: RunPlacement::of(&results),
            finding: placement::finding(&results),
            balance: results
                .balance
                .iter()
                .map(|e| Balance {
                    cell: e.key.label(),
                    placement: e.placement,
                    set_aside: e.set_aside,
                    placements: e.placements.clone(),
                })
                .collect(),
        };
        let text = serde_json::to_string_pretty(&json).map_err(anyhow::Error::from)?;
        println!("{text}");
        return Ok(());
    }
    let section = markdown::placement(&results);
    if section.is_empty() {
        println!(
            "{}: no cross-core round trip recorded (the run measured on one core), so no placement",
            args.results.display()
        );
        return Ok(());
    }
    print!("{section}");
    if let Some(t) = markdown::balance_table(&results) {
        print!("{}", t.to_markdown());
    }
    Ok(())
}
