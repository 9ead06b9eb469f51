//! The oceanbench binary: parses the command line, dispatches, maps errors to exit statuses
//! (2 for bad input, 1 for a failure while running) and prints each error as one line.

use clap::error::ErrorKind;
use clap::Parser;
use oceanbench::cli::{clap_line, execute, Cli};

fn main() {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(err) => match err.kind() {
            ErrorKind::DisplayHelp | ErrorKind::DisplayVersion => {
                let _ = err.print();
                std::process::exit(0);
            }
            ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => {
                let _ = err.print();
                std::process::exit(2);
            }
            _ => {
                eprintln!("oceanbench: {}", clap_line(&err));
                std::process::exit(2);
            }
        },
    };
    if let Err(e) = execute(cli) {
        eprintln!("oceanbench: {e}");
        std::process::exit(e.exit_code());
    }
}
