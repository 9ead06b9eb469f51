//! Placement from the records alone: round trips injected into trial records (one placement,
//! two, a change mid-run), labelled, and read back by every output; a committed run from before
//! placement was recorded placed from its own round trips; the new bad input refused.

mod common;

use common::{assert_one_line_exit_2, assert_success, fixture, oceanbench};
use oceanbench::cell::{Dim, DimValue};
use oceanbench::findings::placement::{self, RunPlacement};
use oceanbench::frame_loop::Mode;
use oceanbench::placement::Class;
use oceanbench::report::compare::{self, Metric};
use oceanbench::report::{csv, markdown};
use oceanbench::results::{CellKey, Results};
use oceanbench::slow_trials::TrialRecord;

/// The fixture run with per-trial records for one row's serial, UP and DP cells (atomic): each
/// `(fps, [before, after])` a trial, in the order run.
fn run(serial: &[(f64, [f64; 2])], up: &[(f64, [f64; 2])], dp: &[(f64, [f64; 2])]) -> Results {
    let mut r = fixture();
    r.round_trip.before = None;
    r.round_trip.after = None;
    for (mode, trials) in [(Mode::Serial, serial), (Mode::Up, up), (Mode::Dp, dp)] {
        let key = key(&r, mode);
        let cell = r.cells.iter_mut().find(|c| c.key == key).unwrap();
        let breakdown = cell.summary.as_ref().unwrap().breakdown.clone();
        cell.trials = trials
            .iter()
            .map(|&(fps, rt)| TrialRecord {
                fps,
                breakdown: breakdown.clone(),
                step_ratio: None,
                workload_ratio: None,
                round_trip_ns: Some(rt),
                taken_away: false,
                slow: None,
                placement: None,
            })
            .collect();
    }
    placement::label(&mut r);
    r
}

/// The row's cell of `mode`: the first DP cell's (atomic), or its twin.
fn key(r: &Results, mode: Mode) -> CellKey {
    let dp = r
        .cells
        .iter()
        .find(|c| c.key.mode == Mode::Dp && c.key.sync.map(|s| s.name()) == Some("atomic"))
        .unwrap()
        .key
        .clone();
    dp.with(Dim::Mode, mode.value()).unwrap()
}

const NEAR: [f64; 2] = [50.0, 55.0];
const FAR: [f64; 2] = [390.0, 400.0];

#[test]
fn one_placement_is_said_and_marks_nothing() {
    let r = run(
        &[(100.0, NEAR); 3],
        &[(90.0, NEAR); 3],
        &[(180.0, NEAR), (181.0, [52.0, 60.0]), (179.0, NEAR)],
    );
    let split = r.placement.as_ref().unwrap();
    assert!(!split.two());
    let dp = r.cell(&key(&r, Mode::Dp)).unwrap();
    assert!(dp.trials.iter().all(|t| t.placement == Some(Class::One)));
    assert!(!dp.mixed_placements());
    let md = markdown::to_string(&r);
    assert!(!md.contains(markdown::MIXED), "{md}");
    let line = markdown::placement_line(&r).unwrap();
    assert!(
        line.starts_with("one placement, round trip 50-60 ns"),
        "{line}"
    );
    assert!(markdown::placement_table(&r).is_none());
    let f = placement::finding(&r).unwrap();
    assert!(f.sentence.contains("cannot say"), "{}", f.sentence);
    assert!((f.sides[0].dp_over_serial.unwrap() - 1.8).abs() < 1e-9);
    assert!(f.serial_placed);
}

#[test]
fn two_placements_name_near_and_far_per_cell() {
    // Serial and UP ran near; DP ran far throughout: no cell mixed, but DP ran in the run's
    // less common placement, and the table says so.
    let r = run(&[(100.0, NEAR); 3], &[(90.0, NEAR); 3], &[(150.0, FAR); 3]);
    assert!(r.placement.as_ref().unwrap().two());
    let placed = RunPlacement::of(&r);
    assert_eq!(placed.mixed().count(), 0);
    assert_eq!(
        placed.cell(&key(&r, Mode::Dp)).unwrap().only(),
        Some(Class::Far)
    );
    let t = markdown::placement_table(&r).unwrap();
    assert_eq!(t.title, "Placement: cells that mixed placements or ran far");
    assert_eq!(t.rows.len(), 1);
    assert_eq!(t.rows[0][1..], ["0", "3", "0", "–", "150", "0"]);
    let results_csv = csv::to_string(&r).unwrap();
    let header: Vec<&str> = results_csv.lines().next().unwrap().split(',').collect();
    let col = header.iter().position(|h| *h == "placement").unwrap();
    let dp_row = results_csv
        .lines()
        .find(|l| l.contains(",dp,") && l.contains(",atomic,"))
        .unwrap();
    assert_eq!(dp_row.split(',').nth(col), Some("far"));
    // No DP cell ran in both: the finding says its two sides come from different cells, and
    // the far side has no serial trial of its own placement to divide by.
    let f = placement::finding(&r).unwrap();
    assert!(f.contrasts.is_empty());
    assert!(
        f.sentence.contains("No DP cell ran in both"),
        "{}",
        f.sentence
    );
    assert_eq!(f.sides[1].dp_trials, 3);
}

#[test]
fn a_change_mid_run_mixes_a_cell_and_every_output_marks_it() {
    // DP's first trial near, its second moved (near before, far after), its third far; the
    // serial twin's trials near, far, far.
    let r = run(
        &[(100.0, NEAR), (80.0, FAR), (80.0, FAR)],
        &[(90.0, NEAR); 3],
        &[(180.0, NEAR), (170.0, [55.0, 395.0]), (140.0, FAR)],
    );
    let dp_key = key(&r, Mode::Dp);
    let dp = r.cell(&dp_key).unwrap();
    let classes: Vec<Option<Class>> = dp.trials.iter().map(|t| t.placement).collect();
    assert_eq!(
        classes,
        [Some(Class::Near), Some(Class::Moved), Some(Class::Far)]
    );
    assert!(dp.mixed_placements());
    // The FPS table marks the cell, and the placement table gives FPS per placement.
    let md = markdown::tables(&r);
    let row = md
        .lines()
        .find(|l| l.starts_with(&format!("| {}×", dp_key.size)))
        .unwrap();
    assert!(row.contains(markdown::MIXED), "{row}");
    let t = markdown::placement_table(&r).unwrap();
    let dp_row = t.rows.iter().find(|r| r[0] == dp_key.label()).unwrap();
    assert_eq!(dp_row[1..], ["1", "1", "1", "180", "140", "0"]);
    // trials.csv places every trial.
    let trials = csv::trials(&r).unwrap();
    assert_eq!(trials.lines().filter(|l| l.ends_with(",moved")).count(), 1);
    // compare marks the verdict and says why.
    let c = compare::between(&r, &r, 5.0, Metric::Fps);
    let text = c.to_text();
    assert!(c.changes.iter().any(|ch| ch.placement), "{text}");
    assert!(text.contains("§ rests on a cell whose trials ran in more than one placement"));
    // The finding: DP against serial within each placement.
    let f = placement::finding(&r).unwrap();
    assert_eq!(f.contrasts.len(), 1);
    assert_eq!(
        f.contrasts[0].dp_over_serial,
        [Some(1.8), Some(140.0 / 80.0)]
    );
    let far_over_near = f.dp_over_serial_far_over_near.unwrap();
    assert!(
        (far_over_near - (1.75 / 1.8)).abs() < 1e-9,
        "{far_over_near}"
    );
}

#[test]
fn a_run_from_before_placement_is_placed_from_its_dp_round_trips() {
    let out = oceanbench(&["placement", "results/projected-20261125T163816Z"]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_success(&out);
    assert!(
        stdout.starts_with("### Placement\n\nTwo placements: near "),
        "{stdout}"
    );
    // 120 DP trials (24 cells of 5), each placed; the serial and UP ones have no round trip.
    assert!(stdout.contains("; 120 placed trials: "), "{stdout}");
    assert!(
        stdout.contains("cells with placed trials mixed placements"),
        "{stdout}"
    );
    assert!(
        stdout.contains("Serial trials were not placed in this run"),
        "{stdout}"
    );
    // Its balance searches predate probe round trips: each is named by its own.
    assert!(stdout.contains(" ns → "), "{stdout}");
}

#[test]
fn latency_and_doctor_refuse_one_core_twice() {
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("l.json");
    for args in [
        vec![
            "latency",
            "--cores",
            "0,0",
            "--json",
            json.to_str().unwrap(),
        ],
        vec!["latency", "--matrix", "--cores", "0,0"],
        vec!["doctor", "--cores", "0,0"],
    ] {
        let out = oceanbench(&args);
        assert_one_line_exit_2(&out, &["--cores"]);
        assert!(out.stdout.is_empty(), "{args:?}");
    }
    assert!(!json.exists(), "nothing written");
}

#[test]
fn a_lone_round_trip_outside_the_cluster_is_named_not_dropped() {
    let one = oceanbench::placement::Split::of([42.5, 49.9, 50.7, 388.7]).unwrap();
    assert!(!one.two());
    assert_eq!(
        one.describe(),
        "one placement, round trip 42-51 ns (and 1 round trip outside it)"
    );
    let two = oceanbench::placement::Split::of([40.0, 41.0, 400.0, 410.0, 4000.0]).unwrap();
    assert!(two.describe().ends_with("(and 1 round trip in neither)"));
}

#[test]
fn a_serial_twin_without_placed_trials_is_read_whole_only_when_no_twin_was_placed() {
    // No serial trial records at all: each DP cell is against its twin's every trial.
    let r = run(&[], &[(90.0, NEAR); 3], &[(180.0, NEAR); 3]);
    let f = placement::finding(&r).unwrap();
    assert!(!f.serial_placed);
    let twin = r.cell(&key(&r, Mode::Serial)).unwrap();
    let whole = twin.summary.as_ref().unwrap().fps_trials.clone();
    let want = 180.0 / (whole.iter().sum::<f64>() / whole.len() as f64);
    let got = f.sides[0].dp_over_serial.unwrap();
    assert!((got - want).abs() < 1e-9, "{got} against {want}");
    assert!(
        f.sentence.contains("Serial trials were not placed"),
        "{}",
        f.sentence
    );

    // One twin placed, another DP cell's not: that cell has no DP ÷ serial of its own
    // placement, so only the placed pair counts.
    let mut r = run(&[(100.0, NEAR); 3], &[(90.0, NEAR); 3], &[(180.0, NEAR); 3]);
    another_row(&mut r, 120.0, vec![]);
    let f = placement::finding(&r).unwrap();
    assert!(f.serial_placed);
    assert_eq!(f.sides[0].dp_trials, 6, "both DP cells' trials");
    assert!((f.sides[0].dp_over_serial.unwrap() - 1.8).abs() < 1e-9);
}

#[test]
fn with_a_cell_in_both_placements_each_side_is_over_those_cells_only() {
    let mut r = run(
        &[(100.0, NEAR), (100.0, NEAR), (110.0, FAR)],
        &[(90.0, NEAR); 3],
        &[(180.0, NEAR), (180.0, NEAR), (165.0, FAR)],
    );
    let step = r.cell(&key(&r, Mode::Dp)).unwrap().trials[0]
        .breakdown
        .step_ms;
    // A DP cell of another row that ran near only, at another speed, its twin near too.
    let twin = r.cell(&key(&r, Mode::Serial)).unwrap().trials[0].clone();
    another_row(&mut r, 120.0, vec![twin; 3]);
    let f = placement::finding(&r).unwrap();
    assert_eq!(f.contrasts.len(), 1, "the atomic cell ran in both");
    let near = &f.sides[0];
    assert_eq!(
        (near.class, near.cells, near.dp_trials),
        (Class::Near, 1, 5)
    );
    assert!(
        (near.dp_over_serial.unwrap() - 1.8).abs() < 1e-9,
        "{near:?}"
    );
    assert_eq!(near.step_ms, Some(step));
    let far = &f.sides[1];
    assert!((far.dp_over_serial.unwrap() - 1.5).abs() < 1e-9, "{far:?}");
    let far_over_near = f.dp_over_serial_far_over_near.unwrap();
    assert!((far_over_near - 1.5 / 1.8).abs() < 1e-9, "{far_over_near}");
    assert_eq!(f.step_far_over_near, Some(1.0), "one step near and far");
}

/// Gives a DP cell of another row (another serial twin) three trials like the row's first DP
/// trial but at `fps`, and its serial twin the trials `twin`; then labels the run again.
fn another_row(r: &mut Results, fps: f64, twin: Vec<TrialRecord>) {
    let (dp, own_twin) = (key(r, Mode::Dp), key(r, Mode::Serial));
    let like = r.cell(&dp).unwrap().trials[0].clone();
    let serial = |k: &CellKey| k.with(Dim::Mode, Mode::Serial.value());
    let other = r
        .cells
        .iter_mut()
        .find(|c| c.key.mode == Mode::Dp && serial(&c.key).as_ref() != Some(&own_twin))
        .expect("a DP cell of another row");
    other.trials = vec![TrialRecord { fps, ..like }; 3];
    let other_twin = serial(&other.key).unwrap();
    r.cells
        .iter_mut()
        .find(|c| c.key == other_twin)
        .expect("its serial twin")
        .trials = twin;
    placement::label(r);
}
