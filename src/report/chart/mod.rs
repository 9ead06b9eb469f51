//! Charts drawn from results files: Figure 5-1 and the views that explain it (DP ÷ UP, the
//! hand-off methods, frame-time percentiles, the per-frame breakdown), as PNG and SVG.
//!
//! Each chart is first built as plain data (`render::Chart`), then drawn once per format, so the
//! PNG and the SVG always show the same thing.

mod balance;
mod bars;
mod frames;
mod glyphs;
pub mod history;
mod latency;
mod render;
mod round_trips;

use crate::cell::Mode;
use crate::cell::{Axes, Dim, DimValue, Value};
use crate::results::latency::LatencyRun;
use crate::results::{Cell, CellKey, Results};
use crate::summary::Summary;
use crate::sync::SyncMethod;
use crate::workload::{Synthetic, WorkloadKind};
use itertools::Itertools;
use plotters::style::RGBColor;
use std::path::{Path, PathBuf};
use strum::VariantArray;

crate::named! {
    /// An image format charts are written in.
    pub enum ChartFormat {
        /// A PNG bitmap.
        Png,
        /// An SVG drawing.
        Svg,
    }
}

/// Why charts could not be written.
#[derive(Debug, thiserror::Error)]
pub enum ChartError {
    /// The output directory could not be created.
    #[error("chart directory {}: {source}", path.display())]
    Dir {
        /// The directory.
        path: PathBuf,
        /// What the OS said.
        source: std::io::Error,
    },
    /// The bundled font was rejected by the font loader.
    #[error("the bundled chart font could not be loaded")]
    Font,
    /// Drawing or writing one chart file failed.
    #[error("chart {}: {message}", path.display())]
    Draw {
        /// The file being written.
        path: PathBuf,
        /// What the drawing backend said.
        message: String,
    },
}

/// Every chart, by the file stem it is written under.
pub const CHARTS: [&str; 7] = [
    "figure-5-1",
    "relative",
    "sync",
    "frame-times",
    "breakdown",
    "latency-vs-fps",
    "balance",
];

/// The chart of a latency run, by the file stem it is written under.
pub const LATENCY_CHART: &str = "round-trips";

/// Chart width and height in pixels (the breakdown grows taller when it has many rows).
pub const CHART_SIZE: (u32, u32) = (1600, 900);

/// What to draw and which cell the single-cell charts (frame-times, breakdown) show.
#[derive(Clone, Debug, PartialEq)]
pub struct ChartOptions {
    /// Formats to write every chart in.
    pub formats: Vec<ChartFormat>,
    /// Values to hold dimensions at. Size and workload choose the single-cell charts' cell
    /// (default: each slice's largest measured size, at its highest workload); any other
    /// dimension is held at the value given, leaving only the slices that hold it.
    pub select: Vec<(Dim, Value)>,
}

impl Default for ChartOptions {
    fn default() -> Self {
        ChartOptions {
            formats: vec![ChartFormat::Png, ChartFormat::Svg],
            select: Vec::new(),
        }
    }
}

/// Why a chart has nothing to draw (it is skipped, and the reason printed).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct NothingToDraw(pub String);

impl NothingToDraw {
    fn new(reason: &str) -> NothingToDraw {
        NothingToDraw(reason.to_string())
    }
}

/// A chart that was not drawn, and why.
#[derive(Clone, Debug, PartialEq)]
pub struct Skipped {
    /// The chart's file stem: one of [`CHARTS`], with its slice for a chart drawn per slice.
    pub chart: String,
    /// Why it had nothing to show.
    pub reason: String,
}

/// What [`draw_with`] wrote and what it skipped.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Drawn {
    /// Every file written, in chart order then format order.
    pub files: Vec<PathBuf>,
    /// Charts with no data at all.
    pub skipped: Vec<Skipped>,
}

/// Draws every chart of `results` (several runs go side by side) into `out_dir` in each format.
pub fn draw(
    results: &[Results],
    out_dir: &Path,
    formats: &[ChartFormat],
) -> Result<Vec<PathBuf>, ChartError> {
    let options = ChartOptions {
        formats: formats.to_vec(),
        ..ChartOptions::default()
    };
    draw_with(results, out_dir, &options).map(|d| d.files)
}

/// Draws every chart as [`draw`] does, with a choice of cell, and also says what was skipped.
pub fn draw_with(
    results: &[Results],
    out_dir: &Path,
    options: &ChartOptions,
) -> Result<Drawn, ChartError> {
    write_all(build(results, options), out_dir, &options.formats)
}

/// Draws a latency run's chart into `out_dir` in each format.
pub fn draw_latency(
    run: &LatencyRun,
    out_dir: &Path,
    formats: &[ChartFormat],
) -> Result<Drawn, ChartError> {
    write_all(vec![latency_built(run)], out_dir, formats)
}

/// Writes each drawn chart in each format, and lists the ones with nothing to draw.
fn write_all(
    built: Vec<Built>,
    out_dir: &Path,
    formats: &[ChartFormat],
) -> Result<Drawn, ChartError> {
    prepare(out_dir)?;
    let mut drawn = Drawn::default();
    for built in built {
        match built.drawn {
            Ok(chart) => {
                let files = write_formats(&chart, out_dir, &built.name, formats)?;
                drawn.files.extend(files);
            }
            Err(NothingToDraw(reason)) => drawn.skipped.push(Skipped {
                chart: built.name,
                reason,
            }),
        }
    }
    Ok(drawn)
}

/// One chart as SVG text, for pages that inline them.
pub struct Svg {
    /// Its file stem: one of [`CHARTS`], with its slice for a chart drawn per slice.
    pub name: String,
    /// Which of [`CHARTS`] (or [`LATENCY_CHART`]) it is.
    pub chart: &'static str,
    /// The SVG text, or why it has nothing to draw.
    pub drawn: Result<String, NothingToDraw>,
}

/// Readies drawing into `dir`: the font registered and the folder made.
fn prepare(dir: &Path) -> Result<(), ChartError> {
    render::register_font()?;
    std::fs::create_dir_all(dir).map_err(|source| ChartError::Dir {
        path: dir.to_path_buf(),
        source,
    })
}

/// Writes `chart` into `dir` as `<stem>.<format>` in each of `formats`; the files written.
fn write_formats(
    chart: &render::Chart,
    dir: &Path,
    stem: &str,
    formats: &[ChartFormat],
) -> Result<Vec<PathBuf>, ChartError> {
    let mut files = Vec::new();
    for &format in formats {
        let path = dir.join(format!("{stem}.{}", format.name()));
        render::write(chart, &path, format)?;
        files.push(path);
    }
    Ok(files)
}

/// Every chart, in the order of [`CHARTS`] (a chart drawn per slice once per slice), as SVG
/// text. `options.formats` is not used.
pub fn svgs(results: &[Results], options: &ChartOptions) -> Result<Vec<Svg>, ChartError> {
    build(results, options).into_iter().map(to_svg).collect()
}

/// A latency run's chart as SVG text, for its page.
pub fn latency_svg(run: &LatencyRun) -> Result<Svg, ChartError> {
    to_svg(latency_built(run))
}

fn to_svg(built: Built) -> Result<Svg, ChartError> {
    render::register_font()?;
    let drawn = match built.drawn {
        Ok(chart) => Ok(render::svg(&chart, &built.name)?),
        Err(why) => Err(why),
    };
    Ok(Svg {
        name: built.name,
        chart: built.chart,
        drawn,
    })
}

fn latency_built(run: &LatencyRun) -> Built {
    Built {
        name: LATENCY_CHART.into(),
        chart: LATENCY_CHART,
        drawn: round_trips::round_trips(run),
    }
}

/// One chart as data, under the file stem it is written as.
struct Built {
    name: String,
    chart: &'static str,
    drawn: Result<render::Chart, NothingToDraw>,
}

/// What a chart draws of one slice.
type DrawSlice = fn(&Runs, &Variant) -> Result<render::Chart, NothingToDraw>;

/// Every chart as data, in the order of [`CHARTS`], each once per slice of the dimensions it
/// does not lay out itself.
fn build(results: &[Results], options: &ChartOptions) -> Vec<Built> {
    let runs = Runs::new(results, &options.select);
    let one = |chart: &'static str, drawn| {
        vec![Built {
            name: chart.to_string(),
            chart,
            drawn,
        }]
    };
    // Each of `slices` under its own file stem, unless the run has one slice (`several` false).
    let sliced = |chart: &'static str, slices: &[Variant], several: bool, draw: DrawSlice| {
        let built: Vec<Built> = match slices {
            [] => return one(chart, Err(NothingToDraw::new("no cells in the results"))),
            [only] if !several => return one(chart, draw(&runs, only)),
            slices => slices
                .iter()
                .map(|v| Built {
                    name: format!("{chart}-{}", v.slug()),
                    chart,
                    drawn: draw(&runs, v),
                })
                .collect(),
        };
        // A chart whose dimension the whole run does not vary is skipped once, not per slice.
        match built.first().map(|b| &b.drawn) {
            Some(Err(why)) if built.iter().all(|b| b.drawn.as_ref().err() == Some(why)) => {
                one(chart, Err(why.clone()))
            }
            _ => built,
        }
    };
    let per_slice = |chart: &'static str, laid_out: &[Dim], draw: DrawSlice| {
        let slices = runs.slices(laid_out);
        sliced(chart, &slices, slices.len() > 1, draw)
    };
    let mut out = per_slice(CHARTS[0], &[], bars::figure_5_1);
    out.extend(per_slice(CHARTS[1], &[], bars::relative));
    out.extend(per_slice(CHARTS[2], &[Dim::Sync], bars::sync));
    out.extend(per_slice(CHARTS[3], &[Dim::Sync], frames::frame_times));
    out.extend(per_slice(CHARTS[4], &[Dim::Sync], frames::breakdown));
    out.extend(per_slice(
        CHARTS[5],
        &latency::LAID_OUT,
        latency::latency_vs_fps,
    ));
    // Only the slices a search was run in get a balance chart; a run without cells to slice
    // (balance searches alone) or without a search gets one chart, or one reason.
    let slices = runs.slices(&[]);
    let searched: Vec<Variant> = slices
        .iter()
        .filter(|v| {
            runs.runs
                .iter()
                .any(|r| r.results.balance.iter().any(|e| v.contains(&e.key)))
        })
        .cloned()
        .collect();
    if searched.is_empty() {
        out.extend(one(CHARTS[6], balance::balance(&runs, None)));
    } else {
        out.extend(sliced(CHARTS[6], &searched, slices.len() > 1, |runs, v| {
            balance::balance(runs, Some(v))
        }));
    }
    out
}

/// Method colours, in the methods' declaration order: the Okabe-Ito palette first (the paper's
/// methods), then further colours distinct from it.
const PALETTE: [RGBColor; 16] = [
    RGBColor(0x00, 0x72, 0xb2),
    RGBColor(0xd5, 0x5e, 0x00),
    RGBColor(0x00, 0x9e, 0x73),
    RGBColor(0xcc, 0x79, 0xa7),
    RGBColor(0xe6, 0x9f, 0x00),
    RGBColor(0x56, 0xb4, 0xe9),
    RGBColor(0x11, 0x11, 0x11),
    RGBColor(0x88, 0x22, 0x55),
    RGBColor(0x44, 0xaa, 0x99),
    RGBColor(0x99, 0x99, 0x33),
    RGBColor(0x33, 0x22, 0x88),
    RGBColor(0xaa, 0x44, 0x99),
    RGBColor(0x66, 0x33, 0x00),
    RGBColor(0x11, 0x77, 0x33),
    RGBColor(0xdd, 0xcc, 0x77),
    RGBColor(0x88, 0xcc, 0xee),
];

/// A colour per hand-off method, fixed so a method looks the same in every chart.
pub(super) fn sync_color(sync: SyncMethod) -> RGBColor {
    let at = SyncMethod::VARIANTS.iter().position(|&m| m == sync);
    PALETTE[at.unwrap_or(0) % PALETTE.len()]
}

/// One results file and the name its series carry.
struct Run<'a> {
    label: String,
    results: &'a Results,
}

impl Run<'_> {
    /// Whether the run's config has serial cells at all (charts draw no serial reference and
    /// report none missing for a run that never meant to measure one).
    fn has_serial(&self) -> bool {
        self.results.config.axes.modes.contains(&Mode::Serial)
    }
}

/// The results being charted, with what they have in common.
struct Runs<'a> {
    runs: Vec<Run<'a>>,
    /// The values the user held dimensions at.
    select: Vec<(Dim, Value)>,
}

/// The cells a chart draws: every dimension but the ones the chart lays out (size, workload,
/// mode, and in some charts the hand-off method) held at one value.
#[derive(Clone, Debug)]
struct Variant {
    /// A threaded cell at the chosen values.
    template: CellKey,
    /// The values that set its slice apart from the run's other slices.
    slice: Vec<(Dim, Value)>,
}

/// The dimensions every chart lays out itself.
const LAID_OUT: [Dim; 3] = [Dim::Size, Dim::Workload, Dim::Mode];

impl Variant {
    /// The slice in a file name: `workload_kind-fog`, `helpers-2-depth-2`.
    fn slug(&self) -> String {
        self.slice
            .iter()
            .map(|(d, v)| format!("{}-{v}", d.config_key()))
            .join("-")
    }

    fn sync(&self) -> SyncMethod {
        self.template.sync.expect("the template is a threaded cell")
    }

    fn key(&self, size: usize, workload: usize, mode: Mode, sync: SyncMethod) -> CellKey {
        let key = CellKey {
            size,
            workload,
            sync: Some(sync),
            ..self.template.clone()
        };
        match mode {
            Mode::Serial => key
                .with(Dim::Mode, mode.value())
                .expect("every threaded cell has a serial twin"),
            _ => CellKey { mode, ..key },
        }
    }

    /// Every held value, defaults included, as titles name them, but those of the dimensions
    /// the chart lays out besides size, workload and mode (`also`): a reader must be able to
    /// tell two slices' charts apart by their titles.
    fn describe(&self, also: &[Dim]) -> String {
        held(&[&self.template], also)
    }

    /// Whether `key` lies in the slice (a serial cell lacks the hand-off dimensions, and lies in
    /// every slice its other values match).
    fn contains(&self, key: &CellKey) -> bool {
        self.slice
            .iter()
            .all(|&(d, v)| key.get(d).is_none_or(|k| k == v))
    }
}

/// The values all of `keys` share, as [`Variant::describe`] names them, leaving out the
/// dimensions every chart lays out and `also`.
fn held(keys: &[&CellKey], also: &[Dim]) -> String {
    Dim::ALL
        .iter()
        .filter(|&&d| !LAID_OUT.contains(&d) && !also.contains(&d))
        .filter_map(|&d| {
            let v = keys.first()?.get(d)?;
            keys.iter().all(|k| k.get(d) == Some(v)).then(|| d.title(v))
        })
        .join(", ")
}

/// Cells a chart wanted and did not find, to say so under the chart.
#[derive(Default)]
struct Missing {
    items: Vec<String>,
}

impl Missing {
    fn add(&mut self, item: String) {
        if !self.items.contains(&item) {
            self.items.push(item);
        }
    }

    /// One note line, shortened so that a mostly empty run does not bury the chart.
    fn notes(&self) -> Vec<String> {
        const SHOWN: usize = 12;
        if self.items.is_empty() {
            return vec![];
        }
        let mut line = format!(
            "missing ({}): {}",
            self.items.len(),
            self.items
                .iter()
                .take(SHOWN)
                .cloned()
                .collect::<Vec<_>>()
                .join("; ")
        );
        if self.items.len() > SHOWN {
            line.push_str(&format!("; and {} more", self.items.len() - SHOWN));
        }
        vec![line]
    }
}

/// The display name of a mode, saying how many cores it uses.
fn mode_name(mode: Mode) -> &'static str {
    match mode {
        Mode::Serial => "serial",
        Mode::Up => "UP (1 core)",
        Mode::Dp => "DP (2 cores)",
    }
}

fn short_mode(mode: Mode) -> &'static str {
    match mode {
        Mode::Serial => "serial",
        Mode::Up => "UP",
        Mode::Dp => "DP",
    }
}

/// `2026-11-22T02:17:33Z` as `2026-11-22 02:17 UTC`; other text is shown as it is.
fn run_date(started: &str) -> String {
    match started.get(..16) {
        Some(day_time) if started.ends_with('Z') => format!("{} UTC", day_time.replace('T', " ")),
        _ => started.to_string(),
    }
}

impl<'a> Runs<'a> {
    fn new(results: &'a [Results], select: &[(Dim, Value)]) -> Runs<'a> {
        let names: Vec<String> = results.iter().map(|r| r.config.name.clone()).collect();
        let unique = |labels: &[String]| {
            labels
                .iter()
                .enumerate()
                .all(|(i, l)| !labels[..i].contains(l))
        };
        // Runs are told apart by name; the machine is added only when names collide, and a
        // number only when that is not enough either.
        let labels = if unique(&names) {
            names
        } else {
            let with_machine: Vec<String> = results
                .iter()
                .map(|r| format!("{} on {}", r.config.name, r.machine.cpu_model))
                .collect();
            if unique(&with_machine) {
                with_machine
            } else {
                names
                    .iter()
                    .enumerate()
                    .map(|(i, n)| format!("{n} #{}", i + 1))
                    .collect()
            }
        };
        Runs {
            runs: labels
                .into_iter()
                .zip(results)
                .map(|(label, results)| Run { label, results })
                .collect(),
            select: select.to_vec(),
        }
    }

    fn multi(&self) -> bool {
        self.runs.len() > 1
    }

    /// A series name, prefixed with the run when several runs share the chart.
    fn series(&self, run: &Run, name: &str) -> String {
        if self.multi() {
            format!("{}: {name}", run.label)
        } else {
            name.to_string()
        }
    }

    /// The subtitle lines naming each machine and the date of each run.
    fn machine_lines(&self) -> Vec<String> {
        self.runs
            .iter()
            .map(|run| {
                let r = run.results;
                let line = format!(
                    "{} · run \"{}\" started {}",
                    r.machine.line(),
                    r.config.name,
                    run_date(&r.started)
                );
                if self.multi() {
                    format!("{}: {line}", run.label)
                } else {
                    line
                }
            })
            .collect()
    }

    fn keys(&self) -> impl Iterator<Item = &CellKey> {
        self.runs
            .iter()
            .flat_map(|r| r.results.cells.iter().map(|c| &c.key))
    }

    /// Every value of a numeric dimension listed in a config or measured, ascending.
    pub(super) fn counts(&self, dim: Dim) -> Vec<usize> {
        let listed = self
            .runs
            .iter()
            .flat_map(|r| r.results.config.axes.values(dim));
        let measured = self.keys().filter_map(|k| k.get(dim));
        let mut v: Vec<usize> = listed
            .chain(measured)
            .filter_map(usize::from_value)
            .collect();
        v.sort_unstable();
        v.dedup();
        v
    }

    fn sizes(&self) -> Vec<usize> {
        self.counts(Dim::Size)
    }

    fn workloads(&self) -> Vec<usize> {
        self.counts(Dim::Workload)
    }

    fn modes(&self) -> Vec<Mode> {
        [Mode::Serial, Mode::Up, Mode::Dp]
            .into_iter()
            .filter(|&m| {
                self.keys().any(|k| k.mode == m)
                    || self
                        .runs
                        .iter()
                        .any(|r| r.results.config.axes.modes.contains(&m))
            })
            .collect()
    }

    /// The hand-off methods the runs measured or listed that can hand over under the variant's
    /// policy (a `latest`-only method has no cell beside `fifo` ones, so no empty slot for it).
    fn syncs(&self, v: &Variant) -> Vec<SyncMethod> {
        SyncMethod::VARIANTS
            .iter()
            .copied()
            .filter(|&s| v.template.policy.is_none_or(|p| s.serves(p)))
            .filter(|&s| {
                self.keys().any(|k| k.sync == Some(s))
                    || self
                        .runs
                        .iter()
                        .any(|r| r.results.config.axes.sync.contains(&s))
            })
            .collect()
    }

    /// The value of every dimension the charts do not lay out: the one `select` gives, else the
    /// first in config order that a measured cell has. Dimensions are fixed in order, each among
    /// the cells that match the ones before, so the chosen combination was measured.
    fn choose_variant(&self, select: &[(Dim, Value)]) -> Option<Variant> {
        let mut cells: Vec<&CellKey> = self.keys().filter(|k| !k.is_serial()).collect();
        if cells.is_empty() {
            cells = self.keys().collect();
        }
        let first = *cells.first()?;
        let mut chosen: Vec<(Dim, Value)> = Vec::new();
        for &dim in Dim::ALL.iter().filter(|d| !LAID_OUT.contains(d)) {
            let listed = self
                .runs
                .iter()
                .flat_map(|r| r.results.config.axes.values(dim));
            let measured = cells.iter().filter_map(|k| k.get(dim));
            let value = match select.iter().find(|(d, _)| *d == dim) {
                Some(&(_, v)) => Some(v),
                None => listed
                    .chain(measured)
                    .find(|&v| cells.iter().any(|k| k.get(dim) == Some(v))),
            };
            if let Some(v) = value {
                cells.retain(|k| k.get(dim).is_none_or(|x| x == v));
                chosen.push((dim, v));
            }
        }
        // A serial-only run still needs a method for its template: the default sweep's first.
        let defaults = Axes::default();
        let template = CellKey::from_fn(|d| match d {
            Dim::Mode => Some(Mode::Up.value()),
            _ => chosen
                .iter()
                .find(|(c, _)| *c == d)
                .map(|&(_, v)| v)
                .or_else(|| first.get(d))
                .or_else(|| defaults.values(d).first().copied()),
        })
        .ok()?;
        Some(Variant {
            template,
            slice: Vec::new(),
        })
    }

    /// A variant per slice ([`crate::findings::Slice`]) of a chart that lays out `laid_out`
    /// itself: the findings' slice dimensions of every run but those, each combination of their
    /// values that a threaded cell (in a serial-only run, any cell) has, in cell order, without
    /// those the selection rules out.
    fn slices(&self, laid_out: &[Dim]) -> Vec<Variant> {
        let select = self.select.as_slice();
        let dims: Vec<Dim> = Dim::ALL
            .iter()
            .copied()
            .filter(|d| !laid_out.contains(d))
            .filter(|d| {
                self.runs
                    .iter()
                    .any(|r| crate::findings::slice_dims(r.results).contains(d))
            })
            .collect();
        let threaded = self.keys().any(|k| !k.is_serial());
        let mut combos: Vec<Vec<(Dim, Value)>> = Vec::new();
        for key in self.keys().filter(|k| !threaded || !k.is_serial()) {
            let combo: Vec<(Dim, Value)> = dims
                .iter()
                .filter_map(|&d| Some((d, key.get(d)?)))
                .collect();
            let chosen = combo
                .iter()
                .all(|(d, v)| select.iter().all(|(s, w)| s != d || w == v));
            if chosen && !combos.contains(&combo) {
                combos.push(combo);
            }
        }
        combos
            .into_iter()
            .filter_map(|combo| {
                let mut held = select.to_vec();
                held.extend(combo.iter().copied());
                let mut v = self.choose_variant(&held)?;
                v.slice = combo;
                Some(v)
            })
            .collect()
    }

    /// The cell of the single-cell charts in the slice: the largest size with a measured cell
    /// there, at its highest measured workload, unless the selection names them.
    fn focus(&self, v: &Variant) -> Option<(usize, usize)> {
        let selected = |dim| {
            self.select
                .iter()
                .find(|(d, _)| *d == dim)
                .and_then(|&(_, v)| usize::from_value(v))
        };
        let (size, workload) = (selected(Dim::Size), selected(Dim::Workload));
        let measured = || {
            self.runs
                .iter()
                .flat_map(|r| &r.results.cells)
                .filter(|c| c.summary.is_some() && v.contains(&c.key))
                .map(|c| &c.key)
        };
        let size = size.or_else(|| measured().map(|k| k.size).max())?;
        let workload = workload.or_else(|| {
            measured()
                .filter(|k| k.size == size)
                .map(|k| k.workload)
                .max()
        })?;
        Some((size, workload))
    }

    /// A measured cell of the slice at `size` and `workload`, for what its workload amounted to:
    /// DP's, else UP's, else serial's.
    fn level_cell(&self, v: &Variant, size: usize, workload: usize) -> Option<&'a Cell> {
        [Mode::Dp, Mode::Up, Mode::Serial]
            .into_iter()
            .find_map(|mode| {
                let key = v.key(size, workload, mode, v.sync());
                self.runs.iter().find_map(|r| r.results.cell(&key))
            })
    }

    /// The title of a workload-level axis: what the slice's workload kind does per frame, in
    /// its unit.
    fn workload_axis(&self, v: &Variant) -> String {
        let kind = v.template.workload_kind;
        let unit = self
            .sizes()
            .into_iter()
            .cartesian_product(self.workloads())
            .find_map(|(s, w)| self.level_cell(v, s, w))
            .map_or(kind.unit(), |c| c.workload_unit());
        match unit {
            Synthetic::UNIT if kind == WorkloadKind::SYNTHETIC => {
                "workload level (synthetic main-thread work, µs per frame)".into()
            }
            _ => format!(
                "workload level ({}: {} per frame)",
                kind.name(),
                kind.amount_text("N", unit)
            ),
        }
    }

    /// A workload level's tick: its index, then what it amounted to at `size` in the slice (µs
    /// for the synthetic chain, else the amount as its kind words it: `19³ voxels`).
    fn level_tick(&self, v: &Variant, size: usize, workload: usize) -> String {
        let head = format!("workload {workload}");
        let Some(cell) = self.level_cell(v, size, workload) else {
            return head;
        };
        let amount = cell.workload_amount();
        let synthetic = v.template.workload_kind == WorkloadKind::SYNTHETIC;
        let tail = match cell.workload_unit() {
            Synthetic::UNIT if synthetic => {
                let micros = cell
                    .calibration
                    .as_ref()
                    .map(|c| c.level_micros)
                    .or_else(|| {
                        self.runs.iter().find_map(|r| {
                            let levels = &r.results.calibration.levels;
                            levels
                                .iter()
                                .find(|l| l.workload == workload)
                                .map(|l| l.micros)
                        })
                    });
                match micros {
                    Some(us) => format!("{} µs", render::short(us)),
                    None => amount.to_string(),
                }
            }
            unit => (cell.key.workload_kind).amount_text(&amount.to_string(), unit),
        };
        format!("{head}\n{tail}")
    }

    /// The summary of `key` in `run`, noting it as missing (or failed) when there is none.
    fn summary(&self, run: &Run<'a>, key: &CellKey, missing: &mut Missing) -> Option<&'a Summary> {
        let cell = run.results.cell(key);
        let what = match cell {
            Some(c) if c.summary.is_some() => return c.summary.as_ref(),
            Some(_) => "failed",
            None => "not measured",
        };
        let mut label = format!(
            "{0}×{0} w{1} {2}",
            key.size,
            key.workload,
            short_mode(key.mode)
        );
        if let Some(s) = key.sync {
            label.push(' ');
            label.push_str(s.name());
        }
        let label = self.series(run, &label);
        missing.add(if what == "failed" {
            format!("{label} (failed)")
        } else {
            label
        });
        None
    }
}
