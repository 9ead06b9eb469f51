//! The findings of hand-made runs: each finding's sentence and figures follow from the cells'
//! median trials (the quick fixture's cells with their trials set).

mod common;

use common::fixture;
use oceanbench::cell::{Dim, Mode};
use oceanbench::findings::{self, Finding};
use oceanbench::placement::Class;
use oceanbench::results::balance::{BalanceEntry, PlacementBalance};
use oceanbench::results::{Cell, CellKey, CellNoise, Results};
use oceanbench::sched::TrialNoise;
use oceanbench::slow_trials::{Cause, Slow, TrialRecord};

/// Trials around `median` (its middle one exactly), as a run of five would record them.
fn set_median(cell: &mut Cell, median: f64) {
    let s = cell.summary.as_mut().expect("a measured cell");
    s.fps_trials = [0.99, 0.995, 1.0, 1.005, 1.01].map(|k| median * k).to_vec();
    s.fps = median;
}

fn in_slice(cell: &Cell, sync: &str) -> bool {
    cell.key.get(Dim::Sync).map(|v| v.to_string()).as_deref() == Some(sync)
        && cell
            .key
            .get(Dim::Threading)
            .map(|v| v.to_string())
            .as_deref()
            == Some("pool")
}

/// The fixture's cell of the atomic, pool slice at `size`, `workload` and `mode` (a serial cell
/// has no hand-off, and serves every slice).
fn cell(r: &mut Results, size: usize, workload: usize, mode: Mode) -> &mut Cell {
    r.cells
        .iter_mut()
        .find(|c| {
            c.key.size == size
                && c.key.workload == workload
                && c.key.mode == mode
                && (mode == Mode::Serial || in_slice(c, "atomic"))
        })
        .unwrap_or_else(|| panic!("no {size} w{workload} {mode:?} atomic pool cell"))
}

/// The atomic, pool slice's findings of `id`.
fn of<'a>(f: &'a findings::Findings, id: &str) -> Vec<&'a Finding> {
    f.findings
        .iter()
        .filter(|x| x.id == id && x.slice.label() == "sync atomic, threading pool")
        .collect()
}

fn names(f: &Finding) -> Vec<&str> {
    f.figures.iter().map(|g| g.name.as_str()).collect()
}

/// The fixture with a third DP level at 40×40 (workload 3, a copy of workload 2's cell) and DP's
/// medians there set to `fps` at workloads 0, 2 and 3.
fn dp_levels(fps: [f64; 3]) -> Results {
    let mut r = fixture();
    let mut third = cell(&mut r, 40, 2, Mode::Dp).clone();
    third.key.workload = 3;
    r.cells.push(third);
    for (w, f) in [0, 2, 3].into_iter().zip(fps) {
        set_median(cell(&mut r, 40, w, Mode::Dp), f);
    }
    r
}

#[test]
fn dp_stays_flat_over_the_levels_within_the_bound_then_falls_or_rises() {
    assert_eq!(findings::FLAT_PERCENT, 5.0);
    let falls = findings::of(&dp_levels([1000.0, 1030.0, 800.0]));
    let flat = of(&falls, "dp-flat");
    // One finding per size: 16×16 has two levels, which is enough for one.
    assert_eq!(flat.len(), 2, "{flat:?}");
    assert!(
        flat[0].sentence.starts_with("On 16×16, DP"),
        "{}",
        flat[0].sentence
    );
    let f = flat[1];
    assert!(
        f.sentence
            .starts_with("On 40×40, DP stays within 5 % of its workload-0 FPS from workload 0"),
        "{}",
        f.sentence
    );
    assert!(
        f.sentence
            .contains("(1000-1030 FPS), then falls to 800 at workload 3"),
        "{}",
        f.sentence
    );
    assert!(f.sentence.contains("(0.80 ×)"), "{}", f.sentence);
    assert_eq!(names(f), ["dp_fps", "dp_fps", "dp_fps_after"]);
    let values: Vec<f64> = f.figures.iter().map(|g| g.value).collect();
    assert_eq!(values, [1000.0, 1030.0, 800.0]);
    // Every figure is read from a 40×40 cell.
    assert!(f
        .figures
        .iter()
        .all(|g| g.cell.as_deref().unwrap().starts_with("40 ")));

    let rises = findings::of(&dp_levels([1000.0, 1030.0, 1300.0]));
    let f = of(&rises, "dp-flat")[1];
    assert!(
        f.sentence.contains("then rises to 1300 at workload 3") && f.sentence.contains("(1.30 ×)"),
        "{}",
        f.sentence
    );
}

#[test]
fn dp_that_leaves_the_bound_at_the_second_level_does_not_stay_flat() {
    let r = findings::of(&dp_levels([1000.0, 940.0, 1000.0]));
    let f = of(&r, "dp-flat")[1];
    assert!(
        f.sentence.starts_with(
            "On 40×40, DP does not stay flat: 1000 FPS at workload 0 and 940 at workload 2"
        ),
        "{}",
        f.sentence
    );
    assert_eq!(names(f), ["dp_fps", "dp_fps"]);
    let values: Vec<f64> = f.figures.iter().map(|g| g.value).collect();
    assert_eq!(values, [1000.0, 940.0]);
}

#[test]
fn up_over_serial_names_its_lowest_and_highest_rows() {
    let mut r = fixture();
    for (size, workload, up, serial) in [
        (16, 0, 900.0, 1000.0),
        (16, 2, 990.0, 1000.0),
        (40, 0, 500.0, 1000.0),
        (40, 2, 1000.0, 1000.0),
    ] {
        set_median(cell(&mut r, size, workload, Mode::Up), up);
        set_median(cell(&mut r, size, workload, Mode::Serial), serial);
    }
    let f = findings::of(&r);
    let u = of(&f, "up-over-serial");
    assert_eq!(u.len(), 1);
    assert_eq!(names(u[0]), ["up_over_serial_min", "up_over_serial_max"]);
    let values: Vec<f64> = u[0].figures.iter().map(|g| g.value).collect();
    assert_eq!(values, [0.5, 1.0]);
    assert!(
        u[0].sentence.starts_with("UP runs at 0.50-1.00 × serial over the 4 rows with both (median trials; lowest at 40×40 workload 0, highest at 40×40 workload 2)"),
        "{}",
        u[0].sentence
    );
}

/// The fixture's DP cells with each hand-off's median a fixed share of 1000 FPS in every row
/// (`share`), and UP's atomic cells at half the others'.
fn handoff_run(share: impl Fn(&Cell) -> f64) -> Results {
    let mut r = fixture();
    for c in &mut r.cells {
        match c.key.mode {
            Mode::Dp => {
                let s = share(c);
                set_median(c, 1000.0 * s);
            }
            Mode::Up => {
                let atomic = method(c) == "atomic";
                set_median(c, if atomic { 500.0 } else { 1000.0 });
            }
            Mode::Serial => {}
        }
    }
    r
}

fn method(c: &Cell) -> String {
    c.key
        .get(Dim::Sync)
        .map(|v| v.to_string())
        .unwrap_or_default()
}

/// DP's shares: atomic the fastest everywhere, condvar the slowest (a quarter in one row, half
/// in the others).
fn dp_share(c: &Cell) -> f64 {
    let worst_row = c.key.size == 40
        && c.key.workload == 2
        && c.key.get(Dim::Threading).map(|v| v.to_string()).as_deref() == Some("spawn");
    match method(c).as_str() {
        "atomic" => 1.0,
        "spin" => 0.9,
        "mutex" => 0.8,
        "mutex-std" => 0.7,
        "condvar-std" => 0.6,
        "condvar" if worst_row => 0.25,
        "condvar" => 0.5,
        other => panic!("no share for {other}"),
    }
}

/// The run's hand-off rankings: UP's, then DP's.
fn handoffs(r: &Results) -> Vec<Finding> {
    let f = findings::of(r).findings;
    f.into_iter().filter(|x| x.id == "handoffs").collect()
}

#[test]
fn handoffs_rank_the_methods_by_their_geometric_mean_share_of_each_rows_fastest() {
    let h = handoffs(&handoff_run(dp_share));
    assert_eq!(h.len(), 2, "one for UP, one for DP: {h:?}");
    let (up, dp) = (&h[0], &h[1]);
    assert!(dp.slice.values.is_empty(), "run-wide");
    // Eight rows (2 sizes × 2 levels × 2 threadings), six methods; condvar's geometric mean is
    // (0.5^7 · 0.25)^(1/8) = 0.5^(9/8).
    let slowest = 0.5f64.powf(9.0 / 8.0);
    assert_eq!(
        dp.sentence,
        format!(
            "In DP, over the 8 rows where all 6 hand-offs ran, the fastest is atomic (1.00 × each row's fastest, geometric mean) and the slowest condvar ({slowest:.2} ×; 0.25 × at worst, in 40×40 workload 2 (threading spawn))."
        )
    );
    assert_eq!(names(dp), ["fastest", "slowest"]);
    assert_eq!(dp.figures[0].cell.as_deref(), Some("atomic"));
    assert_eq!(dp.figures[1].cell.as_deref(), Some("condvar"));
    assert!((dp.figures[0].value - 1.0).abs() < 1e-12);
    assert!((dp.figures[1].value - slowest).abs() < 1e-12);
    assert!(
        up.sentence.starts_with("In UP, over the 8 rows"),
        "{}",
        up.sentence
    );
    assert!(
        up.sentence
            .contains("the slowest atomic (0.50 ×; 0.50 × at worst"),
        "{}",
        up.sentence
    );

    // A row where one method did not run is left out of the ranking.
    let mut r = handoff_run(dp_share);
    let gone = r
        .cells
        .iter()
        .position(|c| c.key.mode == Mode::Dp && c.key.size == 16 && method(c) == "mutex")
        .unwrap();
    r.cells[gone].summary = None;
    let dp = &handoffs(&r)[1];
    assert!(
        dp.sentence
            .starts_with("In DP, over the 7 rows where all 6"),
        "{}",
        dp.sentence
    );
}

#[test]
fn a_run_of_one_handoff_has_no_handoff_ranking_and_one_of_two_has() {
    let mut r = handoff_run(dp_share);
    r.cells
        .retain(|c| c.key.mode == Mode::Serial || method(c) == "atomic");
    assert!(handoffs(&r).is_empty());
    assert!(!findings::of(&r).slice_dims.contains(&"sync".to_string()));

    // Two are enough to rank.
    let mut r = handoff_run(dp_share);
    r.cells
        .retain(|c| c.key.mode == Mode::Serial || ["atomic", "spin"].contains(&method(c).as_str()));
    let dp = &handoffs(&r)[1];
    assert_eq!(
        dp.sentence,
        "In DP, over the 8 rows where all 2 hand-offs ran, the fastest is atomic (1.00 × each row's fastest, geometric mean) and the slowest spin (0.90 ×; 0.90 × at worst, in 16×16 workload 0 (threading pool))."
    );
}

/// The atomic, pool slice's rows as (size, workload, serial, UP, DP) medians.
fn rows(rows: &[(usize, usize, f64, f64, f64)]) -> Results {
    let mut r = fixture();
    for &(size, workload, serial, up, dp) in rows {
        set_median(cell(&mut r, size, workload, Mode::Serial), serial);
        set_median(cell(&mut r, size, workload, Mode::Up), up);
        set_median(cell(&mut r, size, workload, Mode::Dp), dp);
    }
    r
}

/// DP ÷ UP is largest on 16×16 at workload 2, DP ÷ serial on 40×40 at workload 0.
const PEAKS: [(usize, usize, f64, f64, f64); 4] = [
    (16, 0, 1000.0, 900.0, 1200.0),
    (16, 2, 1000.0, 600.0, 1200.0),
    (40, 0, 500.0, 500.0, 900.0),
    (40, 2, 400.0, 400.0, 480.0),
];

fn values(f: &Finding) -> Vec<f64> {
    f.figures.iter().map(|g| g.value).collect()
}

fn interval(f: &Finding) -> [f64; 2] {
    f.figures[0].interval.expect("a ratio carries its interval")
}

#[test]
fn dp_peaks_where_it_gains_most_over_up_and_over_serial() {
    let r = rows(&PEAKS);
    let f = findings::of(&r);
    let up = of(&f, "peak-dp-over-up");
    assert_eq!(up.len(), 1);
    let up = up[0];
    let [lo, hi] = interval(up);
    // Trials 1 % either side of each median: the ratio's interval is about 2 % either side.
    assert!(lo <= 2.0 && 2.0 <= hi && hi - lo < 0.1, "{lo} {hi}");
    assert_eq!(
        up.sentence,
        format!("DP ÷ UP peaks at 2.00 [{lo:.2}, {hi:.2}] on 16×16 at workload 2 (1136 µs) (median trials: DP 1200 FPS, UP 600) (no per-trial records).")
    );
    assert_eq!(up.size, Some(16));
    assert_eq!(names(up), ["dp_over_up", "dp_fps", "up_fps"]);
    assert_eq!(values(up), [2.0, 1200.0, 600.0]);
    let dp_label = cell(&mut r.clone(), 16, 2, Mode::Dp).key.label();
    let up_label = cell(&mut r.clone(), 16, 2, Mode::Up).key.label();
    let cells: Vec<_> = up.figures.iter().map(|g| g.cell.clone().unwrap()).collect();
    assert_eq!(cells, [dp_label.clone(), dp_label, up_label]);
    // Each side's caveat stays on the ratio; the sentence says it once.
    assert_eq!(
        up.figures[0].caveats,
        ["no per-trial records", "no per-trial records"]
    );

    let serial = of(&f, "peak-dp-over-serial");
    assert_eq!(serial.len(), 1);
    let serial = serial[0];
    let [lo, hi] = interval(serial);
    assert!(lo <= 1.8 && 1.8 <= hi && hi - lo < 0.1, "{lo} {hi}");
    assert_eq!(
        serial.sentence,
        format!("DP ÷ serial peaks at 1.80 [{lo:.2}, {hi:.2}] on 40×40 at workload 0 (median trials: DP 900 FPS, serial 500) (no per-trial records).")
    );
    assert_eq!(serial.size, Some(40));
    assert_eq!(names(serial), ["dp_over_serial", "dp_fps", "serial_fps"]);
    assert_eq!(values(serial), [1.8, 900.0, 500.0]);

    // The same trials give the same intervals.
    assert_eq!(findings::of(&r), f);
}

#[test]
fn a_cell_of_no_frames_is_no_base_for_a_peak() {
    // UP ran no frame on 16×16 at workload 2: DP ÷ UP there is no ratio, and the peak is the
    // next largest (40×40 at workload 0, 1.8).
    let mut r = rows(&PEAKS);
    set_median(cell(&mut r, 16, 2, Mode::Up), 0.0);
    let f = findings::of(&r);
    let up = of(&f, "peak-dp-over-up")[0];
    assert_eq!(values(up)[1..], [900.0, 500.0]);
    assert!(
        up.sentence.contains("on 40×40 at workload 0 (median"),
        "{}",
        up.sentence
    );
}

#[test]
fn the_ratio_interval_brackets_the_ratio_of_medians_and_repeats_with_its_seed() {
    let num = [190.0, 195.0, 200.0, 205.0, 210.0];
    let den = [98.0, 99.0, 100.0, 101.0, 102.0];
    let [lo, hi] = findings::median_ratio_interval(&num, &den, 7);
    assert!(1.8 < lo && lo < 2.0 && 2.0 < hi && hi < 2.2, "{lo} {hi}");
    assert_eq!(findings::median_ratio_interval(&num, &den, 7), [lo, hi]);
    // Trials that do not vary give the ratio itself.
    assert_eq!(
        findings::median_ratio_interval(&[300.0; 3], &[100.0; 3], 7),
        [3.0, 3.0]
    );
}

/// Per-trial records of the cell's trials, none slow, in no placement.
fn records(c: &mut Cell) {
    let s = c.summary.as_ref().expect("a measured cell");
    c.trials = s
        .fps_trials
        .iter()
        .map(|&fps| TrialRecord {
            fps,
            breakdown: s.breakdown.clone(),
            step_ratio: None,
            workload_ratio: None,
            round_trip_ns: None,
            taken_away: false,
            slow: None,
            placement: None,
        })
        .collect();
}

/// Sets `fps` as the cell's trials, as a run of that many would record them.
fn set_trials(c: &mut Cell, fps: &[f64]) {
    let s = c.summary.as_mut().expect("a measured cell");
    s.fps_trials = fps.to_vec();
    s.fps = fps[fps.len() / 2];
}

#[test]
fn a_number_carries_its_cells_marks_and_spread_and_the_slice_counts_them() {
    let mut r = rows(&PEAKS);
    // The DP ÷ UP peak's DP cell: trials spread 13 % around 1200 FPS, one of them slow with no
    // cause, on near and far cores, and disturbed beyond the noise threshold.
    let dp = cell(&mut r, 16, 2, Mode::Dp);
    set_trials(dp, &[1050.0, 1190.0, 1200.0, 1206.0, 1206.0]);
    records(dp);
    dp.trials[0].slow = Some(Slow {
        below_median_percent: 12.5,
        causes: vec![Cause::Unexplained],
    });
    for (t, class) in dp.trials.iter_mut().zip([Class::Near, Class::Far]) {
        t.placement = Some(class);
    }
    dp.noise = Some(CellNoise {
        trials: vec![TrialNoise {
            wall_ns: 1000,
            threads: Vec::new(),
            steal_ns: vec![(0, 500)],
        }],
        threshold_percent: 5.0,
        retries: 0,
    });
    // UP's lowest row over serial, and another UP cell: trials spread exactly the bound, which
    // is not over it.
    set_trials(
        cell(&mut r, 16, 2, Mode::Up),
        &[585.0, 600.0, 600.0, 600.0, 615.0],
    );
    set_trials(
        cell(&mut r, 40, 2, Mode::Up),
        &[390.0, 400.0, 400.0, 400.0, 410.0],
    );
    let f = findings::of(&r);

    let peak = of(&f, "peak-dp-over-up")[0];
    assert_eq!(
        peak.figures[0].caveats,
        ["DP †‡§", "DP's trials spread 13 %", "no per-trial records"]
    );
    assert_eq!(
        peak.figures[1].caveats,
        ["DP †‡§", "DP's trials spread 13 %"]
    );
    assert_eq!(peak.figures[2].caveats, ["no per-trial records"]);
    assert!(
        peak.sentence
            .ends_with("UP 600) (DP †‡§; DP's trials spread 13 %; no per-trial records)."),
        "{}",
        peak.sentence
    );

    let up = of(&f, "up-over-serial")[0];
    assert_eq!(up.figures[0].name, "up_over_serial_min");
    assert_eq!(
        up.figures[0].caveats,
        ["no per-trial records", "no per-trial records"]
    );

    let marks = of(&f, "marks");
    assert_eq!(marks.len(), 1);
    assert_eq!(
        marks[0].sentence,
        "Marks over the 12 cells: 1 † (noisy), 1 ‡ (unexplained slow trial), 1 § (mixed placements); 1 with trials spread over 5 %; 11 have no per-trial records."
    );
    assert_eq!(
        names(marks[0]),
        [
            "cells",
            "noisy",
            "unexplained",
            "mixed",
            "spread",
            "no_trial_records"
        ]
    );
    assert_eq!(values(marks[0]), [12.0, 1.0, 1.0, 1.0, 1.0, 11.0]);
}

#[test]
fn a_slice_of_recorded_steady_cells_has_none_marked_and_unmeasured_cells_are_not_counted() {
    let mut r = rows(&PEAKS);
    for c in r.cells.iter_mut().filter(|c| c.summary.is_some()) {
        records(c);
    }
    cell(&mut r, 40, 2, Mode::Up).summary = None;
    let f = findings::of(&r);
    let marks = of(&f, "marks")[0];
    assert_eq!(
        marks.sentence,
        "Marks over the 11 cells: none marked; 0 with trials spread over 5 %."
    );
    assert_eq!(values(marks), [11.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
    // A number from recorded, steady cells carries no caveat.
    let peak = of(&f, "peak-dp-over-serial")[0];
    assert!(peak.figures.iter().all(|g| g.caveats.is_empty()));
    assert!(peak.sentence.ends_with("serial 500)."), "{}", peak.sentence);
}

/// A search's entry for `key` that found `balance_us` against a 400 µs step, in no placement.
fn entry(key: CellKey, balance_us: Option<f64>) -> BalanceEntry {
    BalanceEntry {
        balance_us,
        balance_us_low: balance_us.map(|b| b - 20.0),
        balance_us_high: balance_us.map(|b| b + 20.0),
        ..BalanceEntry::new(key, 400.0)
    }
}

fn placement_balance(placement: Class, step_us: f64) -> PlacementBalance {
    PlacementBalance {
        placement,
        probes: 4,
        round_trip_ns: [100.0, 110.0],
        step_us: Some(step_us),
        balance_us: None,
        balance_us_low: None,
        balance_us_high: None,
        dp_over_serial: None,
        dp_over_up: None,
    }
}

#[test]
fn a_balance_point_is_told_over_the_step_of_its_placement() {
    let mut r = fixture();
    let key = cell(&mut r, 40, 2, Mode::Dp).key.clone();
    // Found in the near placement, whose probes timed the step at 400 µs (the whole search's
    // median step was 450), with DP ÷ serial there and two far probes set aside.
    let mut near = entry(key.clone(), Some(500.0));
    near.step_us = 450.0;
    near.placement = Some(Class::Near);
    near.placements = vec![
        placement_balance(Class::Far, 600.0),
        placement_balance(Class::Near, 400.0),
    ];
    near.dp_over_serial = Some(1.8);
    near.dp_over_serial_low = Some(1.7);
    near.dp_over_serial_high = Some(1.9);
    near.set_aside = 2;
    // No interval for DP ÷ serial, and nothing set aside.
    let mut bare = entry(key.clone(), Some(600.0));
    bare.dp_over_serial = Some(1.5);
    // No balance point, and why.
    let mut none = entry(key.clone(), None);
    none.note = Some("the helper's step outlasts every workload probed".into());
    // Another slice's search is not this slice's.
    let mut spin = entry(
        r.cells
            .iter()
            .find(|c| c.key.mode == Mode::Dp && !in_slice(c, "atomic"))
            .unwrap()
            .key
            .clone(),
        Some(100.0),
    );
    spin.key.size = 16;
    r.balance = vec![near, bare, none, spin];

    let f = findings::of(&r);
    let b = of(&f, "balance");
    let sentences: Vec<&str> = b.iter().map(|x| x.sentence.as_str()).collect();
    assert_eq!(
        sentences,
        [
            "On 40×40, the two threads' work is equal at 500 µs of workload (1.25 × the 400 µs step), placement near; DP ÷ serial there is 1.80 [1.70, 1.90]; 2 probe(s) of another placement set aside.",
            "On 40×40, the two threads' work is equal at 600 µs of workload (1.50 × the 400 µs step); DP ÷ serial there is 1.50.",
            "On 40×40, the search found no balance point: the helper's step outlasts every workload probed.",
        ]
    );
    assert!(b.iter().all(|x| x.size == Some(40)));
    assert_eq!(
        names(b[0]),
        ["balance_us", "step_us", "dp_over_serial_at_balance"]
    );
    assert_eq!(values(b[0]), [500.0, 400.0, 1.8]);
    let intervals: Vec<_> = b[0].figures.iter().map(|g| g.interval).collect();
    assert_eq!(intervals, [Some([480.0, 520.0]), None, Some([1.7, 1.9])]);
    assert_eq!(
        names(b[1]),
        ["balance_us", "step_us", "dp_over_serial_at_balance"]
    );
    assert_eq!(b[1].figures[2].interval, None);
    assert!(b[2].figures.is_empty());
}

#[test]
fn a_level_is_named_by_its_calibrated_time_else_by_its_amount() {
    // Workload 3 without its calibrated level is named by its iterations.
    let mut r = dp_levels([1000.0, 1000.0, 800.0]);
    r.calibration.levels.retain(|l| l.workload != 3);
    let iterations = r
        .cells
        .iter()
        .find(|c| c.key.workload == 3)
        .unwrap()
        .workload_amount();
    let f = findings::of(&r);
    assert_eq!(
        of(&f, "dp-flat")[1].sentence,
        format!("On 40×40, DP stays within 5 % of its workload-0 FPS from workload 0 to workload 2 (1136 µs) (1000-1000 FPS), then falls to 800 at workload 3 ({iterations} iterations) (0.80 ×) (no per-trial records).")
    );
}

#[test]
fn up_over_serial_needs_two_rows() {
    let two = |keep: &[(usize, usize)]| {
        let mut r = rows(&PEAKS);
        r.cells.retain(|c| {
            c.key.mode != Mode::Up
                || !in_slice(c, "atomic")
                || keep.contains(&(c.key.size, c.key.workload))
        });
        r
    };
    let r = two(&[(16, 0), (40, 2)]);
    let f = findings::of(&r);
    let u = of(&f, "up-over-serial");
    assert_eq!(u.len(), 1);
    assert_eq!(
        u[0].sentence,
        "UP runs at 0.90-1.00 × serial over the 2 rows with both (median trials; lowest at 16×16 workload 0, highest at 40×40 workload 2) (no per-trial records)."
    );
    let r = two(&[(16, 0)]);
    assert!(of(&findings::of(&r), "up-over-serial").is_empty());
}

#[test]
fn a_runs_slices_are_its_varying_values_in_the_order_its_threaded_cells_show_them() {
    let r = fixture();
    assert_eq!(findings::slice_dims(&r), [Dim::Sync, Dim::Threading]);
    let labels: Vec<String> = findings::slices(&r).iter().map(|s| s.label()).collect();
    let mut want = Vec::new();
    for threading in ["pool", "spawn"] {
        for sync in [
            "atomic",
            "spin",
            "mutex",
            "condvar",
            "mutex-std",
            "condvar-std",
        ] {
            want.push(format!("sync {sync}, threading {threading}"));
        }
    }
    assert_eq!(labels, want);

    let slices = findings::slices(&r);
    let atomic = &slices[0];
    let key = |mode: Mode, sync: &str| {
        r.cells
            .iter()
            .find(|c| c.key.mode == mode && (mode == Mode::Serial || in_slice(c, sync)))
            .unwrap()
            .key
            .clone()
    };
    assert!(atomic.contains(&key(Mode::Dp, "atomic")));
    assert!(!atomic.contains(&key(Mode::Dp, "spin")));
    // A serial cell has no hand-off, and lies in every slice.
    assert!(slices.iter().all(|s| s.contains(&key(Mode::Serial, ""))));
    assert_eq!(
        findings::Slice::of(&[Dim::Sync, Dim::Threading], &key(Mode::Dp, "atomic")),
        *atomic
    );

    let filter = |pairs: &[(&str, &str)]| -> Vec<(String, String)> {
        pairs.iter().map(|&(k, v)| (k.into(), v.into())).collect()
    };
    let matching =
        |pairs: &[(&str, &str)]| slices.iter().filter(|s| s.matches(&filter(pairs))).count();
    assert_eq!(matching(&[("sync", "atomic")]), 2);
    assert_eq!(matching(&[("sync", "atomic"), ("threading", "spawn")]), 1);
    assert_eq!(matching(&[("sync", "nothing")]), 0);
    assert_eq!(matching(&[]), 12);

    // One slice: no dimension sets it apart.
    let mut one = fixture();
    one.cells
        .retain(|c| c.key.mode == Mode::Serial || in_slice(c, "atomic"));
    assert!(findings::slice_dims(&one).is_empty());
    let only = findings::slices(&one);
    assert_eq!(only, [findings::Slice::default()]);
    assert_eq!(only[0].label(), "every cell");

    // A run of serial cells alone has their slice, and its findings.
    let mut serial = fixture();
    serial.cells.retain(|c| c.key.mode == Mode::Serial);
    assert_eq!(findings::slices(&serial), [findings::Slice::default()]);
    let f = findings::of(&serial);
    assert_eq!(
        f.findings.iter().map(|x| x.id.as_str()).collect::<Vec<_>>(),
        ["marks"]
    );
}

#[test]
fn findings_group_by_slice_with_the_run_wide_ones_last_and_print_as_markdown_and_json() {
    let r = handoff_run(dp_share);
    let f = findings::of(&r);
    let groups = f.grouped();
    let headings: Vec<Option<String>> = groups.iter().map(|(h, _)| h.clone()).collect();
    let mut want: Vec<Option<String>> = findings::slices(&r)
        .iter()
        .map(|s| Some(s.label()))
        .collect();
    want.push(Some("Across the run".into()));
    assert_eq!(headings, want);
    let regrouped: Vec<&Finding> = groups.iter().flat_map(|(_, g)| g.clone()).collect();
    assert_eq!(regrouped, f.findings.iter().collect::<Vec<_>>());
    assert_eq!(
        groups
            .last()
            .unwrap()
            .1
            .iter()
            .map(|x| x.id.as_str())
            .collect::<Vec<_>>(),
        ["handoffs", "handoffs"]
    );

    let mut md = String::from("## Findings\n\n");
    for (i, (heading, group)) in groups.iter().enumerate() {
        if i > 0 {
            md.push('\n');
        }
        md.push_str(&format!("**{}**\n\n", heading.as_ref().unwrap()));
        for x in group {
            md.push_str(&format!("- {}\n", x.sentence));
        }
    }
    md.push('\n');
    assert_eq!(f.to_markdown(), md);
    let back: findings::Findings = serde_json::from_str(&f.to_json().unwrap()).unwrap();
    assert_eq!(back, f);

    // One slice: one group, no heading.
    let mut one = fixture();
    one.cells
        .retain(|c| c.key.mode == Mode::Serial || in_slice(c, "atomic"));
    let f = findings::of(&one);
    let groups = f.grouped();
    assert_eq!(groups.len(), 1);
    assert_eq!(groups[0].0, None);
    assert_eq!(groups[0].1.len(), f.findings.len());
    let items: String = f
        .findings
        .iter()
        .map(|x| format!("- {}\n", x.sentence))
        .collect();
    assert_eq!(f.to_markdown(), format!("## Findings\n\n{items}\n"));

    // No finished cell.
    let mut none = fixture();
    for c in &mut none.cells {
        c.summary = None;
    }
    let f = findings::of(&none);
    assert!(f.findings.is_empty());
    assert!(f.grouped().is_empty());
    assert_eq!(f.to_markdown(), "## Findings\n\nNo finished cell yet.\n\n");
}
