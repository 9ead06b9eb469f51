//! The oceanbench binary: parses the command line, dispatches, maps errors to exit statuses
//! (2 for bad input, 1 for a failure while running) and prints each error as one line.

use clap::error::{ContextKind, ContextValue, ErrorKind};
use clap::Parser;
use oceanbench::cli::{execute, Cli};

/// One line for a clap error: what was wrong, and the allowed values when clap knows them.
fn clap_line(err: &clap::Error) -> String {
    let get = |kind| match err.get(kind) {
        Some(ContextValue::String(s)) => Some(s.clone()),
        Some(ContextValue::Strings(v)) => Some(v.join(", ")),
        _ => None,
    };
    let arg = get(ContextKind::InvalidArg).unwrap_or_default();
    let value = get(ContextKind::InvalidValue).unwrap_or_default();
    let allowed = get(ContextKind::ValidValue)
        .map(|v| format!(" (allowed: {v})"))
        .unwrap_or_default();
    match err.kind() {
        ErrorKind::InvalidValue | ErrorKind::ValueValidation if !arg.is_empty() => {
            let why = err
                .source_message()
                .map(|m| format!(": {m}"))
                .unwrap_or_default();
            format!("{arg}: invalid value '{value}'{why}{allowed}")
        }
        ErrorKind::MissingRequiredArgument if !arg.is_empty() => {
            format!("missing required arguments: {arg}")
        }
        _ => {
            let first = err.render().to_string();
            let line = first.lines().next().unwrap_or("invalid arguments");
            line.trim_start_matches("error: ").to_string()
        }
    }
}

trait SourceMessage {
    fn source_message(&self) -> Option<String>;
}

impl SourceMessage for clap::Error {
    fn source_message(&self) -> Option<String> {
        std::error::Error::source(self).map(|s| s.to_string())
    }
}

fn main() {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(err) => {
            if matches!(
                err.kind(),
                ErrorKind::DisplayHelp | ErrorKind::DisplayVersion
            ) || matches!(
                err.kind(),
                ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand
            ) {
                let _ = err.print();
                std::process::exit(
                    if err.kind() == ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand {
                        2
                    } else {
                        0
                    },
                );
            }
            eprintln!("oceanbench: {}", clap_line(&err));
            std::process::exit(2);
        }
    };
    if let Err(e) = execute(cli) {
        eprintln!("oceanbench: {e}");
        std::process::exit(e.exit_code());
    }
}
