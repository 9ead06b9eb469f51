//! The oceanbench binary: parses the command line, dispatches, maps errors to exit statuses
//! (2 for bad input, 1 for a failure while running, 130 when interrupted) and prints each error
//! as one line (a config with several errors, one line each).

use clap::error::ErrorKind;
use clap::Parser;
use oceanbench::cli::{clap_line, Cli};
use oceanbench::commands::{execute, EXIT_BAD_INPUT};
use std::process::ExitCode;

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(err) => {
            let code = match err.kind() {
                ErrorKind::DisplayHelp | ErrorKind::DisplayVersion => {
                    let _ = err.print();
                    0
                }
                ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => {
                    let _ = err.print();
                    EXIT_BAD_INPUT
                }
                _ => {
                    eprintln!("oceanbench: {}", clap_line(&err));
                    EXIT_BAD_INPUT
                }
            };
            return ExitCode::from(code);
        }
    };
    match execute(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            for line in e.to_string().lines() {
                eprintln!("oceanbench: {line}");
            }
            ExitCode::from(e.exit_code())
        }
    }
}
