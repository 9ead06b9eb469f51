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

/// Ten runs of the fixture's first cell, started a day apart, its trials' FPS times `factor(i)`
/// for run i (from 0) and a seeded spread of about 1 %; the history's output.
fn history_of_ten(dir: &Path, seed: u64, factor: impl Fn(usize) -> f64) -> std::process::Output {
    let mut state = seed;
    let mut noise = move || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        1.0 + ((state >> 33) as f64 / (1u64 << 31) as f64 - 0.5) / 50.0
    };
    let runs: Vec<PathBuf> = (0..10)
        .map(|i| {
            let f = factor(i) * noise();
            run_copy(
                dir,
                &format!("r{i}"),
                &format!("2026-11-{:02}T10:00:00Z", i + 10),
                "CPU A",
                |r| {
                    let cell = r["cells"][0].clone();
                    let trials: Vec<f64> = cell["fps_trials"]
                        .as_array()
                        .unwrap()
                        .iter()
                        .map(|t| t.as_f64().unwrap() * f)
                        .collect();
                    r["cells"] = serde_json::json!([cell]);
                    r["cells"][0]["fps_trials"] = trials.into();
                },
            )
        })
        .collect();
    let charts = dir.join("charts");
    let mut args: Vec<&str> = vec![
        "history",
        "--format",
        "svg",
        "--out",
        charts.to_str().unwrap(),
    ];
    args.extend(runs.iter().map(|p| p.to_str().unwrap()));
    oceanbench(&args)
}

#[test]
fn a_ten_percent_regression_at_run_6_is_found_there_and_fails() {
    let dir = tempfile::tempdir().unwrap();
    let out = history_of_ten(dir.path(), 1, |i| if i >= 5 { 0.9 } else { 1.0 });
    let stdout = String::from_utf8_lossy(&out.stdout);
    let changes: Vec<&str> = stdout
        .lines()
        .filter(|l| l.starts_with("change:"))
        .collect();
    assert_eq!(changes.len(), 1, "{stdout}");
    assert!(
        changes[0].contains("from run 6") && changes[0].contains("regression"),
        "{stdout}"
    );
    assert_eq!(
        out.status.code(),
        Some(1),
        "the newest run follows a regression"
    );
    // The chart marks it: its size as the marker's label, and the change named in a note.
    let percent = changes[0]
        .rsplit_once(": ")
        .and_then(|(_, rest)| rest.split_once(' '))
        .unwrap()
        .0;
    assert!(
        percent.starts_with("-1") || percent.starts_with("-9"),
        "{percent}"
    );
    let svg = std::fs::read_to_string(dir.path().join("charts/history-fps.svg")).unwrap();
    let texts = svg_texts(&svg);
    let x_of = |pred: &dyn Fn(&str) -> bool| {
        texts
            .iter()
            .find(|(_, t)| pred(t))
            .map(|(x, _)| *x)
            .unwrap_or_else(|| panic!("no such text in {texts:?}"))
    };
    let marker = x_of(&|t| t == percent);
    let (run5, run6) = (
        x_of(&|t| t.starts_with("5 ")),
        x_of(&|t| t.starts_with("6 ")),
    );
    assert!(
        (marker - (run5 + run6) / 2.0).abs() <= 2.0,
        "the marker sits between runs 5 and 6: {run5} {marker} {run6}"
    );
    assert!(
        texts.iter().any(|(_, t)| t == changes[0]),
        "the change named in a note"
    );
    // A dashed line runs down the chart where the marker is.
    let dashes = svg
        .lines()
        .filter(|l| l.starts_with("<polyline") && l.contains(&format!("points=\"{marker},")))
        .count();
    assert!(dashes >= 10, "{dashes} dashes at x = {marker}");
}

/// Each `<text>` of an SVG plotters wrote: its x and its content.
fn svg_texts(svg: &str) -> Vec<(f64, String)> {
    svg.split("<text ")
        .skip(1)
        .filter_map(|t| {
            let x = t.strip_prefix("x=\"")?.split('"').next()?.parse().ok()?;
            let body = t.split_once('>')?.1.split_once("</text>")?.0;
            Some((x, body.trim().replace("&apos;", "'")))
        })
        .collect()
}

#[test]
fn unchanged_runs_give_at_most_one_false_change_in_five_series() {
    let mut found = 0;
    for seed in 0..5 {
        let dir = tempfile::tempdir().unwrap();
        let out = history_of_ten(dir.path(), 100 + seed, |_| 1.0);
        let stdout = String::from_utf8_lossy(&out.stdout);
        let changes = stdout.lines().filter(|l| l.starts_with("change:")).count();
        // Every change is reported, and only a regression fails.
        let regression = stdout
            .lines()
            .any(|l| l.starts_with("change:") && l.ends_with("(regression)"));
        assert_eq!(
            out.status.code(),
            Some(if regression { 1 } else { 0 }),
            "{stdout}"
        );
        // The chart notes (and marks) exactly the changes reported.
        let svg = std::fs::read_to_string(dir.path().join("charts/history-fps.svg")).unwrap();
        let noted = svg_texts(&svg)
            .iter()
            .filter(|(_, t)| t.starts_with("change: "))
            .count();
        assert_eq!(noted, changes, "{stdout}");
        found += changes;
    }
    assert!(found <= 1, "{found} false changes");
}
