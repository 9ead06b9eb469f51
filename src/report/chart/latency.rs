//! What run-ahead buys and costs: FPS against the median input-to-consume latency, one panel
//! per mode and size, one trace per method and consumption, its points the depths.

use super::bars::shade;
use super::render::{Body, Chart, Frame, Legend, Trace, TracePanel, TracePlot};
use super::{mode_name, sync_color, Missing, NothingToDraw, Runs, Variant, CHART_SIZE};
use crate::cell::{Consume, Dim, Mode};
use strum::VariantArray;

/// The dimensions the run-ahead chart lays out besides size, workload and mode.
pub(super) const LAID_OUT: [Dim; 3] = [Dim::Sync, Dim::Depth, Dim::Consume];

/// FPS against input-to-consume latency in one slice at its focus workload: UP panels in the
/// top row, DP in the bottom one, a column per size. A method keeps its colour from the other
/// charts, and its consumptions are shades of it, so one legend entry names the same series in
/// every panel.
pub(super) fn latency_vs_fps(runs: &Runs, v: &Variant) -> Result<Chart, NothingToDraw> {
    let depths = runs.counts(Dim::Depth);
    if depths.len() < 2 {
        return Err(NothingToDraw::new(
            "the run measured one run-ahead depth: no latency traded for FPS to show",
        ));
    }
    let (_, workload) = runs
        .focus(v)
        .ok_or_else(|| NothingToDraw(format!("no measured cell with {}", v.describe(&LAID_OUT))))?;
    let mut missing = Missing::default();
    let mut legend: Vec<Legend> = Vec::new();
    let mut panels = Vec::new();
    let modes = [Mode::Up, Mode::Dp];
    for mode in modes {
        for size in runs.sizes() {
            let mut traces = Vec::new();
            for (r, run) in runs.runs.iter().enumerate() {
                for sync in runs.syncs(v) {
                    for (c, &consume) in Consume::VARIANTS.iter().enumerate() {
                        let points: Vec<(f64, f64, String)> = depths
                            .iter()
                            .filter_map(|&d| {
                                let key = crate::results::CellKey {
                                    depth: Some(d),
                                    consume,
                                    ..v.key(size, workload, mode, sync)
                                };
                                let cell = run.results.cell(&key)?;
                                let s = cell.summary.as_ref()?;
                                let l = s.latency.as_ref()?;
                                Some((l.input_to_consume_ms_median, s.fps, format!("d{d}")))
                            })
                            .collect();
                        if points.is_empty() {
                            continue;
                        }
                        let color = shade(sync_color(sync), c + r);
                        let name = runs.series(run, &format!("{sync} {consume}"));
                        if !legend.iter().any(|l| l.name == name) {
                            legend.push(Legend::boxed(name, color));
                        }
                        traces.push(Trace { color, points });
                    }
                }
            }
            if traces.is_empty() {
                missing.add(format!(
                    "{size}×{size} w{workload} {}: no cell with a latency",
                    mode_name(mode)
                ));
            } else {
                panels.push(TracePanel {
                    caption: format!(
                        "{}, {size}×{size} mesh, workload {workload}",
                        mode_name(mode)
                    ),
                    traces,
                });
            }
        }
    }
    if panels.is_empty() {
        return Err(NothingToDraw(
            "no threaded cell records latency (results from before run-ahead depth)".into(),
        ));
    }
    let rows = modes
        .iter()
        .filter(|m| panels.iter().any(|p| p.caption.starts_with(mode_name(**m))))
        .count();
    let mut lines = runs.machine_lines();
    lines.push(
        "Each line joins one method and consumption over run-ahead depths d1, d2, ...: up is more FPS, right is older meshes (input-to-consume: the helper starts a mesh → the main thread takes it); a label hidden by another names the same depth."
            .into(),
    );
    let mut size = CHART_SIZE;
    if rows > 1 {
        size.1 = CHART_SIZE.1 * 3 / 2;
    }
    Ok(Chart {
        frame: Frame {
            title: format!(
                "Run-ahead: frames per second against input-to-consume latency; {}",
                v.describe(&LAID_OUT)
            ),
            lines,
            legend,
            notes: missing.notes(),
        },
        body: Body::Traces(TracePlot {
            panels,
            rows,
            x_desc: "input-to-consume latency, median (ms)".into(),
            y_desc: "frames per second (FPS)".into(),
            log_x: false,
            y_format: |v| format!("{v:.0}"),
        }),
        size,
    })
}
