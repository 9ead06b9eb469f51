//! Every declared dimension reaches every place that deals with cells: config keys and their
//! validation, the sweep's expansion, labels, the CSV columns, the markdown tables,
//! `compare --by` and the chart variants. A dimension that one of them forgets fails here.
//!
//! Also the two bugs that motivated the cell model (the CSV and `compare --by mode` ignored
//! `helpers`), and old results files loading.

mod common;

use common::fixture;
use oceanbench::cell::{Axes, Dim, Value};
use oceanbench::config::SweepConfig;
use oceanbench::measure::{FrameRecord, Trial};
use oceanbench::ocean::OceanKind;
use oceanbench::report::chart::{self, ChartFormat, ChartOptions};
use oceanbench::report::compare::{self, Metric};
use oceanbench::report::{csv, markdown};
use oceanbench::results::{Cell, CellKey, Pins, Results};
use oceanbench::summary::Summary;
use serde_json::json;

/// Two values of `dim` and config keys under which cells with both can run. Every dimension
/// must have an entry: a new one fails `every_dimension_has_test_values` until it is added here.
/// A dimension with a single value so far has no second one (`None`): it is walked through
/// the outputs by `every_value_reaches_csv_json_labels_and_compare` alone, until a second
/// value, which `every_dimension_has_test_values` then asks for, lands.
#[allow(clippy::type_complexity)]
fn case(
    dim: Dim,
) -> Option<(
    serde_json::Value,
    Option<serde_json::Value>,
    serde_json::Value,
)> {
    let (a, b, extra) = match dim {
        Dim::Size => (json!(16), Some(json!(24)), json!({})),
        Dim::Workload => (json!(0), Some(json!(1)), json!({})),
        Dim::WorkloadKind => (json!("synthetic"), Some(json!("render")), json!({})),
        Dim::Mode => (json!("up"), Some(json!("dp")), json!({})),
        Dim::Policy => (json!("fifo"), Some(json!("latest")), json!({})),
        Dim::Sync => (json!("atomic"), Some(json!("condvar")), json!({})),
        Dim::Threading => (json!("pool"), Some(json!("spawn")), json!({})),
        Dim::Helpers => (json!(1), Some(json!(2)), json!({"normals": ["analytic"]})),
        Dim::Depth => (json!(1), Some(json!(2)), json!({})),
        Dim::Consume => (json!("copy"), Some(json!("handle")), json!({})),
        Dim::Normals => (json!("neighbors"), Some(json!("analytic")), json!({})),
        Dim::Ocean => (json!("sines"), Some(json!("fft")), json!({})),
        Dim::Kernel => (json!("reference"), Some(json!("fast")), json!({})),
        Dim::Grid => (
            json!("regular"),
            Some(json!("projected")),
            json!({"normals": ["analytic"]}),
        ),
        #[allow(unreachable_patterns)]
        _ => return None,
    };
    Some((a, b, extra))
}

/// A one-cell-per-value config: every list has one value but `dim`, which has its two (or its
/// only one).
fn config(dim: Dim) -> SweepConfig {
    let (a, b, extra) = case(dim).expect("every dimension has a case");
    config_with(dim, [Some(a), b].into_iter().flatten().collect(), extra)
}

/// The base config with `dim` listing `values` and the `extra` keys set.
fn config_with(dim: Dim, values: Vec<serde_json::Value>, extra: serde_json::Value) -> SweepConfig {
    let mut text = json!({
        "sizes": [16], "workloads": [0], "modes": ["up"], "sync": ["atomic"],
        "threading": ["pool"], "helpers": [1], "depth": [1], "consume": ["copy"],
        "normals": ["neighbors"], "ocean": ["sines"], "kernel": ["reference"],
        "trials": 2
    });
    for (k, v) in extra.as_object().unwrap() {
        text[k] = v.clone();
    }
    text[dim.config_key()] = json!(values);
    SweepConfig::from_json(&text.to_string()).unwrap_or_else(|e| panic!("{dim}: {e}"))
}

/// The dimensions with two test values, which the pair tests below walk.
fn paired() -> impl Iterator<Item = Dim> {
    Dim::ALL
        .iter()
        .copied()
        .filter(|&d| case(d).is_some_and(|(_, b, _)| b.is_some()))
}

/// A summary whose every trial runs at exactly `fps`.
fn summary(fps: f64) -> Summary {
    let frame = FrameRecord {
        total_ns: (1e9 / fps) as u64,
        ..FrameRecord::default()
    };
    let trial = Trial {
        frames: vec![frame; 10],
        ..Trial::default()
    };
    Summary::of(&[trial.clone(), trial]).unwrap()
}

fn cell(key: CellKey, fps: f64) -> Cell {
    Cell {
        workload_unit: Some(key.workload_kind.unit().to_string()),
        workload_amount: Some(0),
        key,
        workload_iterations: 0,
        trials: Vec::new(),
        summary: Some(summary(fps)),
        pinned: true,
        pins: Pins {
            main_core: 0,
            helper_core: None,
            main_held: true,
            helper_held: None,
        },
        error: None,
        calibration: None,
        noise: None,
        work: None,
        set_aside: Vec::new(),
    }
}

/// A results file holding `cells` under `config`, on the fixture's machine.
fn results(config: SweepConfig, cells: Vec<Cell>) -> Results {
    let template = fixture();
    Results {
        schema_version: oceanbench::results::SCHEMA_VERSION,
        config,
        cells,
        ..template
    }
}

/// The values of `dim`'s column in results.csv, one per cell.
fn csv_column(r: &Results, dim: Dim) -> Vec<String> {
    let text = csv::to_string(r).unwrap();
    let mut reader = ::csv::Reader::from_reader(text.as_bytes());
    let header = reader.headers().unwrap().clone();
    let column = header
        .iter()
        .position(|h| h == dim.name())
        .unwrap_or_else(|| panic!("no {dim} column in {header:?}"));
    reader
        .records()
        .map(|r| r.unwrap()[column].to_string())
        .collect()
}

#[test]
fn every_dimension_has_test_values() {
    for &dim in Dim::ALL {
        let (_, b, _) = case(dim).unwrap_or_else(|| panic!("add test values for {dim} to `case`"));
        let values = dim.names().map_or(usize::MAX, |names| names.len());
        assert!(
            b.is_some() || values == 1,
            "{dim} has {values} values: give `case` its second one"
        );
    }
}

/// Test values for the named values past `case`'s pair, with the config keys each needs.
fn more(dim: Dim) -> Vec<(serde_json::Value, serde_json::Value)> {
    match dim {
        Dim::WorkloadKind => vec![
            (
                json!("spray"),
                json!({"ocean": ["fft"], "normals": ["analytic"],
                       "workload_levels": [{"particles": 100}]}),
            ),
            (json!("fog"), json!({"workload_levels": [{"volume": 4}]})),
        ],
        Dim::Sync => vec![(json!("triple-buffer"), json!({"policy": ["latest"]}))],
        _ => Vec::new(),
    }
}

/// One cell of `dim` = `value` (with the `extra` keys it needs) reaches its CSV column, its
/// results.json field and `compare --by`, and every label shows it unless it is the dimension's
/// quiet value.
fn reaches_every_output(dim: Dim, value: serde_json::Value, extra: serde_json::Value) {
    let config = config_with(dim, vec![value], extra);
    let cells = config.axes.cells();
    assert_eq!(cells.len(), 1, "{dim}: {cells:?}");
    let key = cells[0].clone();
    let value = key.get(dim).unwrap();
    let r = results(config, vec![cell(key.clone(), 125.0)]);

    assert_eq!(csv_column(&r, dim), [value.to_string()], "{dim}");

    let json: serde_json::Value =
        serde_json::from_str(&oceanbench::report::json::to_string(&r).unwrap()).unwrap();
    assert_eq!(
        json["cells"][0][dim.name()].to_string().trim_matches('"'),
        value.to_string(),
        "{dim}: results.json"
    );

    let shown = key.label().split(' ').any(|w| w == dim.label(value));
    assert_eq!(shown, Some(value) != dim.quiet(), "{dim}: {}", key.label());

    let by = compare::within(&r, dim, &value.to_string(), 5.0, Metric::Fps).unwrap_err();
    assert!(
        matches!(by, compare::CompareError::NoAlternative { .. }),
        "{dim}: {by}"
    );
}

/// Every dimension's first value reaches every output; a single-valued dimension is covered
/// here only.
#[test]
fn every_value_reaches_csv_json_labels_and_compare() {
    for &dim in Dim::ALL {
        let (a, _, extra) = case(dim).unwrap();
        reaches_every_output(dim, a, extra);
    }
}

/// Every named value of every dimension, not only the pair the other tests walk: each reaches
/// every output, with the config keys `more` gives it or `case`'s; a value added to an enum (a
/// third workload kind, say) that needs other keys fails here until `more` gives them.
#[test]
fn every_named_value_reaches_every_output() {
    for &dim in Dim::ALL {
        let Some(names) = dim.names() else { continue };
        let (_, _, extra) = case(dim).unwrap();
        let special = more(dim);
        for name in names {
            let (value, extra) = special
                .iter()
                .find(|(v, _)| v == &json!(name))
                .cloned()
                .unwrap_or_else(|| (json!(name), extra.clone()));
            reaches_every_output(dim, value, extra);
        }
    }
}

#[test]
fn every_dimension_has_a_config_key_default_and_validation() {
    let keys = SweepConfig::keys();
    for &dim in Dim::ALL {
        assert!(keys.iter().any(|k| k == dim.config_key()), "{dim}");
        assert!(
            !Axes::default().values(dim).is_empty(),
            "{dim} has a default"
        );
        let bad = json!({ dim.config_key(): ["no such value"] }).to_string();
        let err = SweepConfig::from_json(&bad).unwrap_err().to_string();
        assert!(
            err.contains(&format!("{}[0]", dim.config_key())),
            "{dim}: {err}"
        );
        let empty = json!({ dim.config_key(): [] }).to_string();
        let err = SweepConfig::from_json(&empty).unwrap_err().to_string();
        assert!(err.contains(dim.config_key()), "{dim}: {err}");
    }
}

/// The two cells of `config(dim)`: the same in every dimension but `dim`.
fn pair(dim: Dim) -> (CellKey, CellKey) {
    let cells = config(dim).axes.cells();
    assert_eq!(cells.len(), 2, "{dim}: {cells:?}");
    let (a, b) = (cells[0].clone(), cells[1].clone());
    for &other in Dim::ALL.iter().filter(|&&d| d != dim) {
        assert_eq!(a.get(other), b.get(other), "{dim}: {other} differs");
    }
    assert_ne!(
        a.get(dim),
        b.get(dim),
        "{dim}: the two values were not expanded"
    );
    (a, b)
}

#[test]
fn every_dimension_is_expanded_labelled_and_written_to_csv() {
    for dim in paired() {
        let (a, b) = pair(dim);
        assert_ne!(a.label(), b.label(), "{dim}");
        let r = results(
            config(dim),
            vec![cell(a.clone(), 125.0), cell(b.clone(), 250.0)],
        );
        let values = csv_column(&r, dim);
        let want: Vec<String> = [&a, &b]
            .iter()
            .map(|k| k.get(dim).unwrap().to_string())
            .collect();
        assert_eq!(values, want, "{dim}");
    }
}

#[test]
fn every_dimension_keeps_its_cells_apart_in_markdown_and_compare() {
    for dim in paired() {
        let (a, b) = pair(dim);
        let baseline = a.get(dim).unwrap().to_string();
        let r = results(config(dim), vec![cell(a, 125.0), cell(b, 250.0)]);
        let md = markdown::to_string(&r);
        assert!(
            md.contains("| 125 ±") && md.contains("| 250 ±"),
            "{dim}:\n{md}"
        );
        let c = compare::within(&r, dim, &baseline, 5.0, Metric::Fps)
            .unwrap_or_else(|e| panic!("{dim}: {e}"));
        assert_eq!(c.changes.len(), 1, "{dim}: {c:?}");
        assert_eq!(
            (c.changes[0].base, c.changes[0].new),
            (125.0, 250.0),
            "{dim}"
        );
    }
}

/// Whether an SVG shows `text` as a whole text element (plotters writes each on its own line).
fn shows(svg: &str, text: &str) -> bool {
    svg.contains(&format!("\n{text}\n"))
}

/// Every Figure 5-1 drawn: one, or one per slice when a dimension sets slices apart.
fn figure_svgs(r: &Results, select: Vec<(Dim, Value)>) -> Vec<String> {
    let dir = tempfile::tempdir().unwrap();
    let options = ChartOptions {
        formats: vec![ChartFormat::Svg],
        select,
    };
    let drawn = chart::draw_with(std::slice::from_ref(r), dir.path(), &options).unwrap();
    drawn
        .files
        .iter()
        .filter(|f| {
            f.file_name()
                .unwrap()
                .to_string_lossy()
                .starts_with("figure-5-1")
        })
        .map(|f| std::fs::read_to_string(f).unwrap())
        .collect()
}

fn figure_svg(r: &Results, select: Vec<(Dim, Value)>) -> String {
    let mut figures = figure_svgs(r, select);
    assert_eq!(figures.len(), 1, "one slice selected, one Figure 5-1");
    figures.remove(0)
}

#[test]
fn every_dimension_is_laid_out_or_selectable_in_the_charts() {
    for dim in paired() {
        let (a, b) = pair(dim);
        let (va, vb) = (a.get(dim).unwrap(), b.get(dim).unwrap());
        let r = results(config(dim), vec![cell(a, 125.0), cell(b, 250.0)]);
        let all = figure_svgs(&r, vec![]);
        if let [both] = all.as_slice() {
            if shows(both, "125") && shows(both, "250") {
                continue; // the chart lays the dimension out itself
            }
        } else {
            // The dimension sets slices apart: a Figure 5-1 each, titled with its value.
            assert_eq!(all.len(), 2, "{dim}");
            assert!(all.iter().any(|f| f.contains(&dim.title(va))), "{dim}");
            assert!(all.iter().any(|f| f.contains(&dim.title(vb))), "{dim}");
        }
        let only_a = figure_svg(&r, vec![(dim, va)]);
        let only_b = figure_svg(&r, vec![(dim, vb)]);
        assert!(shows(&only_a, "125") && !shows(&only_a, "250"), "{dim}");
        assert!(shows(&only_b, "250") && !shows(&only_b, "125"), "{dim}");
        assert!(
            only_b.contains(&dim.title(vb)),
            "{dim}: the subtitle names the value"
        );
    }
}

/// Regression: results.csv had no `helpers` column, so 1 and 2 helpers were indistinguishable.
#[test]
fn csv_tells_helper_counts_apart() {
    let (a, b) = pair(Dim::Helpers);
    let r = results(config(Dim::Helpers), vec![cell(a, 125.0), cell(b, 250.0)]);
    let text = csv::to_string(&r).unwrap();
    let mut lines = text.lines();
    let column = lines
        .next()
        .unwrap()
        .split(',')
        .position(|h| h == "helpers")
        .expect("a helpers column");
    let rows: Vec<&str> = lines.collect();
    assert_eq!(rows.len(), 2);
    assert_ne!(
        rows[0].split(',').nth(column),
        rows[1].split(',').nth(column),
        "{text}"
    );
}

/// Regression: `compare --by mode` paired cells with different helper counts under one label.
#[test]
fn compare_by_mode_pairs_equal_helper_counts_only() {
    let config = SweepConfig::from_json(
        r#"{"sizes": [16], "workloads": [0], "modes": ["serial", "up", "dp"],
            "sync": ["atomic"], "normals": ["analytic"], "helpers": [1, 2]}"#,
    )
    .unwrap();
    let keys = config.axes.cells();
    assert_eq!(keys.len(), 5, "serial, up ×2, dp ×2: {keys:?}");
    let fps = |k: &CellKey| match (k.mode.name(), k.helpers) {
        ("up", Some(1)) => 100.0,
        ("up", _) => 200.0,
        ("dp", Some(1)) => 125.0,
        ("dp", _) => 400.0,
        _ => 50.0,
    };
    let cells = keys.iter().map(|k| cell(k.clone(), fps(k))).collect();
    let r = results(config, cells);
    let c = compare::within(&r, Dim::Mode, "up", 5.0, Metric::Fps).unwrap();
    let dp: Vec<_> = c
        .changes
        .iter()
        .filter(|c| c.versus.as_deref() == Some("dp vs up"))
        .collect();
    assert_eq!(dp.len(), 2, "{c:?}");
    let mut ratios: Vec<(f64, f64)> = dp.iter().map(|c| (c.base, c.new)).collect();
    ratios.sort_by(|x, y| x.0.total_cmp(&y.0));
    assert_eq!(ratios, [(100.0, 125.0), (200.0, 400.0)]);
    assert_ne!(
        dp[0].label, dp[1].label,
        "the labels say which helper count"
    );
}

#[test]
fn results_written_before_helpers_existed_still_load() {
    let old = fixture();
    assert!(!old.cells.is_empty());
    for c in &old.cells {
        match c.key.is_serial() {
            true => assert_eq!(
                (c.key.sync, c.key.threading, c.key.helpers),
                (None, None, None)
            ),
            false => assert_eq!(c.key.helpers, Some(1)),
        }
        assert_eq!(
            c.key.ocean,
            OceanKind::SINES,
            "written before the ocean dimension"
        );
    }
    let text = serde_json::to_string(&old).unwrap();
    let again: Results = serde_json::from_str(&text).unwrap();
    assert_eq!(again, old, "a loaded file writes back to itself");
    let expanded = again.config.axes.cells();
    assert!(old.cells.iter().all(|c| expanded.contains(&c.key)));
}

/// Every dimension survives results.json: written, read back, each cell keeps its value and
/// the two cells stay apart by key.
#[test]
fn every_dimension_round_trips_through_results_json() {
    for dim in paired() {
        let (a, b) = pair(dim);
        let r = results(
            config(dim),
            vec![cell(a.clone(), 125.0), cell(b.clone(), 250.0)],
        );
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("results.json");
        std::fs::write(&path, oceanbench::report::json::to_string(&r).unwrap()).unwrap();
        let back = Results::load(&path).unwrap();
        let json: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
        for (i, key) in [&a, &b].into_iter().enumerate() {
            assert_eq!(&back.cells[i].key, key, "{dim}");
            assert_eq!(
                back.cell(key).unwrap().summary.as_ref().unwrap().fps,
                r.cells[i].summary.as_ref().unwrap().fps
            );
            let stored = &json["cells"][i][dim.name()];
            assert!(
                !stored.is_null(),
                "{dim}: no `{}` in results.json cell {i}",
                dim.name()
            );
        }
    }
}

/// Every chart the pair of cells can draw names the dimension's value it shows: either it lays
/// the dimension out (both values appear) or, holding it at one value, says which.
#[test]
fn every_chart_names_the_value_of_every_dimension() {
    for dim in paired() {
        let (a, b) = pair(dim);
        let vb = b.get(dim).unwrap();
        let r = results(config(dim), vec![cell(a, 125.0), cell(b, 250.0)]);
        let dir = tempfile::tempdir().unwrap();
        // The charts lay modes out themselves and refuse a mode selection.
        let select = if dim == Dim::Mode {
            vec![]
        } else {
            vec![(dim, vb)]
        };
        let options = ChartOptions {
            formats: vec![ChartFormat::Svg],
            select,
        };
        let drawn = chart::draw_with(std::slice::from_ref(&r), dir.path(), &options).unwrap();
        // A chart whose dimension does not vary (one method, one depth) is not drawn.
        assert!(drawn.files.len() >= 3, "{dim}: {:?}", drawn.skipped);
        for file in &drawn.files {
            let svg = std::fs::read_to_string(file).unwrap();
            let name = file.file_name().unwrap().to_string_lossy();
            let label = vb.to_string();
            let named = svg.contains(&dim.title(vb))
                || has_word(&svg, &label)
                || has_word(&svg, &label.to_uppercase());
            assert!(named, "{dim}: {name} does not name {label}");
        }
    }
}

/// Whether some text element of an SVG has `word` as a whole word.
fn has_word(svg: &str, word: &str) -> bool {
    let doc = roxmltree::Document::parse(svg).expect("SVG parses");
    doc.descendants().filter_map(|n| n.text()).any(|t| {
        t.split(|c: char| c.is_whitespace() || ",:;()·".contains(c))
            .any(|w| w == word)
    })
}
