//! Every trial is kept with its breakdown, canaries and round trips, and a slow one is put down to
//! its causes: in results.json, trials.csv, the markdown (the warning, the "Slow trials" table,
//! ‡), `compare` (a cell with an unexplained slow trial counts as noisy) and `run`. The
//! attribution itself is unit-tested with injected causes (src/slow_trials.rs); here the records
//! flow through every output. Bad thresholds, and flags a mode ignores, are said once.

mod common;

use common::{assert_one_line_exit_2, oceanbench_locked};
use oceanbench::affinity;
use oceanbench::cell::Axes;
use oceanbench::config::{Level, SweepConfig};
use oceanbench::frame_loop::Mode;
use oceanbench::report::compare::{self, Metric};
use oceanbench::report::{csv, markdown};
use oceanbench::results::{CellNoise, Results};
use oceanbench::sched::TrialNoise;
use oceanbench::slow_trials::{Cause, Slow};
use oceanbench::sweep::Sweep;
use oceanbench::sync::SyncMethod;

fn tiny() -> Results {
    let modes = if affinity::allowed_cores().len() >= 2 {
        vec![Mode::Up, Mode::Dp]
    } else {
        vec![Mode::Up]
    };
    let config = SweepConfig {
        name: "slow".into(),
        axes: Axes {
            sizes: vec![24],
            workloads: vec![0, 1],
            modes,
            sync: vec![SyncMethod::Atomic, SyncMethod::Mutex],
            ..Axes::default()
        },
        trials: 3,
        warmup_frames: 2,
        min_frames: 10,
        min_seconds: 0.01,
        workload_levels: vec![Level::micros(0.0), Level::micros(40.0)],
        ..SweepConfig::default()
    };
    Sweep::prepare(config).unwrap().run(&mut ())
}

#[test]
fn every_trial_is_recorded_with_its_breakdown_canaries_and_round_trips() {
    let results = tiny();
    for cell in &results.cells {
        let s = cell.summary.as_ref().unwrap();
        assert_eq!(cell.trials.len(), 3, "{}", cell.key.label());
        for (t, &fps) in cell.trials.iter().zip(&s.fps_trials) {
            assert_eq!(t.fps, fps);
            assert!(t.breakdown.step_ms > 0.0);
            assert!(t.step_ratio.is_some_and(|r| r > 0.0));
            // The workload canary exists exactly where there is synthetic work to time.
            assert_eq!(t.workload_ratio.is_some(), cell.key.workload == 1);
            // Round trips around every trial, UP's too, wherever the sweep has two cores.
            assert_eq!(
                t.round_trip_ns.is_some(),
                affinity::allowed_cores().len() >= 2
            );
            assert_eq!(t.taken_away, {
                let n = cell.noise.as_ref().unwrap();
                n.trials[cell.trials.iter().position(|x| x == t).unwrap()]
                    .is_noisy(n.threshold_percent)
            });
        }
    }
    // The trials are placed from them (a preempted ping-pong may leave one unplaced).
    let two = affinity::allowed_cores().len() >= 2;
    assert_eq!(results.placement.is_some(), two);
    let placed = results.cells.iter().flat_map(|c| &c.trials);
    assert_eq!(placed.filter(|t| t.placement.is_some()).count() > 0, two);
    let text = csv::trials(&results).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap();
    for column in [
        "size",
        "trial",
        "fps",
        "step_ms",
        "workload_ms",
        "step_ratio",
        "workload_ratio",
        "round_trip_before_ns",
        "slow_causes",
    ] {
        assert!(header.split(',').any(|c| c == column), "{column}: {header}");
    }
    assert_eq!(lines.count(), results.cells.len() * 3);
    // The records survive results.json.
    let again: Results = serde_json::from_str(&serde_json::to_string(&results).unwrap()).unwrap();
    assert_eq!(again.cells, results.cells);
}

/// `results` with trial 2 of the first cell slow and unexplained, trial 1 of the second slow
/// and taken away, and every cell noisy.
fn doctored() -> Results {
    let mut results = tiny();
    // Whatever the machine did to the real trials, start from none slow.
    for t in results.cells.iter_mut().flat_map(|c| c.trials.iter_mut()) {
        t.slow = None;
    }
    let slow = |causes: Vec<Cause>| {
        Some(Slow {
            below_median_percent: 40.0,
            causes,
        })
    };
    results.cells[0].trials[1].slow = slow(vec![Cause::Unexplained]);
    results.cells[1].trials[0].slow = slow(vec![Cause::TakenAway, Cause::SlowHelperCore]);
    for (i, c) in results.cells.iter_mut().enumerate() {
        let busy = TrialNoise {
            wall_ns: 1_000_000,
            steal_ns: vec![(0, 100_000 + i as u64 * 10_000)],
            ..TrialNoise::default()
        };
        c.noise = Some(CellNoise {
            trials: vec![busy],
            threshold_percent: 2.0,
            retries: 0,
        });
    }
    results
}

#[test]
fn markdown_says_how_many_trials_each_cause_explains_and_lists_them() {
    let results = doctored();
    let md = markdown::to_string(&results);
    let warning = md
        .lines()
        .find(|l| l.contains("trials ran more than 10% below"))
        .unwrap_or_else(|| panic!("{md}"));
    let total = results.cells.len() * 3;
    assert!(
        warning.contains(&format!("2 of {total} trials")),
        "{warning}"
    );
    assert!(warning.contains("taken away 1"), "{warning}");
    assert!(warning.contains("slow helper core 1"), "{warning}");
    assert!(warning.contains("unexplained 1"), "{warning}");
    assert!(md.contains("### Slow trials"), "{md}");
    let first = results.cells[0].key.label();
    assert!(
        md.lines()
            .any(|l| l.starts_with(&format!("| {first} | 2 |")) && l.contains("unexplained")),
        "{md}"
    );
    assert!(
        md.contains('‡'),
        "the cell with an unexplained slow trial is marked"
    );
    // Noisy cells: one line, the worst five named, the rest listed below.
    let noisy = md
        .lines()
        .find(|l| l.contains("cells kept trials in which"))
        .unwrap();
    let n = results.cells.len();
    assert!(noisy.contains(&format!("{n} of {n} cells")), "{noisy}");
    assert!(n > 5 || affinity::allowed_cores().len() < 2, "{n} cells");
    if n > 5 {
        assert!(noisy.contains("\"Noisy cells\""), "{noisy}");
        // The list under the noisy-cells heading, not the findings' bullets above it.
        let list = &md[md.find("### Noisy cells").expect("the list's heading")..];
        assert_eq!(list.matches("\n- ").count(), n, "{md}");
    }
    let named = results
        .cells
        .iter()
        .filter(|c| noisy.contains(&format!("{} (off", c.key.label())))
        .count();
    assert_eq!(named, n.min(5), "{noisy}");
    // The worst first: the last cell has the most steal.
    let last = results.cells[n - 1].key.label();
    assert!(noisy.contains(&format!("the worst: {last} (")), "{noisy}");
}

#[test]
fn compare_marks_a_verdict_resting_on_an_unexplained_slow_trial() {
    let mut base = tiny();
    for t in base.cells.iter_mut().flat_map(|c| c.trials.iter_mut()) {
        t.slow = None;
    }
    let mut new = base.clone();
    new.cells[0].trials[1].slow = Some(Slow {
        below_median_percent: 30.0,
        causes: vec![Cause::Unexplained],
    });
    let mut quiet = base.clone();
    for c in new.cells.iter_mut().chain(quiet.cells.iter_mut()) {
        c.noise = None;
    }
    let report = compare::between(&quiet, &new, 5.0, Metric::Fps);
    let label = new.cells[0].key.label();
    let noisy: Vec<&str> = report
        .changes
        .iter()
        .filter(|c| c.noisy)
        .map(|c| c.label.as_str())
        .collect();
    assert_eq!(noisy, [label.as_str()]);
}

#[test]
fn a_threshold_outside_0_to_100_is_refused_and_ignored_flags_are_said_once() {
    // Its runs take cores: its own lock folder keeps it from waiting on other tests' locks.
    let locks = std::env::temp_dir().join("oceanbench-test-slow");
    for bad in ["0", "100", "-5"] {
        let flag = format!("--slow-trial-percent={bad}");
        assert_one_line_exit_2(
            &oceanbench_locked(&locks, &["run", &flag]),
            &["--slow-trial-percent:"],
        );
    }
    let err = SweepConfig::from_json(r#"{"slow_trial_percent": 250}"#)
        .unwrap_err()
        .to_string();
    assert!(err.contains("slow_trial_percent: must be above 0"), "{err}");
    let out = oceanbench_locked(
        &locks,
        &[
            "run", "--mode", "serial", "--sync", "condvar", "--depth", "2", "--size", "8",
            "--frames", "5", "--trials", "1",
        ],
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{stderr}");
    let said: Vec<&str> = stderr.lines().filter(|l| l.contains("ignored")).collect();
    assert_eq!(said.len(), 1, "{stderr}");
    assert!(
        said[0].contains("--sync") && said[0].contains("--depth"),
        "{stderr}"
    );
}
