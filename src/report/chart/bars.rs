//! The grouped-bar charts: Figure 5-1, DP ÷ UP and the hand-off methods.

use super::render::{Bar, BarPanel, BarPlot, Body, Chart, Frame, Legend, RefLine};
use super::{mode_name, Missing, NothingToDraw, Runs, Variant, CHART_SIZE};
use crate::cell::{Dim, Mode};
use crate::stats;
use crate::summary::Summary;
use plotters::style::RGBColor;

/// Colour per mode: serial grey, UP orange, DP blue (Okabe-Ito, readable with colour blindness).
fn mode_color(mode: Mode) -> RGBColor {
    match mode {
        Mode::Serial => RGBColor(0x99, 0x99, 0x99),
        Mode::Up => RGBColor(0xe6, 0x9f, 0x00),
        Mode::Dp => RGBColor(0x00, 0x72, 0xb2),
    }
}

/// A darker shade per further run, so runs of one mode stay recognisably that mode.
pub(super) fn shade(c: RGBColor, run: usize) -> RGBColor {
    let f = 1.0 - 0.3 * (run % 3) as f64;
    let s = |v: u8| (v as f64 * f) as u8;
    RGBColor(s(c.0), s(c.1), s(c.2))
}

/// FPS with three significant figures, `k` for thousands, so values fit over narrow bars.
fn fps(v: f64) -> String {
    if v >= 10_000.0 {
        format!("{:.0}k", v / 1000.0)
    } else if v >= 1000.0 {
        format!("{:.1}k", v / 1000.0)
    } else if v >= 10.0 {
        format!("{v:.0}")
    } else if v == 0.0 {
        "0".into()
    } else {
        format!("{v:.1}")
    }
}

const IDEAL: RGBColor = RGBColor(0xd5, 0x5e, 0x00);
const NO_GAIN: RGBColor = RGBColor(0x55, 0x55, 0x55);

fn ratio(v: f64) -> String {
    format!("{v:.2}")
}

fn size_caption(size: usize) -> String {
    format!("{size}×{size} mesh")
}

/// One cell's FPS bar, its error bar from the slowest to the fastest trial.
fn fps_bar(s: &Summary, group: usize, slot: usize, color: RGBColor) -> Bar {
    Bar {
        group,
        slot,
        value: s.fps,
        range: Some((s.fps_spread.min, s.fps_spread.max)),
        color,
    }
}

/// A legend entry per run and mode, each mode in its colour.
fn mode_legend(runs: &Runs, r: usize, modes: &[Mode]) -> Vec<Legend> {
    modes
        .iter()
        .map(|&m| {
            Legend::boxed(
                runs.series(&runs.runs[r], mode_name(m)),
                shade(mode_color(m), r),
            )
        })
        .collect()
}

/// A bar chart from its panels: the machine lines and `note` under the title, what is missing
/// under the chart, or nothing to draw (`empty`) without a panel.
fn bar_chart(
    runs: &Runs,
    title: String,
    note: String,
    legend: Vec<Legend>,
    missing: Missing,
    plot: BarPlot,
    empty: impl FnOnce() -> String,
) -> Result<Chart, NothingToDraw> {
    if plot.panels.is_empty() {
        return Err(NothingToDraw(empty()));
    }
    let mut lines = runs.machine_lines();
    lines.push(note);
    Ok(Chart {
        frame: Frame {
            title,
            lines,
            legend,
            notes: missing.notes(),
        },
        body: Body::Bars(plot),
        size: CHART_SIZE,
    })
}

/// Figure 5-1 of one slice: FPS per workload, one panel per mesh size, serial / UP / DP bars.
pub(super) fn figure_5_1(runs: &Runs, v: &Variant) -> Result<Chart, NothingToDraw> {
    let modes = runs.modes();
    let workloads = runs.workloads();
    let mut missing = Missing::default();
    let legend = (0..runs.runs.len())
        .flat_map(|r| mode_legend(runs, r, &modes))
        .collect();
    let slots = runs.runs.len() * modes.len();
    let mut panels = vec![];
    for size in runs.sizes() {
        let mut bars = vec![];
        for (g, &w) in workloads.iter().enumerate() {
            for (r, run) in runs.runs.iter().enumerate() {
                for (m, &mode) in modes.iter().enumerate() {
                    let key = v.key(size, w, mode, v.sync());
                    if let Some(s) = runs.summary(run, &key, &mut missing) {
                        let color = shade(mode_color(mode), r);
                        bars.push(fps_bar(s, g, r * modes.len() + m, color));
                    }
                }
            }
        }
        if !bars.is_empty() {
            panels.push(BarPanel {
                caption: size_caption(size),
                groups: workloads
                    .iter()
                    .map(|&w| runs.level_tick(v, size, w))
                    .collect(),
                bars,
                refs: vec![],
            });
        }
    }
    bar_chart(
        runs,
        format!(
            "Figure 5-1: frames per second by workload, serial vs UP vs DP; {}",
            v.describe(&[])
        ),
        "Bars: all frames ÷ all seconds over the trials; error bars: slowest and fastest trial."
            .into(),
        legend,
        missing,
        BarPlot {
            panels,
            slots,
            x_desc: runs.workload_axis(v),
            y_desc: "frames per second (FPS)".into(),
            shared_y: false,
            format: fps,
        },
        || format!("no measured cell with {}", v.describe(&[])),
    )
}

/// DP ÷ UP and DP ÷ serial per workload in one slice, one panel per size, with the ideal 2.0.
pub(super) fn relative(runs: &Runs, v: &Variant) -> Result<Chart, NothingToDraw> {
    let workloads = runs.workloads();
    let pairs = [(Mode::Up, "DP ÷ UP"), (Mode::Serial, "DP ÷ serial")];
    let colors = [RGBColor(0x00, 0x72, 0xb2), RGBColor(0x00, 0x9e, 0x73)];
    let mut missing = Missing::default();
    let mut legend = vec![];
    for (r, run) in runs.runs.iter().enumerate() {
        for (p, (_, name)) in pairs.iter().enumerate() {
            legend.push(Legend::boxed(runs.series(run, name), shade(colors[p], r)));
        }
    }
    legend.push(Legend::line("ideal 2.0 (two cores, no overhead)", IDEAL));
    legend.push(Legend::line("no gain 1.0", NO_GAIN));
    let mut panels = vec![];
    for size in runs.sizes() {
        let mut bars = vec![];
        for (g, &w) in workloads.iter().enumerate() {
            for (r, run) in runs.runs.iter().enumerate() {
                let dp = runs.summary(run, &v.key(size, w, Mode::Dp, v.sync()), &mut missing);
                for (p, &(base, _)) in pairs.iter().enumerate() {
                    let b = runs.summary(run, &v.key(size, w, base, v.sync()), &mut missing);
                    if let (Some(dp), Some(b)) = (dp, b) {
                        // The bound pairs DP's slowest trial with the base's fastest and back.
                        let lo = dp.fps_spread.min / b.fps_spread.max;
                        let hi = dp.fps_spread.max / b.fps_spread.min;
                        bars.push(Bar {
                            group: g,
                            slot: r * pairs.len() + p,
                            value: dp.fps / b.fps,
                            range: (lo.is_finite() && hi.is_finite()).then_some((lo, hi)),
                            color: shade(colors[p], r),
                        });
                    }
                }
            }
        }
        if !bars.is_empty() {
            panels.push(BarPanel {
                caption: size_caption(size),
                groups: workloads
                    .iter()
                    .map(|&w| runs.level_tick(v, size, w))
                    .collect(),
                bars,
                refs: vec![
                    RefLine {
                        value: 2.0,
                        color: IDEAL,
                    },
                    RefLine {
                        value: 1.0,
                        color: NO_GAIN,
                    },
                ],
            });
        }
    }
    bar_chart(
        runs,
        format!(
            "DP speed-up: DP ÷ UP and DP ÷ serial FPS; {}",
            v.describe(&[])
        ),
        "Error bars: DP's slowest trial ÷ the other's fastest, and the reverse.".into(),
        legend,
        missing,
        BarPlot {
            panels,
            slots: runs.runs.len() * pairs.len(),
            x_desc: runs.workload_axis(v),
            y_desc: "FPS ratio (×)".into(),
            shared_y: true,
            format: ratio,
        },
        || {
            format!(
                "no DP cell with a UP or serial cell to divide by ({})",
                v.describe(&[])
            )
        },
    )
}

/// Each hand-off method's FPS in UP and DP in one slice, one panel per size at the highest
/// workload.
pub(super) fn sync(runs: &Runs, v: &Variant) -> Result<Chart, NothingToDraw> {
    let syncs = runs.syncs(v);
    if syncs.len() < 2 {
        return Err(NothingToDraw(format!(
            "the run measured one hand-off method ({})",
            v.sync().name()
        )));
    }
    let workload = *runs
        .workloads()
        .last()
        .ok_or(NothingToDraw::new("no workloads in the results"))?;
    let modes = [Mode::Up, Mode::Dp];
    let mut missing = Missing::default();
    let mut panels = vec![];
    let mut cpu_panels = vec![];
    let mut serial_runs = vec![false; runs.runs.len()];
    for size in runs.sizes() {
        let mut bars = vec![];
        let mut cpu_bars = vec![];
        let mut refs = vec![];
        for (r, run) in runs.runs.iter().enumerate() {
            for (g, &sync) in syncs.iter().enumerate() {
                for (m, &mode) in modes.iter().enumerate() {
                    let key = v.key(size, workload, mode, sync);
                    if let Some(s) = runs.summary(run, &key, &mut missing) {
                        let color = shade(mode_color(mode), r);
                        bars.push(fps_bar(s, g, r * modes.len() + m, color));
                        if !s.wait_cpu_ms_trials.is_empty() {
                            cpu_bars.push(Bar {
                                group: g,
                                slot: r * modes.len() + m,
                                value: s.breakdown.wait_cpu_ms(),
                                range: Some(stats::min_max(&s.wait_cpu_ms_trials)),
                                color,
                            });
                        }
                    }
                }
            }
            // A run without serial cells draws no dashed line, and its legend and subtitle do not
            // promise one.
            let serial = v.key(size, workload, Mode::Serial, v.sync());
            if run.has_serial() {
                if let Some(s) = runs.summary(run, &serial, &mut missing) {
                    serial_runs[r] = true;
                    refs.push(RefLine {
                        value: s.fps,
                        color: shade(NO_GAIN, r),
                    });
                }
            }
        }
        let groups: Vec<String> = syncs.iter().map(|s| s.name().to_string()).collect();
        let caption = format!("{}, workload {workload}", size_caption(size));
        if !cpu_bars.is_empty() {
            cpu_panels.push(BarPanel {
                caption: format!("{caption}: CPU spent waiting"),
                groups: groups.clone(),
                bars: cpu_bars,
                refs: vec![],
            });
        }
        if !bars.is_empty() {
            panels.push(BarPanel {
                caption,
                groups,
                bars,
                refs,
            });
        }
    }
    let mut legend = vec![];
    for (r, run) in runs.runs.iter().enumerate() {
        legend.extend(mode_legend(runs, r, &modes));
        if serial_runs[r] {
            legend.push(Legend::line(runs.series(run, "serial"), shade(NO_GAIN, r)));
        }
    }
    let dashed = if serial_runs.contains(&true) {
        "Dashed line: serial FPS. "
    } else {
        ""
    };
    let slots = runs.runs.len() * modes.len();
    let mut chart = bar_chart(
        runs,
        format!(
            "Hand-off methods: FPS in UP and DP at workload {workload}, and the CPU their waits burn; {}",
            v.describe(&[Dim::Sync])
        ),
        format!(
            "{dashed}Error bars: slowest and fastest trial. Lower row: CPU time per frame the main thread and the helper spent waiting (a method that sleeps burns none)."
        ),
        legend,
        missing,
        BarPlot {
            panels,
            slots,
            x_desc: "hand-off method".into(),
            y_desc: "frames per second (FPS)".into(),
            shared_y: false,
            format: fps,
        },
        || {
            format!(
                "no threaded cell at workload {workload} ({})",
                v.describe(&[Dim::Sync])
            )
        },
    )?;
    if !cpu_panels.is_empty() {
        if let Body::Bars(fps_plot) = std::mem::replace(&mut chart.body, Body::BarRows(vec![])) {
            chart.body = Body::BarRows(vec![
                fps_plot,
                BarPlot {
                    panels: cpu_panels,
                    slots,
                    x_desc: "hand-off method".into(),
                    y_desc: "CPU ms per frame spent waiting".into(),
                    shared_y: true,
                    format: super::render::ms,
                },
            ]);
            chart.size.1 = CHART_SIZE.1 * 3 / 2;
        }
    }
    Ok(chart)
}
