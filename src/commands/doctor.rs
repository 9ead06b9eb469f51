//! `oceanbench doctor`: what on this machine makes measurements noisy, and how to fix it.

use super::{two_cores, CliError};
use crate::cli::DoctorArgs;
use crate::config::InputError;
use crate::doctor;
use std::time::Duration;

pub(super) fn doctor(args: DoctorArgs) -> Result<(), CliError> {
    if !(args.seconds.is_finite() && (0.1..=60.0).contains(&args.seconds)) {
        return Err(InputError(format!(
            "--seconds: must be 0.1 to 60, got {}",
            args.seconds
        ))
        .into());
    }
    let [main, helper] = two_cores(args.cores.as_deref())?;
    let mut cores = vec![main];
    if helper != main {
        cores.push(helper);
    }
    let report = doctor::examine(&cores, Duration::from_secs_f64(args.seconds));
    if args.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&report).map_err(anyhow::Error::from)?
        );
    } else {
        print!("{}", report.to_text());
        println!("{}", report.summary());
    }
    Ok(())
}
