//! Sweep scheduling, persistence and failure handling, through the library.

use oceanbench::cell::Axes;
use oceanbench::config::{Level, SweepConfig};
use oceanbench::frame_loop::Mode;
use oceanbench::results::{CellKey, Results};
use oceanbench::sweep::{self, Observer, Progress, Sweep};
use oceanbench::sync::SyncMethod;

fn tiny(name: &str) -> SweepConfig {
    SweepConfig {
        name: name.into(),
        axes: Axes {
            sizes: vec![6, 8],
            workloads: vec![0, 1],
            modes: vec![Mode::Serial, Mode::Up],
            sync: vec![SyncMethod::Atomic, SyncMethod::Condvar],
            ..Axes::default()
        },
        trials: 3,
        warmup_frames: 1,
        min_frames: 3,
        min_seconds: 0.0,
        workload_levels: vec![Level::micros(0.0), Level::micros(5.0)],
        ..SweepConfig::default()
    }
}

#[test]
fn trials_of_a_row_run_in_rotation() {
    let config = tiny("rotation");
    let s = Sweep::prepare(config).unwrap();
    struct Order(Vec<CellKey>);
    impl Observer for Order {
        fn trial_starting(&mut self, p: Progress<'_>) {
            self.0.push(p.cell.clone());
        }
    }
    let mut seen = Order(Vec::new());
    let results = s.run(&mut seen);
    let order = seen.0;
    // Each row (size × workload) has serial + 2 UP cells, run A B C A B C A B C.
    assert_eq!(order.len(), 4 * 3 * 3);
    for row in order.chunks(9) {
        let first: Vec<&CellKey> = row[..3].iter().collect();
        assert_eq!(first.len(), 3);
        assert!(first[0] != first[1] && first[1] != first[2] && first[0] != first[2]);
        for round in row.chunks(3) {
            assert_eq!(
                round.iter().collect::<Vec<_>>(),
                first,
                "A B C in every round"
            );
        }
    }
    assert_eq!(results.cells.len(), 12);
    assert!(results
        .cells
        .iter()
        .all(|c| c.summary.as_ref().unwrap().fps_trials.len() == 3));
}

#[test]
fn cells_expand_serial_once_and_threaded_per_method() {
    let config = tiny("expand");
    let keys = sweep::cells(&config);
    assert_eq!(keys.len(), 2 * 2 * (1 + 2));
    assert_eq!(keys.iter().filter(|k| k.mode == Mode::Serial).count(), 4);
    assert!(keys
        .iter()
        .filter(|k| k.mode == Mode::Serial)
        .all(|k| k.sync.is_none() && k.threading.is_none()));
}

#[test]
fn a_stalled_hand_off_times_out_and_the_sweep_goes_on() {
    let base = tiny("stall");
    let config = SweepConfig {
        axes: Axes {
            sizes: vec![6],
            workloads: vec![0],
            ..base.axes.clone()
        },
        timeout_seconds: 0.3,
        inject_stall_at_frame: Some(2),
        trials: 1,
        ..base
    };
    // A hang must fail the test rather than hang it: the sweep runs on its own thread and the
    // test gives up after a bound far above what the three cells need (calibration plus three
    // 0.3 s timeouts, a few seconds) even on a loaded two-core runner.
    let (done, finished) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let _ = done.send(Sweep::prepare(config).unwrap().run(&mut ()));
    });
    let results = finished
        .recv_timeout(std::time::Duration::from_secs(180))
        .expect("the sweep never hangs on a stalled hand-off");
    assert!(results.finished.is_some());
    assert_eq!(results.cells.len(), 3);
    for cell in &results.cells {
        if cell.key.mode == Mode::Serial {
            assert!(cell.error.is_none(), "serial has no hand-off");
        } else {
            let err = cell.error.as_deref().expect("threaded cells stall");
            let method = cell.key.sync.unwrap().name();
            assert!(err.contains(method) && err.contains("up"), "{err}");
            assert!(cell.summary.is_none() && !cell.pinned);
        }
    }
}

#[test]
fn an_interrupted_sweep_keeps_finished_rows_and_resumes_to_the_same_cells() {
    let config = tiny("resume");
    let all = sweep::cells(&config);
    let s = Sweep::prepare(config).unwrap();
    /// Raises the stop flag after the second row, keeping what each row hands over.
    struct StopAfterTwo {
        stop: std::sync::Arc<std::sync::atomic::AtomicBool>,
        rows: usize,
        saved: Option<Results>,
    }
    impl Observer for StopAfterTwo {
        fn row_finished(&mut self, r: &Results) {
            self.rows += 1;
            self.saved = Some(r.clone());
            if self.rows == 2 {
                self.stop.store(true, std::sync::atomic::Ordering::SeqCst);
            }
        }
    }
    let mut observer = StopAfterTwo {
        stop: s.stop_flag(),
        rows: 0,
        saved: None,
    };
    let partial = s.run(&mut observer);
    let saved = observer.saved;
    assert!(partial.finished.is_none());
    assert_eq!(partial.cells.len(), 6, "two rows of three cells kept");
    assert_eq!(saved.as_ref().unwrap().cells.len(), 6);
    let resumed = Sweep::resume(partial.clone()).unwrap();
    assert_eq!(resumed.keys().len(), all.len() - 6);
    // A file an older build wrote, or one that says it finished, is resumed as this build's
    // and unfinished until the resumed rows are done.
    let mut older = partial.clone();
    older.schema_version = 1;
    older.finished = Some("2026-01-01T00:00:00Z".into());
    let again = Sweep::resume(older).unwrap();
    assert_eq!(
        again.results.schema_version,
        oceanbench::results::SCHEMA_VERSION
    );
    assert!(again.results.finished.is_none());
    let done = resumed.run(&mut ());
    assert!(done.finished.is_some());
    let mut got: Vec<&CellKey> = done.cells.iter().map(|c| &c.key).collect();
    let mut want: Vec<&CellKey> = all.iter().collect();
    let by_label = |a: &&CellKey, b: &&CellKey| a.label().cmp(&b.label());
    got.sort_by(by_label);
    want.sort_by(by_label);
    assert_eq!(got, want);
    assert_eq!(
        done.calibration, partial.calibration,
        "resume keeps the calibration"
    );
    // The finished rows come back as they were measured; only each trial's placement label may
    // differ, since the resumed rows' round trips join the run's split (one placement can
    // become near and far).
    let unlabelled = |cells: &[oceanbench::results::Cell]| {
        let mut cells = cells.to_vec();
        for t in cells
            .iter_mut()
            .flat_map(|c| c.trials.iter_mut().chain(c.set_aside.iter_mut()))
        {
            t.placement = None;
        }
        cells
    };
    assert_eq!(unlabelled(&done.cells[..6]), unlabelled(&partial.cells));
}

/// `fog` beside `synthetic` at the same µs: each fog row's level comes to a volume edge through
/// the fog's own calibration (recorded as the cell's amount in `volume`, with its pass split
/// into noise, blur and coefficients), the synthetic rows' to iterations; level 0 runs no pass.
#[test]
fn fog_levels_in_micros_resolve_to_a_volume_through_its_own_calibration() {
    use oceanbench::workload::WorkloadKind;
    let mut config = tiny("fog");
    config.axes.sizes = vec![8];
    config.axes.modes = vec![Mode::Serial];
    config.axes.workload_kind = vec![WorkloadKind::SYNTHETIC, WorkloadKind::FOG];
    config.workload_levels = vec![Level::micros(0.0), Level::micros(3000.0)];
    config.trials = 1;
    let results = Sweep::prepare(config).unwrap().run(&mut ());
    assert_eq!(results.cells.len(), 4);
    for c in &results.cells {
        let what = c.key.label();
        let amount = c.workload_amount.unwrap();
        match (c.key.workload_kind, c.key.workload) {
            (WorkloadKind::FOG, 0) => {
                assert_eq!((c.workload_unit(), amount), ("volume", 0), "{what}");
                assert!(c.work.is_none(), "{what}: no pass at volume 0");
            }
            (WorkloadKind::FOG, _) => {
                assert_eq!(c.workload_unit(), "volume", "{what}");
                assert!((1..=512).contains(&amount), "{what}: volume {amount}");
                let Some(r) = &c.work else {
                    panic!("{what}: the fog's pass is recorded")
                };
                let keys: Vec<&str> = r.iter().map(|(k, _)| k).collect();
                assert_eq!(
                    keys,
                    ["volume", "octaves", "noise_ms", "blur_ms", "coefficient_ms"],
                    "{what}"
                );
                assert_eq!(
                    (r.get("volume"), r.get("octaves")),
                    (Some(amount as f64), Some(4.0)),
                    "{what}"
                );
                assert!(
                    r.get("noise_ms") > Some(0.0) && r.get("blur_ms") > Some(0.0),
                    "{what}"
                );
                let cal = c.calibration.as_ref().unwrap();
                assert_eq!(
                    (cal.level_micros, cal.asked_micros),
                    (3000.0, None),
                    "{what}"
                );
            }
            (_, w) => {
                assert_eq!(c.workload_unit(), "iterations", "{what}");
                assert_eq!(amount > 0, w > 0, "{what}");
                assert!(c.work.is_none(), "{what}");
            }
        }
    }
}

/// Fog below its smallest pass: on a 256×256 mesh the vertices' coefficients alone outlast
/// 20 µs, so the row runs a 1³ volume and records the µs that ran beside the µs asked, and the
/// run's warnings name the row.
#[test]
fn fog_below_its_vertex_pass_records_what_ran() {
    use oceanbench::workload::WorkloadKind;
    let mut config = tiny("fog-floor");
    config.axes.sizes = vec![256];
    config.axes.modes = vec![Mode::Serial];
    config.axes.workload_kind = vec![WorkloadKind::FOG];
    config.axes.workloads = vec![1];
    config.workload_levels = vec![Level::micros(0.0), Level::micros(20.0)];
    config.trials = 1;
    let results = Sweep::prepare(config).unwrap().run(&mut ());
    let [c] = &results.cells[..] else {
        panic!("one cell: {:?}", results.cells.len())
    };
    let cal = c.calibration.as_ref().unwrap();
    assert_eq!(c.workload_amount, Some(1));
    assert_eq!(cal.asked_micros, Some(20.0));
    assert!(cal.level_micros > 22.0, "ran {} µs", cal.level_micros);
    let warnings = oceanbench::report::markdown::noise_warnings(&results);
    assert!(
        warnings.iter().any(
            |w| w.starts_with("1 row(s) ran more work than their level asked")
                && w.contains("asked 20 µs")
                && w.contains("1³ voxels")
        ),
        "{warnings:?}"
    );
}

/// A level in µs that no volume up to 512³ reaches is refused before anything runs.
#[test]
fn fog_micros_beyond_the_largest_volume_are_refused() {
    use oceanbench::workload::WorkloadKind;
    let mut config = tiny("fog-too-much");
    config.axes.workload_kind = vec![WorkloadKind::FOG];
    config.timeout_seconds = 86_400.0;
    config.workload_levels = vec![Level::micros(0.0), Level::micros(3.0e10)];
    let Err(e) = Sweep::prepare(config) else {
        panic!("30 000 s of fog per frame is refused")
    };
    assert!(
        e.0.starts_with("workload_levels[1]: 30000000000 µs of fog")
            && e.0.contains("allowed up to 512³"),
        "{}",
        e.0
    );
}

/// One cell, UP, atomic: the smallest sweep that runs a helper.
fn one_cell(name: &str) -> SweepConfig {
    let base = tiny(name);
    SweepConfig {
        axes: Axes {
            sizes: vec![6],
            workloads: vec![0],
            modes: vec![Mode::Up],
            sync: vec![SyncMethod::Atomic],
            ..base.axes.clone()
        },
        trials: 1,
        ..base
    }
}

#[test]
fn a_sweep_stopping_on_a_raised_flag_measures_nothing_and_stays_unfinished() {
    let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(true));
    let s = Sweep::prepare(tiny("stopped")).unwrap().stopping_on(stop);
    let mut trials = 0;
    struct Count<'a>(&'a mut usize);
    impl Observer for Count<'_> {
        fn trial_starting(&mut self, _: Progress<'_>) {
            *self.0 += 1;
        }
    }
    let results = s.run(&mut Count(&mut trials));
    assert!(
        results.finished.is_none(),
        "a stopped sweep is not finished"
    );
    assert!(
        results.cells.iter().all(|c| c.summary.is_none()),
        "no cell measured after the stop: {} cells, {trials} trials started",
        results.cells.len()
    );
}

#[test]
fn a_tracing_sweep_writes_one_trace_per_chosen_cell() {
    use oceanbench::trace::{CellFilter, Target, TracePlan};
    let dir = tempfile::tempdir().unwrap();
    let traces = dir.path().join("traces");
    let plan = TracePlan::new(Target::Dir(traces.clone()), CellFilter::default(), 4).unwrap();
    let config = one_cell("traced");
    let key = sweep::cells(&config).remove(0);
    let results = Sweep::prepare(config)
        .unwrap()
        .tracing(plan.clone())
        .run(&mut ());
    assert!(results.finished.is_some());
    let path = plan.path_for(&key);
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("{} not written: {e}", path.display()));
    let trace: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert!(trace.is_object() || trace.is_array(), "a JSON trace");
    assert_eq!(std::fs::read_dir(&traces).unwrap().count(), 1);
}

#[test]
fn a_latest_cell_records_its_mailbox_and_a_fifo_cell_none() {
    use oceanbench::sync::Policy;
    let base = one_cell("mailbox");
    let config = SweepConfig {
        axes: Axes {
            policy: vec![Policy::Fifo, Policy::Latest],
            sync: vec![SyncMethod::TripleBuffer, SyncMethod::Atomic],
            ..base.axes.clone()
        },
        ..base
    };
    let results = Sweep::prepare(config).unwrap().run(&mut ());
    let threaded: Vec<_> = results
        .cells
        .iter()
        .filter(|c| c.key.mode != Mode::Serial)
        .collect();
    assert!(threaded
        .iter()
        .any(|c| c.key.policy == Some(Policy::Latest)));
    assert!(threaded.iter().any(|c| c.key.policy == Some(Policy::Fifo)));
    for cell in threaded {
        let summary = cell.summary.as_ref().expect("measured");
        let latest = cell.key.policy == Some(Policy::Latest);
        assert_eq!(summary.mailbox.is_some(), latest, "{}", cell.key.label());
        if let Some(m) = &summary.mailbox {
            assert_eq!(
                m.consumed.len(),
                summary.fps_trials.len(),
                "a run of frames per trial"
            );
        }
    }
}
