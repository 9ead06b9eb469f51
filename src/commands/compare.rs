//! `oceanbench compare`: two runs cell by cell, or the values of one dimension within a run.

use super::{check_threshold, load_results, CliError};
use crate::cli::{CompareArgs, CompareFormat};
use crate::config::InputError;
use crate::report::compare;

pub(super) fn compare(args: CompareArgs) -> Result<(), CliError> {
    check_threshold(args.threshold)?;
    let base = load_results(&args.base)?;
    let comparison = match (&args.new, args.by, &args.baseline) {
        (Some(new), None, _) => {
            compare::between(&base, &load_results(new)?, args.threshold, args.metric)
        }
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
