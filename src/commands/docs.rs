//! `oceanbench docs`: regenerates, checks or audits the published numbers of README.md and
//! docs/*.md (see [`crate::publish`]).

use super::CliError;
use crate::cli::DocsArgs;
use crate::config::InputError;
use crate::publish::{self, Context};

pub(super) fn docs(args: DocsArgs) -> Result<(), CliError> {
    let files = publish::files(&args.root)
        .map_err(|e| InputError(format!("--root {}: {e}", args.root.display())))?;
    if args.numbers {
        let (mut labels, mut unchecked) = (0, 0);
        for file in &files {
            let text = std::fs::read_to_string(file)
                .map_err(|e| InputError(format!("{}: {e}", file.display())))?;
            for n in publish::loose::numbers(&text) {
                let what = match &n.label {
                    Some(label) => {
                        labels += 1;
                        label.describe()
                    }
                    None => {
                        unchecked += 1;
                        "UNCHECKED".into()
                    }
                };
                println!(
                    "{}:{}: {} ({what}): {}",
                    file.display(),
                    n.line,
                    n.number,
                    n.context
                );
            }
        }
        eprintln!(
            "{} number(s) outside generated blocks: {labels} label(s) checked against the code, {unchecked} unchecked",
            labels + unchecked
        );
        if unchecked > 0 {
            return Err(CliError::Run(anyhow::anyhow!(
                "{unchecked} number(s) outside generated blocks that nothing checks"
            )));
        }
        return Ok(());
    }
    let mut ctx = Context::new(&args.root);
    // Every file is regenerated before any is written, so a bad block leaves every file as it was.
    let mut outcomes = Vec::new();
    for file in &files {
        let outcome = publish::regenerate(&mut ctx, file).map_err(InputError)?;
        outcomes.push((file, outcome));
    }
    let stale: Vec<String> = outcomes
        .iter()
        .flat_map(|(f, o)| o.stale.iter().map(move |l| format!("{}:{l}", f.display())))
        .collect();
    if args.write {
        for (file, outcome) in &outcomes {
            if !outcome.stale.is_empty() {
                crate::report::json::write_atomic(file, outcome.text.as_bytes())
                    .map_err(|e| anyhow::anyhow!("{}: {e}", file.display()))?;
            }
        }
        println!("{} block(s) rewritten", stale.len());
        return Ok(());
    }
    // Prose outside the blocks carries no measured number: one there is a failure too.
    let mut loose = Vec::new();
    for (file, outcome) in &outcomes {
        for n in publish::loose::numbers(&outcome.text) {
            if n.label.is_none() {
                loose.push(format!(
                    "{}:{}: {} sits outside generated blocks and is no label the code checks",
                    file.display(),
                    n.line,
                    n.number
                ));
            }
        }
    }
    if stale.is_empty() && loose.is_empty() {
        println!("every generated block matches its run, and no number sits outside one");
        return Ok(());
    }
    for s in &stale {
        eprintln!("{s}: the block differs from what its run gives (run `oceanbench docs --write`)");
    }
    for l in &loose {
        eprintln!("{l}");
    }
    Err(CliError::Run(anyhow::anyhow!(
        "{} generated block(s) out of date, {} number(s) outside blocks",
        stale.len(),
        loose.len()
    )))
}
