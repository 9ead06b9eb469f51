//! How much work the second core can hide: DP ÷ serial against W ÷ S for every searched cell,
//! the ideal (W + S) / max(W, S), each balance point with its bracket, and the run's workload
//! levels on the same axis.

use super::bars::shade;
use super::render::{Body, Chart, Frame, Legend, Trace, TracePanel, TracePlot};
use super::{held, NothingToDraw, Runs, Variant, CHART_SIZE};
use crate::cell::Dim;
use crate::stats;
use plotters::style::RGBColor;

const IDEAL: RGBColor = super::PALETTE[1];
const LEVEL: RGBColor = RGBColor(0x99, 0x99, 0x99);

/// One colour per searched cell in a panel: the methods' palette without the orange of the
/// ideal curve.
fn cell_color(i: usize) -> RGBColor {
    const CELLS: [usize; 5] = [0, 2, 3, 4, 5];
    shade(super::PALETTE[CELLS[i % CELLS.len()]], i / CELLS.len())
}

/// The speed-up curve of every searched cell in the slice (every one without a slice), one
/// panel per size.
pub(super) fn balance(runs: &Runs, v: Option<&Variant>) -> Result<Chart, NothingToDraw> {
    let entries: Vec<_> = runs
        .runs
        .iter()
        .flat_map(|r| r.results.balance.iter().map(move |e| (r, e)))
        .filter(|(_, e)| v.is_none_or(|v| v.contains(&e.key)))
        .collect();
    if entries.is_empty() {
        return Err(NothingToDraw(match v {
            Some(v) if runs.runs.iter().any(|r| !r.results.balance.is_empty()) => {
                format!("no balance search with {}", v.describe(&[]))
            }
            _ => "no balance search in the results".into(),
        }));
    }
    // The title names what every searched cell holds; the legend tells the cells apart.
    let keys: Vec<_> = entries.iter().map(|(_, e)| &e.key).collect();
    let title = format!(
        "Where the two threads balance: DP speed-up against main-thread work; {}",
        held(&keys, &[])
    );
    let mut sizes: Vec<usize> = entries.iter().map(|(_, e)| e.key.size).collect();
    sizes.sort_unstable();
    sizes.dedup();
    let mut legend = vec![Legend::line("ideal (W + S) / max(W, S)", IDEAL)];
    let mut panels = Vec::new();
    for size in sizes {
        let mut traces = Vec::new();
        let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
        for (i, (run, e)) in entries
            .iter()
            .filter(|(_, e)| e.key.size == size)
            .enumerate()
        {
            let color = cell_color(i);
            let points: Vec<(f64, f64, String)> = e
                .probes
                .iter()
                .map(|p| {
                    (
                        p.workload_us / e.step_us,
                        stats::mean(&p.fps) / stats::mean(&p.serial_fps),
                        String::new(),
                    )
                })
                .collect();
            for p in &points {
                lo = lo.min(p.0);
                hi = hi.max(p.0);
            }
            let name = runs.series(run, &e.key.label_without(&[Dim::Workload, Dim::Size]));
            if !legend.iter().any(|l| l.name == name) {
                legend.push(Legend::boxed(name, color));
            }
            traces.push(Trace { color, points });
            if let (Some(b), Some(l), Some(h), Some(r)) = (
                e.balance_us,
                e.balance_us_low,
                e.balance_us_high,
                e.dp_over_serial,
            ) {
                let s = e.step_us;
                traces.push(Trace {
                    color,
                    points: vec![
                        (l / s, r, String::new()),
                        (b / s, r, format!("balance {:.2}·S: {r:.2}×", b / s)),
                        (h / s, r, String::new()),
                    ],
                });
            }
            for level in run
                .results
                .calibration
                .levels
                .iter()
                .filter(|l| l.micros > 0.0)
            {
                let x = level.micros / e.step_us;
                if (lo..=hi).contains(&x) || lo.is_infinite() {
                    traces.push(Trace {
                        color: LEVEL,
                        points: vec![
                            (x, 0.0, String::new()),
                            (x, 2.0, format!("w{}", level.workload)),
                        ],
                    });
                }
            }
        }
        if lo.is_finite() {
            let ideal = (0..=60)
                .map(|i| {
                    let x = lo * (hi / lo).powf(i as f64 / 60.0);
                    (x, (x + 1.0) / x.max(1.0), String::new())
                })
                .collect();
            traces.insert(
                0,
                Trace {
                    color: IDEAL,
                    points: ideal,
                },
            );
        }
        panels.push(TracePanel {
            caption: format!("{size}×{size} mesh"),
            traces,
        });
    }
    let mut lines = runs.machine_lines();
    lines.push(
        "Each line: DP ÷ serial FPS (mean of paired trials) against the main thread's workload W over the helper's step S; \
         the horizontal bar marks the balance point's bracket; grey lines are the run's workload levels."
            .into(),
    );
    legend.push(Legend::line("workload levels w1-w3", LEVEL));
    Ok(Chart {
        frame: Frame {
            title,
            lines,
            legend,
            notes: Vec::new(),
        },
        body: Body::Traces(TracePlot {
            panels,
            rows: 1,
            x_desc: "main-thread workload W ÷ helper step S (log scale)".into(),
            y_desc: "DP ÷ serial FPS (×)".into(),
            log_x: true,
            y_format: |v| format!("{v:.2}"),
        }),
        size: CHART_SIZE,
    })
}
