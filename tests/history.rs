//! `oceanbench history`: runs ordered by the time they started, a chart per metric with a change
//! of machine marked, and the refusals (one run, runs of different configs).

mod common;

use common::{assert_input_error, assert_success, oceanbench, FIXTURE};
use serde_json::Value;
use std::path::{Path, PathBuf};

/// A copy of the fixture run in `dir/name`, started at `started` on CPU `cpu`, with `edit`
/// applied to it.
fn run_copy(
    dir: &Path,
    name: &str,
    started: &str,
    cpu: &str,
    edit: impl Fn(&mut Value),
) -> PathBuf {
    let mut run: Value = serde_json::from_str(&std::fs::read_to_string(FIXTURE).unwrap()).unwrap();
    run["started"] = started.into();
    run["machine"]["cpu_model"] = cpu.into();
    edit(&mut run);
    let folder = dir.join(name);
    std::fs::create_dir_all(&folder).unwrap();
    std::fs::write(folder.join("results.json"), run.to_string()).unwrap();
    folder
}

#[test]
fn runs_are_drawn_in_time_order_with_a_new_machine_marked() {
    let dir = tempfile::tempdir().unwrap();
    // Given newest first; the middle run is on another CPU than the first.
    let runs = [
        run_copy(dir.path(), "c", "2026-11-27T10:00:00Z", "CPU A", |_| {}),
        run_copy(dir.path(), "a", "2026-11-25T10:00:00Z", "CPU A", |_| {}),
        run_copy(dir.path(), "b", "2026-11-26T10:00:00Z", "CPU B", |_| {}),
    ];
    let charts = dir.path().join("charts");
    let mut args: Vec<&str> = vec!["history"];
    args.extend(runs.iter().map(|p| p.to_str().unwrap()));
    args.extend(["--out", charts.to_str().unwrap(), "--format", "svg"]);
    let out = oceanbench(&args);
    assert_success(&out);
    let stdout = String::from_utf8_lossy(&out.stdout);
    let lines: Vec<&str> = stdout.lines().take(3).collect();
    assert!(
        lines[0].starts_with("1. 2026-11-25") && lines[0].contains("CPU A"),
        "{stdout}"
    );
    assert!(lines[1].starts_with("2. 2026-11-26") && lines[1].ends_with("* another machine"));
    // Back on CPU A is a change too: a step there is the machine's.
    assert!(lines[2].starts_with("3. 2026-11-27") && lines[2].ends_with("* another machine"));
    let svg = std::fs::read_to_string(charts.join("history-fps.svg")).unwrap();
    assert!(svg.contains("FPS across 3 runs"), "the chart's title");
    assert!(
        svg.contains("run 2 ran on another machine"),
        "the change named in a note"
    );
}

#[test]
fn one_run_or_runs_of_different_configs_are_refused_and_nothing_is_drawn() {
    let dir = tempfile::tempdir().unwrap();
    let a = run_copy(dir.path(), "a", "2026-11-25T10:00:00Z", "CPU A", |_| {});
    let b = run_copy(dir.path(), "b", "2026-11-26T10:00:00Z", "CPU A", |r| {
        r["config"]["trials"] = 7.into();
    });
    let charts = dir.path().join("charts");
    let (a, b, out) = (
        a.to_str().unwrap(),
        b.to_str().unwrap(),
        charts.to_str().unwrap(),
    );
    assert_input_error(
        &oceanbench(&["history", a, "--out", out]),
        &["RUN", "at least 2"],
    );
    assert_input_error(
        &oceanbench(&["history", a, b, "--out", out]),
        &["different configs", "trials", "--force"],
    );
    assert!(!charts.exists(), "nothing drawn");
    assert_success(&oceanbench(&[
        "history", a, b, "--out", out, "--force", "--format", "svg",
    ]));
    assert!(charts.join("history-fps.svg").exists());
}
