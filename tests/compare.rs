//! Noise-aware comparisons on the quick fixture and on hand-made trials: verdicts, unmatched and
//! failed cells, within-run ranking, errors and the three renderings.

use oceanbench::cell::Dim;
use oceanbench::report::compare::{self, CompareError, Comparison, Metric, Verdict};
use oceanbench::results::{Cell, Results};
use std::path::Path;

fn fixture() -> Results {
    Results::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/quick-results.json"))
        .expect("the fixture loads")
}

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

#[test]
fn fixture_against_itself_is_all_within_noise() {
    let r = fixture();
    let c = compare::between(&r, &r, 5.0, Metric::Fps);
    assert_eq!(c.changes.len(), r.cells.len());
    assert!(c.changes.iter().all(|c| c.verdict == Verdict::WithinNoise));
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
    let base = fixture();
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

#[test]
fn overlapping_trials_are_within_noise() {
    let r = fixture();
    let base = one_cell(&r, &[100.0, 120.0, 80.0]);
    let new = one_cell(&r, &[110.0, 90.0, 115.0]);
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
    let base = one_cell(&r, &[100.0, 101.0, 99.0]);
    let up = one_cell(&r, &[110.0, 111.0, 109.0]);
    let c = compare::between(&base, &up, 5.0, Metric::Fps);
    assert_eq!(c.changes[0].verdict, Verdict::Improved);
    // The same +10% does not clear a 12% threshold.
    let c = compare::between(&base, &up, 12.0, Metric::Fps);
    assert_eq!(c.changes[0].verdict, Verdict::WithinNoise);
}

#[test]
fn single_trial_uses_the_point_estimate_and_is_marked() {
    let r = fixture();
    let base = one_cell(&r, &[100.0]);
    let new = one_cell(&r, &[80.0, 81.0]);
    let c = compare::between(&base, &new, 5.0, Metric::Fps);
    let ch = &c.changes[0];
    assert!(ch.single_trial);
    assert_eq!(ch.ci_low_pct, ch.change_pct);
    assert_eq!(ch.ci_high_pct, ch.change_pct);
    assert_eq!(ch.verdict, Verdict::Regressed);
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
    let r = fixture();
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
    let r = fixture();
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
        let mut one = one_cell(&r, &[100.0, 101.0, 99.0]);
        one.cells[0].summary.as_mut().unwrap().wait_cpu_ms_trials = cpu.to_vec();
        one
    };
    let base = with_cpu(&[1.0, 1.02, 0.98]);
    let more = compare::between(&base, &with_cpu(&[2.0, 2.04, 1.96]), 5.0, Metric::WaitCpu);
    assert_eq!(more.changes[0].verdict, Verdict::Regressed);
    assert!(more.regressed());
    let less = compare::between(&base, &with_cpu(&[0.5, 0.51, 0.49]), 5.0, Metric::WaitCpu);
    assert_eq!(less.changes[0].verdict, Verdict::Improved);
    assert!(less.to_text().contains("waiting CPU ms"));
    let fps = compare::between(&base, &with_cpu(&[2.0, 2.04, 1.96]), 5.0, Metric::Fps);
    assert_eq!(
        fps.changes[0].verdict,
        Verdict::WithinNoise,
        "FPS did not move"
    );
    // Results from before the CPU was recorded cannot be compared on it, and say so.
    let old = compare::between(&r, &r, 5.0, Metric::WaitCpu);
    assert!(old.changes.is_empty() && !old.failed.is_empty());
}
