//! Charts drawn from a real results file: the files exist, decode, and show every series.

mod common;

use common::fixture;
use oceanbench::cell::{Axes, Dim, Value};
use oceanbench::config::{Level, SweepConfig};
use oceanbench::frame_loop::Consume;
use oceanbench::frame_loop::Mode;
use oceanbench::report::chart::{self, ChartFormat, ChartOptions, CHARTS, CHART_SIZE};
use oceanbench::sweep::Sweep;
use oceanbench::sync::SyncMethod;
use std::path::{Path, PathBuf};

fn png_size(path: &Path) -> (u32, u32) {
    let decoder = png::Decoder::new(std::fs::File::open(path).unwrap());
    let reader = decoder.read_info().expect("PNG decodes");
    let info = reader.info();
    (info.width, info.height)
}

/// Every text node of an SVG, which must parse as XML.
fn svg_text(path: &Path) -> String {
    let text = std::fs::read_to_string(path).unwrap();
    let doc = roxmltree::Document::parse(&text).expect("SVG parses");
    doc.descendants()
        .filter_map(|n| n.text())
        .collect::<Vec<_>>()
        .join("\n")
}

fn file(files: &[PathBuf], name: &str) -> PathBuf {
    files
        .iter()
        .find(|f| f.file_name().unwrap() == name)
        .unwrap_or_else(|| panic!("{name} not written: {files:?}"))
        .clone()
}

/// The charts a results file from before run-ahead depth and balance searches can draw.
const OLD_CHARTS: [&str; 5] = ["figure-5-1", "relative", "sync", "frame-times", "breakdown"];

#[test]
fn fixture_charts_every_chart_in_both_formats() {
    let dir = tempfile::tempdir().unwrap();
    let options = ChartOptions {
        formats: vec![ChartFormat::Png, ChartFormat::Svg],
        ..ChartOptions::default()
    };
    let drawn = chart::draw_with(&[fixture()], dir.path(), &options).unwrap();
    let files = drawn.files;
    assert_eq!(files.len(), OLD_CHARTS.len() * 2);
    let skipped: Vec<&str> = drawn.skipped.iter().map(|s| s.chart).collect();
    assert_eq!(skipped, ["latency-vs-fps", "balance"]);
    assert!(drawn.skipped[0].reason.contains("latency"));
    assert!(drawn.skipped[1].reason.contains("balance"));
    for name in OLD_CHARTS {
        let (w, h) = png_size(&file(&files, &format!("{name}.png")));
        assert_eq!(w, CHART_SIZE.0, "{name}");
        assert!(h >= CHART_SIZE.1, "{name}");
        svg_text(&file(&files, &format!("{name}.svg")));
    }
    assert_eq!(png_size(&file(&files, "figure-5-1.png")), CHART_SIZE);
}

#[test]
fn svgs_name_every_series_and_the_machine() {
    let dir = tempfile::tempdir().unwrap();
    let files = chart::draw(&[fixture()], dir.path(), &[ChartFormat::Svg]).unwrap();
    assert!(files.iter().all(|f| f.extension().unwrap() == "svg"));
    let expect: [(&str, &[&str]); 5] = [
        (
            "figure-5-1",
            &[
                "serial",
                "UP (1 core)",
                "DP (2 cores)",
                "16×16 mesh",
                "40×40 mesh",
            ],
        ),
        ("relative", &["DP ÷ UP", "DP ÷ serial", "ideal 2.0"]),
        (
            "sync",
            &[
                "UP (1 core)",
                "DP (2 cores)",
                "atomic",
                "spin",
                "mutex",
                "condvar",
                "mutex-std",
                "condvar-std",
            ],
        ),
        (
            "frame-times",
            &[
                "atomic",
                "spin",
                "mutex",
                "condvar",
                "mutex-std",
                "condvar-std",
                "serial",
                "p99",
            ],
        ),
        (
            "breakdown",
            &[
                "workload (main thread)",
                "waiting for the mesh (main)",
                "UP spin",
                "DP atomic",
                "serial",
            ],
        ),
    ];
    for (name, series) in expect {
        let text = svg_text(&file(&files, &format!("{name}.svg")));
        assert!(
            text.contains("Intel(R) Xeon(R) Processor"),
            "{name}: no machine"
        );
        assert!(text.contains("2026-11-22"), "{name}: no run date");
        for s in series {
            assert!(text.contains(s), "{name}: no {s:?}");
        }
        assert!(!text.contains("missing"), "{name}: the fixture is complete");
    }
}

#[test]
fn missing_cells_still_chart_and_are_named() {
    let mut results = fixture();
    results.cells.retain(|c| {
        !(c.key.size == 40 && c.key.mode == Mode::Dp) && c.key.workload != 0 || c.key.size == 16
    });
    let dir = tempfile::tempdir().unwrap();
    let files = chart::draw(
        &[results],
        dir.path(),
        &[ChartFormat::Png, ChartFormat::Svg],
    )
    .unwrap();
    assert_eq!(files.len(), OLD_CHARTS.len() * 2);
    let figure = svg_text(&file(&files, "figure-5-1.svg"));
    assert!(figure.contains("missing"), "{figure}");
    assert!(figure.contains("40×40 w0 DP"), "{figure}");
    assert_eq!(png_size(&file(&files, "figure-5-1.png")), CHART_SIZE);
}

#[test]
fn failed_cells_are_named_as_failed() {
    let mut results = fixture();
    let cell = results
        .cells
        .iter_mut()
        .find(|c| c.key.size == 40 && c.key.workload == 2 && c.key.mode == Mode::Up)
        .unwrap();
    cell.summary = None;
    cell.error = Some("hand-off timed out".into());
    let dir = tempfile::tempdir().unwrap();
    let files = chart::draw(&[results], dir.path(), &[ChartFormat::Svg]).unwrap();
    let text = svg_text(&file(&files, "figure-5-1.svg"));
    assert!(text.contains("40×40 w2 UP atomic (failed)"), "{text}");
}

#[test]
fn results_without_cells_skip_every_chart_with_a_reason() {
    let mut results = fixture();
    results.cells.clear();
    let dir = tempfile::tempdir().unwrap();
    let drawn = chart::draw_with(&[results], dir.path(), &ChartOptions::default()).unwrap();
    assert!(drawn.files.is_empty());
    assert_eq!(drawn.skipped.len(), CHARTS.len());
    assert!(drawn.skipped.iter().all(|s| !s.reason.is_empty()));
}

#[test]
fn two_runs_side_by_side_are_labelled_by_run() {
    let a = fixture();
    let mut b = fixture();
    b.config.name = "second".into();
    let dir = tempfile::tempdir().unwrap();
    let files = chart::draw(&[a, b], dir.path(), &[ChartFormat::Svg]).unwrap();
    let text = svg_text(&file(&files, "figure-5-1.svg"));
    for s in [
        "quick: UP (1 core)",
        "second: DP (2 cores)",
        "second: serial",
    ] {
        assert!(text.contains(s), "no {s:?}");
    }
}

#[test]
fn a_chosen_cell_drives_the_single_cell_charts() {
    let dir = tempfile::tempdir().unwrap();
    let options = ChartOptions {
        formats: vec![ChartFormat::Svg],
        select: vec![
            (Dim::Size, Value::Count(16)),
            (Dim::Workload, Value::Count(0)),
        ],
    };
    let drawn = chart::draw_with(&[fixture()], dir.path(), &options).unwrap();
    let text = svg_text(&file(&drawn.files, "breakdown.svg"));
    assert!(text.contains("16×16 mesh, workload 0"), "{text}");
}

#[test]
fn run_ahead_is_charted_as_fps_against_latency() {
    let config = SweepConfig {
        name: "pipeline".into(),
        axes: Axes {
            sizes: vec![16],
            workloads: vec![0],
            modes: vec![Mode::Up, Mode::Dp],
            sync: vec![SyncMethod::Atomic, SyncMethod::Mutex, SyncMethod::Condvar],
            depth: vec![1, 2],
            consume: vec![Consume::Copy, Consume::Handle],
            ..Axes::default()
        },
        trials: 1,
        warmup_frames: 2,
        min_frames: 10,
        min_seconds: 0.0,
        workload_levels: vec![Level::micros(0.0)],
        ..SweepConfig::default()
    };
    let results = Sweep::prepare(config).unwrap().run(&mut ());
    let dir = tempfile::tempdir().unwrap();
    let files = chart::draw(&[results], dir.path(), &[ChartFormat::Svg]).unwrap();
    let svg = file(&files, "latency-vs-fps.svg");
    let text = svg_text(&svg);
    for series in [
        "atomic copy",
        "atomic handle",
        "mutex copy",
        "condvar handle",
        "UP (1 core), 16×16 mesh",
        "DP (2 cores), 16×16 mesh",
        "d1",
        "d2",
    ] {
        assert!(text.contains(series), "no {series:?}");
    }
    // Six series (three methods × two consumptions), each its own colour, the same colour in
    // the UP and the DP panel.
    let source = std::fs::read_to_string(&svg).unwrap();
    let doc = roxmltree::Document::parse(&source).unwrap();
    let mut fills: Vec<&str> = doc
        .descendants()
        .filter(|n| n.has_tag_name("circle"))
        .filter_map(|n| n.attribute("fill"))
        .collect();
    fills.sort_unstable();
    fills.dedup();
    assert_eq!(fills.len(), 6, "{fills:?}");
    // Labels never overlap: a two-character label at 13 px is at least 12 px wide and 10 high.
    let labels: Vec<(f64, f64)> = doc
        .descendants()
        .filter(|n| n.has_tag_name("text"))
        .filter(|n| n.text().is_some_and(|t| matches!(t.trim(), "d1" | "d2")))
        .filter_map(|n| {
            Some((
                n.attribute("x")?.parse().ok()?,
                n.attribute("y")?.parse().ok()?,
            ))
        })
        .collect();
    assert!(labels.len() >= 2, "the depths are labelled");
    // UP panels above DP ones.
    let caption_y = |prefix: &str| -> f64 {
        doc.descendants()
            .filter(|n| n.has_tag_name("text"))
            .find(|n| n.text().is_some_and(|t| t.trim().starts_with(prefix)))
            .and_then(|n| n.attribute("y")?.parse().ok())
            .unwrap_or_else(|| panic!("no caption {prefix}"))
    };
    assert!(caption_y("UP (1 core), 16") < caption_y("DP (2 cores), 16"));
    for (i, a) in labels.iter().enumerate() {
        for b in &labels[i + 1..] {
            assert!(
                (a.0 - b.0).abs() >= 12.0 || (a.1 - b.1).abs() >= 10.0,
                "labels at {a:?} and {b:?} overlap"
            );
        }
    }
}

/// The sync chart has a slot only for methods of the chart's policy, and promises a serial
/// line only when the run has serial cells.
#[test]
fn the_sync_chart_shows_only_what_the_run_has() {
    let with_serial = fixture();
    assert!(with_serial.config.axes.modes.contains(&Mode::Serial));
    let mut no_serial = with_serial.clone();
    no_serial.cells.retain(|c| c.key.mode != Mode::Serial);
    no_serial.config.axes.modes.retain(|&m| m != Mode::Serial);
    // A latest-only method listed in the config has no FIFO cell to show.
    no_serial.config.axes.sync.push(SyncMethod::TripleBuffer);
    for (results, serial) in [(with_serial, true), (no_serial, false)] {
        let dir = tempfile::tempdir().unwrap();
        let files = chart::draw(&[results], dir.path(), &[ChartFormat::Svg]).unwrap();
        let text = svg_text(&file(&files, "sync.svg"));
        assert_eq!(text.contains("Dashed line: serial FPS"), serial, "{text}");
        assert_eq!(text.lines().any(|l| l.trim() == "serial"), serial, "{text}");
        assert!(!text.contains("triple-buffer"), "{text}");
        assert!(
            !text.contains("missing"),
            "nothing the run meant to measure is missing: {text}"
        );
        for m in [
            "atomic",
            "spin",
            "mutex",
            "condvar",
            "mutex-std",
            "condvar-std",
        ] {
            assert!(text.lines().any(|l| l.trim() == m), "no group {m}");
        }
        let frames = svg_text(&file(&files, "frame-times.svg"));
        assert_eq!(frames.lines().any(|l| l.trim() == "serial"), serial);
        assert!(!frames.contains("triple-buffer"), "{frames}");
        assert!(!frames.contains("missing"), "{frames}");
    }
}
