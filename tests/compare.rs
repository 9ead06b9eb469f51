//! Noise-aware comparisons on the quick fixture and on hand-made trials: verdicts, unmatched and
//! failed cells, within-run ranking, errors and the three renderings.

mod common;

use common::{five_trials, fixture, oceanbench};
use oceanbench::cell::Dim;
use oceanbench::crosscore::PLACEMENT_CHANGE_RATIO;
use oceanbench::report::compare::{
    self, CompareError, Comparison, Metric, Verdict, LEVEL_MISMATCH,
};
use oceanbench::results::latency::LatencyRun;
use oceanbench::results::{Cell, Results};
use std::path::Path;

/// Sets a cell's trials and headline FPS as a run would have measured them.
fn set_trials(cell: &mut Cell, trials: &[f64]) {
    let s = cell.summary.as_mut().expect("a measured cell");
    s.fps_trials = trials.to_vec();
    s.fps = trials.iter().sum::<f64>() / trials.len() as f64;
}

fn one_cell(results: &Results, trials: &[f64]) -> Results {
    let mut r = results.clone();
    r.cells.truncate(1);
    set_trials(&mut r.cells[0], trials);
    r
}

/// A trial record at `fps` in `placement`, both of its round trips `round_trip` ns.
fn trial(fps: f64, placement: &str, round_trip: f64) -> oceanbench::slow_trials::TrialRecord {
    serde_json::from_value(serde_json::json!({
        "fps": fps,
        "breakdown": {"workload_ms": 0.0, "wait_ms": 1.0, "wait_cpu_ms": 1.0, "copy_ms": 0.01,
                      "step_ms": 1.0, "other_ms": 0.0},
        "step_ratio": 1.0, "workload_ratio": null, "round_trip_ns": [round_trip, round_trip],
        "taken_away": false, "placement": placement
    }))
    .unwrap()
}

#[test]
fn fixture_against_itself_is_all_within_noise() {
    let r = five_trials();
    let c = compare::between(&r, &r, 5.0, Metric::Fps);
    assert_eq!(c.changes.len(), r.cells.len());
    assert!(c.changes.iter().all(|c| c.verdict == Verdict::WithinNoise));
    assert!(
        c.warnings.is_empty(),
        "one run is like for like with itself"
    );
    assert!(c.changes.iter().all(|c| c.change_pct == 0.0));
    assert!(c
        .changes
        .iter()
        .all(|c| c.ci_low_pct <= 0.0 && c.ci_high_pct >= 0.0));
    assert!(!c.regressed());
    assert!(c.only_in_base.is_empty() && c.only_in_new.is_empty() && c.failed.is_empty());
    assert!(
        !c.to_text().contains("-0.0%"),
        "no change must not read as a loss"
    );
    let n = r.cells.len();
    assert!(c.to_markdown().contains(&format!(
        "0 improved, 0 regressed, {n} within noise (threshold 5%)"
    )));
}

#[test]
fn halved_cell_is_regressed_and_named() {
    let base = five_trials();
    let mut new = base.clone();
    let victim = new.cells[5].key.label();
    let s = new.cells[5].summary.as_mut().unwrap();
    s.fps /= 2.0;
    s.fps_trials.iter_mut().for_each(|f| *f /= 2.0);

    let c = compare::between(&base, &new, 5.0, Metric::Fps);
    assert!(c.regressed());
    assert_eq!(c.count(Verdict::Regressed), 1);
    let first = &c.changes[0];
    assert_eq!(first.label, victim, "regressions sort first");
    assert_eq!(first.verdict, Verdict::Regressed);
    assert!((first.change_pct + 50.0).abs() < 1e-9);
    assert!(first.ci_high_pct < -5.0);
    assert_eq!(c.count(Verdict::WithinNoise), base.cells.len() - 1);

    let md = c.to_markdown();
    assert!(md.contains(&victim));
    assert!(md.contains("0 improved, 1 regressed"));
    let text = c.to_text();
    let line = text.lines().find(|l| l.contains(&victim)).unwrap();
    assert!(line.starts_with("regressed") && line.contains("-50.0%"));

    // The other way round it is an improvement, and nothing regressed.
    let back = compare::between(&new, &base, 5.0, Metric::Fps);
    assert!(!back.regressed());
    assert_eq!(back.count(Verdict::Improved), 1);
    assert!((back.changes[0].change_pct - 100.0).abs() < 1e-9);
}

/// Regressions come first, worst first; then improvements, largest first.
#[test]
fn changes_sort_worst_regression_first_then_largest_improvement() {
    let base = five_trials();
    let mut new = base.clone();
    for (cell, factor) in [(1, 1.2), (2, 0.8), (3, 1.5), (4, 0.5)] {
        let s = new.cells[cell].summary.as_mut().unwrap();
        s.fps *= factor;
        s.fps_trials.iter_mut().for_each(|f| *f *= factor);
    }
    let c = compare::between(&base, &new, 5.0, Metric::Fps);
    let first: Vec<(Verdict, String)> = c.changes[..4]
        .iter()
        .map(|c| (c.verdict, c.label.clone()))
        .collect();
    let label = |cell: usize| base.cells[cell].key.label();
    assert_eq!(
        first,
        [
            (Verdict::Regressed, label(4)),
            (Verdict::Regressed, label(2)),
            (Verdict::Improved, label(3)),
            (Verdict::Improved, label(1)),
        ]
    );
}

#[test]
fn overlapping_trials_are_within_noise() {
    let r = fixture();
    let base = one_cell(&r, &[100.0, 120.0, 80.0, 100.0, 100.0]);
    let new = one_cell(&r, &[110.0, 90.0, 115.0, 105.0, 105.0]);
    let c = compare::between(&base, &new, 5.0, Metric::Fps);
    let ch = &c.changes[0];
    assert!((ch.change_pct - 5.0).abs() < 1e-9);
    assert!(ch.ci_low_pct < -5.0 && ch.ci_high_pct > 5.0);
    assert_eq!(ch.verdict, Verdict::WithinNoise);
    assert!(!ch.single_trial);
    assert!(!c.regressed());
    // Seeded: the same inputs give the same interval.
    assert_eq!(compare::between(&base, &new, 5.0, Metric::Fps), c);
}

#[test]
fn tight_trials_clear_the_threshold() {
    let r = fixture();
    let base = one_cell(&r, &[100.0, 101.0, 99.0, 100.5, 99.5]);
    let up = one_cell(&r, &[110.0, 111.0, 109.0, 110.5, 109.5]);
    let c = compare::between(&base, &up, 5.0, Metric::Fps);
    assert_eq!(c.changes[0].verdict, Verdict::Improved);
    // The same +10% does not clear a 12% threshold, but its interval excludes 0: it is real,
    // and the words say so rather than "within noise".
    let c = compare::between(&base, &up, 12.0, Metric::Fps);
    let ch = &c.changes[0];
    assert!(ch.ci_low_pct > 0.0 && ch.ci_low_pct < 12.0, "{ch:?}");
    assert_eq!(ch.verdict, Verdict::BelowThreshold);
    assert!(!c.regressed());
    assert!(c.to_text().contains("below threshold"), "{}", c.to_text());
    assert!(c.summary_line().contains("1 below threshold"));
    // Markdown shows it among the notable rows, not folded away with the noise.
    let md = c.to_markdown();
    let notable = md.split("<details>").next().unwrap();
    assert!(notable.contains("| below threshold |"), "{md}");
    // The same drop the other way regresses at 5 % but only reads "below threshold" at 12 %.
    assert_eq!(
        compare::between(&up, &base, 12.0, Metric::Fps).changes[0].verdict,
        Verdict::BelowThreshold
    );
}

/// An interval that includes 0 is "within noise" even when the point estimate is beyond the
/// threshold; with the interval excluding 0 on the other side the same point would be real.
#[test]
fn within_noise_only_when_the_interval_includes_zero() {
    let r = fixture();
    let base = one_cell(&r, &[100.0, 100.0, 100.0, 100.0, 100.0]);
    let wide = one_cell(&r, &[70.0, 150.0, 100.0, 130.0, 90.0]);
    let c = compare::between(&base, &wide, 5.0, Metric::Fps);
    let ch = &c.changes[0];
    assert!(ch.ci_low_pct <= 0.0 && ch.ci_high_pct >= 0.0, "{ch:?}");
    assert_eq!(ch.verdict, Verdict::WithinNoise);
}

#[test]
fn too_few_trials_get_no_verdict_and_never_fail() {
    let r = fixture();
    let few = compare::MIN_TRIALS - 1;
    let base = one_cell(&r, &vec![100.0; few]);
    let halved = one_cell(&r, &vec![50.0; few]);
    let c = compare::between(&base, &halved, 5.0, Metric::Fps);
    let ch = &c.changes[0];
    assert_eq!(ch.verdict, Verdict::TooFewTrials);
    assert!(
        (ch.change_pct + 50.0).abs() < 1e-9,
        "the point estimate is kept"
    );
    assert_eq!((ch.base_trials, ch.new_trials), (few, few));
    assert!(!c.regressed(), "too few trials never fail CI");
    let text = c.to_text();
    assert!(
        text.contains("too few trials") && text.contains("-50.0%"),
        "{text}"
    );
    assert!(text.contains(&format!("n = {few} vs {few}")), "{text}");
    // One side at the minimum is not enough if the other is below it, either way round.
    let five = one_cell(&r, &[50.0; compare::MIN_TRIALS]);
    assert_eq!(
        compare::between(&base, &five, 5.0, Metric::Fps).changes[0].verdict,
        Verdict::TooFewTrials
    );
    let base_five = one_cell(&r, &[100.0; compare::MIN_TRIALS]);
    assert_eq!(
        compare::between(&base_five, &halved, 5.0, Metric::Fps).changes[0].verdict,
        Verdict::TooFewTrials
    );
    // At the minimum on both sides the same halving regresses.
    let base5 = one_cell(&r, &[100.0; compare::MIN_TRIALS]);
    assert!(compare::between(&base5, &five, 5.0, Metric::Fps).regressed());
}

#[test]
fn single_trial_uses_the_point_estimate_and_is_marked() {
    let r = fixture();
    let base = one_cell(&r, &[100.0]);
    let new = one_cell(&r, &[80.0, 81.0, 79.0, 80.0, 80.0]);
    let c = compare::between(&base, &new, 5.0, Metric::Fps);
    let ch = &c.changes[0];
    assert!(ch.single_trial);
    assert_eq!(ch.ci_low_pct, ch.change_pct);
    assert_eq!(ch.ci_high_pct, ch.change_pct);
    assert_eq!(
        ch.verdict,
        Verdict::TooFewTrials,
        "a 1-trial cell never gets a verdict"
    );
    assert!(!c.regressed());
    assert!(c.to_text().contains("* one trial"));
}

#[test]
fn unmatched_and_failed_cells_are_listed() {
    let base = fixture();
    let mut new = base.clone();
    let mut base_less = base.clone();
    let gone_from_new = new.cells.remove(3).key.label();
    let gone_from_base = base_less.cells.remove(7).key.label();
    new.cells[0].summary = None;
    new.cells[0].error = Some("helper thread panicked".into());
    let failed = new.cells[0].key.label();

    let c = compare::between(&base_less, &new, 5.0, Metric::Fps);
    assert_eq!(c.only_in_base, vec![gone_from_new.clone()]);
    assert_eq!(c.only_in_new, vec![gone_from_base.clone()]);
    assert_eq!(c.failed.len(), 1);
    assert!(c.failed[0].contains(&failed) && c.failed[0].contains("helper thread panicked"));
    assert_eq!(c.changes.len(), base.cells.len() - 3);
    for out in [c.to_text(), c.to_markdown(), c.to_json()] {
        assert!(out.contains(&gone_from_new), "{out}");
        assert!(out.contains(&gone_from_base), "{out}");
        assert!(out.contains("helper thread panicked"), "{out}");
    }
}

#[test]
fn within_by_sync_ranks_five_methods_per_group() {
    let r = five_trials();
    let c = compare::within(&r, Dim::Sync, "atomic", 5.0, Metric::Fps).unwrap();
    let groups: Vec<_> = r
        .cells
        .iter()
        .filter(|c| c.key.sync.is_some_and(|s| s.name() == "atomic"))
        .collect();
    assert_eq!(c.changes.len(), groups.len() * 5);
    for g in &groups {
        let group = g.key.label().replace(" atomic", "");
        let mine: Vec<_> = c.changes.iter().filter(|c| c.label == group).collect();
        assert_eq!(mine.len(), 5, "{group}");
        let mut vs: Vec<_> = mine.iter().map(|c| c.versus.clone().unwrap()).collect();
        vs.sort();
        assert_eq!(
            vs,
            [
                "condvar vs atomic",
                "condvar-std vs atomic",
                "mutex vs atomic",
                "mutex-std vs atomic",
                "spin vs atomic"
            ]
        );
    }
    // Serial cells have no hand-off: out of scope, not unmatched.
    assert!(c.only_in_base.is_empty() && c.only_in_new.is_empty());
    // Spin at 125 FPS (up, pool, w0) is a clear regression against atomic at ~16000.
    assert!(c.regressed());
    assert_eq!(c.changes[0].verdict, Verdict::Regressed);
    assert!(c.changes[0].versus.as_deref() == Some("spin vs atomic"));
    assert!(c.to_markdown().contains("FPS by sync against atomic"));
}

#[test]
fn within_by_mode_pairs_serial_with_every_threaded_cell() {
    let r = fixture();
    let serial = r
        .cells
        .iter()
        .filter(|c| c.key.mode.name() == "serial")
        .count();
    let threaded = r.cells.len() - serial;
    let c = compare::within(&r, Dim::Mode, "serial", 5.0, Metric::Fps).unwrap();
    assert_eq!(c.changes.len(), threaded);
    assert!(c
        .changes
        .iter()
        .any(|c| c.label == "16 w0 atomic pool neighbors reference"
            && c.versus.as_deref() == Some("dp vs serial")));
    // up against dp pairs by the full key but mode, and serial against every up cell.
    let c = compare::within(&r, Dim::Mode, "up", 5.0, Metric::Fps).unwrap();
    let up = r.cells.iter().filter(|c| c.key.mode.name() == "up").count();
    assert_eq!(c.changes.len(), up * 2);
}

#[test]
fn bad_baselines_name_the_values_present() {
    let r = fixture();
    let err = compare::within(&r, Dim::Sync, "futexes", 5.0, Metric::Fps).unwrap_err();
    assert!(matches!(err, CompareError::UnknownBaseline { .. }));
    let msg = err.to_string();
    assert!(!msg.contains('\n'));
    for v in [
        "atomic",
        "spin",
        "mutex",
        "condvar",
        "mutex-std",
        "condvar-std",
        "futexes",
    ] {
        assert!(msg.contains(v), "{msg}");
    }

    let mut atomic_only = r.clone();
    atomic_only
        .cells
        .retain(|c| c.key.sync.is_none_or(|s| s.name() != "spin"));
    let err = compare::within(&atomic_only, Dim::Sync, "spin", 5.0, Metric::Fps).unwrap_err();
    assert!(matches!(err, CompareError::AbsentBaseline { .. }));
    assert!(err.to_string().contains("atomic") && !err.to_string().contains("spin,"));

    let err = compare::within(&r, Dim::Normals, "neighbors", 5.0, Metric::Fps).unwrap_err();
    assert!(matches!(err, CompareError::NoAlternative { .. }));
}

#[test]
fn json_round_trips() {
    let r = five_trials();
    let c = compare::within(&r, Dim::Sync, "atomic", 5.0, Metric::Fps).unwrap();
    let back: Comparison = serde_json::from_str(&c.to_json()).unwrap();
    // serde_json's default float parsing may differ from the printed value in the last bit.
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-9 * a.abs().max(1.0);
    assert_eq!(back.changes.len(), c.changes.len());
    assert_eq!((back.by, &back.baseline), (c.by, &c.baseline));
    for (b, a) in back.changes.iter().zip(&c.changes) {
        assert_eq!(
            (&b.label, &b.versus, b.verdict),
            (&a.label, &a.versus, a.verdict)
        );
        assert!(close(b.change_pct, a.change_pct) && close(b.ci_low_pct, a.ci_low_pct));
        assert!(close(b.ci_high_pct, a.ci_high_pct) && close(b.new, a.new));
    }
    assert!(c.to_json().contains("\"verdict\": \"within-noise\""));
}

/// Waiting CPU is better lower: a cell that burns twice the CPU waiting regressed, half improved.
#[test]
fn waiting_cpu_is_compared_with_lower_better() {
    let r = fixture();
    let with_cpu = |cpu: &[f64]| {
        let mut one = one_cell(&r, &[100.0, 101.0, 99.0, 100.5, 99.5]);
        one.cells[0].summary.as_mut().unwrap().wait_cpu_ms_trials = cpu.to_vec();
        one
    };
    let base = with_cpu(&[1.0, 1.02, 0.98, 1.01, 0.99]);
    let double = [2.0, 2.04, 1.96, 2.02, 1.98];
    let more = compare::between(&base, &with_cpu(&double), 5.0, Metric::WaitCpu);
    assert_eq!(more.changes[0].verdict, Verdict::Regressed);
    assert!(more.regressed());
    let half = [0.5, 0.51, 0.49, 0.505, 0.495];
    let less = compare::between(&base, &with_cpu(&half), 5.0, Metric::WaitCpu);
    assert_eq!(less.changes[0].verdict, Verdict::Improved);
    assert!(less.to_text().contains("waiting CPU ms"));
    let fps = compare::between(&base, &with_cpu(&double), 5.0, Metric::Fps);
    assert_eq!(
        fps.changes[0].verdict,
        Verdict::WithinNoise,
        "FPS did not move"
    );
    // Results from before the CPU was recorded cannot be compared on it, and say so.
    let old = compare::between(&r, &r, 5.0, Metric::WaitCpu);
    assert!(old.changes.is_empty() && !old.failed.is_empty());
}

#[test]
fn nothing_matched_is_an_error_not_a_pass() {
    let r = five_trials();
    let mut other = r.clone();
    for c in &mut other.cells {
        c.key.size += 1;
    }
    let c = compare::between(&r, &other, 5.0, Metric::Fps);
    assert!(c.changes.is_empty() && !c.regressed());
    let why = c.nothing_compared().expect("no pair is an error");
    assert!(
        why.contains("no cell matched") && !why.contains('\n'),
        "{why}"
    );
    assert!(compare::between(&r, &r, 5.0, Metric::Fps)
        .nothing_compared()
        .is_none());
    // Pairs that exist but all failed are no comparison either.
    let mut failed = r.clone();
    for c in &mut failed.cells {
        c.summary = None;
        c.error = Some("stalled".into());
    }
    let why = compare::between(&r, &failed, 5.0, Metric::Fps)
        .nothing_compared()
        .unwrap();
    assert!(why.contains("stalled"), "{why}");
}

#[test]
fn runs_that_are_not_like_for_like_are_named() {
    let base = five_trials();
    let mut new = base.clone();
    new.machine.cpu_model = "AMD EPYC".into();
    new.machine.logical_cores = 4;
    for t in new
        .round_trip
        .before
        .iter_mut()
        .chain(&mut new.round_trip.during)
    {
        t.median_ns *= 3.0;
    }
    for t in new.round_trip.after.iter_mut() {
        t.median_ns *= 3.0;
    }
    new.calibration.levels[2].micros *= 1.2;
    let w = compare::mismatches(&base, &new);
    assert_eq!(w.len(), 4, "{w:?}");
    assert!(w[0].contains("AMD EPYC") && w[0].contains(&base.machine.cpu_model));
    assert!(w[1].contains("4") && w[1].contains("core counts"));
    assert!(w[2].contains("placement"));
    assert!(w[3].starts_with("workload 2"), "{w:?}");
    let c = compare::between(&base, &new, 5.0, Metric::Fps);
    assert_eq!(c.warnings, w);
    assert!(c.to_text().contains("warning: different CPUs"));
    assert!(c.to_markdown().contains("**Warning**: workload 2"));
    // Within the noise the sweep itself tolerates, levels and placements are the same.
    let mut near = base.clone();
    near.calibration.levels[2].micros *= 1.05;
    for t in near.round_trip.before.iter_mut() {
        t.median_ns *= 1.5;
    }
    assert!(compare::mismatches(&base, &near).is_empty());
    // Round trips exactly the ratio apart are not over it; a little more is.
    let apart = |ratio: f64| {
        let mut r = base.clone();
        let trips = r
            .round_trip
            .before
            .iter_mut()
            .chain(&mut r.round_trip.during);
        for t in trips.chain(&mut r.round_trip.after) {
            t.median_ns *= ratio;
        }
        compare::mismatches(&base, &r)
    };
    assert!(apart(PLACEMENT_CHANGE_RATIO).is_empty());
    assert_eq!(apart(PLACEMENT_CHANGE_RATIO * 1.01).len(), 1);
}

fn write(dir: &Path, name: &str, r: &Results) -> std::path::PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, serde_json::to_string(r).unwrap()).unwrap();
    p
}

/// The command's exit statuses: 2 when nothing was compared (CI must not pass vacuously), a
/// warning and exit 0 for runs that are not like for like, exit 2 for them with --strict.
#[test]
fn the_command_refuses_vacuous_and_unlike_comparisons() {
    let dir = tempfile::tempdir().unwrap();
    let base = five_trials();
    let mut shifted = base.clone();
    shifted.cells.iter_mut().for_each(|c| c.key.size += 1);
    let mut other_cpu = base.clone();
    other_cpu.machine.cpu_model = "AMD EPYC".into();
    let b = write(dir.path(), "base.json", &base);
    let s = write(dir.path(), "shifted.json", &shifted);
    let o = write(dir.path(), "other.json", &other_cpu);

    let out = oceanbench(&["compare".as_ref(), b.as_os_str(), s.as_os_str()]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("no cell matched") && err.trim().lines().count() == 1,
        "{err}"
    );

    let out = oceanbench(&["compare".as_ref(), b.as_os_str(), o.as_os_str()]);
    assert_eq!(out.status.code(), Some(0), "a warning only");
    assert!(String::from_utf8_lossy(&out.stdout).contains("warning: different CPUs"));

    let strict = oceanbench(&[
        "compare".as_ref(),
        b.as_os_str(),
        o.as_os_str(),
        "--strict".as_ref(),
    ]);
    assert_eq!(strict.status.code(), Some(2));
    let err = String::from_utf8_lossy(&strict.stderr);
    assert!(
        err.contains("--strict") && err.contains("AMD EPYC"),
        "{err}"
    );

    let same = oceanbench(&[
        "compare".as_ref(),
        b.as_os_str(),
        b.as_os_str(),
        "--strict".as_ref(),
    ]);
    assert_eq!(same.status.code(), Some(0));
}

/// The documented minimum: four trials a side are too few, five are enough (docs/ci.md and
/// `compare --help` say 5).
#[test]
fn five_trials_a_side_is_the_documented_minimum() {
    let r = fixture();
    let four = |v: f64| one_cell(&r, &[v, v * 1.001, v * 0.999, v]);
    let five = |v: f64| one_cell(&r, &[v, v * 1.001, v * 0.999, v, v * 1.0005]);
    assert_eq!(
        compare::between(&four(100.0), &four(50.0), 5.0, Metric::Fps).changes[0].verdict,
        Verdict::TooFewTrials
    );
    assert_eq!(
        compare::between(&five(100.0), &five(50.0), 5.0, Metric::Fps).changes[0].verdict,
        Verdict::Regressed
    );
    let help = oceanbench(&["compare", "--help"]);
    let help = String::from_utf8_lossy(&help.stdout);
    assert!(help.contains("fewer than 5"), "{help}");
}

/// A cell re-run and appended to a file is compared once, by its first record.
#[test]
fn a_rerun_cell_is_compared_once() {
    let r = five_trials();
    let mut twice = r.clone();
    let mut again = twice.cells[0].clone();
    set_trials(&mut again, &[1.0; 5]);
    twice.cells.push(again);
    let c = compare::between(&r, &twice, 5.0, Metric::Fps);
    assert_eq!(c.changes.len(), r.cells.len());
    assert!(!c.regressed(), "the second record is not the one compared");
    let c = compare::between(&twice, &r, 5.0, Metric::Fps);
    assert_eq!(
        c.changes.len(),
        r.cells.len(),
        "nor compared twice as a base"
    );
}

/// One noisy trial on one side is enough for the mark.
#[test]
fn one_noisy_trial_marks_the_verdict() {
    let r = fixture();
    let base = one_cell(&r, &[100.0; 5]);
    let mut new = base.clone();
    let quiet = r#"{"wall_ns": 1000000, "threads": [{"thread": "main", "core": 0, "cpu_ns": 1000000, "run_delay_ns": 0, "involuntary_switches": 0}], "steal_ns": []}"#;
    let loud = r#"{"wall_ns": 1000000, "threads": [{"thread": "main", "core": 0, "cpu_ns": 500000, "run_delay_ns": 500000, "involuntary_switches": 9}], "steal_ns": []}"#;
    let noise = |trials: &[&str]| {
        serde_json::from_str(&format!(
            r#"{{"trials": [{}], "threshold_percent": 2.0, "retries": 0}}"#,
            trials.join(",")
        ))
        .unwrap()
    };
    new.cells[0].noise = Some(noise(&[quiet, quiet, quiet, quiet, quiet]));
    assert!(!compare::between(&base, &new, 5.0, Metric::Fps).changes[0].noisy);
    new.cells[0].noise = Some(noise(&[quiet, loud, quiet, quiet, quiet]));
    let c = compare::between(&base, &new, 5.0, Metric::Fps);
    assert!(c.changes[0].noisy);
    assert!(c.to_text().contains("† rests on trials"));
}

/// A change that rounds to zero reads +0.0 %, never -0.0 %, which would read as a loss.
#[test]
fn a_tiny_drop_does_not_print_minus_zero() {
    let r = fixture();
    let base = one_cell(&r, &[100.0; 5]);
    let new = one_cell(&r, &[99.99; 5]);
    let text = compare::between(&base, &new, 5.0, Metric::Fps).to_text();
    assert!(text.contains("+0.0%") && !text.contains("-0.0%"), "{text}");
}

/// A trial of 0 FPS is no measurement; a file from before per-trial FPS stands as one trial.
#[test]
fn zero_fps_fails_and_old_files_use_the_headline() {
    let r = fixture();
    let base = one_cell(&r, &[100.0; 5]);
    let zero = one_cell(&r, &[0.0, 100.0, 100.0, 100.0, 100.0]);
    let c = compare::between(&base, &zero, 5.0, Metric::Fps);
    assert!(c.changes.is_empty() && c.failed.len() == 1, "{c:?}");
    assert!(c.failed[0].contains("no FPS measured"), "{:?}", c.failed);

    let mut old = one_cell(&r, &[100.0; 5]);
    let s = old.cells[0].summary.as_mut().unwrap();
    s.fps_trials.clear();
    s.fps = 80.0;
    let c = compare::between(&base, &old, 5.0, Metric::Fps);
    let ch = &c.changes[0];
    assert!((ch.change_pct + 20.0).abs() < 1e-9, "{ch:?}");
    assert_eq!((ch.new_trials, ch.verdict), (1, Verdict::TooFewTrials));

    // An old file's headline of 0 FPS is no measurement either.
    let s = old.cells[0].summary.as_mut().unwrap();
    s.fps = 0.0;
    let c = compare::between(&base, &old, 5.0, Metric::Fps);
    assert!(c.changes.is_empty() && c.failed.len() == 1, "{c:?}");
    assert!(c.failed[0].contains("no FPS measured"), "{:?}", c.failed);
}

/// The same failure on both sides is listed once.
#[test]
fn a_failure_on_both_sides_is_listed_once() {
    let r = five_trials();
    let mut broken = r.clone();
    broken.cells[0].summary = None;
    broken.cells[0].error = Some("stalled".into());
    let c = compare::between(&broken, &broken, 5.0, Metric::Fps);
    assert_eq!(c.failed.len(), 1, "{:?}", c.failed);
}

/// docs/ci.md quotes configs/ci.json's methods and trials and the trial minimum through blocks
/// that `docs --check` holds to the config and the code, and the config gives a verdict.
#[test]
fn the_ci_docs_match_the_ci_config() {
    let root = common::root();
    let config: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(root.join("configs/ci.json")).unwrap())
            .unwrap();
    let doc = std::fs::read_to_string(root.join("docs/ci.md")).unwrap();
    for block in [
        "<!-- ob:config file=configs/ci.json key=sync -->",
        "<!-- ob:config file=configs/ci.json key=trials -->",
        "fewer than <!-- ob:const name=compare_min_trials -->",
    ] {
        assert!(doc.contains(block), "docs/ci.md lacks {block}");
    }
    assert!(config["trials"].as_u64().unwrap() >= compare::MIN_TRIALS as u64);
}

/// Two cells whose rows resolved the workload to microseconds over `LEVEL_MISMATCH` apart
/// compare other game work: their pair is marked ¶ with its footnote, whatever its verdict;
/// a drift within the bound marks nothing.
#[test]
fn pairs_whose_levels_came_to_other_microseconds_are_marked() {
    use oceanbench::calibrate::RowCalibration;
    use oceanbench::level::Calibrate;
    let base = five_trials();
    let at = base.cells.iter().position(|c| c.summary.is_some()).unwrap();
    let with_level = |r: &Results, micros: f64| {
        let mut r = r.clone();
        r.cells[at].calibration = Some(RowCalibration {
            calibrate: Calibrate::Row,
            step_ms_at_start: 1.0,
            step_ms_in_row: 1.0,
            ns_per_iteration_at_start: 1.0,
            ns_per_iteration_in_row: 1.0,
            level_micros: micros,
            asked_micros: None,
        });
        r
    };
    let (b, drifted, other) = (
        with_level(&base, 1000.0),
        with_level(&base, 1080.0),
        with_level(&base, 1500.0),
    );
    let label = base.cells[at].key.label();
    let marked = |c: &Comparison| c.changes.iter().find(|x| x.label == label).unwrap().level;

    let within = compare::between(&b, &drifted, 5.0, Metric::Fps);
    assert!(!marked(&within));
    assert!(!within.to_markdown().contains('¶'));
    // 100 us of 1000 is the bound itself (0.1 × 1000 rounds to 100 exactly), not over it.
    assert_eq!(LEVEL_MISMATCH, 0.1);
    let bound = compare::between(&b, &with_level(&base, 900.0), 5.0, Metric::Fps);
    assert!(!marked(&bound));

    let c = compare::between(&b, &other, 5.0, Metric::Fps);
    assert!(marked(&c));
    assert_eq!(c.changes.iter().filter(|x| x.level).count(), 1);
    let md = c.to_markdown();
    let row = md.lines().find(|l| l.contains(&label)).unwrap();
    assert!(row.contains('¶'), "{row}");
    assert!(md.contains("¶ compares cells whose workload came to microseconds over 10% apart"));
}

/// `--placement` compares each cell's trials in one placement only: a new run whose near
/// trials are 20% slower regresses there, while its far trials, unchanged, are within noise;
/// a placement where a cell ran no trial leaves it uncompared, never a pass.
#[test]
fn placement_compares_the_trials_of_one_placement() {
    use oceanbench::placement::Class;
    let trial = |fps: f64, placement: &str| trial(fps, placement, 80.0);
    let run = |near: f64, far: f64| -> Results {
        let mut r = one_cell(&fixture(), &[1.0]);
        let jitter = [0.99, 0.995, 1.0, 1.005, 1.01];
        let cell = &mut r.cells[0];
        cell.trials = jitter
            .iter()
            .flat_map(|k| [trial(near * k, "near"), trial(far * k, "far")])
            .collect();
        let fps: Vec<f64> = cell.trials.iter().map(|t| t.fps).collect();
        set_trials(cell, &fps);
        cell.summary.as_mut().unwrap().wait_cpu_ms_trials = (0..10).map(f64::from).collect();
        r
    };
    let (base, new) = (run(100.0, 50.0), run(80.0, 50.0));

    let near = new.in_placement(Class::Near);
    let s = near.cells[0].summary.as_ref().unwrap();
    let expected = [0.99, 0.995, 1.0, 1.005, 1.01].map(|k| 80.0 * k);
    assert_eq!(s.fps_trials, expected);
    assert_eq!(s.wait_cpu_ms_trials, [0.0, 2.0, 4.0, 6.0, 8.0]);
    assert!(near.cells[0]
        .trials
        .iter()
        .all(|t| t.placement == Some(Class::Near)));

    let verdict = |class: Class| {
        compare::between(
            &base.in_placement(class),
            &new.in_placement(class),
            5.0,
            Metric::Fps,
        )
        .changes[0]
            .verdict
    };
    assert_eq!(verdict(Class::Near), Verdict::Regressed);
    assert_eq!(verdict(Class::Far), Verdict::WithinNoise);
    let none = compare::between(
        &base.in_placement(Class::Moved),
        &new.in_placement(Class::Moved),
        5.0,
        Metric::Fps,
    );
    assert!(none.nothing_compared().is_some(), "{}", none.to_text());
}

/// Two trials a side are resampled: a point estimate is kept for a side of one trial alone.
#[test]
fn two_trials_a_side_get_an_interval_and_one_trial_either_side_is_marked() {
    let r = fixture();
    let two = |a: f64, b: f64| one_cell(&r, &[a, b]);
    let c = compare::between(&two(100.0, 104.0), &two(90.0, 96.0), 5.0, Metric::Fps);
    let ch = &c.changes[0];
    assert!(!ch.single_trial, "two trials are not one");
    assert!(ch.ci_low_pct < ch.ci_high_pct, "{ch:?}");
    assert_eq!(ch.verdict, Verdict::TooFewTrials);
    // One trial in the new run alone, as the base's alone is elsewhere.
    let five = one_cell(&r, &[100.0, 101.0, 99.0, 100.0, 100.0]);
    let ch = &compare::between(&five, &one_cell(&r, &[80.0]), 5.0, Metric::Fps).changes[0];
    assert!(ch.single_trial);
    assert_eq!(
        (ch.ci_low_pct, ch.ci_high_pct),
        (ch.change_pct, ch.change_pct)
    );
}

/// A latency row is marked noisy when one of its repeats, in either run, lost its pins.
#[test]
fn a_latency_row_with_an_unpinned_repeat_is_marked_noisy() {
    let base = LatencyRun::load(Path::new("results/latency-20261127T193624Z")).unwrap();
    assert!(base.rows.iter().flat_map(|r| &r.repeats).all(|r| r.pinned));
    let mut new = base.clone();
    new.rows[3].repeats[2].pinned = false;
    let unpinned = new.rows[3].label();
    for (b, n) in [(&base, &new), (&new, &base)] {
        let c = compare::latency_between(b, n, 5.0);
        assert_eq!(c.changes.len(), base.rows.len());
        for ch in &c.changes {
            assert_eq!(ch.noisy, ch.label == unpinned, "{}", ch.label);
        }
    }
}

/// An interval that touches the threshold, or zero, is not past it. Every value here is exact
/// in binary (68 ÷ 64 − 1 is 6.25 %), and a third of the resamples draw no outlier, so the
/// interval's near end lies exactly on the bound.
#[test]
fn an_interval_touching_a_bound_is_not_past_it() {
    let r = fixture();
    let base = one_cell(&r, &[64.0; 5]);
    let verdict = |new: &[f64]| {
        let c = compare::between(&base, &one_cell(&r, new), 6.25, Metric::Fps);
        let ch = c.changes[0].clone();
        (ch.ci_low_pct, ch.ci_high_pct, ch.verdict)
    };
    let (low, high, v) = verdict(&[68.0, 68.0, 68.0, 68.0, 72.0]);
    assert_eq!(low, 6.25, "the interval starts on the threshold");
    assert!(high > 6.25);
    assert_eq!(v, Verdict::BelowThreshold);
    let (low, high, v) = verdict(&[60.0, 60.0, 60.0, 60.0, 56.0]);
    assert_eq!(high, -6.25, "the interval ends on minus the threshold");
    assert!(low < -6.25);
    assert_eq!(v, Verdict::BelowThreshold);
    let (low, high, v) = verdict(&[64.0, 64.0, 64.0, 64.0, 66.0]);
    assert_eq!(
        (low, high > 0.0),
        (0.0, true),
        "the interval starts on zero"
    );
    assert_eq!(v, Verdict::WithinNoise);
    let (low, high, v) = verdict(&[64.0, 64.0, 64.0, 64.0, 62.0]);
    assert_eq!((low < 0.0, high), (true, 0.0), "the interval ends on zero");
    assert_eq!(v, Verdict::WithinNoise);
}

/// A latency row that only one run has is listed on its side and earns no change.
#[test]
fn a_latency_row_in_one_run_alone_is_listed_there() {
    let base = LatencyRun::load(Path::new("results/latency-20261127T193624Z")).unwrap();
    let mut new = base.clone();
    let mut extra = new.rows[0].clone();
    extra.method = "extra".into();
    let label = extra.label();
    new.rows.push(extra);
    let c = compare::latency_between(&base, &new, 5.0);
    assert_eq!(c.only_in_new, std::slice::from_ref(&label));
    assert!(c.only_in_base.is_empty());
    assert_eq!(c.changes.len(), base.rows.len());
    let c = compare::latency_between(&new, &base, 5.0);
    assert_eq!(c.only_in_base, [label]);
    assert!(c.only_in_new.is_empty());
}

/// Runs whose floor rows (ping-pong, the raw cross-core line) lie far apart were measured on
/// different placements, and are told so; the other rows do not decide it.
#[test]
fn latency_runs_with_floors_far_apart_are_named_as_different_placements() {
    use oceanbench::results::latency::FLOOR;
    let base = LatencyRun::load(Path::new("results/latency-20261127T193624Z")).unwrap();
    let placement = |c: &Comparison| {
        c.warnings
            .iter()
            .any(|w| w.starts_with("different core placement"))
    };
    assert!(!placement(&compare::latency_between(&base, &base, 5.0)));
    let scaled = |floor: bool| {
        let mut run = base.clone();
        for row in &mut run.rows {
            if (row.method == FLOOR) == floor {
                for r in &mut row.repeats {
                    r.median_ns *= 3.0;
                    r.batched_ns = r.batched_ns.map(|ns| ns * 3.0);
                }
            }
        }
        run
    };
    assert!(base.rows.iter().any(|r| r.method == FLOOR));
    assert!(placement(&compare::latency_between(
        &base,
        &scaled(true),
        5.0
    )));
    assert!(!placement(&compare::latency_between(
        &base,
        &scaled(false),
        5.0
    )));
}

/// A change is marked for placement when either run's cell mixed placements, or when the two
/// cells' round trips put them on different placements; only when neither holds is it clean.
#[test]
fn a_change_is_marked_for_placement_by_either_side_or_by_their_round_trips() {
    // Five trials alternating between `placements`, every one with the round trip given.
    let run = |placements: [&str; 2], round_trip: f64| -> Results {
        let mut r = one_cell(&fixture(), &[1.0]);
        let cell = &mut r.cells[0];
        cell.trials = [0.99, 0.995, 1.0, 1.005, 1.01]
            .iter()
            .enumerate()
            .map(|(k, f)| trial(100.0 * f, placements[k % 2], round_trip))
            .collect();
        let fps: Vec<f64> = cell.trials.iter().map(|t| t.fps).collect();
        set_trials(cell, &fps);
        r
    };
    let marked = |base: &Results, new: &Results| {
        compare::between(base, new, 5.0, Metric::Fps).changes[0].placement
    };
    let (near, mixed) = (run(["near", "near"], 80.0), run(["near", "far"], 80.0));
    assert!(!marked(&near, &near));
    assert!(marked(&mixed, &near), "the base mixed placements");
    assert!(marked(&near, &mixed), "the new run mixed placements");
    let slow = run(["near", "near"], 400.0);
    assert!(marked(&near, &slow), "round trips five times apart");
    let twice = run(["near", "near"], 80.0 * PLACEMENT_CHANGE_RATIO);
    assert!(
        !marked(&near, &twice),
        "round trips the ratio apart, not over it"
    );
    assert!(
        !marked(&near, &run(["near", "near"], 120.0)),
        "1.5 times apart"
    );
    // A trial that measured no round trip (0 ns) leaves the median to those that did.
    let mut unmeasured = run(["near", "near"], 80.0);
    for t in unmeasured.cells[0].trials.iter_mut().take(3) {
        t.round_trip_ns = Some([0.0, 0.0]);
    }
    assert!(
        !marked(&near, &unmeasured),
        "unmeasured round trips are no placement"
    );
}
