//! `oceanbench balance` end to end on a tiny mesh: the results family (JSON with every probe,
//! CSV, markdown, chart) holds it, `compare` reads it, and bad input exits 2 with one line.
//! Apart from tests/balance.rs, whose model machine checks the search itself: cargo runs
//! that target first and stops at its failure, so a search broken into an endless loop fails
//! there in seconds instead of hanging the real searches here.

mod common;

use common::{assert_one_line_exit_2, oceanbench};
use oceanbench::affinity;
use oceanbench::report::compare::{self, Metric};
use oceanbench::results::Results;
use std::path::Path;
use std::process::Output;

/// `oceanbench balance` of the 16² cell in `mode`, into `out`, with `args`.
fn balance_16(mode: &str, out: &Path, args: &[&str]) -> Output {
    let mut all = vec!["balance", "--size", "16", "--mode", mode];
    all.extend(args);
    all.extend(["--out", out.to_str().unwrap()]);
    oceanbench(&all)
}

#[test]
fn a_tiny_search_writes_its_files_whatever_else_runs() {
    // A real search on this machine. Its outcome depends on what else runs (a busy machine
    // can hide the balance at 16²), so the checks below hold either way: a DP search that
    // brackets a point, or one line saying on which side the range fell.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("b");
    let two = affinity::allowed_cores().len() > 1;
    let mode = if two { "dp,up" } else { "up" };
    let run = balance_16(
        mode,
        &out,
        &["--points", "4", "--trials", "2", "--tolerance", "10"],
    );
    let stderr = String::from_utf8_lossy(&run.stderr);
    if run.status.code() == Some(2) {
        let last = stderr.trim_end().lines().last().unwrap_or_default();
        assert!(
            two && (last.contains("top of the range") || last.contains("bottom of the range")),
            "{stderr}"
        );
        return;
    }
    assert!(run.status.success(), "{stderr}");
    let results = Results::load(&out).unwrap();
    let modes = mode.split(',').count();
    assert_eq!(results.balance.len(), modes, "{:?}", results.balance);
    for e in &results.balance {
        assert!(e.step_us > 0.0);
        assert!(e.probes.len() >= 4, "the curve's points at least");
        assert!(e.probes.iter().all(|p| p.step_us.len() == 2));
        match e.key.mode.name() {
            "up" => assert!(e.balance_us.is_none() && e.note.is_some()),
            _ if e.set_aside > 0 => assert!(e.note.as_deref().unwrap().contains("set aside")),
            _ => {
                let (b, lo, hi) = (
                    e.balance_us.unwrap(),
                    e.balance_us_low.unwrap(),
                    e.balance_us_high.unwrap(),
                );
                assert!(lo <= b && b <= hi, "{lo} {b} {hi}");
                let r = e.dp_over_serial.unwrap();
                assert!(e.dp_over_serial_low.unwrap() <= r && r <= e.dp_over_serial_high.unwrap());
                assert!(e.dp_over_up.is_some());
            }
        }
    }
    for file in [
        "results.json",
        "results.md",
        "balance.csv",
        "balance-probes.csv",
        "balance.svg",
    ] {
        assert!(out.join(file).exists(), "{file}");
    }
    let md = std::fs::read_to_string(out.join("results.md")).unwrap();
    assert!(md.contains("### Balance points"), "{md}");
    let c = compare::between(&results, &results, 5.0, Metric::Fps);
    let dp = results
        .balance
        .iter()
        .filter(|e| e.balance_us.is_some())
        .count();
    assert_eq!(c.balance.len(), dp);
    assert!(c.balance.iter().all(|b| b.shift_us[0] == 0.0));
}

#[test]
fn bad_balance_input_exits_2_with_one_line() {
    let dir = tempfile::tempdir().unwrap();
    for (args, needle) in [
        (vec!["--tolerance", "0"], "tolerance_percent"),
        (vec!["--range", "10,2"], "range"),
        (vec!["--mode", "serial"], "--mode"),
        (vec!["--size", "1"], "sizes"),
        (
            vec!["--size", "16", "--mode", "up", "--range", "0.5"],
            "--range",
        ),
    ] {
        let out = dir.path().join(format!("x{}", args.len()));
        let mut all = vec!["balance", "--out", out.to_str().unwrap()];
        all.extend(&args);
        assert_one_line_exit_2(&oceanbench(&all), &[needle]);
    }
}

#[test]
fn a_range_without_a_balance_point_is_one_line_and_exit_2() {
    // The model's message (tests/balance.rs), here one line and exit 2; a busy machine can
    // move the waits enough to find a sign change after all, so success is no failure here.
    let dir = tempfile::tempdir().unwrap();
    let mode = if affinity::allowed_cores().len() > 1 {
        "dp"
    } else {
        "up"
    };
    let out = dir.path().join("r");
    let run = balance_16(
        mode,
        &out,
        &["--points", "2", "--trials", "1", "--range", "0.02,0.3"],
    );
    let stderr = String::from_utf8_lossy(&run.stderr);
    if run.status.success() {
        return;
    }
    assert_eq!(run.status.code(), Some(2), "{stderr}");
    let last = stderr.trim_end().lines().last().unwrap_or_default();
    assert!(
        last.contains("of the range (") && last.contains("try a range"),
        "{stderr}"
    );
}
