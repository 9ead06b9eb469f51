//! `oceanbench balance`: the workload at which the main thread stops waiting for the helper,
//! per cell, with the speed-up curve around it.

use super::{command_line, default_out_dir, interrupt, lock_cores, prepare_out_dir, CliError};
use crate::balance::{self, BalanceError, BalanceSettings};
use crate::cell::{Axes, Dim};
use crate::cli::BalanceArgs;
use crate::config::{InputError, Level, SweepConfig};
use crate::findings::placement;
use crate::frame_loop::Mode;
use crate::report;
use crate::report::chart::{self, ChartOptions};
use crate::sweep::{self, Sweep};
use crate::sync::SyncMethod;

/// What `balance` searches when no config or flag says otherwise: the Figure 5-1 sizes in DP
/// with the paper's interlocked hand-off, and a short trial budget (a search runs hundreds).
fn defaults() -> SweepConfig {
    SweepConfig {
        name: "balance".into(),
        axes: Axes {
            modes: vec![Mode::Dp],
            sync: vec![SyncMethod::Atomic],
            ..Axes::default()
        },
        warmup_frames: 3,
        min_frames: 8,
        min_seconds: 0.08,
        max_seconds: 3.0,
        workload_levels: crate::config::default_levels(),
        balance: Some(BalanceSettings::default()),
        ..SweepConfig::default()
    }
}

pub(super) fn balance(args: BalanceArgs) -> Result<(), CliError> {
    if args.select.get(Dim::Workload).is_some() {
        return Err(InputError(
            "--workload: balance searches the workload itself (see --range); choose cells with the other dimensions".into(),
        )
        .into());
    }
    let mut config = match &args.config {
        Some(path) => SweepConfig::load(path)?,
        None => defaults(),
    };
    for (dim, values) in &args.select.given {
        config.axes.set(*dim, values)?;
    }
    if args.config.is_none() {
        // The search sets the level itself; a kind whose levels are not in time needs one in
        // its unit to start from.
        let start = config.axes.workload_kind.iter().find_map(|k| {
            let kind = k.kind().ok()?;
            kind.no_time_levels()?;
            Some(Level::in_unit(kind.unit(), kind.default_amount()?))
        });
        if let Some(level) = start {
            config.workload_levels = vec![level];
            config.axes.workloads = vec![0];
        }
    }
    let mut settings = config.balance.clone().unwrap_or_default();
    if let Some(t) = args.tolerance {
        settings.tolerance_percent = t;
    }
    if let Some(p) = args.points {
        settings.points = p;
    }
    if let Some(r) = &args.range {
        settings.range = match r.as_slice() {
            [a, b] => [*a, *b],
            _ => {
                return Err(InputError(format!(
                    "--range: give FROM,TO as multiples of the step, got {} value(s)",
                    r.len()
                ))
                .into())
            }
        };
    }
    if let Some(t) = args.trials {
        settings.trials = t;
    }
    let mut flags = args.select.flag_fields();
    if let Some(cores) = &args.cores {
        config.cores = Some(cores.clone());
        flags.push(("cores", "--cores".into()));
    }
    settings.validate("--")?;
    if let Some(bad) = config.axes.modes.iter().find(|m| **m == Mode::Serial) {
        return Err(InputError(format!(
            "--mode: {bad} has no helper to balance against; use dp (and up for contrast)"
        ))
        .into());
    }
    config.balance = Some(settings.clone());
    config.validate().map_err(|e| e.naming_flags(&flags))?;
    let dir = args
        .out
        .clone()
        .unwrap_or_else(|| default_out_dir(&config.name));
    let _out_lock = prepare_out_dir(&dir)?;
    let _core_locks = lock_cores(&config.placement()?, &args.wait)?;
    let stop = interrupt::flag();
    eprintln!("oceanbench: calibrating; results go to {}", dir.display());
    let sweep = Sweep::prepare(config)?.stopping_on(stop);
    let mut cells = Vec::new();
    for key in sweep.results.config.axes.cells() {
        let key = key
            .with(Dim::Workload, crate::cell::Value::Count(0))
            .expect("the workload dimension takes a count");
        if !cells.contains(&key) {
            cells.push(key);
        }
    }
    let mut results = sweep.results.clone();
    results.command = Some(command_line());
    for key in &cells {
        eprintln!("oceanbench: searching {}", key.label());
        match balance::search(&sweep, key, &settings) {
            Ok(entry) => {
                results.balance.push(entry);
                placement::label(&mut results);
            }
            Err(BalanceError::Input(e)) => return Err(e.into()),
            Err(BalanceError::Interrupted) => {
                report::write_all(&dir, &results).map_err(anyhow::Error::from)?;
                return Err(CliError::Interrupted(format!(
                    "interrupted; {} finished search(es) kept in {}",
                    results.balance.len(),
                    dir.display()
                )));
            }
            Err(e) => return Err(anyhow::anyhow!("{e}").into()),
        }
        report::write_all(&dir, &results).map_err(anyhow::Error::from)?;
    }
    results.finished = Some(sweep::utc_now());
    report::write_all(&dir, &results).map_err(anyhow::Error::from)?;
    print!("{}", report::markdown::balance(&results));
    if !args.no_charts {
        // Only the balance chart has something to show: the run measured no cells.
        let drawn = chart::draw_with(
            std::slice::from_ref(&results),
            &dir,
            &ChartOptions::default(),
        )
        .map_err(anyhow::Error::from)?;
        for file in &drawn.files {
            println!("chart: {}", file.display());
        }
        if let Some(s) = drawn.skipped.iter().find(|s| s.chart == "balance") {
            eprintln!("oceanbench: chart balance skipped: {}", s.reason);
        }
    }
    println!("Results: {}", dir.display());
    Ok(())
}
