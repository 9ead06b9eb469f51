//! The single-cell charts: frame-time percentiles and the per-frame breakdown.

use super::bars::shade;
use super::render::{Body, Chart, Frame, Legend, LinePanel, LinePlot, Series, StackPlot, StackRow};
use super::{mode_name, short_mode, sync_color, Missing, NothingToDraw, Runs, Variant, CHART_SIZE};
use crate::cell::{Dim, Mode};
use crate::summary::{Summary, QUANTILES};
use crate::sync::SyncMethod;
use plotters::style::RGBColor;

const SERIAL: RGBColor = RGBColor(0x70, 0x70, 0x70);

/// The summary's frame-time points: mean, then median, p99, slowest-1% mean and max.
fn points(s: &Summary) -> Vec<Option<f64>> {
    let slow = (s.one_percent_low_fps > 0.0).then(|| 1000.0 / s.one_percent_low_fps);
    let t = &s.frame_time_ms;
    vec![Some(t.mean), Some(t.median), Some(t.p99), slow, Some(t.max)]
}

/// The recorded distribution at [`QUANTILES`], when the results file has it.
fn quantile_points(s: &Summary) -> Option<Vec<Option<f64>>> {
    let qs = &s.frame_time_quantiles;
    (qs.len() == QUANTILES.len()
        && qs
            .iter()
            .zip(QUANTILES)
            .all(|(p, q)| (p.q - q).abs() < 1e-9))
    .then(|| qs.iter().map(|p| Some(p.ms)).collect())
}

/// Axis label of a quantile.
fn quantile_label(q: f64) -> String {
    match q {
        0.0 => "min".into(),
        0.5 => "median".into(),
        1.0 => "max".into(),
        _ => format!("p{}", q * 100.0),
    }
}

fn focus_text(size: usize, workload: usize) -> String {
    format!("{size}×{size} mesh, workload {workload}")
}

/// Why a single-cell chart has no cell in the slice.
fn no_focus(v: &Variant) -> NothingToDraw {
    NothingToDraw(format!(
        "no measured cell with {}",
        v.describe(&[Dim::Sync])
    ))
}

/// Frame-time points per hand-off method in one slice, one panel per threaded mode, serial in
/// each.
pub(super) fn frame_times(runs: &Runs, v: &Variant) -> Result<Chart, NothingToDraw> {
    let (size, workload) = runs.focus(v).ok_or_else(|| no_focus(v))?;
    let syncs = runs.syncs(v);
    let mut missing = Missing::default();
    // The legend names only the series some panel draws.
    let mut legend: Vec<Legend> = vec![];
    let name = |legend: &mut Vec<Legend>, series: String, color| {
        if !legend.iter().any(|l| l.name == series) {
            legend.push(Legend::boxed(series, color));
        }
    };
    // The full distribution when every cell recorded it; older files give the five points.
    let all_have_quantiles = runs.runs.iter().all(|run| {
        run.results
            .cells
            .iter()
            .filter(|c| c.key.size == size && c.key.workload == workload)
            .filter_map(|c| c.summary.as_ref())
            .all(|s| quantile_points(s).is_some())
    });
    let points = |s: &Summary| {
        if all_have_quantiles {
            quantile_points(s).unwrap_or_else(|| points(s))
        } else {
            points(s)
        }
    };
    let mut panels = vec![];
    let mut any = false;
    for mode in runs.modes().into_iter().filter(|&m| m != Mode::Serial) {
        let mut series = vec![];
        for (r, run) in runs.runs.iter().enumerate() {
            for &sync in &syncs {
                if let Some(s) = runs.summary(run, &v.key(size, workload, mode, sync), &mut missing)
                {
                    let color = shade(sync_color(sync), r);
                    name(&mut legend, runs.series(run, sync.name()), color);
                    series.push(Series {
                        color,
                        values: points(s),
                    });
                }
            }
            let serial = v.key(size, workload, Mode::Serial, v.sync());
            if run.has_serial() {
                if let Some(s) = runs.summary(run, &serial, &mut missing) {
                    let color = shade(SERIAL, r);
                    name(&mut legend, runs.series(run, "serial"), color);
                    series.push(Series {
                        color,
                        values: points(s),
                    });
                }
            }
        }
        any |= !series.is_empty();
        panels.push(LinePanel {
            caption: mode_name(mode).to_string(),
            series,
        });
    }
    if !any {
        return Err(NothingToDraw(format!(
            "no measured cell at {}",
            focus_text(size, workload)
        )));
    }
    let mut lines = runs.machine_lines();
    lines.push(if all_have_quantiles {
        "Each line is the frame-time distribution over all measured frames of the cell: \
         the frame time at each quantile (nearest rank), fastest to slowest."
            .into()
    } else {
        "This results file stores no quantiles, so each line goes through the stored points: \
         median, p99, mean of the slowest 1% (from the 1% low) and max; the mean stands apart."
            .into()
    });
    Ok(Chart {
        frame: Frame {
            title: format!(
                "Frame-time distribution by hand-off method, {}; {}",
                focus_text(size, workload),
                v.describe(&[Dim::Sync])
            ),
            lines,
            legend,
            notes: missing.notes(),
        },
        body: Body::Lines(LinePlot {
            panels,
            categories: if all_have_quantiles {
                QUANTILES.iter().map(|&q| quantile_label(q)).collect()
            } else {
                ["mean", "median", "p99", "slowest 1%", "max"]
                    .map(String::from)
                    .to_vec()
            },
            first_apart: !all_have_quantiles,
            markers: Vec::new(),
            x_desc: if all_have_quantiles {
                "quantile of the measured frames".into()
            } else {
                "statistic over all measured frames".into()
            },
            y_desc: "frame time (ms, log scale)".into(),
        }),
        size: CHART_SIZE,
    })
}

/// The mean frame in one slice split into workload, wait, copy and the mesh step, one row per
/// mode and method.
pub(super) fn breakdown(runs: &Runs, v: &Variant) -> Result<Chart, NothingToDraw> {
    const WORKLOAD: usize = 0;
    const WAIT: usize = 1;
    const COPY: usize = 2;
    const STEP: usize = 3;
    let (size, workload) = runs.focus(v).ok_or_else(|| no_focus(v))?;
    let syncs = runs.syncs(v);
    let modes = runs.modes();
    let mut missing = Missing::default();
    let mut rows = vec![];
    // The first UP row's workload part and serial's, to say why the first is the longer.
    let (mut up_workload, mut serial_workload) = (None, None);
    for run in &runs.runs {
        for &mode in &modes {
            let methods: Vec<SyncMethod> = if mode == Mode::Serial {
                vec![v.sync()]
            } else {
                syncs.clone()
            };
            for sync in methods {
                let Some(s) = runs.summary(run, &v.key(size, workload, mode, sync), &mut missing)
                else {
                    continue;
                };
                let b = &s.breakdown;
                match mode {
                    Mode::Up => up_workload = up_workload.or(Some(b.workload_ms)),
                    Mode::Serial => serial_workload = serial_workload.or(Some(b.workload_ms)),
                    Mode::Dp => {}
                }
                let (label, main, helper) = if mode == Mode::Serial {
                    (
                        "serial".to_string(),
                        vec![
                            (WORKLOAD, b.workload_ms),
                            (STEP, b.step_ms),
                            (COPY, b.copy_ms),
                        ],
                        None,
                    )
                } else {
                    (
                        format!("{} {}", short_mode(mode), sync.name()),
                        vec![
                            (WORKLOAD, b.workload_ms),
                            (WAIT, b.wait_ms),
                            (COPY, b.copy_ms),
                        ],
                        Some((STEP, b.step_ms)),
                    )
                };
                rows.push(StackRow {
                    label: runs.series(run, &label),
                    main,
                    helper,
                    total: s.frame_time_ms.mean,
                });
            }
        }
    }
    if rows.is_empty() {
        return Err(NothingToDraw(format!(
            "no measured cell at {}",
            focus_text(size, workload)
        )));
    }
    let colors = vec![
        RGBColor(0x00, 0x72, 0xb2),
        RGBColor(0xd5, 0x5e, 0x00),
        RGBColor(0x00, 0x9e, 0x73),
        RGBColor(0xcc, 0x79, 0xa7),
    ];
    let legend = vec![
        Legend::boxed("workload (main thread)", colors[WORKLOAD]),
        Legend::boxed("waiting for the mesh (main)", colors[WAIT]),
        Legend::boxed("copying the mesh (main)", colors[COPY]),
        Legend::boxed("mesh step (helper: lower bar; serial: main)", colors[STEP]),
        Legend::boxed("mean frame time (tick)", RGBColor(0, 0, 0)),
    ];
    let mut lines = runs.machine_lines();
    lines.push(
        "Mean per frame. The upper bar is the main thread's frame; in UP and DP the lower bar is \
         the helper's step, which overlaps it."
            .into(),
    );
    if let Some(up) = up_workload {
        let alone = serial_workload.map_or(String::new(), |serial| {
            format!(
                ": UP's workload part is {} ms where the workload alone (serial) takes {} ms",
                super::render::ms(up),
                super::render::ms(serial)
            )
        });
        lines.push(format!(
            "In UP both threads share one core, so the main thread's parts are wall time that \
             includes the helper's slices run inside them{alone}."
        ));
    }
    let height = CHART_SIZE.1.max(300 + 44 * rows.len() as u32);
    Ok(Chart {
        frame: Frame {
            title: format!(
                "Where a frame's time goes, {}; {}",
                focus_text(size, workload),
                v.describe(&[Dim::Sync])
            ),
            lines,
            legend,
            notes: missing.notes(),
        },
        body: Body::Stacks(StackPlot {
            rows,
            colors,
            x_desc: "time per frame (ms)".into(),
        }),
        size: (CHART_SIZE.0, height),
    })
}
