//! `oceanbench findings`: what a run shows, computed from its results file alone.

use super::{load_results, CliError};
use crate::cli::FindingsArgs;
use crate::findings;

pub(super) fn findings(args: FindingsArgs) -> Result<(), CliError> {
    let results = load_results(&args.results)?;
    if args.cells {
        use std::io::Write;
        let mut out = std::io::stdout().lock();
        // A closed pipe (`| head`) ends the listing; it is not an error.
        for c in &results.cells {
            if writeln!(out, "{}", c.key.label()).is_err() {
                break;
            }
        }
        return Ok(());
    }
    let found = findings::of(&results);
    if args.json {
        println!("{}", found.to_json().map_err(anyhow::Error::from)?);
    } else {
        print!("{}", found.to_markdown());
    }
    Ok(())
}
