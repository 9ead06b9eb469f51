//! `oceanbench run`: measure the cells the flags describe and print their statistics.

use super::{command_line, fail_on_errors, interrupt, lock_cores, prepare_out_dir, CliError};
use crate::cell::{Axes, Dim};
use crate::cli::{DimArgs, RunArgs, TraceFramesArg};
use crate::config::{InputError, Level, SweepConfig};
use crate::frame_log::FrameLogger;
use crate::frame_loop::Mode;
use crate::machine::Machine;
use crate::report;
use crate::results::Results;
use crate::sweep::Sweep;
use crate::trace::{CellFilter, Target, TracePlan, DEFAULT_FRAMES};
use crate::workload::WorkloadKind;
use std::path::PathBuf;

/// The cell `run` measures when its flags are left out: a mid-size mesh in DP, where the
/// hand-off matters, rather than the sweep's first values.
fn default_axes() -> Axes {
    Axes {
        sizes: vec![128],
        workloads: vec![0],
        modes: vec![Mode::Dp],
        ..Axes::default()
    }
}

/// Each dimension's flag replaces that dimension's list; the others keep `run`'s defaults.
fn axes(cell: &DimArgs) -> Axes {
    let mut axes = default_axes();
    for &dim in Dim::ALL {
        let values = match cell.get(dim) {
            Some(given) => given.to_vec(),
            None => axes.values(dim).into_iter().take(1).collect(),
        };
        axes.set(dim, &values)
            .expect("flag values are parsed by their dimension");
    }
    axes
}

/// The flags no cell uses because every mode listed is `serial` (no hand-off, so no method,
/// helper or depth), each named once.
fn ignored_flags(cell: &DimArgs, axes: &Axes) -> Vec<String> {
    if axes.modes.iter().any(|&m| m != Mode::Serial) {
        return Vec::new();
    }
    Dim::ALL
        .iter()
        .filter(|&&d| !d.in_serial_cells() && cell.get(d).is_some())
        .map(|&d| format!("--{}", DimArgs::flag(d)))
        .collect()
}

/// The config keys `run`'s flags set, each with its flag, so that an error names what was typed.
fn flag_fields(args: &RunArgs) -> Vec<(&'static str, String)> {
    let mut fields: Vec<(&'static str, String)> = [
        ("min_seconds", "--seconds"),
        ("min_frames", "--frames"),
        ("max_seconds", "--max-seconds"),
        ("trials", "--trials"),
        ("timeout_seconds", "--timeout"),
        ("cores", "--cores"),
        ("workload_levels[0].micros", "--workload-micros"),
    ]
    .into_iter()
    .map(|(field, flag)| (field, flag.to_string()))
    .collect();
    fields.extend(args.cell.flag_fields());
    fields.extend(args.noise.flag_fields());
    fields.extend(args.camera.flag_fields());
    fields
}

pub(super) fn run(args: RunArgs) -> Result<(), CliError> {
    let flags = flag_fields(&args);
    let mut cells = axes(&args.cell);
    // Normals the flags left out are fitted as a config's are, so `run --grid projected` and
    // `run --helpers 2` run rather than refuse a value nobody gave.
    if args.cell.get(Dim::Normals).is_none() {
        if let Some(note) = cells.fit_default_normals() {
            eprintln!("oceanbench: --{note}");
        }
    }
    let ignored = ignored_flags(&args.cell, &cells);
    if !ignored.is_empty() {
        eprintln!(
            "oceanbench: {} ignored: `--mode serial` runs everything on one thread, with no hand-off",
            ignored.join(", ")
        );
    }
    let mut config = SweepConfig {
        name: "run".into(),
        axes: cells,
        trials: args.trials,
        min_frames: args.frames,
        min_seconds: args.seconds,
        max_seconds: args.max_seconds.unwrap_or((args.seconds * 10.0).max(10.0)),
        waves_file: args.waves,
        fft_params: args.fft_params,
        timeout_seconds: args.timeout,
        cores: args.cores,
        ..SweepConfig::default()
    };
    args.noise.apply(&mut config);
    args.camera.apply(&mut config.camera);
    if let Some(level) = given_level(&config, args.workload_micros, args.amount)? {
        config.workload_levels = vec![level];
        config.axes.workloads = vec![0];
    }
    let trace = args
        .trace
        .map(|file| trace_plan(file, &args.trace_frames, &config))
        .transpose()?;
    let _out_lock = args.out.as_deref().map(prepare_out_dir).transpose()?;
    config.validate().map_err(|e| e.naming_flags(&flags))?;
    if let Some(note) = crate::sweep::kind_skips(&config) {
        eprintln!("oceanbench: {note}");
    }
    let mut frame_log = args
        .frame_log
        .as_deref()
        .map(|dir| {
            let keys = crate::sweep::cells(&config);
            FrameLogger::prepare("--frame-log", dir, &keys, &Machine::current())
        })
        .transpose()?;
    let _core_locks = lock_cores(&config.placement()?, &args.wait)?;
    let stop = interrupt::flag();
    let mut sweep = Sweep::prepare(config)?.stopping_on(stop);
    if let Some(plan) = trace {
        sweep = sweep.tracing(plan);
    }
    // Recorded before the run, so the frame logs' and traces' provenance carries it too.
    sweep.results.command = Some(command_line());
    let results = match &mut frame_log {
        Some(logger) => sweep.run(logger),
        None => sweep.run(&mut ()),
    };
    if let Some(dir) = &args.out {
        report::write_all(dir, &results).map_err(anyhow::Error::from)?;
    }
    print_cells(&results);
    if let Some(logger) = frame_log {
        for path in logger
            .finish()
            .map_err(|e| anyhow::anyhow!("frame log {e}"))?
        {
            println!("frame log: {}", path.display());
        }
    }
    // The time cap ends a slow trial before --frames; the numbers stand, but say so.
    for cell in &results.cells {
        let Some(s) = &cell.summary else { continue };
        let asked = args.frames * u64::from(args.trials);
        if (s.frames as u64) < asked {
            eprintln!(
                "oceanbench: {}: {} frames over {} trial(s), fewer than --frames {} each: a trial stops after --max-seconds {}; raise it for the full count",
                cell.key.label(),
                s.frames,
                args.trials,
                args.frames,
                results.config.max_seconds
            );
        }
    }
    if results.finished.is_none() {
        return Err(CliError::Interrupted(format!(
            "interrupted; {} finished cell(s) printed above",
            results.cells.len()
        )));
    }
    fail_on_errors(&results)
}

/// `--trace FILE`: one file holds one cell's trace, so the flags must list one cell.
fn trace_plan(
    file: PathBuf,
    frames: &TraceFramesArg,
    config: &SweepConfig,
) -> Result<TracePlan, InputError> {
    let cells = crate::sweep::cells(config).len();
    if cells != 1 {
        return Err(InputError(format!(
            "--trace: FILE holds one cell's trace, and these flags list {cells} cells; give one value per flag, or use `sweep --trace DIR`"
        )));
    }
    TracePlan::new(
        Target::File(file),
        CellFilter::default(),
        frames.trace_frames.unwrap_or(DEFAULT_FRAMES as i64),
    )
}

fn print_cells(results: &Results) {
    print!("{}", report::markdown::preamble(results));
    for cell in &results.cells {
        println!("{}", cell.key.label());
        match &cell.summary {
            Some(s) => println!(
                "  {:.1} FPS (trials {}; cv {:.1}%), frame median {:.3} ms, p99 {:.3} ms, 1% low (slowest 1% of frames) {:.1} FPS\n  per frame: workload {:.3} ms, wait {:.3} ms, copy {:.3} ms, step {:.3} ms; pinned: {}",
                s.fps,
                s.fps_trials
                    .iter()
                    .map(|f| format!("{f:.1}"))
                    .collect::<Vec<_>>()
                    .join(", "),
                s.fps_spread.cv_percent,
                s.frame_time_ms.median,
                s.frame_time_ms.p99,
                s.one_percent_low_fps,
                s.breakdown.workload_ms,
                s.breakdown.wait_ms,
                s.breakdown.copy_ms,
                s.breakdown.step_ms,
                cell.pinned
            ),
            None => println!("  failed: {}", cell.error.as_deref().unwrap_or("no frames")),
        }
        if let Some(m) = cell.summary.as_ref().and_then(|s| s.frame_metrics.as_ref()) {
            println!(
                "  frame-time metrics: P1 {:.1} FPS, 1% low average {:.1}, 1% low integral {:.1}; P0.1 {:.1}; stutter {:.2}% of the time",
                m.p1_fps,
                m.one_percent_low_average_fps,
                m.one_percent_low_integral_fps,
                m.p0_1_fps,
                m.stutter_time_percent
            );
        }
        if let Some(s) = &cell.summary {
            if let (Some(m), Some(l)) = (&s.mailbox, &s.latency) {
                println!(
                    "  latest: mesh age {:.3} ms median, {:.3} ms p99; {} helper frames dropped, {} meshes taken twice, in {} frames",
                    l.age_ms_median, l.age_ms_p99, m.dropped, m.repeated, s.frames
                );
            }
        }
        let kind = cell.key.workload_kind;
        for (i, t) in cell.summary.iter().flat_map(|s| &s.work_trials).enumerate() {
            let counts: Vec<String> = t
                .counts
                .iter()
                .map(|c| match (c.min, c.max) {
                    (Some(lo), Some(hi)) => format!("{} {:.0} ({lo}-{hi})", c.key, c.mean),
                    _ => format!("{} {:.0}", c.key, c.mean),
                })
                .collect();
            println!(
                "  {kind}, trial {}: per frame {}; {:.3} ms per frame on the main thread",
                i + 1,
                counts.join(", "),
                t.main_ms
            );
        }
        if let Some(r) = &cell.work {
            let values: Vec<String> = r.iter().map(|(k, v)| format!("{k} {v}")).collect();
            println!("  {kind} recorded: {}", values.join(", "));
        }
        let placed = crate::findings::placement::CellPlacement::of(cell);
        if !placed.classes.is_empty() {
            let mark = if placed.mixed() {
                format!(
                    " {}: its trials mixed placements",
                    crate::report::markdown::MIXED
                )
            } else {
                String::new()
            };
            let aside = if cell.set_aside.is_empty() {
                String::new()
            } else {
                format!(", {} trial(s) set aside", cell.set_aside.len())
            };
            println!("  placement: {}{aside}{mark}", placed.fps_line());
        }
        if let Some(n) = &cell.noise {
            println!(
                "  noise: kept off its core by other tasks up to {:.2}%, steal up to {:.2}% of a trial, {} involuntary switches; {} noisy trial(s), {} retried",
                n.preempted_percent(),
                n.steal_percent(),
                n.involuntary_switches(),
                n.noisy_trials(),
                n.retries
            );
        }
        for (i, t) in cell.trials.iter().enumerate() {
            let Some(slow) = &t.slow else { continue };
            let causes: Vec<&str> = slow.causes.iter().map(|c| c.name()).collect();
            let ratio = |r: Option<f64>| r.map_or("–".to_string(), |r| format!("{r:.2}"));
            println!(
                "  slow trial {}: {:.1} FPS, {:.0}% below the median: {} (step ÷ median {}, workload ÷ calibration {}, round trip {})",
                i + 1,
                t.fps,
                slow.below_median_percent,
                causes.join(", "),
                ratio(t.step_ratio),
                ratio(t.workload_ratio),
                t.round_trip_ns
                    .map_or("–".to_string(), |[a, b]| format!("{a:.0} / {b:.0} ns"))
            );
        }
    }
}

/// The level `run` was given: `--workload-micros` in µs, `--amount` in the kind's unit, or for
/// a kind whose levels cannot be given in time, its default amount; `None` leaves the config's
/// levels.
fn given_level(
    config: &SweepConfig,
    micros: Option<f64>,
    amount: Option<f64>,
) -> Result<Option<Level>, InputError> {
    let kind = config
        .axes
        .workload_kind
        .first()
        .copied()
        .unwrap_or(WorkloadKind::SYNTHETIC)
        .kind()?;
    let unit = kind.unit();
    match (micros, amount, kind.no_time_levels()) {
        (Some(_), _, Some(why)) => Err(InputError(format!(
            "--workload-micros: {why}, so `{}` levels are in {unit}; give --amount N",
            kind.name()
        ))),
        (Some(us), _, None) => Ok(Some(Level::micros(us))),
        (None, Some(a), _) => {
            kind.check_amount("--amount", a)?;
            Ok(Some(Level::in_unit(unit, a as u64)))
        }
        (None, None, Some(why)) => match kind.default_amount() {
            Some(a) => Ok(Some(Level::in_unit(unit, a))),
            None => Err(InputError(format!(
                "--amount: {why}, so `{}` needs a level in {unit}; give --amount N",
                kind.name()
            ))),
        },
        (None, None, None) => Ok(None),
    }
}
