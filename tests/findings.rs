//! The findings of hand-made runs: each finding's sentence and figures follow from the cells'
//! median trials (the quick fixture's cells with their trials set).

mod common;

use common::fixture;
use oceanbench::cell::{Dim, Mode};
use oceanbench::findings::{self, Finding};
use oceanbench::results::{Cell, Results};

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
