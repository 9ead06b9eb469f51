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

/// The fixture's Figure 5-1 of the atomic hand-off to a pool thread.
const FIGURE: &str = "figure-5-1-sync-atomic-threading-pool";

/// The charts a results file from before run-ahead depth and balance searches can draw: Figure
/// 5-1 and the speed-up once per slice, the fixture's methods with each way of running the
/// helper (a pool thread, or one spawned per frame); the charts that lay the methods out once
/// per way of running the helper.
fn old_charts() -> Vec<String> {
    let axes = fixture().config.axes;
    let mut charts = vec![];
    for chart in ["figure-5-1", "relative"] {
        for sync in &axes.sync {
            for threading in &axes.threading {
                charts.push(format!("{chart}-sync-{sync}-threading-{threading}"));
            }
        }
    }
    for chart in ["sync", "frame-times", "breakdown"] {
        for threading in &axes.threading {
            charts.push(format!("{chart}-threading-{threading}"));
        }
    }
    charts
}

#[test]
fn fixture_charts_every_chart_in_both_formats() {
    let dir = tempfile::tempdir().unwrap();
    let options = ChartOptions {
        formats: vec![ChartFormat::Png, ChartFormat::Svg],
        ..ChartOptions::default()
    };
    let drawn = chart::draw_with(&[fixture()], dir.path(), &options).unwrap();
    let files = drawn.files;
    assert_eq!(files.len(), old_charts().len() * 2);
    let skipped: Vec<&str> = drawn.skipped.iter().map(|s| s.chart.as_str()).collect();
    assert_eq!(skipped, ["latency-vs-fps", "balance"]);
    assert!(drawn.skipped[0].reason.contains("latency"));
    assert!(drawn.skipped[1].reason.contains("balance"));
    for name in old_charts() {
        let (w, h) = png_size(&file(&files, &format!("{name}.png")));
        assert_eq!(w, CHART_SIZE.0, "{name}");
        assert!(h >= CHART_SIZE.1, "{name}");
        svg_text(&file(&files, &format!("{name}.svg")));
    }
    assert_eq!(
        png_size(&file(&files, &format!("{FIGURE}.png"))),
        CHART_SIZE
    );
}

#[test]
fn svgs_name_every_series_and_the_machine() {
    let dir = tempfile::tempdir().unwrap();
    let files = chart::draw(&[fixture()], dir.path(), &[ChartFormat::Svg]).unwrap();
    assert!(files.iter().all(|f| f.extension().unwrap() == "svg"));
    let expect: [(&str, &[&str]); 5] = [
        (
            FIGURE,
            &[
                "serial",
                "UP (1 core)",
                "DP (2 cores)",
                "16×16 mesh",
                "40×40 mesh",
            ],
        ),
        (
            "relative-sync-mutex-threading-spawn",
            &[
                "DP ÷ UP",
                "DP ÷ serial",
                "ideal 2.0",
                "mutex hand-off",
                "spawn helper",
            ],
        ),
        (
            "sync-threading-pool",
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
            "frame-times-threading-spawn",
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
            "breakdown-threading-pool",
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
    assert_eq!(files.len(), old_charts().len() * 2);
    let figure = svg_text(&file(&files, &format!("{FIGURE}.svg")));
    assert!(figure.contains("missing"), "{figure}");
    assert!(figure.contains("40×40 w0 DP"), "{figure}");
    assert_eq!(
        png_size(&file(&files, &format!("{FIGURE}.png"))),
        CHART_SIZE
    );
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
    let text = svg_text(&file(&files, &format!("{FIGURE}.svg")));
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
    let text = svg_text(&file(&files, &format!("{FIGURE}.svg")));
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
    let text = svg_text(&file(&drawn.files, "breakdown-threading-pool.svg"));
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
        let text = svg_text(&file(&files, "sync-threading-pool.svg"));
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
        let frames = svg_text(&file(&files, "frame-times-threading-pool.svg"));
        assert_eq!(frames.lines().any(|l| l.trim() == "serial"), serial);
        assert!(!frames.contains("triple-buffer"), "{frames}");
        assert!(!frames.contains("missing"), "{frames}");
    }
}

/// A committed run's results, as `oceanbench chart RUN` reads them.
fn committed(run: &str) -> oceanbench::results::Results {
    let path = common::root()
        .join("results")
        .join(run)
        .join("results.json");
    oceanbench::results::Results::load(&path).unwrap()
}

/// The texts of an SVG chart drawn at `size` px (plotters' size; the SVG's font-size is that
/// ÷ 1.24), in drawing order.
fn texts_at(svg: &str, size: f64) -> Vec<String> {
    let doc = roxmltree::Document::parse(svg).unwrap();
    doc.descendants()
        .filter(|n| n.has_tag_name("text"))
        .filter(|n| {
            n.attribute("font-size")
                .and_then(|f| f.parse::<f64>().ok())
                .is_some_and(|f| (f * 1.24 - size).abs() < 0.01)
        })
        .filter_map(|n| Some(n.text()?.trim().to_string()))
        .collect()
}

/// The chart's title, its wrapped lines joined.
fn title(svg: &str) -> String {
    texts_at(svg, 26.0).join(" ")
}

/// The colours its bars and legend boxes are filled with: one per series.
fn series(svg: &str) -> usize {
    let doc = roxmltree::Document::parse(svg).unwrap();
    let mut fills: Vec<&str> = doc
        .descendants()
        .filter(|n| n.has_tag_name("rect"))
        .filter_map(|n| n.attribute("fill"))
        .filter(|f| *f != "#FFFFFF")
        .collect();
    fills.sort_unstable();
    fills.dedup();
    fills.len()
}

/// Figure 5-1 and the speed-up of each slice of a committed run: the slice's part of the file
/// stem, the values its title must name and the unit its workload axis must name; and the
/// charts the run has nothing to show in.
struct Expect {
    run: &'static str,
    slices: &'static [(&'static str, &'static [&'static str], &'static str)],
    skipped: &'static [&'static str],
}

#[test]
fn figure_5_1_and_the_speed_up_are_drawn_per_slice_titled_with_every_value() {
    // Values every title names though they are the defaults.
    let defaults = ["fifo policy", "pool helper", "reference kernel"];
    let cases = [
        Expect {
            run: "fog-20261125T163342Z",
            slices: &[
                (
                    "workload_kind-synthetic",
                    &["synthetic workload", "regular grid"],
                    "µs",
                ),
                (
                    "workload_kind-fog",
                    &["fog workload", "atomic hand-off"],
                    "voxels",
                ),
            ],
            skipped: &["sync", "latency-vs-fps", "balance"],
        },
        Expect {
            run: "fft-spray-20261125T162607Z",
            slices: &[
                (
                    "helpers-1-depth-1-consume-copy",
                    &["1 helper,", "depth 1", "copy consume"],
                    "particles",
                ),
                (
                    "helpers-2-depth-2-consume-handle",
                    &["2 helpers", "depth 2", "handle consume"],
                    "particles",
                ),
                (
                    "helpers-2-depth-1-consume-copy",
                    &["2 helpers", "depth 1", "fft ocean"],
                    "particles",
                ),
            ],
            skipped: &["sync", "balance"],
        },
        Expect {
            run: "projected-20261125T163816Z",
            slices: &[
                ("grid-regular", &["regular grid", "analytic normals"], "µs"),
                (
                    "grid-projected",
                    &["projected grid", "synthetic workload"],
                    "µs",
                ),
            ],
            skipped: &["sync", "latency-vs-fps"],
        },
        Expect {
            run: "figure-5-1-20261125T064618Z",
            slices: &[
                ("sync-atomic", &["atomic hand-off"], "µs"),
                ("sync-mutex", &["mutex hand-off"], "µs"),
                ("sync-condvar", &["condvar hand-off"], "µs"),
            ],
            skipped: &["latency-vs-fps", "balance"],
        },
    ];
    for case in cases {
        let charts = chart::svgs(&[committed(case.run)], &ChartOptions::default()).unwrap();
        let run = case.run;
        for (chart, count) in [("figure-5-1", 3), ("relative", 2)] {
            let drawn: Vec<&str> = charts
                .iter()
                .filter(|c| c.chart == chart)
                .map(|c| c.name.as_str())
                .collect();
            assert!(drawn.len() >= case.slices.len(), "{run}: {drawn:?}");
            for (slice, values, unit) in case.slices {
                let name = format!("{chart}-{slice}");
                let svg = charts
                    .iter()
                    .find(|c| c.name == name)
                    .unwrap_or_else(|| panic!("{run}: no {name} in {drawn:?}"));
                let svg = svg.drawn.as_ref().unwrap();
                let title = title(svg);
                for v in values.iter().chain(&defaults) {
                    assert!(
                        title.contains(v),
                        "{run} {name}: title {title:?} lacks {v:?}"
                    );
                }
                assert_eq!(series(svg), count, "{run} {name}: series");
                let axes = texts_at(svg, 17.0);
                let workload = axes.iter().find(|a| a.starts_with("workload level"));
                assert!(
                    workload.is_some_and(|a| a.contains(unit)),
                    "{run} {name}: no workload axis in {unit}: {axes:?}"
                );
            }
        }
        for name in case.skipped {
            let c = charts.iter().find(|c| c.name == *name).unwrap();
            assert!(c.drawn.is_err(), "{run}: {name} has nothing to show");
        }
    }
}

/// UP's breakdown bars are wall time on the one core both threads share, longer than the
/// workload alone; the chart says so with both numbers.
#[test]
fn the_breakdown_says_why_ups_workload_bar_is_longer() {
    let charts = chart::svgs(
        &[committed("fog-20261125T163342Z")],
        &ChartOptions::default(),
    )
    .unwrap();
    let svg = charts
        .iter()
        .find(|c| c.name == "breakdown-workload_kind-fog")
        .unwrap();
    let text = texts_at(svg.drawn.as_ref().unwrap(), 16.0).join(" ");
    assert!(text.contains("In UP both threads share one core"), "{text}");
    assert!(
        text.contains("where the workload alone (serial) takes"),
        "{text}"
    );
}

/// A chart names the values it holds, not one value of a dimension it lays out: the run-ahead
/// chart draws every depth and consumption, so its subtitle names neither.
#[test]
fn the_run_ahead_chart_does_not_name_one_depth() {
    let run = committed("fft-spray-20261125T162607Z");
    let charts = chart::svgs(&[run], &ChartOptions::default()).unwrap();
    let svg = charts
        .iter()
        .find(|c| c.name == "latency-vs-fps-helpers-2")
        .unwrap();
    let text = title(svg.drawn.as_ref().unwrap());
    assert!(
        text.contains("spray workload") && text.contains("fft ocean"),
        "{text}"
    );
    assert!(
        !text.contains("depth 1") && !text.contains("copy consume"),
        "{text}"
    );
}

/// The charts each slice of a committed run gets beside Figure 5-1 and the speed-up, by file
/// stem, with the values each title must name; the dimensions a chart lays out itself (the
/// hand-off method, run-ahead's depth and consumption) split no chart and are named by none.
struct PerSlice {
    run: &'static str,
    charts: &'static [(&'static str, &'static [&'static str])],
    not_named: &'static [&'static str],
}

#[test]
fn every_chart_is_drawn_per_slice_titled_with_every_value() {
    let defaults = ["fifo policy", "pool helper", "reference kernel"];
    let cases = [
        PerSlice {
            run: "fog-20261125T163342Z",
            charts: &[
                (
                    "frame-times-workload_kind-synthetic",
                    &["synthetic workload", "regular grid"],
                ),
                ("frame-times-workload_kind-fog", &["fog workload"]),
                ("breakdown-workload_kind-synthetic", &["synthetic workload"]),
                (
                    "breakdown-workload_kind-fog",
                    &["fog workload", "1 helper,"],
                ),
            ],
            not_named: &["atomic hand-off"],
        },
        PerSlice {
            run: "fft-spray-20261125T162607Z",
            charts: &[
                (
                    "frame-times-helpers-1-depth-1-consume-copy",
                    &["1 helper,", "depth 1", "copy consume", "spray workload"],
                ),
                (
                    "breakdown-helpers-2-depth-2-consume-handle",
                    &["2 helpers", "depth 2", "handle consume", "fft ocean"],
                ),
                ("latency-vs-fps-helpers-1", &["1 helper,", "spray workload"]),
                ("latency-vs-fps-helpers-2", &["2 helpers", "fft ocean"]),
            ],
            not_named: &["atomic hand-off", "copy consume", "depth 1"],
        },
        PerSlice {
            run: "projected-20261125T163816Z",
            charts: &[
                ("frame-times-grid-projected", &["projected grid"]),
                ("breakdown-grid-regular", &["regular grid"]),
                (
                    "balance-grid-regular",
                    &["regular grid", "analytic normals"],
                ),
                (
                    "balance-grid-projected",
                    &["projected grid", "atomic hand-off"],
                ),
            ],
            not_named: &[],
        },
    ];
    for case in cases {
        let run = case.run;
        let charts = chart::svgs(&[committed(run)], &ChartOptions::default()).unwrap();
        let names: Vec<&str> = charts.iter().map(|c| c.name.as_str()).collect();
        // No chart is drawn for the run as a whole beside its slices' charts.
        for chart in ["frame-times", "breakdown"] {
            assert!(!names.contains(&chart), "{run}: {names:?}");
        }
        for (name, values) in case.charts {
            let svg = charts
                .iter()
                .find(|c| c.name == *name)
                .unwrap_or_else(|| panic!("{run}: no {name} in {names:?}"));
            let title = title(svg.drawn.as_ref().unwrap());
            for v in values.iter().chain(&defaults) {
                assert!(title.contains(v), "{run} {name}: {title:?} lacks {v:?}");
            }
            for v in case.not_named.iter().filter(|v| !values.contains(v)) {
                if !name.starts_with("balance") {
                    assert!(!title.contains(v), "{run} {name}: {title:?} names {v:?}");
                }
            }
        }
    }
}
