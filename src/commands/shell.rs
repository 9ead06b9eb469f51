//! `oceanbench completions` and `oceanbench man`: what a shell and `man` need once the binary is
//! installed, generated from the same clap definitions that parse the command line, so they
//! cannot drift from it.

use super::CliError;
use crate::cli::{Cli, CompletionsArgs, ManArgs};
use crate::config::InputError;
use clap::CommandFactory;
use std::io::Write;

pub(super) fn completions(args: CompletionsArgs) -> Result<(), CliError> {
    let mut command = Cli::command();
    let name = command.get_name().to_string();
    let mut script = Vec::new();
    clap_complete::generate(args.shell, &mut command, name, &mut script);
    print(&script)
}

pub(super) fn man(args: ManArgs) -> Result<(), CliError> {
    let command = Cli::command();
    match args.out {
        Some(dir) => {
            if !dir.is_dir() {
                return Err(InputError(format!(
                    "--out: {} is not an existing folder",
                    dir.display()
                ))
                .into());
            }
            clap_mangen::generate_to(command, &dir).map_err(anyhow::Error::from)?;
        }
        None => {
            let mut page = Vec::new();
            clap_mangen::Man::new(command)
                .render(&mut page)
                .map_err(anyhow::Error::from)?;
            print(&page)?;
        }
    }
    Ok(())
}

/// Writes `text` to stdout; a reader that stopped early (`| head`) is not a failure.
fn print(text: &[u8]) -> Result<(), CliError> {
    match std::io::stdout().write_all(text) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => Err(anyhow::Error::from(e).into()),
        _ => Ok(()),
    }
}
