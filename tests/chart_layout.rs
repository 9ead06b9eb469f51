//! No chart text overlaps other text or is struck by a line: every text's box is computed from
//! the bundled font's metrics, as the charts lay text out, and checked against every other box
//! and every line drawn, in the charts of committed runs. A line counts where it shows: an
//! opaque box drawn over it later (a label's backdrop) hides it.

mod common;

use ab_glyph::{Font, FontRef, PxScale, ScaleFont};
use oceanbench::report::chart::{self, ChartFormat};
use oceanbench::results::latency::LatencyRun;
use oceanbench::results::Results;

/// Runs whose charts show every kind of chart and text the report draws.
const RUNS: [&str; 4] = [
    "fog-20261125T163342Z",
    "fft-spray-20261125T162607Z",
    "projected-20261125T163816Z",
    "figure-5-1-20261125T064618Z",
];

/// Overlaps thinner than this (pixels) are rounding, not a collision.
const SLACK: f64 = 0.5;

type Rect = [f64; 4];

/// Drawn elements in drawing order: a later one covers an earlier one.
struct Label {
    text: String,
    rect: Rect,
}

struct Line {
    seg: [f64; 4],
    stroke: String,
    /// Half the stroke's width: the line covers that much either side of its segment.
    half: f64,
    order: usize,
}

struct Cover {
    rect: Rect,
    order: usize,
}

#[derive(Default)]
struct Layout {
    labels: Vec<Label>,
    lines: Vec<Line>,
    covers: Vec<Cover>,
}

fn font() -> FontRef<'static> {
    let bytes = include_bytes!("../assets/fonts/DejaVuSans.ttf");
    FontRef::try_from_slice(bytes).expect("the bundled font loads")
}

/// Where a text's ink lies around its anchor, as the SVG draws it at `em` (its font-size):
/// across, the glyphs' advances and kerning; down from the anchor, the tallest and deepest
/// glyph outlines about the baseline that `dy` sets (0.76em for a top anchor, half an x-height
/// off a centre or bottom one). Returns (width, top, bottom).
fn ink(font: &FontRef, em: f64, dy: Option<&str>, text: &str) -> (f64, f64, f64) {
    let upem = font.units_per_em().unwrap() as f64;
    let scale = PxScale::from((em * font.height_unscaled() as f64 / upem) as f32);
    let scaled = font.as_scaled(scale);
    let x_height = font
        .outline_glyph(font.glyph_id('x').with_scale(scale))
        .map(|o| -o.px_bounds().min.y as f64)
        .unwrap();
    let baseline = match dy {
        Some("0.5ex") => x_height / 2.0,
        Some("-0.5ex") => -x_height / 2.0,
        _ => 0.76 * em,
    };
    let (mut width, mut top, mut bottom) = (0.0f64, f64::INFINITY, f64::NEG_INFINITY);
    let mut prev = None;
    for c in text.chars() {
        let id = scaled.glyph_id(c);
        if let Some(p) = prev {
            width += scaled.kern(p, id) as f64;
        }
        if let Some(o) = font.outline_glyph(id.with_scale(scale)) {
            top = top.min(o.px_bounds().min.y as f64);
            bottom = bottom.max(o.px_bounds().max.y as f64);
        }
        width += scaled.h_advance(id) as f64;
        prev = Some(id);
    }
    if top > bottom {
        (top, bottom) = (0.0, 0.0);
    }
    (width, baseline + top, baseline + bottom)
}

fn attr(n: roxmltree::Node, name: &str) -> f64 {
    n.attribute(name)
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("{name} of {n:?}"))
}

/// Every text's box, line segment and opaque box of an SVG chart.
fn layout(svg: &str) -> Layout {
    let font = font();
    let doc = roxmltree::Document::parse(svg).expect("SVG parses");
    let mut out = Layout::default();
    for (order, n) in doc.descendants().enumerate() {
        match n.tag_name().name() {
            "text" => {
                let text = n.text().unwrap_or("").trim().to_string();
                if text.is_empty() {
                    continue;
                }
                let (x, y) = (attr(n, "x"), attr(n, "y"));
                let em = attr(n, "font-size");
                let (w, top, bottom) = ink(&font, em, n.attribute("dy"), &text);
                let x0 = match n.attribute("text-anchor") {
                    Some("middle") => -w / 2.0,
                    Some("end") => -w,
                    _ => 0.0,
                };
                let rect = match n.attribute("transform") {
                    // rotate(270, x, y): (dx, dy) from the anchor turns to (dy, -dx).
                    Some(t) if t.starts_with("rotate(270") => {
                        [x + top, y - x0 - w, x + bottom, y - x0]
                    }
                    Some(t) => panic!("unexpected transform {t}"),
                    None => [x + x0, y + top, x + x0 + w, y + bottom],
                };
                out.labels.push(Label { text, rect });
            }
            "line" => out.lines.push(Line {
                seg: [attr(n, "x1"), attr(n, "y1"), attr(n, "x2"), attr(n, "y2")],
                stroke: n.attribute("stroke").unwrap_or("").to_string(),
                half: half_stroke(n),
                order,
            }),
            "rect"
                if n.attribute("fill").is_some_and(|f| f != "none")
                    && n.attribute("opacity") == Some("1") =>
            {
                let (x, y) = (attr(n, "x"), attr(n, "y"));
                let rect = [x, y, x + attr(n, "width"), y + attr(n, "height")];
                out.covers.push(Cover { rect, order });
            }
            "polyline" => {
                let points: Vec<(f64, f64)> = n
                    .attribute("points")
                    .unwrap_or("")
                    .split_whitespace()
                    .filter_map(|p| {
                        let (x, y) = p.split_once(',')?;
                        Some((x.parse().ok()?, y.parse().ok()?))
                    })
                    .collect();
                let stroke = n.attribute("stroke").unwrap_or("").to_string();
                for pair in points.windows(2) {
                    out.lines.push(Line {
                        seg: [pair[0].0, pair[0].1, pair[1].0, pair[1].1],
                        stroke: stroke.clone(),
                        half: half_stroke(n),
                        order,
                    });
                }
            }
            _ => {}
        }
    }
    out
}

fn half_stroke(n: roxmltree::Node) -> f64 {
    n.attribute("stroke-width")
        .and_then(|v| v.parse::<f64>().ok())
        .unwrap_or(1.0)
        / 2.0
}

fn contains(outer: &Rect, inner: &Rect) -> bool {
    outer[0] <= inner[0] && outer[1] <= inner[1] && inner[2] <= outer[2] && inner[3] <= outer[3]
}

fn overlap(a: &Rect, b: &Rect) -> bool {
    a[0].max(b[0]) + SLACK < a[2].min(b[2]) && a[1].max(b[1]) + SLACK < a[3].min(b[3])
}

/// Whether a line `half` wide either side of the segment crosses the inside of the box (its
/// edges shrunk by [`SLACK`]): the segment clipped to the box grown by `half`.
fn crosses(seg: &[f64; 4], half: f64, r: &Rect) -> bool {
    let grow = half - SLACK;
    let r = [r[0] - grow, r[1] - grow, r[2] + grow, r[3] + grow];
    if r[0] >= r[2] || r[1] >= r[3] {
        return false;
    }
    let [x1, y1, x2, y2] = *seg;
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for (p, q) in [
        (-(x2 - x1), x1 - r[0]),
        (x2 - x1, r[2] - x1),
        (-(y2 - y1), y1 - r[1]),
        (y2 - y1, r[3] - y1),
    ] {
        if p == 0.0 {
            if q < 0.0 {
                return false;
            }
        } else {
            let t = q / p;
            if p < 0.0 {
                t0 = t0.max(t);
            } else {
                t1 = t1.min(t);
            }
        }
    }
    t0 < t1
}

/// Every collision in an SVG chart, one line each.
fn collisions(svg: &str) -> Vec<String> {
    let layout = layout(svg);
    let labels = &layout.labels;
    let mut out = vec![];
    for (i, a) in labels.iter().enumerate() {
        for b in &labels[i + 1..] {
            if overlap(&a.rect, &b.rect) {
                out.push(format!("{:?} overlaps {:?}", a.text, b.text));
            }
        }
        for line in &layout.lines {
            let hidden = layout
                .covers
                .iter()
                .any(|c| c.order > line.order && contains(&c.rect, &a.rect));
            if !hidden && crosses(&line.seg, line.half, &a.rect) {
                out.push(format!(
                    "{:?} is struck by a {} line {:?}",
                    a.text, line.stroke, line.seg
                ));
            }
        }
    }
    out
}

fn committed(run: &str) -> Results {
    let path = common::root()
        .join("results")
        .join(run)
        .join("results.json");
    Results::load(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn check(results: Results, what: &str) -> Vec<String> {
    let dir = tempfile::tempdir().unwrap();
    let files = chart::draw(&[results], dir.path(), &[ChartFormat::Svg]).unwrap();
    assert!(!files.is_empty(), "{what}: no chart drawn");
    collisions_in(&files, what)
}

/// Every collision in the SVG `files`, each named by `what` and the file.
fn collisions_in(files: &[std::path::PathBuf], what: &str) -> Vec<String> {
    let mut out = vec![];
    for f in files {
        let svg = std::fs::read_to_string(f).unwrap();
        let name = f.file_name().unwrap().to_string_lossy().to_string();
        out.extend(
            collisions(&svg)
                .into_iter()
                .map(|c| format!("{what} {name}: {c}")),
        );
    }
    out
}

#[test]
fn no_text_in_the_committed_runs_charts_overlaps_text_or_a_line() {
    let mut all = vec![];
    for run in RUNS {
        all.extend(check(committed(run), run));
    }
    assert_clear(&all);
}

fn assert_clear(collisions: &[String]) {
    assert!(
        collisions.is_empty(),
        "{} collisions:\n{}",
        collisions.len(),
        collisions.join("\n")
    );
}

/// The round-trip charts of the committed latency runs: the one with repeats and a machine, and
/// a bare list of rows from before.
#[test]
fn no_text_in_the_latency_charts_overlaps_text_or_a_line() {
    let mut all = vec![];
    for run in ["latency-20261127T193624Z", "latency-20261125T085346Z"] {
        let path = common::root().join("results").join(run);
        let latency = LatencyRun::load(&path).unwrap();
        let dir = tempfile::tempdir().unwrap();
        let drawn = chart::draw_latency(&latency, dir.path(), &[ChartFormat::Svg]).unwrap();
        assert_eq!(drawn.files.len(), 1, "{run}: {:?}", drawn.skipped);
        all.extend(collisions_in(&drawn.files, run));
    }
    assert_clear(&all);
}

#[test]
fn no_text_in_the_fixture_charts_overlaps_text_or_a_line() {
    assert_clear(&check(common::fixture(), "fixture"));
}

/// The check itself: a label struck by a line and two labels on one spot are both caught.
#[test]
fn the_check_catches_a_struck_label_and_overlapping_labels() {
    let text = |x: i32, y: i32, s: &str| {
        format!(
            r##"<text x="{x}" y="{y}" dy="0.76em" text-anchor="middle" font-size="12" fill="#000">{s}</text>"##
        )
    };
    let svg = |body: String| {
        format!(r#"<svg xmlns="http://www.w3.org/2000/svg" width="200" height="200">{body}</svg>"#)
    };
    let struck = svg(format!(
        r##"{}<polyline fill="none" stroke="#D55E00" points="0,106 200,106 "/>"##,
        text(100, 100, "1.74")
    ));
    assert_eq!(collisions(&struck).len(), 1, "{struck}");
    let clear = svg(format!(
        r##"{}<polyline fill="none" stroke="#D55E00" points="0,130 200,130 "/>"##,
        text(100, 100, "1.74")
    ));
    assert!(collisions(&clear).is_empty());
    let pair = svg(format!(
        "{}{}",
        text(100, 100, "balance"),
        text(110, 104, "w3")
    ));
    assert_eq!(collisions(&pair).len(), 1);
    // Charts committed with the runs, drawn before the check existed, collide.
    for (run, chart) in [
        ("projected-20261125T163816Z", "balance.svg"),
        ("figure-5-1-20261125T064618Z", "relative.svg"),
    ] {
        let path = common::root().join("results").join(run).join(chart);
        let old = std::fs::read_to_string(&path).unwrap();
        assert!(!collisions(&old).is_empty(), "{}", path.display());
    }
}
