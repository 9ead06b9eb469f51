//! A latency run's chart: every method's round trip on each core pair, the median of its repeats
//! with their spread, beside the cross-core floor no hand-off between those cores can beat.

use super::render::{self, Body, Chart, Frame, Legend, RangePanel, RangePlot, RangePoint, RefLine};
use super::{run_date, sync_color, NothingToDraw, CHART_SIZE};
use crate::named::Named;
use crate::results::latency::{LatencyRun, BATCH, FLOOR};
use crate::stats;
use crate::sync::SyncMethod;
use plotters::style::RGBColor;

/// The floor's colour: a dark red no method's colour is, for the line nothing goes below.
const FLOOR_COLOR: RGBColor = RGBColor(0xa0, 0x1c, 0x1c);
const OTHER: RGBColor = RGBColor(0x70, 0x70, 0x70);

/// A method's colour in the other charts (`atomic latest` is atomic's); grey for the floor and
/// for methods this build does not know.
fn color(method: &str) -> RGBColor {
    method
        .split(' ')
        .next()
        .and_then(|m| SyncMethod::parse(m).ok())
        .map_or(OTHER, sync_color)
}

fn pair_caption(main: usize, helper: usize) -> String {
    if main == helper {
        format!("cores {main},{helper}: both threads on one core")
    } else {
        format!("cores {main},{helper}: one core each")
    }
}

/// The round trip of every method per core pair, one panel per pair, one row per method.
pub(super) fn round_trips(run: &LatencyRun) -> Result<Chart, NothingToDraw> {
    if run.rows.is_empty() {
        return Err(NothingToDraw::new("the latency run has no rows"));
    }
    // The floor first, then the methods in the order measured: the rows read from the bound down.
    let mut methods: Vec<&str> = Vec::new();
    for r in run
        .rows
        .iter()
        .filter(|r| r.method == FLOOR)
        .chain(&run.rows)
    {
        if !methods.contains(&r.method.as_str()) {
            methods.push(&r.method);
        }
    }
    let mut pairs: Vec<(usize, usize)> = Vec::new();
    for r in &run.rows {
        if !pairs.contains(&(r.main_core, r.helper_core)) {
            pairs.push((r.main_core, r.helper_core));
        }
    }
    let mut unpinned = Vec::new();
    let panels: Vec<RangePanel> = pairs
        .iter()
        .map(|&(main, helper)| {
            let rows = run
                .rows
                .iter()
                .filter(|r| (r.main_core, r.helper_core) == (main, helper));
            let mut points = Vec::new();
            for r in rows.filter(|r| !r.repeats.is_empty()) {
                let trips = r.round_trips();
                if !r.summary().pinned {
                    unpinned.push(r.label());
                }
                points.push(RangePoint {
                    row: methods.iter().position(|m| *m == r.method).unwrap_or(0),
                    value: stats::median(&trips),
                    range: stats::min_max(&trips),
                    color: if r.method == FLOOR {
                        FLOOR_COLOR
                    } else {
                        color(&r.method)
                    },
                });
            }
            let floor = run
                .rows
                .iter()
                .find(|f| f.method == FLOOR && (f.main_core, f.helper_core) == (main, helper));
            RangePanel {
                caption: pair_caption(main, helper),
                points,
                refs: floor
                    .map(|f| RefLine {
                        value: stats::median(&f.round_trips()),
                        color: FLOOR_COLOR,
                    })
                    .into_iter()
                    .collect(),
            }
        })
        .collect();
    let mut lines = Vec::new();
    lines.push(match &run.machine {
        Some(m) => format!(
            "{} · latency run started {}",
            m.line(),
            run_date(&run.started)
        ),
        None => "machine not recorded (a latency file from before runs kept it)".into(),
    });
    lines.push(format!(
        "Dot and value: the median over the repeats of each repeat's batched median round trip \
         (one clock read per {BATCH} trips); whisker: the fastest to the slowest repeat. Dashed \
         line: the cross-core floor, the raw cache line's round trip ({FLOOR}) on the same \
         cores, which no hand-off between them beats."
    ));
    let legend = if run.rows.iter().any(|r| r.method == FLOOR) {
        vec![Legend::line(
            format!("cross-core floor ({FLOOR})"),
            FLOOR_COLOR,
        )]
    } else {
        Vec::new()
    };
    let notes = if unpinned.is_empty() {
        Vec::new()
    } else {
        vec![format!("pin did not hold: {}", unpinned.join("; "))]
    };
    let values = || {
        panels
            .iter()
            .flat_map(|p: &RangePanel| p.points.iter().map(|q| q.range))
    };
    let lo = values().map(|r| r.0).fold(f64::INFINITY, f64::min);
    let hi = values().map(|r| r.1).fold(0.0, f64::max);
    // Beyond this span a linear axis would pile the fast methods on top of each other at 0.
    let log_x = lo > 0.0 && hi / lo > 20.0;
    let height = CHART_SIZE.1.max(300 + 40 * methods.len() as u32);
    Ok(Chart {
        frame: Frame {
            title: format!(
                "Hand-off round trip per method and core pair: median of {} repeat(s)",
                run.repeats
            ),
            lines,
            legend,
            notes,
        },
        body: Body::Ranges(RangePlot {
            panels,
            rows: methods.iter().map(|m| m.to_string()).collect(),
            x_desc: if log_x {
                "round trip (log scale)".into()
            } else {
                "round trip".into()
            },
            log_x,
            format: render::ns,
        }),
        size: (CHART_SIZE.0, height),
    })
}
