//! The HTML report: parsed as a browser would (scraper), it holds every cell, every chart the
//! run can draw, the config's text escaped, the comparison with a baseline; bad input is one
//! line, exit 2 and nothing written; sweep writes the page and records its command line.

mod common;

use common::{assert_success, fixture, oceanbench, root, write_file};
use oceanbench::cell::Dim;
use oceanbench::report::chart::{self, ChartOptions};
use oceanbench::report::compare::{self, Metric};
use oceanbench::report::html::{self, Baseline};
use oceanbench::report::{json, markdown};
use oceanbench::results::{Results, SCHEMA_VERSION};
use scraper::{ElementRef, Html, Selector};
use std::path::{Path, PathBuf};

fn sel(s: &str) -> Selector {
    Selector::parse(s).unwrap()
}

fn text(e: ElementRef) -> String {
    e.text().collect::<String>().trim().to_string()
}

fn page(results: &Results) -> Html {
    Html::parse_document(&html::page(results, "fixture", None).unwrap())
}

/// Every table of the page whose caption starts with `caption`, as rows of cell texts.
fn tables(doc: &Html, caption: &str) -> Vec<Vec<Vec<String>>> {
    doc.select(&sel("table"))
        .filter(|t| {
            t.select(&sel("caption"))
                .next()
                .is_some_and(|c| text(c).starts_with(caption))
        })
        .map(|t| {
            t.select(&sel("tbody tr"))
                .map(|r| r.select(&sel("td")).map(text).collect())
                .collect()
        })
        .collect()
}

/// The value of `dt` in the page's fact lists.
fn fact(doc: &Html, dt: &str) -> String {
    let dts: Vec<ElementRef> = doc.select(&sel("dl.facts dt")).collect();
    let dds: Vec<ElementRef> = doc.select(&sel("dl.facts dd")).collect();
    let at = dts.iter().position(|d| text(*d) == dt).unwrap_or_else(|| {
        panic!("no fact {dt}");
    });
    text(dds[at])
}

/// A copy of `results` in its own folder.
fn folder(results: &Results) -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let run = dir.path().join("run");
    std::fs::create_dir(&run).unwrap();
    std::fs::write(run.join("results.json"), json::to_string(results).unwrap()).unwrap();
    (dir, run)
}

#[test]
fn every_cell_is_in_the_fps_and_frame_time_tables() {
    let r = fixture();
    let doc = page(&r);
    let fps = tables(&doc, "FPS, ");
    assert_eq!(fps.len(), markdown::fps_tables(&r).len());
    let frames = tables(&doc, "Frame-time metrics");
    assert_eq!(frames.len(), 1);
    assert_eq!(frames[0].len(), r.cells.len());
    let measured = r.cells.iter().filter(|c| c.summary.is_some()).count();
    assert!(measured > 0);
    // Rows name a cell without what every cell shares, which the caption names once.
    let held: Vec<Dim> = html::held_dims(&r).iter().map(|&(d, _)| d).collect();
    assert!(held.contains(&Dim::Kernel) && !held.contains(&Dim::Sync));
    let labels: std::collections::HashSet<&String> = frames[0].iter().map(|row| &row[0]).collect();
    assert_eq!(labels.len(), r.cells.len(), "every row names its own cell");
    for c in &r.cells {
        let Some(s) = &c.summary else { continue };
        // Its FPS with its spread, in the row of its mesh and workload of some FPS table.
        let figure = format!("{:.0} ±{:.1}%", s.fps, s.fps_spread.cv_percent);
        let mesh = format!("{0}×{0}", c.key.size);
        let found = fps.iter().flatten().any(|row| {
            row[0] == mesh
                && row[1] == c.key.workload.to_string()
                && row[2..5].iter().any(|v| v.starts_with(&figure))
        });
        assert!(found, "{} ({figure}) is in no FPS table", c.key.label());
        let row = frames[0]
            .iter()
            .find(|row| row[0] == format!("{}{}", c.key.label_without(&held), markdown::marks(c)))
            .unwrap_or_else(|| panic!("{} has no frame-time row", c.key.label()));
        assert_eq!(row[1], format!("{:.3}", s.frame_time_ms.median));
        assert_eq!(row[2], format!("{:.3}", s.frame_time_ms.p99));
    }
}

#[test]
fn noisy_cells_carry_the_markdown_mark() {
    let r = Results::load(&root().join("results/figure-5-1-20261125T064618Z")).unwrap();
    let noisy: Vec<_> = r.cells.iter().filter(|c| c.noisy()).collect();
    assert!(!noisy.is_empty(), "the reference run has noisy cells");
    let doc = page(&r);
    let marked = tables(&doc, "FPS, ")
        .iter()
        .flatten()
        .flat_map(|row| row[2..5].to_vec())
        .filter(|v| v.contains(markdown::NOISY))
        .count();
    assert_eq!(marked, noisy.len());
}

/// The frame-time table reads in order (size, workload, mode) with each cell's marks, its
/// labels explained beneath it, and a table longer than a screenful starts collapsed.
#[test]
fn tables_are_sorted_marked_explained_and_long_ones_collapsed() {
    let r = Results::load(&root().join("results/fft-spray-20261125T162607Z")).unwrap();
    let doc = page(&r);
    let frames = tables(&doc, "Frame-time metrics");
    assert_eq!(frames[0].len(), r.cells.len());
    let mut order: Vec<_> = r
        .cells
        .iter()
        .map(|c| (c.key.size, c.key.workload, c.key.mode))
        .collect();
    order.sort();
    let held: Vec<Dim> = html::held_dims(&r).iter().map(|&(d, _)| d).collect();
    for (row, want) in frames[0].iter().zip(&order) {
        let cell = r
            .cells
            .iter()
            .find(|c| row[0] == format!("{}{}", c.key.label_without(&held), markdown::marks(c)))
            .unwrap_or_else(|| panic!("no cell is labelled {}", row[0]));
        assert_eq!((cell.key.size, cell.key.workload, cell.key.mode), *want);
    }
    let marked = r
        .cells
        .iter()
        .filter(|c| !markdown::marks(c).is_empty())
        .count();
    assert!(marked > 0, "the run has marked cells");
    let rows_marked = frames[0]
        .iter()
        .filter(|row| {
            [markdown::NOISY, markdown::UNEXPLAINED, markdown::MIXED]
                .iter()
                .any(|m| row[0].contains(m))
        })
        .count();
    assert_eq!(rows_marked, marked);
    let notes: Vec<String> = doc.select(&sel("p.note")).map(text).collect();
    let legend = notes
        .iter()
        .find(|n| n.starts_with("Cell labels"))
        .expect("a legend of the labels");
    for part in [
        "h2 = 2 helpers",
        "d2 = depth 2",
        "handle = handle consume",
        "w2 = workload 2",
    ] {
        assert!(legend.contains(part), "{part}: {legend}");
    }
    for details in doc.select(&sel("details.long-table")) {
        let rows = details.select(&sel("tbody tr")).count();
        assert!(rows > 40, "only long tables collapse: {rows}");
    }
    let long = doc
        .select(&sel("table"))
        .filter(|t| t.select(&sel("tbody tr")).count() > 40)
        .count();
    assert!(long > 0, "the run has a long table");
    assert_eq!(doc.select(&sel("details.long-table")).count(), long);
}

#[test]
fn every_chart_the_run_can_draw_is_inline_and_the_rest_say_why() {
    let r = fixture();
    let doc = page(&r);
    let charts = chart::svgs(std::slice::from_ref(&r), &ChartOptions::default()).unwrap();
    let drawn = charts.iter().filter(|c| c.drawn.is_ok()).count();
    assert!(drawn >= 5, "the fixture draws most charts");
    for c in &charts {
        let name = &c.name;
        let id = format!("#chart-{name}");
        let shown: Vec<ElementRef> = doc.select(&sel(&id)).collect();
        match &c.drawn {
            Ok(_) => {
                assert_eq!(shown.len(), 1, "{name} is on the page once");
                assert!(
                    shown[0].select(&sel("svg text")).next().is_some(),
                    "{name} is inline SVG with its text"
                );
            }
            // The balance chart belongs to a section the fixture, without a search, lacks.
            Err(why) if *name == "balance" => assert!(shown.is_empty(), "{why}"),
            Err(why) => assert!(text(shown[0]).contains(&why.0), "{name}: {why}"),
        }
    }
    assert_eq!(doc.select(&sel("svg")).count(), drawn);
    // Self-contained: nothing is fetched.
    for (tag, attr) in [("img", "src"), ("script", "src"), ("link", "href")] {
        assert_eq!(doc.select(&sel(&format!("{tag}[{attr}]"))).count(), 0);
    }
}

#[test]
fn config_text_is_escaped() {
    let mut r = fixture();
    let evil = "<script>alert('x')</script> & <b>bold</b>";
    r.config.description = evil.into();
    r.config.name = "<script>name</script>".into();
    let page_text = html::page(&r, "fixture", None).unwrap();
    assert!(
        !page_text.contains("<script>"),
        "no script tag gets through"
    );
    let doc = Html::parse_document(&page_text);
    assert_eq!(doc.select(&sel("script")).count(), 0);
    assert_eq!(doc.select(&sel("dd b")).count(), 0);
    assert_eq!(fact(&doc, "description"), evil);
    assert_eq!(
        text(doc.select(&sel("h1")).next().unwrap()),
        "oceanbench: <script>name</script>"
    );
}

#[test]
fn what_an_older_file_lacks_reads_not_recorded() {
    let mut r = fixture();
    assert!(r.command.is_none() && r.doctor.is_none());
    let doc = page(&r);
    assert_eq!(fact(&doc, "command line"), "not recorded");
    assert_eq!(fact(&doc, "governor"), "not recorded");
    r.command = Some(vec![
        "oceanbench".into(),
        "sweep".into(),
        "my config.json".into(),
    ]);
    let doc = page(&r);
    assert_eq!(
        fact(&doc, "command line"),
        "oceanbench sweep 'my config.json'"
    );
}

#[test]
fn a_baseline_adds_every_verdict_with_its_interval() {
    let base = fixture();
    let mut new = fixture();
    for c in &mut new.cells {
        if let Some(s) = &mut c.summary {
            for f in &mut s.fps_trials {
                *f *= 1.5;
            }
        }
    }
    let comparison = compare::between(&base, &new, 5.0, Metric::Fps);
    assert!(!comparison.changes.is_empty());
    let baseline = Baseline {
        name: "base-run",
        comparison: &comparison,
    };
    let doc = Html::parse_document(&html::page(&new, "new", Some(&baseline)).unwrap());
    let rows = tables(&doc, "Verdicts per cell");
    assert_eq!(rows.len(), 1);
    assert_eq!(rows[0].len(), comparison.changes.len());
    for (row, change) in rows[0].iter().zip(&comparison.changes) {
        assert!(row[0].starts_with(change.verdict.words()), "{row:?}");
        assert!(row[2].starts_with('[') && row[2].contains(", "), "{row:?}");
        assert!(row[5].contains(&change.label), "{row:?}");
    }
    assert!(text(doc.select(&sel("#comparison + p")).next().unwrap()).contains("base-run"));
    assert_eq!(tables(&page(&new), "Verdicts per cell").len(), 0);
}

#[test]
fn report_writes_the_page_beside_the_results_or_where_asked() {
    let (_dir, run) = folder(&fixture());
    let out = oceanbench(&["report", run.to_str().unwrap()]);
    assert_success(&out);
    let page = std::fs::read_to_string(run.join("report.html")).unwrap();
    assert!(page.starts_with("<!DOCTYPE html>"));
    let elsewhere = run.join("other.html");
    let base = run.join("results.json");
    let out = oceanbench(&[
        "report",
        base.to_str().unwrap(),
        "--baseline",
        run.to_str().unwrap(),
        "--out",
        elsewhere.to_str().unwrap(),
    ]);
    assert_success(&out);
    assert!(std::fs::read_to_string(elsewhere)
        .unwrap()
        .contains("Verdicts per cell"));
}

/// Runs `report` with `args` and checks: exit 2, one line naming `needle`, no page written.
fn refused(args: &[&str], needle: &str, page: &Path) {
    let out = oceanbench(args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
    assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
    assert!(stderr.contains(needle), "{needle}: {stderr}");
    assert!(!page.exists(), "{args:?} wrote {}", page.display());
}

#[test]
fn bad_input_is_one_line_exit_2_and_nothing_written() {
    let empty = tempfile::tempdir().unwrap();
    let page = empty.path().join("report.html");
    refused(
        &["report", empty.path().to_str().unwrap()],
        "results.json",
        &page,
    );

    let mut newer = serde_json::to_value(fixture()).unwrap();
    newer["schema_version"] = (SCHEMA_VERSION + 1).into();
    let (_n, newer_run) = folder(&fixture());
    std::fs::write(newer_run.join("results.json"), newer.to_string()).unwrap();
    refused(
        &["report", newer_run.to_str().unwrap()],
        "newer",
        &newer_run.join("report.html"),
    );

    // A baseline that measured other cells: every size differs.
    let (_r, run) = folder(&fixture());
    let mut other = fixture();
    for c in &mut other.cells {
        c.key.size += 1000;
    }
    let (_o, other_run) = folder(&other);
    refused(
        &[
            "report",
            run.to_str().unwrap(),
            "--baseline",
            other_run.to_str().unwrap(),
        ],
        "--baseline: compare: no cell matched",
        &run.join("report.html"),
    );
    refused(
        &["report", run.to_str().unwrap(), "--threshold=-1"],
        "--threshold",
        &run.join("report.html"),
    );
}

#[test]
fn sweep_writes_the_report_and_records_its_command_line() {
    let dir = tempfile::tempdir().unwrap();
    let config = write_file(
        dir.path(),
        "tiny.json",
        r#"{"name": "tiny", "description": "<script>x</script>", "sizes": [8], "workloads": [0],
            "modes": ["serial", "dp"], "sync": ["atomic"], "trials": 1, "warmup_frames": 1,
            "min_frames": 3, "min_seconds": 0.0, "workload_levels": [{"micros": 0}]}"#,
    );
    let sweep = |out: &Path, extra: &[&str]| {
        let mut args = vec![
            "sweep",
            config.as_str(),
            "--out",
            out.to_str().unwrap(),
            "--quiet",
            "--no-doctor",
            "--no-charts",
        ];
        args.extend(extra);
        let o = oceanbench(&args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    };
    let with = dir.path().join("with");
    sweep(&with, &[]);
    let r = Results::load(&with).unwrap();
    assert_eq!(r.schema_version, SCHEMA_VERSION);
    let command = r.command.clone().expect("the command line is recorded");
    assert_eq!(command[1..3], ["sweep".to_string(), config.clone()]);
    let doc = Html::parse_document(&std::fs::read_to_string(with.join("report.html")).unwrap());
    assert!(fact(&doc, "command line").contains("--no-charts"));
    assert_eq!(fact(&doc, "description"), "<script>x</script>");
    assert_eq!(tables(&doc, "Frame-time metrics")[0].len(), r.cells.len());

    let without = dir.path().join("without");
    sweep(&without, &["--no-report"]);
    assert!(without.join("results.json").exists());
    assert!(!without.join("report.html").exists());
}

#[test]
fn every_committed_run_carries_its_report() {
    for dir in std::fs::read_dir(root().join("results")).unwrap() {
        let dir = dir.unwrap().path();
        if dir.join("results.json").exists() {
            assert!(
                dir.join("report.html").exists(),
                "{} has no report.html: run `oceanbench report {}` and commit it",
                dir.display(),
                dir.display()
            );
        }
    }
}

#[test]
fn a_balance_point_gets_its_section() {
    use oceanbench::results::balance::BalanceEntry;
    let mut r = fixture();
    let key = r
        .cells
        .iter()
        .find(|c| !c.key.is_serial())
        .unwrap()
        .key
        .clone();
    r.balance.push(BalanceEntry {
        balance_us: Some(500.0),
        balance_us_low: Some(480.0),
        balance_us_high: Some(520.0),
        dp_over_serial: Some(1.8),
        dp_over_serial_low: Some(1.7),
        dp_over_serial_high: Some(1.9),
        overhead_percent: Some(3.0),
        round_trip_ns: vec![100.0, 110.0],
        ..BalanceEntry::new(key, 400.0)
    });
    let doc = page(&r);
    let balance = tables(&doc, "Balance points");
    assert_eq!(balance.len(), 1);
    assert_eq!(balance[0].len(), 1);
    assert_eq!(balance[0][0][2], "500 [480, 520]");
    assert_eq!(balance[0][0][4], "1.80 [1.70, 1.90]");
    // The chart of the one slice searched is in the section, drawn or saying why not; the
    // slices without a search get none.
    let shown: Vec<_> = doc.select(&sel("[id^=chart-balance]")).collect();
    assert_eq!(shown.len(), 1);
    assert_eq!(tables(&page(&fixture()), "Balance points").len(), 0);
}

#[test]
fn slow_trials_and_every_noisy_cell_are_listed() {
    use oceanbench::slow_trials::{Cause, Slow, TrialRecord};
    // The reference run has more noisy cells than its warning names; the page lists them all.
    let r = Results::load(&root().join("results/figure-5-1-20261125T064618Z")).unwrap();
    let noisy: Vec<String> = r
        .cells
        .iter()
        .filter(|c| c.noisy())
        .map(|c| c.key.label())
        .collect();
    assert!(noisy.len() > 5);
    let doc = page(&r);
    let items: Vec<String> = doc.select(&sel("#noisy-cells li")).map(text).collect();
    assert_eq!(items.len(), noisy.len());
    for (item, label) in items.iter().zip(&noisy) {
        assert!(item.starts_with(&format!("{label}: ")), "{item}");
    }
    assert_eq!(tables(&doc, "Slow trials").len(), 0);

    let mut r = fixture();
    // A threaded cell: a serial one stands in every table of its row.
    let cell = r.cells.iter_mut().find(|c| !c.key.is_serial()).unwrap();
    let breakdown = cell.summary.as_ref().unwrap().breakdown.clone();
    cell.trials = vec![TrialRecord {
        fps: 12.5,
        breakdown,
        step_ratio: Some(1.25),
        workload_ratio: None,
        round_trip_ns: None,
        taken_away: false,
        slow: Some(Slow {
            below_median_percent: 40.0,
            causes: vec![Cause::Unexplained],
        }),
        placement: None,
    }];
    let label = cell.key.label();
    let doc = page(&r);
    let slow = tables(&doc, "Slow trials");
    assert_eq!(slow.len(), 1);
    assert_eq!(slow[0].len(), 1);
    let row = &slow[0][0];
    assert_eq!(
        (&row[0], &row[2], &row[3]),
        (&label, &"12.5".to_string(), &"40%".to_string())
    );
    assert!(row[4].contains("unexplained"), "{row:?}");
    let marked = tables(&doc, "FPS, ")
        .iter()
        .flatten()
        .flat_map(|row| row[2..5].to_vec())
        .filter(|v| v.contains(markdown::UNEXPLAINED))
        .count();
    assert_eq!(marked, 1);
    assert_eq!(doc.select(&sel("#noisy-cells")).count(), 0);
}

#[test]
fn refresh_rewrites_the_write_ups_from_results_json_and_leaves_it_as_it_was() {
    let (_dir, run) = folder(&fixture());
    let before = std::fs::read(run.join("results.json")).unwrap();
    std::fs::write(run.join("results.md"), "stale\n").unwrap();
    let out = oceanbench(&["report", run.to_str().unwrap(), "--refresh"]);
    assert_success(&out);
    assert_eq!(std::fs::read(run.join("results.json")).unwrap(), before);
    let md = std::fs::read_to_string(run.join("results.md")).unwrap();
    assert!(
        md.starts_with("# oceanbench results\n\n## Findings"),
        "{md}"
    );
    let findings: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(run.join("findings.json")).unwrap()).unwrap();
    assert!(!findings["findings"].as_array().unwrap().is_empty());
    assert!(run.join("report.html").is_file());
}

/// The page opens with its verdict (the run's findings, and with a baseline how many cells
/// moved), then contents linking every section, and keeps the list of what ran for last.
#[test]
fn the_page_opens_with_the_verdict_and_links_every_section() {
    let results = fixture();
    let doc = page(&results);
    let body_order: Vec<String> = doc
        .select(&sel("body > h2, body > section > h2"))
        .map(text)
        .collect();
    assert_eq!(
        body_order.first().map(String::as_str),
        Some("Verdict"),
        "{body_order:?}"
    );
    assert_eq!(
        body_order.last().map(String::as_str),
        Some("What was run"),
        "{body_order:?}"
    );
    let findings = oceanbench::findings::of(&results).findings;
    let shown: Vec<String> = doc.select(&sel("#findings li")).map(text).collect();
    assert_eq!(shown.len(), findings.len());
    assert!(!shown.is_empty() && shown[0] == findings[0].sentence);
    // What ran is collapsed, as the full config inside it; the machine and the noise
    // warnings stay open.
    let collapsed: Vec<String> = doc
        .select(&sel("details#what-ran-list dl.facts dt"))
        .map(text)
        .collect();
    assert!(
        collapsed.contains(&"trials per cell".to_string()),
        "{collapsed:?}"
    );
    let hidden = sel("details#what-ran-list #noise-warnings");
    assert!(doc.select(&hidden).next().is_none());
    assert!(doc.select(&sel("#noise-warnings")).next().is_some());
    let machine = text(doc.select(&sel("#verdict-machine")).next().unwrap());
    assert!(machine.contains(&results.machine.cpu_model), "{machine}");
    // A run of several slices heads each slice's findings with its values.
    let mut fog = Results::load(&root().join("results/fog-20261125T163342Z")).unwrap();
    oceanbench::findings::placement::label(&mut fog);
    let fog_doc = page(&fog);
    let headings: Vec<String> = fog_doc.select(&sel("#findings h3")).map(text).collect();
    let fog_findings = oceanbench::findings::of(&fog);
    let groups = fog_findings.grouped();
    assert!(groups.len() >= 3, "two kinds and the run-wide findings");
    let want: Vec<String> = groups.iter().filter_map(|(h, _)| h.clone()).collect();
    assert_eq!(headings, want);
    assert!(headings.iter().any(|h| h.contains("fog")), "{headings:?}");
    assert_eq!(headings.last().map(String::as_str), Some("Across the run"));
    let links: Vec<String> = doc
        .select(&sel("#contents a"))
        .map(|a| a.value().attr("href").unwrap().to_string())
        .collect();
    assert!(links.len() >= 5, "{links:?}");
    for href in &links {
        assert!(
            doc.select(&sel(href)).next().is_some(),
            "{href} links to no section"
        );
    }

    let c = compare::between(&results, &results, 5.0, Metric::Fps);
    let with = Html::parse_document(
        &html::page(
            &results,
            "new",
            Some(&Baseline {
                name: "base-run",
                comparison: &c,
            }),
        )
        .unwrap(),
    );
    let line = text(with.select(&sel("#verdict-baseline")).next().unwrap());
    assert!(
        line.contains(&c.summary_line()) && line.contains("base-run"),
        "{line}"
    );
    assert!(with
        .select(&sel("#contents a[href='#comparison']"))
        .next()
        .is_some());
}
