//! `oceanbench balance` end to end on a tiny mesh: the search brackets a balance point, the
//! results family (JSON with every probe, CSV, markdown, chart) holds it, `compare` reads it,
//! and bad input exits 2 with one line.

use oceanbench::affinity;
use oceanbench::report::compare::{self, Metric};
use oceanbench::results::Results;
use std::process::{Command, Output};

fn oceanbench(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_oceanbench"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("the binary runs")
}

#[test]
fn a_tiny_search_brackets_the_balance_and_writes_its_files() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("b");
    let mode = if affinity::allowed_cores().len() > 1 {
        "dp,up"
    } else {
        "up"
    };
    let run = oceanbench(&[
        "balance",
        "--size",
        "16",
        "--mode",
        mode,
        "--points",
        "4",
        "--trials",
        "2",
        "--tolerance",
        "10",
        "--out",
        out.to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "{stderr}");
    let results = Results::load(&out).unwrap();
    // One entry per searched cell: the loop below checks nothing if the list is empty.
    let modes = mode.split(',').count();
    assert_eq!(results.balance.len(), modes, "{:?}", results.balance);
    assert!(
        results.balance.iter().any(|e| e.balance_us.is_some()) || modes == 1,
        "DP finds a balance point on two cores"
    );
    for e in &results.balance {
        assert!(e.step_us > 0.0);
        assert!(e.probes.len() >= 4, "the curve's points at least");
        match e.key.mode.name() {
            "up" => assert!(e.balance_us.is_none() && e.note.is_some()),
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
        let run = oceanbench(&all);
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert_eq!(run.status.code(), Some(2), "{args:?}: {stderr}");
        assert_eq!(stderr.trim_end().lines().count(), 1, "{args:?}: {stderr}");
        assert!(stderr.contains(needle), "{args:?}: {stderr}");
    }
}

#[test]
fn a_range_without_a_balance_point_says_which_side_and_suggests_one() {
    let dir = tempfile::tempdir().unwrap();
    let mode = if affinity::allowed_cores().len() > 1 {
        "dp"
    } else {
        "up"
    };
    let out = dir.path().join("r");
    // Up to a third of the step the main thread always waits for the mesh.
    let run = oceanbench(&[
        "balance",
        "--size",
        "16",
        "--mode",
        mode,
        "--points",
        "2",
        "--trials",
        "1",
        "--range",
        "0.02,0.3",
        "--out",
        out.to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    if mode == "up" {
        assert!(
            run.status.success(),
            "up has no balance point to bracket: {stderr}"
        );
        return;
    }
    assert_eq!(run.status.code(), Some(2), "{stderr}");
    assert_eq!(
        stderr
            .trim_end()
            .lines()
            .last()
            .map(|l| l.contains("top of the range")),
        Some(true),
        "{stderr}"
    );
    assert!(stderr.contains("\"range\": [0.02, 3]"), "{stderr}");
}
