//! Sweep scheduling, persistence and failure handling, through the library.

use oceanbench::config::{Level, SweepConfig};
use oceanbench::frame_loop::Mode;
use oceanbench::results::CellKey;
use oceanbench::sweep::{self, Sweep};
use oceanbench::sync::SyncMethod;

fn tiny(name: &str) -> SweepConfig {
    SweepConfig {
        name: name.into(),
        sizes: vec![6, 8],
        workloads: vec![0, 1],
        modes: vec![Mode::Serial, Mode::Up],
        sync: vec![SyncMethod::Atomic, SyncMethod::Condvar],
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
    let mut order: Vec<CellKey> = Vec::new();
    let results = s.run(|p| order.push(p.cell.clone()), |_| {});
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
    let config = SweepConfig {
        sizes: vec![6],
        workloads: vec![0],
        timeout_seconds: 0.3,
        inject_stall_at_frame: Some(2),
        trials: 1,
        ..tiny("stall")
    };
    let started = std::time::Instant::now();
    let results = Sweep::prepare(config).unwrap().run(|_| {}, |_| {});
    assert!(started.elapsed().as_secs() < 30, "the process never hangs");
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
    let stop = s.stop_flag();
    let mut saved = None;
    let mut rows = 0;
    let partial = s.run(
        |_| {},
        |r| {
            rows += 1;
            saved = Some(r.clone());
            if rows == 2 {
                stop.store(true, std::sync::atomic::Ordering::SeqCst);
            }
        },
    );
    assert!(partial.finished.is_none());
    assert_eq!(partial.cells.len(), 6, "two rows of three cells kept");
    assert_eq!(saved.as_ref().unwrap().cells.len(), 6);
    let resumed = Sweep::resume(partial.clone()).unwrap();
    assert_eq!(resumed.keys().len(), all.len() - 6);
    let done = resumed.run(|_| {}, |_| {});
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
    assert_eq!(&done.cells[..6], &partial.cells[..]);
}
