//! Drawing the chart data with plotters, the same way for every backend.

use super::glyphs::{Glyphs, FONT_BYTES};
use super::{ChartError, ChartFormat};
use plotters::chart::MeshStyle;
use plotters::coord::ranged1d::{DefaultFormatting, KeyPointHint, Ranged, ValueFormatter};
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::ops::Range;
use std::path::Path;
use std::sync::OnceLock;

const FONT: &str = "sans-serif";
const TEXT: RGBColor = RGBColor(0x20, 0x20, 0x20);
const SUBTLE: RGBColor = RGBColor(0x50, 0x50, 0x50);
const NOTE: RGBColor = RGBColor(0xa0, 0x1c, 0x1c);
const LIGHT: RGBColor = RGBColor(0xee, 0xee, 0xee);
const PAD: i32 = 24;

/// Registers the bundled font once; plotters' `ab_glyph` backend knows no system fonts.
pub(super) fn register_font() -> Result<(), ChartError> {
    static DONE: OnceLock<bool> = OnceLock::new();
    let ok = *DONE.get_or_init(|| {
        plotters::style::register_font(FONT, FontStyle::Normal, FONT_BYTES).is_ok()
    });
    ok.then_some(()).ok_or(ChartError::Font)
}

fn font(size: f64) -> TextStyle<'static> {
    TextStyle::from((FONT, size).into_font()).color(&TEXT)
}

/// The text around a chart's plot.
pub(super) struct Frame {
    pub title: String,
    pub lines: Vec<String>,
    pub legend: Vec<Legend>,
    pub notes: Vec<String>,
}

/// A legend entry: a filled box for bars and points, a dashed line for reference lines.
pub(super) struct Legend {
    pub name: String,
    pub color: RGBColor,
    pub line: bool,
}

impl Legend {
    /// An entry for bars or points.
    pub fn boxed(name: impl Into<String>, color: RGBColor) -> Legend {
        Legend {
            name: name.into(),
            color,
            line: false,
        }
    }

    /// An entry for a dashed reference line.
    pub fn line(name: impl Into<String>, color: RGBColor) -> Legend {
        Legend {
            name: name.into(),
            color,
            line: true,
        }
    }
}

/// A horizontal dashed reference line across a bar panel, named in the legend.
pub(super) struct RefLine {
    pub value: f64,
    pub color: RGBColor,
}

/// One bar: its group on the x axis, its slot in the group, value and optional range.
pub(super) struct Bar {
    pub group: usize,
    pub slot: usize,
    pub value: f64,
    pub range: Option<(f64, f64)>,
    pub color: RGBColor,
}

/// A panel of grouped bars.
pub(super) struct BarPanel {
    pub caption: String,
    pub groups: Vec<String>,
    pub bars: Vec<Bar>,
    pub refs: Vec<RefLine>,
}

/// Grouped bars in side-by-side panels.
pub(super) struct BarPlot {
    pub panels: Vec<BarPanel>,
    pub slots: usize,
    pub x_desc: String,
    pub y_desc: String,
    /// One y scale for all panels (ratios), or one per panel (FPS of very different sizes).
    pub shared_y: bool,
    pub format: fn(f64) -> String,
}

/// One line of points over the categories of a line panel.
pub(super) struct Series {
    pub color: RGBColor,
    pub values: Vec<Option<f64>>,
}

/// A panel of lines over categories.
pub(super) struct LinePanel {
    pub caption: String,
    pub series: Vec<Series>,
}

/// A labelled vertical mark across a line plot, such as a change between two runs.
pub(super) struct Marker {
    /// On the category axis: a category's index, or between two (4.5 lies between 4 and 5).
    pub at: f64,
    pub color: RGBColor,
    pub label: String,
}

/// Category lines on a log y axis; the first category can stand apart from the curve.
pub(super) struct LinePlot {
    pub panels: Vec<LinePanel>,
    pub categories: Vec<String>,
    pub first_apart: bool,
    pub x_desc: String,
    pub y_desc: String,
    /// Drawn across every panel, over the lines.
    pub markers: Vec<Marker>,
}

/// One row of a stacked breakdown.
pub(super) struct StackRow {
    pub label: String,
    /// The main thread's parts in stacking order: (part index, ms).
    pub main: Vec<(usize, f64)>,
    /// A part that ran on the helper thread, drawn as its own thinner bar.
    pub helper: Option<(usize, f64)>,
    /// The mean frame time, drawn as a tick.
    pub total: f64,
}

/// Horizontal stacked bars, one row per mode and method.
pub(super) struct StackPlot {
    pub rows: Vec<StackRow>,
    pub colors: Vec<RGBColor>,
    pub x_desc: String,
}

/// Points joined in order, each with a short label (a scatter whose points belong together).
pub(super) struct Trace {
    pub color: RGBColor,
    /// (x, y, label) in the order the line joins them.
    pub points: Vec<(f64, f64, String)>,
}

/// A panel of traces on numeric axes.
pub(super) struct TracePanel {
    pub caption: String,
    pub traces: Vec<Trace>,
}

/// Traces in side-by-side panels, linear y from 0; x linear from 0, or logarithmic over the
/// points' range.
pub(super) struct TracePlot {
    pub panels: Vec<TracePanel>,
    /// Rows the panels are laid out in, filled left to right.
    pub rows: usize,
    pub x_desc: String,
    pub y_desc: String,
    pub log_x: bool,
    pub y_format: fn(f64) -> String,
}

/// What a chart draws below its frame.
pub(super) enum Body {
    Bars(BarPlot),
    Ranges(RangePlot),
    Lines(LinePlot),
    Stacks(StackPlot),
    Traces(TracePlot),
    /// Bar plots stacked in rows, each with its own axes.
    BarRows(Vec<BarPlot>),
}

/// One row's value in a range panel: a dot, and a whisker over its range.
pub(super) struct RangePoint {
    pub row: usize,
    pub value: f64,
    pub range: (f64, f64),
    pub color: RGBColor,
}

/// A panel of [`RangePlot`]: its points and its dashed vertical reference lines.
pub(super) struct RangePanel {
    pub caption: String,
    pub points: Vec<RangePoint>,
    pub refs: Vec<RefLine>,
}

/// Named rows, top to bottom, each a dot with a whisker and its value beside it, in panels side
/// by side on one x axis: logarithmic, or linear from 0.
pub(super) struct RangePlot {
    pub panels: Vec<RangePanel>,
    pub rows: Vec<String>,
    pub x_desc: String,
    pub log_x: bool,
    pub format: fn(f64) -> String,
}

/// A whole chart, ready to draw in any format.
pub(super) struct Chart {
    pub frame: Frame,
    pub body: Body,
    pub size: (u32, u32),
}

/// Writes `chart` to `path` in `format`.
pub(super) fn write(chart: &Chart, path: &Path, format: ChartFormat) -> Result<(), ChartError> {
    let drawn = match format {
        ChartFormat::Png => draw(
            &Glyphs::new(BitMapBackend::new(path, chart.size)).into_drawing_area(),
            chart,
        ),
        ChartFormat::Svg => draw(
            &SVGBackend::new(path, chart.size).into_drawing_area(),
            chart,
        ),
    };
    drawn.map_err(|e| ChartError::Draw {
        path: path.to_path_buf(),
        message: e.to_string(),
    })
}

/// The chart as SVG text; `name` names it in an error.
pub(super) fn svg(chart: &Chart, name: &str) -> Result<String, ChartError> {
    let mut text = String::new();
    draw(
        &SVGBackend::with_string(&mut text, chart.size).into_drawing_area(),
        chart,
    )
    .map_err(|e| ChartError::Draw {
        path: format!("{name}.svg").into(),
        message: e.to_string(),
    })?;
    Ok(text)
}

/// What a plotters backend reported; its error type differs per backend, so it is kept as text.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub(super) struct DrawError(String);

fn err(e: impl std::fmt::Display) -> DrawError {
    DrawError(e.to_string())
}

fn draw<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, chart: &Chart) -> Result<(), DrawError> {
    root.fill(&WHITE).map_err(err)?;
    let body = frame(root, &chart.frame)?;
    match &chart.body {
        Body::Bars(p) => bars(&body, p)?,
        Body::Ranges(p) => ranges(&body, p)?,
        Body::Lines(p) => lines(&body, p)?,
        Body::Stacks(p) => stacks(&body, p)?,
        Body::Traces(p) => traces(&body, p)?,
        Body::BarRows(rows) => {
            for (plot, area) in rows.iter().zip(body.split_evenly((rows.len().max(1), 1))) {
                bars(&area, plot)?;
            }
        }
    }
    root.present().map_err(err)
}

/// Splits `text` into lines no wider than `width` pixels at `style`.
fn wrap<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    text: &str,
    style: &TextStyle,
    width: u32,
) -> Result<Vec<String>, DrawError> {
    let mut out = vec![];
    let mut line = String::new();
    for word in text.split(' ') {
        let candidate = if line.is_empty() {
            word.to_string()
        } else {
            format!("{line} {word}")
        };
        if !line.is_empty() && area.estimate_text_size(&candidate, style).map_err(err)?.0 > width {
            out.push(std::mem::replace(&mut line, word.to_string()));
        } else {
            line = candidate;
        }
    }
    out.push(line);
    Ok(out)
}

/// Draws title, subtitle lines, legend and notes; returns the area left for the plot.
fn frame<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    frame: &Frame,
) -> Result<DrawingArea<DB, Shift>, DrawError> {
    let (w, h) = root.dim_in_pixel();
    let inner = w - 2 * PAD as u32;
    let mut y = 14;
    let title = font(26.0);
    for line in wrap(root, &frame.title, &title, inner)? {
        root.draw_text(&line, &title, (PAD, y)).map_err(err)?;
        y += 34;
    }
    let sub = font(16.0).color(&SUBTLE);
    for text in &frame.lines {
        for line in wrap(root, text, &sub, inner)? {
            root.draw_text(&line, &sub, (PAD, y)).map_err(err)?;
            y += 22;
        }
    }
    y += 8;
    let legend = font(16.0);
    let mut x = PAD;
    for entry in &frame.legend {
        let mark = if entry.line { 34 } else { 17 };
        let width = mark
            + 6
            + root
                .estimate_text_size(&entry.name, &legend)
                .map_err(err)?
                .0 as i32;
        if x > PAD && x + width > w as i32 - PAD {
            x = PAD;
            y += 26;
        }
        if entry.line {
            for dash in [0, 13, 26] {
                root.draw(&PathElement::new(
                    vec![(x + dash, y + 10), (x + dash + 8, y + 10)],
                    entry.color.stroke_width(3),
                ))
                .map_err(err)?;
            }
        } else {
            root.draw(&Rectangle::new(
                [(x, y + 1), (x + 17, y + 18)],
                entry.color.filled(),
            ))
            .map_err(err)?;
        }
        // Three pixels down centres the capitals (0.76 em from the top to the baseline) on the
        // 17-pixel mark.
        root.draw_text(&entry.name, &legend, (x + mark + 6, y + 3))
            .map_err(err)?;
        x += width + 30;
    }
    if !frame.legend.is_empty() {
        y += 30;
    }
    let note = font(16.0).color(&NOTE);
    let mut notes = vec![];
    for text in &frame.notes {
        notes.extend(wrap(root, text, &note, inner)?);
    }
    let footer = if notes.is_empty() {
        8
    } else {
        notes.len() as i32 * 22 + 14
    };
    for (i, line) in notes.iter().enumerate() {
        let ny = h as i32 - footer + 6 + i as i32 * 22;
        root.draw_text(line, &note, (PAD, ny)).map_err(err)?;
    }
    Ok(root.margin(y, footer, 8, 16))
}

/// A panel's chart in the house style: its caption above, room for tick labels and an axis name
/// on the left and `x_labels` pixels of it below.
fn panel_chart<'a, 'b, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    caption: &str,
    x_labels: u32,
) -> ChartBuilder<'a, 'b, DB> {
    let mut builder = ChartBuilder::on(area);
    builder
        .caption(caption, font(19.0))
        .margin(10)
        .x_label_area_size(x_labels)
        .y_label_area_size(88);
    builder
}

/// Draws a chart's axes in the house style, named `x_desc` and `y_desc` (if any), their ticks
/// labelled by `x_fmt` and `y_fmt`; `mesh` holds what the chart sets apart (a grid direction
/// left out, more labels).
fn draw_axes<'b, X, Y, DB>(
    mesh: &mut MeshStyle<'_, 'b, X, Y, DB>,
    x_desc: &str,
    y_desc: Option<&str>,
    x_fmt: &'b dyn Fn(&X::ValueType) -> String,
    y_fmt: &'b dyn Fn(&Y::ValueType) -> String,
) -> Result<(), DrawError>
where
    X: Ranged + ValueFormatter<X::ValueType>,
    Y: Ranged + ValueFormatter<Y::ValueType>,
    DB: DrawingBackend,
{
    if let Some(y_desc) = y_desc {
        mesh.y_desc(y_desc);
    }
    mesh.x_desc(x_desc)
        .x_label_formatter(x_fmt)
        .y_label_formatter(y_fmt)
        .label_style(font(15.0))
        .axis_desc_style(font(17.0))
        .light_line_style(LIGHT)
        .max_light_lines(1)
        .draw()
        .map_err(err)
}

/// An f64 axis whose ticks sit at the category indices 0..n. Plotters' `with_key_points`
/// cannot be used: on an f64 axis it loses the label formatter `configure_mesh` needs.
#[derive(Clone)]
struct Categories {
    range: Range<f64>,
    n: usize,
}

fn categories(range: Range<f64>, n: usize) -> Categories {
    Categories { range, n }
}

impl Ranged for Categories {
    type FormatOption = DefaultFormatting;
    type ValueType = f64;

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        RangedCoordf64::from(self.range.clone()).map(value, limit)
    }

    fn key_points<Hint: KeyPointHint>(&self, hint: Hint) -> Vec<f64> {
        // Only bold points: light grid lines between categories mean nothing.
        if hint.weight().allow_light_points() {
            vec![]
        } else {
            (0..self.n).map(|i| i as f64).collect()
        }
    }

    fn range(&self) -> Range<f64> {
        self.range.clone()
    }
}

fn label_at(labels: &[String], v: f64) -> String {
    let i = v.round();
    if i < 0.0 || (v - i).abs() > 1e-6 {
        return String::new();
    }
    labels.get(i as usize).cloned().unwrap_or_default()
}

fn bar_top(bar: &Bar) -> f64 {
    bar.range.map_or(bar.value, |(_, hi)| hi.max(bar.value))
}

fn bars<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    plot: &BarPlot,
) -> Result<(), DrawError> {
    let panel_top = |p: &BarPanel| {
        p.bars
            .iter()
            .map(bar_top)
            .chain(p.refs.iter().map(|r| r.value))
            .fold(0.0, f64::max)
    };
    let shared = plot.panels.iter().map(panel_top).fold(0.0, f64::max);
    let areas = area.split_evenly((1, plot.panels.len().max(1)));
    for (panel, area) in plot.panels.iter().zip(&areas) {
        let top = if plot.shared_y {
            shared
        } else {
            panel_top(panel)
        };
        let y_max = if top > 0.0 { top * 1.12 } else { 1.0 };
        bar_panel(area, plot, panel, y_max)?;
    }
    Ok(())
}

fn bar_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    plot: &BarPlot,
    panel: &BarPanel,
    y_max: f64,
) -> Result<(), DrawError> {
    let n = panel.groups.len().max(1);
    let mut chart = panel_chart(area, &panel.caption, 64)
        .build_cartesian_2d(categories(-0.5..n as f64 - 0.5, n), 0.0..y_max)
        .map_err(err)?;
    let group_px = chart.plotting_area().dim_in_pixel().0 as f64 / n as f64;
    let fits = panel.groups.iter().try_fold(true, |fits, g| {
        let w = area.estimate_text_size(g, &font(15.0)).map_err(err)?.0 as f64;
        Ok::<_, DrawError>(fits && !g.contains('\n') && w < group_px * 0.92)
    })?;
    // Group names too wide for their slot are drawn by hand below, broken after a hyphen.
    let x_fmt = |v: &f64| {
        if fits {
            label_at(&panel.groups, *v)
        } else {
            String::new()
        }
    };
    let y_fmt = |v: &f64| (plot.format)(*v);
    draw_axes(
        chart.configure_mesh().disable_x_mesh(),
        &plot.x_desc,
        Some(&plot.y_desc),
        &x_fmt,
        &y_fmt,
    )?;
    if !fits {
        group_labels(area, &chart, &panel.groups, group_px)?;
    }
    let slot = 0.8 / plot.slots.max(1) as f64;
    let plot_width = chart.plotting_area().dim_in_pixel().0 as f64;
    let slot_px = plot_width * slot / n as f64;
    let value_style = font(12.0).pos(Pos::new(HPos::Center, VPos::Bottom));
    let mut values = Vec::new();
    for bar in &panel.bars {
        let x0 = bar.group as f64 - 0.4 + bar.slot as f64 * slot + slot * 0.08;
        let x1 = x0 + slot * 0.84;
        let mid = (x0 + x1) / 2.0;
        chart
            .draw_series(std::iter::once(Rectangle::new(
                [(x0, 0.0), (x1, bar.value)],
                bar.color.filled(),
            )))
            .map_err(err)?;
        if let Some((lo, hi)) = bar.range {
            // Plain whiskers: plotters' error bar puts a circle on the mean that hides short ranges.
            let cap = slot * 0.22;
            let style = BLACK.stroke_width(2);
            for line in [
                vec![(mid, lo), (mid, hi)],
                vec![(mid - cap, lo), (mid + cap, lo)],
                vec![(mid - cap, hi), (mid + cap, hi)],
            ] {
                chart
                    .draw_series(std::iter::once(PathElement::new(line, style)))
                    .map_err(err)?;
            }
        }
        // Values are printed only when they fit over their bar, to keep bars readable.
        let text = (plot.format)(bar.value);
        let text_px = area.estimate_text_size(&text, &value_style).map_err(err)?.0 as f64;
        if text_px < slot_px * 0.98 {
            values.push((
                text,
                chart.backend_coord(&(mid, bar_top(bar) + y_max * 0.012)),
            ));
        }
    }
    for r in &panel.refs {
        chart
            .draw_series(DashedLineSeries::new(
                [(-0.5, r.value), (n as f64 - 0.5, r.value)],
                10,
                6,
                r.color.stroke_width(2),
            ))
            .map_err(err)?;
    }
    // Last, so that a reference line stops at a value instead of striking it through.
    for (text, at) in values {
        label(area, &text, &value_style, at)?;
    }
    Ok(())
}

/// Draws `text` at `at` (backend pixels, placed by the style's anchor) over a white box of its
/// size, so that a grid or data line under it stops at its edge instead of striking it.
fn label<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    text: &str,
    style: &TextStyle,
    at: (i32, i32),
) -> Result<(), DrawError> {
    let (w, h) = area.estimate_text_size(text, style).map_err(err)?;
    let (w, h) = (w as i32, h as i32);
    let base = area.get_base_pixel();
    let (x, y) = (at.0 - base.0, at.1 - base.1);
    let x0 = match style.pos.h_pos {
        HPos::Left => x,
        HPos::Center => x - w / 2,
        HPos::Right => x - w,
    };
    let y0 = match style.pos.v_pos {
        VPos::Top => y,
        VPos::Center => y - h / 2,
        VPos::Bottom => y - h,
    };
    area.draw(&Rectangle::new(
        [(x0 - 2, y0 - 2), (x0 + w + 2, y0 + h + 2)],
        WHITE.filled(),
    ))
    .map_err(err)?;
    area.draw(&Text::new(text.to_string(), (x, y), style.clone()))
        .map_err(err)
}

/// Draws each group's name centred under its slot, a line per `\n`, and a line in two when it
/// is too wide for one (broken after its first hyphen, else in the middle), in a smaller font.
fn group_labels<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    chart: &ChartContext<'_, DB, Cartesian2d<Categories, RangedCoordf64>>,
    groups: &[String],
    group_px: f64,
) -> Result<(), DrawError> {
    let style = font(15.0).pos(Pos::new(HPos::Center, VPos::Top));
    let base = area.get_base_pixel();
    for (i, g) in groups.iter().enumerate() {
        let (x, y) = chart.backend_coord(&(i as f64, 0.0));
        let mut lines: Vec<String> = Vec::new();
        for part in g.split('\n') {
            let width = area.estimate_text_size(part, &style).map_err(err)?.0 as f64;
            if width < group_px * 0.95 {
                lines.push(part.to_string());
            } else {
                let at = part.find('-').map_or(part.len() / 2, |h| h + 1);
                let at = (0..=at)
                    .rev()
                    .find(|&i| part.is_char_boundary(i))
                    .unwrap_or(0);
                lines.extend([part[..at].to_string(), part[at..].to_string()]);
            }
        }
        for (k, line) in lines.into_iter().enumerate() {
            area.draw(&Text::new(
                line,
                (x - base.0, y - base.1 + 9 + 15 * k as i32),
                style.clone(),
            ))
            .map_err(err)?;
        }
    }
    Ok(())
}

/// Ticks a vertical log axis shows at least: its labels stack, so it can afford many.
const LOG_Y_TICKS: usize = 6;

/// Ticks a horizontal log axis shows at least; its labels sit side by side, so the sparsest
/// set that gives these few is kept.
const LOG_X_TICKS: usize = 4;

/// Mantissas of log-axis ticks, sparsest first: plotters' own log ticks are whole decades
/// only, which leaves a range shorter than a decade with one label or none.
const LOG_MANTISSAS: [&[f64]; 4] = [
    &[1.0, 2.0, 5.0],
    &[1.0, 2.0, 3.0, 5.0],
    &[1.0, 1.5, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0],
    &[
        1.0, 1.2, 1.4, 1.6, 1.8, 2.0, 2.5, 3.0, 3.5, 4.0, 4.5, 5.0, 6.0, 7.0, 8.0, 9.0,
    ],
];

/// Log-axis tick values inside `lo..hi`: the sparsest mantissa set that gives at least
/// `at_least` ticks (the densest when none does). Each value is the decimal it reads as
/// (0.3, not 3 × 0.1 = 0.30000000000000004).
pub(super) fn log_ticks(lo: f64, hi: f64, at_least: usize) -> Vec<f64> {
    let with = |mantissas: &[f64]| {
        let mut ticks = Vec::new();
        let mut exp = lo.log10().floor() as i32;
        while 10f64.powi(exp) <= hi {
            for m in mantissas {
                let v = if exp >= 0 {
                    m * 10f64.powi(exp)
                } else {
                    m / 10f64.powi(-exp)
                };
                if (lo..=hi).contains(&v) {
                    ticks.push(v);
                }
            }
            exp += 1;
        }
        ticks
    };
    let mut ticks = Vec::new();
    for set in LOG_MANTISSAS {
        ticks = with(set);
        if ticks.len() >= at_least {
            break;
        }
    }
    ticks
}

/// A tick label without float noise: three significant figures (whole numbers whole), no
/// trailing zeros: 0.3, 1.5, 20, 1235.
pub(super) fn short(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let decimals = (2 - v.abs().log10().floor() as i32).clamp(0, 9) as usize;
    let s = format!("{v:.decimals$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

fn lines<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    plot: &LinePlot,
) -> Result<(), DrawError> {
    let values = || {
        plot.panels
            .iter()
            .flat_map(|p| &p.series)
            .flat_map(|s| s.values.iter().flatten().copied())
            .filter(|v| *v > 0.0)
    };
    let lo = values().fold(f64::INFINITY, f64::min);
    let hi = values().fold(0.0, f64::max);
    let (lo, hi) = if lo.is_finite() && hi > 0.0 {
        (lo / 1.4, hi * 1.4)
    } else {
        (0.1, 10.0)
    };
    let n = plot.categories.len().max(1);
    let areas = area.split_evenly((1, plot.panels.len().max(1)));
    for (panel, area) in plot.panels.iter().zip(&areas) {
        let mut chart = panel_chart(area, &panel.caption, 58)
            .build_cartesian_2d(
                categories(-0.4..n as f64 - 0.6, n),
                (lo..hi)
                    .log_scale()
                    .with_key_points(log_ticks(lo, hi, LOG_Y_TICKS)),
            )
            .map_err(err)?;
        let x_fmt = |v: &f64| label_at(&plot.categories, *v);
        let y_fmt = |v: &f64| ms(*v);
        draw_axes(
            chart.configure_mesh().y_labels(15),
            &plot.x_desc,
            Some(&plot.y_desc),
            &x_fmt,
            &y_fmt,
        )?;
        let count = panel.series.len().max(1) as f64;
        for (s, series) in panel.series.iter().enumerate() {
            // A small sideways shift per series keeps equal values from hiding each other.
            let shift = (s as f64 - (count - 1.0) / 2.0) * (0.25 / count);
            let points: Vec<(usize, f64, f64)> = series
                .values
                .iter()
                .enumerate()
                .filter_map(|(i, v)| v.map(|v| (i, i as f64 + shift, v)))
                .collect();
            let curve: Vec<(f64, f64)> = points
                .iter()
                .filter(|(i, _, _)| !(plot.first_apart && *i == 0))
                .map(|&(_, x, v)| (x, v))
                .collect();
            chart
                .draw_series(LineSeries::new(curve, series.color.stroke_width(2)))
                .map_err(err)?;
            chart
                .draw_series(
                    points
                        .iter()
                        .map(|&(_, x, v)| Circle::new((x, v), 5, series.color.filled())),
                )
                .map_err(err)?;
        }
        let style = font(15.0).pos(Pos::new(HPos::Center, VPos::Top));
        for (k, m) in plot.markers.iter().enumerate() {
            chart
                .draw_series(DashedLineSeries::new(
                    [(m.at, lo), (m.at, hi)],
                    8,
                    5,
                    m.color.stroke_width(2),
                ))
                .map_err(err)?;
            // Stacked down from the top, so two changes at one place both stay legible.
            let (x, y) = chart.backend_coord(&(m.at, hi));
            label(area, &m.label, &style, (x, y + 4 + 18 * k as i32))?;
        }
    }
    Ok(())
}

fn traces<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    plot: &TracePlot,
) -> Result<(), DrawError> {
    let rows = plot.rows.max(1);
    let areas = area.split_evenly((rows, plot.panels.len().div_ceil(rows).max(1)));
    for (panel, area) in plot.panels.iter().zip(&areas) {
        let points = || panel.traces.iter().flat_map(|t| &t.points);
        let y_max = points().map(|p| p.1).fold(0.0, f64::max).max(1e-3) * 1.15;
        let x_max = points().map(|p| p.0).fold(0.0, f64::max).max(1e-3) * 1.15;
        let builder = || panel_chart(area, &panel.caption, 58);
        if plot.log_x {
            let x_min = points()
                .map(|p| p.0)
                .filter(|x| *x > 0.0)
                .fold(f64::INFINITY, f64::min);
            let (lo, hi) = if x_min.is_finite() {
                (x_min / 1.3, x_max)
            } else {
                (0.1, 10.0)
            };
            let chart = builder()
                .build_cartesian_2d(
                    (lo..hi)
                        .log_scale()
                        .with_key_points(log_ticks(lo, hi, LOG_X_TICKS)),
                    0.0..y_max,
                )
                .map_err(err)?;
            trace_panel(area, chart, plot, panel, short)?;
        } else {
            let chart = builder()
                .build_cartesian_2d(0.0..x_max, 0.0..y_max)
                .map_err(err)?;
            trace_panel(area, chart, plot, panel, ms)?;
        }
    }
    Ok(())
}

fn trace_panel<DB: DrawingBackend, X>(
    area: &DrawingArea<DB, Shift>,
    mut chart: ChartContext<'_, DB, Cartesian2d<X, RangedCoordf64>>,
    plot: &TracePlot,
    panel: &TracePanel,
    x_label: impl Fn(f64) -> String,
) -> Result<(), DrawError>
where
    X: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    let x_fmt = |v: &f64| x_label(*v);
    let y_fmt = |v: &f64| (plot.y_format)(*v);
    draw_axes(
        &mut chart.configure_mesh(),
        &plot.x_desc,
        Some(&plot.y_desc),
        &x_fmt,
        &y_fmt,
    )?;
    // A point's label is drawn only where it overlaps no label already placed: in a cluster of
    // points the first trace's labels stand for the rest. Labels are drawn after every line.
    let mut placed: Vec<(i32, i32, i32, i32)> = Vec::new();
    let mut labels: Vec<(String, (i32, i32))> = Vec::new();
    let label_style = font(13.0);
    for trace in &panel.traces {
        let line: Vec<(f64, f64)> = trace.points.iter().map(|p| (p.0, p.1)).collect();
        chart
            .draw_series(LineSeries::new(line, trace.color.stroke_width(2)))
            .map_err(err)?;
        chart
            .draw_series(
                trace
                    .points
                    .iter()
                    .map(|(x, y, _)| Circle::new((*x, *y), 5, trace.color.filled())),
            )
            .map_err(err)?;
        for (x, y, label) in trace.points.iter().filter(|p| !p.2.is_empty()) {
            let (px, py) = chart.backend_coord(&(*x, *y));
            let (w, h) = chart
                .plotting_area()
                .estimate_text_size(label, &label_style)
                .map_err(err)?;
            let rect = (px + 7, py - 18, px + 7 + w as i32, py - 18 + h as i32);
            let clear = placed
                .iter()
                .all(|r| rect.2 < r.0 || r.2 < rect.0 || rect.3 < r.1 || r.3 < rect.1);
            if clear {
                placed.push(rect);
                labels.push((label.clone(), (rect.0, rect.1)));
            }
        }
    }
    for (text, at) in labels {
        label(area, &text, &label_style, at)?;
    }
    Ok(())
}

fn stacks<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    plot: &StackPlot,
) -> Result<(), DrawError> {
    let n = plot.rows.len().max(1);
    let top = plot
        .rows
        .iter()
        .flat_map(|r| {
            [
                r.main.iter().map(|p| p.1).sum::<f64>(),
                r.helper.map_or(0.0, |h| h.1),
                r.total,
            ]
        })
        .fold(0.0, f64::max);
    let x_max = if top > 0.0 { top * 1.1 } else { 1.0 };
    // Rows run top to bottom in the order given, so row i sits at y = n - 1 - i.
    let labels: Vec<String> = plot.rows.iter().rev().map(|r| r.label.clone()).collect();
    let longest = labels
        .iter()
        .map(|l| area.estimate_text_size(l, &font(15.0)).map(|s| s.0))
        .try_fold(0, |a, s| s.map(|s| a.max(s)))
        .map_err(err)?;
    let mut chart = ChartBuilder::on(area)
        .margin(10)
        .x_label_area_size(58)
        .y_label_area_size(longest + 24)
        .build_cartesian_2d(0.0..x_max, categories(-0.55..n as f64 - 0.45, n))
        .map_err(err)?;
    let y_fmt = |v: &f64| label_at(&labels, *v);
    let x_fmt = |v: &f64| ms(*v);
    draw_axes(
        chart.configure_mesh().disable_y_mesh(),
        &plot.x_desc,
        None,
        &x_fmt,
        &y_fmt,
    )?;
    for (i, row) in plot.rows.iter().enumerate() {
        let y = (n - 1 - i) as f64;
        let (main_lo, main_hi) = if row.helper.is_some() {
            (y - 0.02, y + 0.36)
        } else {
            (y - 0.2, y + 0.2)
        };
        let mut x = 0.0;
        for &(part, v) in &row.main {
            chart
                .draw_series(std::iter::once(Rectangle::new(
                    [(x, main_lo), (x + v, main_hi)],
                    plot.colors[part].filled(),
                )))
                .map_err(err)?;
            x += v;
        }
        if let Some((part, v)) = row.helper {
            chart
                .draw_series(std::iter::once(Rectangle::new(
                    [(0.0, y - 0.34), (v, y - 0.08)],
                    plot.colors[part].mix(0.75).filled(),
                )))
                .map_err(err)?;
        }
        chart
            .draw_series(std::iter::once(PathElement::new(
                vec![(row.total, y - 0.42), (row.total, y + 0.42)],
                BLACK.stroke_width(3),
            )))
            .map_err(err)?;
    }
    Ok(())
}

fn ranges<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    plot: &RangePlot,
) -> Result<(), DrawError> {
    let values = || {
        plot.panels.iter().flat_map(|p| {
            p.points
                .iter()
                .flat_map(|q| [q.value, q.range.0, q.range.1])
                .chain(p.refs.iter().map(|r| r.value))
        })
    };
    let lo = values().filter(|v| *v > 0.0).fold(f64::INFINITY, f64::min);
    let hi = values().fold(0.0, f64::max);
    let n = plot.rows.len().max(1);
    // Rows run top to bottom in the order given, so row i sits at y = n - 1 - i.
    let labels: Vec<String> = plot.rows.iter().rev().cloned().collect();
    let longest = labels
        .iter()
        .map(|l| area.estimate_text_size(l, &font(15.0)).map(|s| s.0))
        .try_fold(0, |a, s| s.map(|s| a.max(s)))
        .map_err(err)?;
    let y = || categories(-0.6..n as f64 - 0.4, n);
    let areas = area.split_evenly((1, plot.panels.len().max(1)));
    for (panel, area) in plot.panels.iter().zip(&areas) {
        let builder = || {
            let mut b = ChartBuilder::on(area);
            b.caption(&panel.caption, font(19.0))
                .margin(10)
                .x_label_area_size(58)
                .y_label_area_size(longest + 24);
            b
        };
        if plot.log_x && lo.is_finite() {
            // Room on the right for the highest value's label; whole decades when there are
            // enough of them to read the axis by, so that the tick labels keep apart.
            let (x_lo, x_hi) = (lo / 1.6, hi * 5.0);
            let decades: Vec<f64> = (x_lo.log10().ceil() as i32..=x_hi.log10().floor() as i32)
                .map(|e| 10f64.powi(e))
                .collect();
            let ticks = if decades.len() >= LOG_X_TICKS {
                decades
            } else {
                log_ticks(x_lo, x_hi, LOG_X_TICKS)
            };
            let chart = builder()
                .build_cartesian_2d((x_lo..x_hi).log_scale().with_key_points(ticks), y())
                .map_err(err)?;
            range_panel(area, chart, plot, panel, &labels)?;
        } else {
            let chart = builder()
                .build_cartesian_2d(0.0..hi.max(1e-9) * 1.35, y())
                .map_err(err)?;
            range_panel(area, chart, plot, panel, &labels)?;
        }
    }
    Ok(())
}

fn range_panel<DB: DrawingBackend, X>(
    area: &DrawingArea<DB, Shift>,
    mut chart: ChartContext<'_, DB, Cartesian2d<X, Categories>>,
    plot: &RangePlot,
    panel: &RangePanel,
    labels: &[String],
) -> Result<(), DrawError>
where
    X: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    let n = plot.rows.len().max(1);
    let x_fmt = |v: &f64| (plot.format)(*v);
    let y_fmt = |v: &f64| label_at(labels, *v);
    draw_axes(
        chart.configure_mesh().disable_y_mesh(),
        &plot.x_desc,
        None,
        &x_fmt,
        &y_fmt,
    )?;
    for r in &panel.refs {
        chart
            .draw_series(DashedLineSeries::new(
                [(r.value, -0.6), (r.value, n as f64 - 0.4)],
                10,
                6,
                r.color.stroke_width(2),
            ))
            .map_err(err)?;
    }
    let right = chart.backend_coord(&(chart.x_range().end, 0.0)).0;
    let style = font(13.0);
    let mut values = Vec::new();
    for p in &panel.points {
        let y = (n - 1 - p.row) as f64;
        let style = BLACK.stroke_width(2);
        let (lo, hi) = p.range;
        for line in [
            vec![(lo, y), (hi, y)],
            vec![(lo, y - 0.2), (lo, y + 0.2)],
            vec![(hi, y - 0.2), (hi, y + 0.2)],
        ] {
            chart
                .draw_series(std::iter::once(PathElement::new(line, style)))
                .map_err(err)?;
        }
        chart
            .draw_series(std::iter::once(Circle::new(
                (p.value, y),
                6,
                p.color.filled(),
            )))
            .map_err(err)?;
        values.push(((plot.format)(p.value), (lo, hi, y)));
    }
    // Each value right of its whisker, or left of it where the panel ends first.
    for (text, (lo, hi, y)) in values {
        let (w, _) = area.estimate_text_size(&text, &style).map_err(err)?;
        let (px, py) = chart.backend_coord(&(hi, y));
        let (at, h) = if px + 10 + w as i32 <= right {
            ((px + 10, py), HPos::Left)
        } else {
            ((chart.backend_coord(&(lo, y)).0 - 10, py), HPos::Right)
        };
        label(area, &text, &style.pos(Pos::new(h, VPos::Center)), at)?;
    }
    Ok(())
}

/// Nanoseconds in the unit that reads best: ns, µs or ms.
pub(super) fn ns(v: f64) -> String {
    if v >= 1e6 {
        format!("{} ms", short(v / 1e6))
    } else if v >= 1e3 {
        format!("{} µs", short(v / 1e3))
    } else {
        format!("{} ns", short(v))
    }
}

/// Milliseconds with as many decimals as their size needs.
pub(super) fn ms(v: f64) -> String {
    if v >= 100.0 {
        format!("{v:.0}")
    } else if v >= 10.0 {
        format!("{v:.1}")
    } else if v >= 1.0 {
        format!("{v:.2}")
    } else if v >= 0.01 {
        format!("{v:.3}")
    } else if v == 0.0 {
        "0".into()
    } else {
        format!("{v:.1e}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_ticks_read_as_decimals_and_are_dense_enough() {
        let ticks = log_ticks(0.1, 10.0, LOG_X_TICKS);
        assert_eq!(ticks, [0.1, 0.2, 0.5, 1.0, 2.0, 5.0, 10.0]);
        assert!(ticks.contains(&0.2), "0.2 is the decimal, not 2 × 0.1");
        // A narrow range, like the DP frame times of one cell, gets finer ticks.
        let narrow = log_ticks(3.5, 33.0, LOG_Y_TICKS);
        assert!(narrow.len() >= LOG_Y_TICKS, "{narrow:?}");
        assert_eq!(&narrow[..4], [4.0, 5.0, 6.0, 7.0]);
        assert_eq!(log_ticks(0.25, 0.35, 1), [0.3]);
        assert_eq!(log_ticks(0.25, 0.35, 1)[0].to_string(), "0.3");
    }

    #[test]
    fn short_labels_have_no_float_noise() {
        assert_eq!(short(0.1 * 3.0), "0.3");
        assert_eq!(short(0.30000000000000004), "0.3");
        assert_eq!(short(1.5), "1.5");
        assert_eq!(short(20.0), "20");
        assert_eq!(short(0.05), "0.05");
        assert_eq!(short(1234.6), "1235");
    }
}
