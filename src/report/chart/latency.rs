//! What run-ahead buys and costs: FPS against the median input-to-consume latency, one trace per
//! mode, method and consumption, its points the depths.

use super::bars::shade;
use super::render::{Body, Chart, Frame, Legend, Trace, TracePanel, TracePlot};
use super::{mode_name, Missing, NothingToDraw, Runs, CHART_SIZE};
use crate::frame_loop::{Consume, Mode};
use plotters::style::RGBColor;
use strum::VariantArray;

/// One colour per mode; methods and consumptions get darker shades of it.
fn mode_color(mode: Mode) -> RGBColor {
    match mode {
        Mode::Up => RGBColor(0xe6, 0x9f, 0x00),
        _ => RGBColor(0x00, 0x72, 0xb2),
    }
}

/// FPS against input-to-consume latency, one panel per size at the focus workload.
pub(super) fn latency_vs_fps(
    runs: &Runs,
    focus: Option<(usize, usize)>,
) -> Result<Chart, NothingToDraw> {
    let (_, workload) = focus.ok_or(NothingToDraw::new("no measured cell in the results"))?;
    let v = runs.variant()?;
    let depths = runs.counts(crate::cell::Dim::Depth);
    let mut missing = Missing::default();
    let mut legend = Vec::new();
    let mut panels = Vec::new();
    for size in runs.sizes() {
        let mut traces = Vec::new();
        for (r, run) in runs.runs.iter().enumerate() {
            let mut shade_index = r;
            for mode in [Mode::Up, Mode::Dp] {
                for sync in runs.syncs() {
                    for &consume in Consume::VARIANTS {
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
                        let color = shade(mode_color(mode), shade_index);
                        shade_index += 1;
                        let name = format!("{} {sync} {consume}", mode_name(mode));
                        if !legend
                            .iter()
                            .any(|l: &Legend| l.name == runs.series(run, &name))
                        {
                            legend.push(Legend::boxed(runs.series(run, &name), color));
                        }
                        traces.push(Trace { color, points });
                    }
                }
            }
        }
        if traces.is_empty() {
            missing.add(format!("{size}×{size} w{workload}: no cell with a latency"));
        } else {
            panels.push(TracePanel {
                caption: format!("{size}×{size} mesh, workload {workload}"),
                traces,
            });
        }
    }
    if panels.is_empty() {
        return Err(NothingToDraw(
            "no threaded cell records latency (results from before run-ahead depth)".into(),
        ));
    }
    let mut lines = runs.machine_lines();
    lines.push(format!(
        "Each line joins one mode, method and consumption over run-ahead depths d1, d2, ...: up is more FPS, right is older meshes. {}.",
        v.describe(false)
    ));
    Ok(Chart {
        frame: Frame {
            title: "Run-ahead: frames per second against input-to-consume latency".into(),
            lines,
            legend,
            notes: missing.notes(),
        },
        body: Body::Traces(TracePlot {
            panels,
            x_desc:
                "median input-to-consume latency (ms): helper starts a mesh → main thread takes it"
                    .into(),
            y_desc: "frames per second (FPS)".into(),
            log_x: false,
            y_format: |v| format!("{v:.0}"),
        }),
        size: CHART_SIZE,
    })
}
